use arrow_array::cast::AsArray;
use arrow_array::types::{Float64Type, Int64Type, UInt32Type, UInt64Type};
use arrow_array::{
    Array, BinaryArray, BooleanArray, Float64Array, Int64Array, ListArray, RecordBatch, StringArray, UInt32Array,
    UInt64Array,
};

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

    fn column(&self, name: &str) -> Result<&'a dyn Array, String> {
        self.batch.column_by_name(name).map(|c| c.as_ref()).ok_or_else(|| missing(name))
    }

    /// An `int64` column.
    pub fn i64(&self, name: &str) -> Result<&'a Int64Array, String> {
        self.column(name)?.as_primitive_opt::<Int64Type>().ok_or_else(|| missing(name))
    }

    /// A `uint64` column.
    pub fn u64(&self, name: &str) -> Result<&'a UInt64Array, String> {
        self.column(name)?.as_primitive_opt::<UInt64Type>().ok_or_else(|| missing(name))
    }

    /// A `uint32` column.
    pub fn u32(&self, name: &str) -> Result<&'a UInt32Array, String> {
        self.column(name)?.as_primitive_opt::<UInt32Type>().ok_or_else(|| missing(name))
    }

    /// A `float64` column.
    pub fn f64(&self, name: &str) -> Result<&'a Float64Array, String> {
        self.column(name)?.as_primitive_opt::<Float64Type>().ok_or_else(|| missing(name))
    }

    /// A `bool` column.
    pub fn bool(&self, name: &str) -> Result<&'a BooleanArray, String> {
        self.column(name)?.as_boolean_opt().ok_or_else(|| missing(name))
    }

    /// A `string` column.
    pub fn utf8(&self, name: &str) -> Result<&'a StringArray, String> {
        self.column(name)?.as_string_opt::<i32>().ok_or_else(|| missing(name))
    }

    /// A `binary` column.
    pub fn binary(&self, name: &str) -> Result<&'a BinaryArray, String> {
        self.column(name)?.as_binary_opt::<i32>().ok_or_else(|| missing(name))
    }

    /// A `list<...>` column.
    pub fn list(&self, name: &str) -> Result<&'a ListArray, String> {
        self.column(name)?.as_list_opt::<i32>().ok_or_else(|| missing(name))
    }

    /// Row `row` of a `list<float64>` column, nulls rejected.
    pub fn list_f64(&self, name: &str, row: usize) -> Result<Vec<f64>, String> {
        let values = self.list(name)?.value(row);
        let values = values.as_primitive_opt::<Float64Type>().ok_or_else(|| missing(name))?;
        no_nulls(values, name, row)?;
        Ok(values.values().to_vec())
    }

    /// Row `row` of a `list<int64>` column, nulls rejected.
    pub fn list_i64(&self, name: &str, row: usize) -> Result<Vec<i64>, String> {
        let values = self.list(name)?.value(row);
        let values = values.as_primitive_opt::<Int64Type>().ok_or_else(|| missing(name))?;
        no_nulls(values, name, row)?;
        Ok(values.values().to_vec())
    }

    /// Row `row` of a `list<bool>` column, nulls rejected.
    pub fn list_bool(&self, name: &str, row: usize) -> Result<Vec<bool>, String> {
        let values = self.list(name)?.value(row);
        let values = values.as_boolean_opt().ok_or_else(|| missing(name))?;
        no_nulls(values, name, row)?;
        Ok(values.iter().map(|v| v.unwrap_or(false)).collect())
    }
}

fn no_nulls(values: &dyn Array, name: &str, row: usize) -> Result<(), String> {
    if values.null_count() > 0 { Err(format!("row {row}: column '{name}' holds null list items")) } else { Ok(()) }
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
