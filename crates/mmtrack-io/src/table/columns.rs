use std::borrow::Borrow;
use std::sync::Arc;

use arrow_array::builder::{BooleanBuilder, Float64Builder, Int64Builder, ListBuilder};
use arrow_array::cast::AsArray;
use arrow_array::types::{Float64Type, Int64Type};
use arrow_array::{
    Array, ArrayRef, BinaryArray, BooleanArray, Float64Array, Int64Array, ListArray, RecordBatch, StringArray,
    UInt32Array, UInt64Array,
};

use super::ColumnType;

/// Typed access to the columns of a batch already checked against its spec.
///
/// Getters return `Err` (never panic) on a missing column or a type mismatch,
/// so a spec/code disagreement surfaces as an error naming the column.
pub struct Columns<'a> {
    batch: &'a RecordBatch,
}

fn missing(name: &str) -> String {
    format!("column '{name}' missing or of unexpected type")
}

impl<'a> Columns<'a> {
    pub(crate) fn new(batch: &'a RecordBatch) -> Self {
        Self { batch }
    }

    /// Number of rows.
    #[must_use]
    pub fn num_rows(&self) -> usize {
        self.batch.num_rows()
    }

    /// Column `name` as its Arrow array type `A` (`Int64Array`, `ListArray`, ...).
    pub fn array<A: Array + 'static>(&self, name: &str) -> Result<&'a A, String> {
        self.batch.column_by_name(name).and_then(|c| c.as_any().downcast_ref::<A>()).ok_or_else(|| missing(name))
    }
}

/// Fails when a non-nullable column holds nulls.
pub(crate) fn check_no_nulls(batch: &RecordBatch, name: &str) -> Result<(), String> {
    match batch.column_by_name(name) {
        Some(c) if c.null_count() > 0 => {
            let row = (0..c.len()).find(|&i| c.is_null(i)).unwrap_or(0);
            Err(format!("row {row}: column '{name}' is null but the schema does not allow nulls"))
        }
        _ => Ok(()),
    }
}

/// A Rust value stored in one column: its Arrow type, the column of a list of
/// values, and one value read back. `Option<T>` is the nullable column of `T`.
///
/// [`define_table!`](crate::define_table) generates a table's writer and
/// reader from these; readers downcast each column once, then read row by row.
pub trait ColumnValue: Sized {
    /// Arrow type of the column.
    const TYPE: ColumnType;
    /// Whether the column allows nulls (only `Option<T>` does).
    const NULLABLE: bool = false;
    /// The column, downcast.
    type Column<'a>;
    /// The column of `values`, `None` meaning null.
    fn array(values: &[Option<&Self>]) -> ArrayRef;
    /// Column `name` of a batch, downcast; errors name the column.
    fn column<'a>(columns: &Columns<'a>, name: &str) -> Result<Self::Column<'a>, String>;
    /// Row `row` of column `name`, `None` when null; errors name the row and column.
    fn get(column: &Self::Column<'_>, row: usize, name: &str) -> Result<Option<Self>, String>;

    /// The column of `values`, for writers.
    fn write<B: Borrow<Self>>(values: impl Iterator<Item = B>) -> ArrayRef {
        let values: Vec<B> = values.collect();
        Self::array(&values.iter().map(|v| Some(v.borrow())).collect::<Vec<_>>())
    }

    /// Row `row` of column `name`, for readers: null only as `Option<T>`.
    fn read(column: &Self::Column<'_>, row: usize, name: &str) -> Result<Self, String> {
        Self::get(column, row, name)?.ok_or_else(|| format!("row {row}: column '{name}' is null"))
    }
}

impl<T: ColumnValue> ColumnValue for Option<T> {
    const TYPE: ColumnType = T::TYPE;
    const NULLABLE: bool = true;
    type Column<'a> = T::Column<'a>;
    fn array(values: &[Option<&Self>]) -> ArrayRef {
        T::array(&values.iter().map(|v| v.and_then(Option::as_ref)).collect::<Vec<_>>())
    }
    fn column<'a>(columns: &Columns<'a>, name: &str) -> Result<Self::Column<'a>, String> {
        T::column(columns, name)
    }
    fn get(column: &Self::Column<'_>, row: usize, name: &str) -> Result<Option<Self>, String> {
        T::get(column, row, name).map(Some)
    }
}

