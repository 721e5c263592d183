use std::path::PathBuf;

use mmtrack_core::error::printable;
use thiserror::Error;

/// Everything that can go wrong reading or writing mmtrack's canonical formats.
///
/// Every variant names the file; record-level variants also name the record
/// (message sequence, row) and the field, so a user can find the bad byte.
///
/// Each message says its part once: text quoted from a file goes through
/// [`printable`] (no raw control bytes), and a wrapped OS error is the
/// [`source`](std::error::Error::source), not repeated in the message, so
/// `anyhow`'s `{:#}` prints `file: problem` once.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum IoError {
    /// An operating-system error on a file (the message names the file; the
    /// OS error is the source).
    #[error("{path}")]
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
    /// The output directory exists as something else (a file, a FIFO, a
    /// device node).
    #[error("{path}: exists and is {kind}, not a directory; choose another output")]
    NotADirectory {
        /// The file in the way.
        path: PathBuf,
        /// What it is, with its article (`a regular file`, `a FIFO`).
        kind: &'static str,
    },
    /// An output file's path exists as something other than a regular file
    /// (a directory, a FIFO, a device node, a socket): never replaced, with or
    /// without `--force`, since replacing means renaming a new file over it.
    #[error("{path}: exists and is {kind}, not a regular file; mmtrack only replaces files it can write atomically")]
    NotARegularFile {
        /// The path in the way.
        path: PathBuf,
        /// What it is, with its article (`a directory`, `a character device`).
        kind: &'static str,
    },
    /// An output that is one of the command's inputs.
    #[error("{path}: is also this command's input {}; choose another output", .input.display())]
    OutputIsInput {
        /// The output as given.
        path: PathBuf,
        /// The input as given.
        input: PathBuf,
    },
    /// `--force` would replace a directory holding entries the command does
    /// not write.
    #[error(
        "{path}: holds {} which `{command}` does not write; refusing to replace it (choose an empty or new output)",
        .entries.join(", ")
    )]
    ForeignEntries {
        /// The directory to be replaced.
        path: PathBuf,
        /// The command that would replace it (`mmtrack simulate radar`).
        command: String,
        /// The entries it does not write, relative to `path`, sorted.
        entries: Vec<String>,
    },
    /// The MCAP container is malformed or cut short.
    #[error("{path}: not a readable MCAP recording ({}); the file may be truncated or corrupted", printable(.detail))]
    CorruptRecording {
        /// The recording.
        path: PathBuf,
        /// What the MCAP parser reported.
        detail: String,
    },
    /// An MCAP write failed.
    #[error("{path}: writing MCAP failed: {}", printable(.detail))]
    RecordingWrite {
        /// The recording being written.
        path: PathBuf,
        /// What the MCAP writer reported.
        detail: String,
    },
    /// A message could not be decoded with its channel's schema.
    #[error("{path}: message {sequence} on {}: {}", printable(.topic), printable(.detail))]
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
    #[error("{path}: {}: field {field}: {}", printable(.record), printable(.detail))]
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
    #[error("{path}: not a readable Parquet table ({})", printable(.detail))]
    CorruptTable {
        /// The table file.
        path: PathBuf,
        /// What the Parquet reader reported.
        detail: String,
    },
    /// A Parquet table lacks a column its schema requires.
    #[error("{path}: table '{}' has no column '{column}' (expected columns: {expected})", printable(.table))]
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
    #[error("{path}: table '{}' column '{}' has type {}, expected {expected}", printable(.table), printable(.column), printable(.found))]
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
    #[error("{path}: table '{}' has unknown column '{}' (expected columns: {expected})", printable(.table), printable(.column))]
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
    #[error("{path}: writing Parquet failed: {}", printable(.detail))]
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Each part once: the OS error is the source, not also in the message;
    /// quoted input is escaped.
    #[test]
    fn messages_say_each_part_once_and_escape_quoted_input() {
        let source = std::io::Error::from(std::io::ErrorKind::NotFound);
        let os = IoError::Os { path: PathBuf::from("x.mcap"), source };
        let source_text = std::error::Error::source(&os).map(ToString::to_string).unwrap_or_default();
        assert_eq!(os.to_string(), "x.mcap");
        assert!(!source_text.is_empty() && !os.to_string().contains(&source_text));

        let bad = IoError::BadMessage {
            path: PathBuf::from("bag.mcap"),
            topic: "/odom\u{1b}[2J".into(),
            sequence: 7,
            detail: "bytes \u{0}\u{7}".into(),
        };
        assert_eq!(bad.to_string(), r"bag.mcap: message 7 on /odom\x1b[2J: bytes \x00\x07");
    }
}
