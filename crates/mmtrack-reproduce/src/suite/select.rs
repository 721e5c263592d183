//! One number out of a table directory: the rows a suite metric names
//! (Hive partitions such as `sequence=drive-a/` or `run=cfear/`, then
//! column equalities), one column of them, reduced to one value.
//!
//! Read with the `parquet` crate, so any writer's Parquet works (pyarrow,
//! polars, DuckDB) as long as the column is numeric or boolean.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use arrow_array::cast::AsArray;
use arrow_array::types::{
    Float32Type, Float64Type, Int8Type, Int16Type, Int32Type, Int64Type, UInt8Type, UInt16Type, UInt32Type, UInt64Type,
};
use arrow_array::{Array, RecordBatch};
use arrow_schema::DataType;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use serde::Deserialize;

/// Most Parquet files one metric may read (a table of a few thousand
/// sequences); more is refused before reading any.
pub const MAX_FILES: usize = 100_000;

/// A value a row must hold in a column or partition key.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum Wanted {
    /// Equal as text (string columns, partition keys).
    Text(String),
    /// Equal as a number (numeric columns; partition keys parsed as numbers).
    Number(f64),
    /// Equal as a boolean.
    Bool(bool),
}

impl std::fmt::Display for Wanted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Text(s) => write!(f, "\"{s}\""),
            Self::Number(v) => write!(f, "{v}"),
            Self::Bool(b) => write!(f, "{b}"),
        }
    }
}

/// How the selected rows become one value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Aggregate {
    /// Arithmetic mean.
    Mean,
    /// Smallest value.
    Min,
    /// Largest value.
    Max,
    /// Sum.
    Sum,
    /// Number of rows (the column is not read).
    Count,
}

/// The rows and the column of one metric.
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    /// `(column or partition key, value)`: every one must hold.
    pub filters: Vec<(String, Wanted)>,
    /// The column the value comes from.
    pub column: String,
    /// Required when more than one row is selected.
    pub aggregate: Option<Aggregate>,
}

/// The value and how many rows it came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Selected {
    /// The value (NaN when the table holds NaN).
    pub value: f64,
    /// Rows selected.
    pub rows: usize,
}

/// The value `selection` names in the table directory `table_dir`.
///
/// # Errors
/// No such directory (naming the tables beside it), no Parquet file, a
/// filter or the column absent from a file (naming the file and its
/// columns), a non-numeric column, a null, no row selected (naming the
/// partitions there), or several rows without an aggregate.
pub fn select(table_dir: &Path, selection: &Selection) -> anyhow::Result<Selected> {
    if !table_dir.is_dir() {
        let beside = table_dir.parent().map(subdirectories).unwrap_or_default();
        bail!("{}: no such table directory (directories beside it: {})", table_dir.display(), list(&beside));
    }
    let files = parquet_files(table_dir)?;
    if files.is_empty() {
        bail!("{}: no Parquet file in this table directory", table_dir.display());
    }
    let mut values = Vec::new();
    let mut partitions_seen = Vec::new();
    for (partitions, file) in &files {
        for (key, value) in partitions {
            let seen = format!("{key}={value}");
            if !partitions_seen.contains(&seen) {
                partitions_seen.push(seen);
            }
        }
        values.extend(values_of_file(file, partitions, selection)?);
    }
    let rows = values.len();
    let filters = if selection.filters.is_empty() {
        "no filter".to_string()
    } else {
        selection.filters.iter().map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(" and ")
    };
    let value = match (rows, selection.aggregate) {
        (0, _) => bail!("{}: no row has {filters} (partitions there: {})", table_dir.display(), list(&partitions_seen)),
        (_, Some(Aggregate::Count)) => rows as f64,
        (1, None) => values[0],
        (_, None) => bail!(
            "{}: {rows} rows have {filters}; narrow them with `sequence`/`where` or give an `aggregate` (mean, min, \
             max, sum, count)",
            table_dir.display()
        ),
        (_, Some(Aggregate::Mean)) => values.iter().sum::<f64>() / rows as f64,
        (_, Some(Aggregate::Sum)) => values.iter().sum(),
        (_, Some(Aggregate::Min)) => values.iter().copied().fold(f64::INFINITY, f64::min),
        (_, Some(Aggregate::Max)) => values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    };
    Ok(Selected { value, rows })
}

fn list(items: &[String]) -> String {
    if items.is_empty() { "none".to_string() } else { items.join(", ") }
}

fn subdirectories(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter(|e| e.path().is_dir())
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .collect();
    names.sort();
    names
}

/// The `key=value` folders of a file's path, outermost first.
type Partitions = Vec<(String, String)>;

/// Every `*.parquet` under `dir` with the partitions of its path, in path
/// order. Hidden entries (partials being written) are skipped.
fn parquet_files(dir: &Path) -> anyhow::Result<Vec<(Partitions, PathBuf)>> {
    let mut out = Vec::new();
    let mut stack = vec![(Vec::new(), dir.to_path_buf())];
    while let Some((partitions, d)) = stack.pop() {
        let mut entries: Vec<_> = std::fs::read_dir(&d)
            .with_context(|| d.display().to_string())?
            .collect::<Result<_, _>>()
            .with_context(|| d.display().to_string())?;
        entries.sort_by_key(std::fs::DirEntry::file_name);
        for entry in entries.into_iter().rev() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') {
                continue;
            }
            let path = entry.path();
            if path.is_dir() {
                let mut inner: Partitions = partitions.clone();
                if let Some((key, value)) = name.split_once('=') {
                    inner.push((key.to_string(), value.to_string()));
                }
                stack.push((inner, path));
            } else if name.ends_with(".parquet") {
                if out.len() == MAX_FILES {
                    bail!(
                        "{}: more than {MAX_FILES} Parquet files; point the metric at a smaller table",
                        dir.display()
                    );
                }
                out.push((partitions.clone(), path));
            }
        }
    }
    out.sort_by(|a, b| a.1.cmp(&b.1));
    Ok(out)
}

