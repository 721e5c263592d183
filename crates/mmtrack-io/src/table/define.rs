//! [`define_table!`](crate::define_table): one declaration per table.

/// Declares a table once: its [`TableSpec`](crate::table::TableSpec) const and
/// the [`TableRow`](crate::table::TableRow) impl of its row type, see `table/rows.rs`.
///
/// - Header: the const's docs, `pub const NAME = "name", "description", frame: TableFrame;`
///   (the [`TableFrame`](crate::table::TableFrame) of its positions and angles).
/// - Then `Row { column: Type, "unit", "meaning"[, value of a row r];* }`: the
///   Arrow type follows from [`ColumnValue`](crate::table::ColumnValue) for
///   `Type` (`Option<T>`: nullable); the value is `|r| &r.column` unless given.
/// - Then how the reader builds a row from variables named like the columns:
///   `Self { columns }` by default, `=> expression`, or `=>? expression` giving a
///   `Result` whose error the reader reports with the row number.
/// - `#[attributes] pub struct Row { ... }` also declares the struct, one public
///   field per column, documented by its meaning.
/// - `Row(Inner);` instead: the columns of `Inner`'s table, for `Row(pub Inner)`.
#[macro_export]
macro_rules! define_table {
    (@get $col:ident) => { |row| &row.$col };
    (@get $col:ident $get:expr) => { $get };
    (@new $row:ident [$($col:ident)*]) => { ::std::result::Result::Ok(Self { $($col),* }) };
    (@new $row:ident [$($col:ident)*] =>? $new:expr) => { ($new).map_err(|e| ::std::format!("row {}: {e}", $row)) };
    (@new $row:ident [$($col:ident)*] => $new:expr) => { ::std::result::Result::Ok($new) };
    (
        $(#[$doc:meta])* $vis:vis const $spec:ident = $name:literal, $description:expr, frame: $frame:expr;
        $(#[$row_attr:meta])* $row_vis:vis struct $row:ident {
            $($col:ident: $ty:ty, $unit:literal, $meaning:literal $(, $get:expr)?;)*
        }
        $($new:tt)*
    ) => {
        $(#[$row_attr])*
        $row_vis struct $row {
            $(#[doc = $meaning] pub $col: $ty,)*
        }
        $crate::define_table! {
            $(#[$doc])* $vis const $spec = $name, $description, frame: $frame;
            $row { $($col: $ty, $unit, $meaning $(, $get)?;)* }
            $($new)*
        }
    };
    (
        $(#[$doc:meta])* $vis:vis const $spec:ident = $name:literal, $description:expr, frame: $frame:expr;
        $row:ident($inner:ty);
    ) => {
        $(#[$doc])*
        $vis const $spec: $crate::table::TableSpec = $crate::table::TableSpec {
            name: $name,
            description: $description,
            columns: <$inner as $crate::table::TableRow>::SPEC.columns,
            frame: $frame,
        };

        impl $crate::table::TableRow for $row {
            const SPEC: &'static $crate::table::TableSpec = &$spec;

            fn to_columns(rows: &[Self]) -> ::std::vec::Vec<$crate::table::ArrayRef> {
                let inner: ::std::vec::Vec<$inner> = rows.iter().map(|r| r.0.clone()).collect();
                <$inner as $crate::table::TableRow>::to_columns(&inner)
            }

            fn from_columns(
                columns: &$crate::table::Columns<'_>,
            ) -> ::std::result::Result<::std::vec::Vec<Self>, ::std::string::String> {
                let inner = <$inner as $crate::table::TableRow>::from_columns(columns)?;
                ::std::result::Result::Ok(inner.into_iter().map($row).collect())
            }
        }
    };
    (
        $(#[$doc:meta])* $vis:vis const $spec:ident = $name:literal, $description:expr, frame: $frame:expr;
        $row:ty {
            $($col:ident: $ty:ty, $unit:literal, $meaning:literal $(, $get:expr)?;)*
        }
        $($new:tt)*
    ) => {
        $(#[$doc])*
        $vis const $spec: $crate::table::TableSpec = $crate::table::TableSpec {
            name: $name,
            description: $description,
            columns: &[$($crate::table::ColumnSpec {
                name: ::std::stringify!($col),
                ty: <$ty as $crate::table::ColumnValue>::TYPE,
                nullable: <$ty as $crate::table::ColumnValue>::NULLABLE,
                unit: $unit,
                meaning: $meaning,
            }),*],
            frame: $frame,
        };

        impl $crate::table::TableRow for $row {
            const SPEC: &'static $crate::table::TableSpec = &$spec;

            fn to_columns(rows: &[Self]) -> ::std::vec::Vec<$crate::table::ArrayRef> {
                ::std::vec![$(<$ty as $crate::table::ColumnValue>::write(
                    rows.iter().map($crate::define_table!(@get $col $($get)?)),
                )),*]
            }

            fn from_columns(
                columns: &$crate::table::Columns<'_>,
            ) -> ::std::result::Result<::std::vec::Vec<Self>, ::std::string::String> {
                $(let $col = <$ty as $crate::table::ColumnValue>::column(columns, ::std::stringify!($col))?;)*
                (0..columns.num_rows())
                    .map(|row| -> ::std::result::Result<Self, ::std::string::String> {
                        $(
                            #[allow(unused_variables)] // a derived column, not needed to build the row
                            let $col = <$ty as $crate::table::ColumnValue>::read(&$col, row, ::std::stringify!($col))?;
                        )*
                        $crate::define_table!(@new row [$($col)*] $($new)*)
                    })
                    .collect()
            }
        }
    };
}
