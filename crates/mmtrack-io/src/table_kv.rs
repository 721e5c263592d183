//! The key-value metadata of a Parquet table file (`units`, `time_base`,
//! `frame`, `mmtrack.table`, `mmtrack.version`, `mmtrack.run_config`, ...)
//! and its fields' metadata (`unit`, `description`), read from its footer
//! without reading any rows.

use std::collections::BTreeMap;
use std::fs::File;
use std::path::Path;

use parquet::file::reader::{FileReader, SerializedFileReader};

use crate::error::{IoError, Result, os_err};

/// The key-value pairs of `path`'s footer (a key without a value maps to "").
pub fn read_key_value_metadata(path: &Path) -> Result<BTreeMap<String, String>> {
    let file = File::open(path).map_err(os_err(path))?;
    let reader = SerializedFileReader::new(file)
        .map_err(|e| IoError::CorruptTable { path: path.to_path_buf(), detail: e.to_string() })?;
    let pairs = reader.metadata().file_metadata().key_value_metadata().cloned().unwrap_or_default();
    Ok(pairs.into_iter().map(|kv| (kv.key, kv.value.unwrap_or_default())).collect())
}

/// The metadata of each Arrow field of `path` (`unit`, `description`), by
/// column name in file order, read from the footer without reading any rows.
pub fn read_field_metadata(path: &Path) -> Result<Vec<(String, BTreeMap<String, String>)>> {
    let file = File::open(path).map_err(os_err(path))?;
    let builder = parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(file)
        .map_err(|e| IoError::CorruptTable { path: path.to_path_buf(), detail: e.to_string() })?;
    Ok(builder
        .schema()
        .fields()
        .iter()
        .map(|f| (f.name().clone(), f.metadata().iter().map(|(k, v)| (k.clone(), v.clone())).collect()))
        .collect())
}