/// The selected values of one file.
fn values_of_file(file: &Path, partitions: &[(String, String)], selection: &Selection) -> anyhow::Result<Vec<f64>> {
    let name = file.display().to_string();
    // A filter on a partition key decides the whole file.
    let mut column_filters = Vec::new();
    for (key, wanted) in &selection.filters {
        match partitions.iter().find(|(k, _)| k == key) {
            Some((_, value)) if !partition_matches(value, wanted) => return Ok(Vec::new()),
            Some(_) => {}
            None => column_filters.push((key.as_str(), wanted)),
        }
    }
    let reader = std::fs::File::open(file).with_context(|| name.clone())?;
    let builder = ParquetRecordBatchReaderBuilder::try_new(reader).with_context(|| name.clone())?;
    let schema = builder.schema().clone();
    let columns: Vec<String> = schema.fields().iter().map(|f| f.name().clone()).collect();
    let partition_keys: Vec<String> = partitions.iter().map(|(k, _)| k.clone()).collect();
    for (key, _) in &column_filters {
        if !columns.iter().any(|c| c == key) {
            bail!(
                "{name}: no column or partition `{key}` (columns: {}; partitions: {})",
                columns.join(", "),
                list(&partition_keys)
            );
        }
    }
    let counting = selection.aggregate == Some(Aggregate::Count);
    if !counting && !columns.iter().any(|c| c == &selection.column) {
        // A partition key is text (the sequence or run of the path), not a number to check.
        if partition_keys.contains(&selection.column) {
            bail!(
                "{name}: `{}` is a partition (text from the path), not a numeric column (columns: {})",
                selection.column,
                columns.join(", ")
            );
        }
        bail!("{name}: no column `{}` (columns: {})", selection.column, columns.join(", "));
    }
    let mut values = Vec::new();
    let mut row0 = 0;
    for batch in builder.build().with_context(|| name.clone())? {
        let batch = batch.with_context(|| name.clone())?;
        for row in 0..batch.num_rows() {
            let mut keep = true;
            for (key, wanted) in &column_filters {
                keep &=
                    cell_matches(&batch, key, row, wanted).with_context(|| format!("{name}: row {}", row0 + row))?;
            }
            if !keep {
                continue;
            }
            if counting {
                values.push(1.0);
            } else {
                let value = cell_number(&batch, &selection.column, row)
                    .with_context(|| format!("{name}: row {}: {}", row0 + row, selection.column))?;
                values.push(value);
            }
        }
        row0 += batch.num_rows();
    }
    Ok(values)
}

fn partition_matches(value: &str, wanted: &Wanted) -> bool {
    match wanted {
        Wanted::Text(s) => value == s,
        Wanted::Number(v) => value.parse::<f64>().is_ok_and(|p| p == *v),
        Wanted::Bool(b) => value.parse::<bool>().is_ok_and(|p| p == *b),
    }
}

fn cell_matches(batch: &RecordBatch, column: &str, row: usize, wanted: &Wanted) -> anyhow::Result<bool> {
    let array = batch.column_by_name(column).context("column vanished")?;
    if array.is_null(row) {
        return Ok(false);
    }
    Ok(match (array.data_type(), wanted) {
        (DataType::Utf8, Wanted::Text(s)) => array.as_string::<i32>().value(row) == s,
        (DataType::LargeUtf8, Wanted::Text(s)) => array.as_string::<i64>().value(row) == s,
        (DataType::Utf8View, Wanted::Text(s)) => array.as_string_view().value(row) == s,
        (DataType::Boolean, Wanted::Bool(b)) => array.as_boolean().value(row) == *b,
        (_, Wanted::Number(v)) => number_at(array.as_ref(), row).with_context(|| column.to_string())? == *v,
        (t, w) => bail!("{column}: a {t} column cannot equal {w}"),
    })
}

fn cell_number(batch: &RecordBatch, column: &str, row: usize) -> anyhow::Result<f64> {
    let array = batch.column_by_name(column).context("column vanished")?;
    if array.is_null(row) {
        bail!("null");
    }
    number_at(array.as_ref(), row)
}

/// A numeric or boolean cell as `f64` (integers above 2^53 lose precision,
/// as in any f64 comparison).
#[allow(clippy::cast_precision_loss)]
fn number_at(array: &dyn Array, row: usize) -> anyhow::Result<f64> {
    Ok(match array.data_type() {
        DataType::Float64 => array.as_primitive::<Float64Type>().value(row),
        DataType::Float32 => f64::from(array.as_primitive::<Float32Type>().value(row)),
        DataType::Int64 => array.as_primitive::<Int64Type>().value(row) as f64,
        DataType::Int32 => f64::from(array.as_primitive::<Int32Type>().value(row)),
        DataType::Int16 => f64::from(array.as_primitive::<Int16Type>().value(row)),
        DataType::Int8 => f64::from(array.as_primitive::<Int8Type>().value(row)),
        DataType::UInt64 => array.as_primitive::<UInt64Type>().value(row) as f64,
        DataType::UInt32 => f64::from(array.as_primitive::<UInt32Type>().value(row)),
        DataType::UInt16 => f64::from(array.as_primitive::<UInt16Type>().value(row)),
        DataType::UInt8 => f64::from(array.as_primitive::<UInt8Type>().value(row)),
        DataType::Boolean => f64::from(u8::from(array.as_boolean().value(row))),
        other => bail!("a {other} column is not a number"),
    })
}
