use std::path::PathBuf;

use thiserror::Error;

/// Everything that can go wrong reading or writing mmtrack's canonical formats.
///
/// Every variant names the file; record-level variants also name the record
/// (message sequence, row) and the field, so a user can find the bad byte.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum IoError {
    /// An operating-system error on a file.
    #[error("{path}: {source}")]
    Os {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The output exists and overwriting was not requested.
    #[error("{path}: output already exists (pass --force to replace it)")]
    OutputExists {
        /// The existing output.
        path: PathBuf,
    },
    /// The MCAP container is malformed or cut short.
    #[error("{path}: not a readable MCAP recording ({detail}); the file may be truncated or corrupted")]
    CorruptRecording {
        /// The recording.
        path: PathBuf,
        /// What the MCAP parser reported.
        detail: String,
    },
    /// An MCAP write failed.
    #[error("{path}: writing MCAP failed: {detail}")]
    RecordingWrite {
        /// The recording being written.
        path: PathBuf,
        /// What the MCAP writer reported.
        detail: String,
    },
    /// A message could not be decoded with its channel's schema.
    #[error("{path}: message {sequence} on {topic}: {detail}")]
    BadMessage {
        /// The recording.
        path: PathBuf,
        /// Topic of the message.
        topic: String,
        /// MCAP sequence number of the message.
        sequence: u32,
        /// What is wrong.
        detail: String,
    },
    /// A value cannot be represented in the canonical format.
    #[error("{path}: {record}: field {field}: {detail}")]
    BadValue {
        /// The file being written or read.
        path: PathBuf,
        /// Which record (message or row), in words.
        record: String,
        /// The field, with its unit.
        field: &'static str,
        /// What is wrong.
        detail: String,
    },
    /// A Parquet file is unreadable or malformed.
    #[error("{path}: not a readable Parquet table ({detail})")]
    CorruptTable {
        /// The table file.
        path: PathBuf,
        /// What the Parquet reader reported.
        detail: String,
    },
    /// A Parquet table lacks a column its schema requires.
    #[error("{path}: table '{table}' has no column '{column}' (expected columns: {expected})")]
    MissingColumn {
        /// The table file.
        path: PathBuf,
        /// Table name.
        table: String,
        /// The missing column.
        column: String,
        /// The columns the schema requires, comma-separated.
        expected: String,
    },
    /// A Parquet column has the wrong type.
    #[error("{path}: table '{table}' column '{column}' has type {found}, expected {expected}")]
    WrongColumnType {
        /// The table file.
        path: PathBuf,
        /// Table name.
        table: String,
        /// The column.
        column: String,
        /// Type required by the schema.
        expected: String,
        /// Type found in the file.
        found: String,
    },
    /// A Parquet table carries a column its schema does not know.
    #[error("{path}: table '{table}' has unknown column '{column}' (expected columns: {expected})")]
    UnknownColumn {
        /// The table file.
        path: PathBuf,
        /// Table name.
        table: String,
        /// The unexpected column.
        column: String,
        /// The columns the schema defines, comma-separated.
        expected: String,
    },
    /// A Parquet write failed.
    #[error("{path}: writing Parquet failed: {detail}")]
    TableWrite {
        /// The table file.
        path: PathBuf,
        /// What the writer reported.
        detail: String,
    },
}

/// Result alias for this crate.
pub type Result<T, E = IoError> = std::result::Result<T, E>;

/// Attaches a path to an `std::io::Error`.
pub(crate) fn os_err(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> IoError + '_ {
    move |source| IoError::Os { path: path.to_path_buf(), source }
}