/// `ColumnValue` for a type with an Arrow array of its own: the type, its
/// column type, array type, and value as the array takes it.
macro_rules! scalar {
    ($t:ty, $ty:ident, $array:ty, $to_arrow:expr) => {
        impl ColumnValue for $t {
            const TYPE: ColumnType = ColumnType::$ty;
            type Column<'a> = &'a $array;
            fn array(values: &[Option<&Self>]) -> ArrayRef {
                Arc::new(values.iter().map(|v| v.map($to_arrow)).collect::<$array>())
            }
            fn column<'a>(columns: &Columns<'a>, name: &str) -> Result<&'a $array, String> {
                columns.array::<$array>(name)
            }
            fn get(column: &&$array, row: usize, _: &str) -> Result<Option<Self>, String> {
                Ok(column.is_valid(row).then(|| column.value(row).to_owned()))
            }
        }
    };
}

scalar!(i64, Int64, Int64Array, |v: &i64| *v);
scalar!(u64, UInt64, UInt64Array, |v: &u64| *v);
scalar!(u32, UInt32, UInt32Array, |v: &u32| *v);
scalar!(f64, Float64, Float64Array, |v: &f64| *v);
scalar!(bool, Boolean, BooleanArray, |v: &bool| *v);
scalar!(String, Utf8, StringArray, String::as_str);
scalar!(Vec<u8>, Binary, BinaryArray, Vec::as_slice);

/// A `list<...>` column, downcast once: the lists and their items.
pub struct ListColumn<'a, A> {
    lists: &'a ListArray,
    items: &'a A,
}

/// `ColumnValue` for `Vec<item>` stored as `list<item>`: the item type, the
/// column type, the item builder and array, and the items downcast.
macro_rules! list {
    ($item:ty, $ty:ident, $builder:ident, $array:ty, $downcast:ident $(::<$arrow:ty>)?) => {
        impl ColumnValue for Vec<$item> {
            const TYPE: ColumnType = ColumnType::$ty;
            type Column<'a> = ListColumn<'a, $array>;
            fn array(values: &[Option<&Self>]) -> ArrayRef {
                let mut builder = ListBuilder::with_capacity($builder::new(), values.len());
                for items in values {
                    builder.values().append_slice(items.map_or(&[], |items| items.as_slice()));
                    builder.append(items.is_some());
                }
                Arc::new(builder.finish())
            }
            fn column<'a>(columns: &Columns<'a>, name: &str) -> Result<Self::Column<'a>, String> {
                let lists = columns.array::<ListArray>(name)?;
                let items = lists.values().$downcast$(::<$arrow>)?().ok_or_else(|| missing(name))?;
                Ok(ListColumn { lists, items })
            }
            fn get(column: &Self::Column<'_>, row: usize, name: &str) -> Result<Option<Self>, String> {
                let ListColumn { lists, items } = column;
                if lists.is_null(row) {
                    return Ok(None);
                }
                // Offsets are valid by the invariants of `ListArray`; `row` is below its length.
                let range = lists.value_offsets()[row] as usize..lists.value_offsets()[row + 1] as usize;
                if items.null_count() > 0 && range.clone().any(|k| items.is_null(k)) {
                    return Err(format!("row {row}: column '{name}' holds null list items"));
                }
                Ok(Some(range.map(|k| items.value(k)).collect()))
            }
        }
    };
}

list!(f64, ListFloat64, Float64Builder, Float64Array, as_primitive_opt::<Float64Type>);
list!(i64, ListInt64, Int64Builder, Int64Array, as_primitive_opt::<Int64Type>);
list!(bool, ListBoolean, BooleanBuilder, BooleanArray, as_boolean_opt);
