use std::path::PathBuf;

use mmtrack_core::error::printable;
use thiserror::Error;

/// Errors of the ingest adapters. Each names the file, the record (row, line,
/// scan) and the field, and says what was expected. Text quoted from the
/// input goes through [`printable`]; a wrapped OS error is the source, not
/// repeated in the message.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum IngestError {
    /// An operating-system error on a file (the message names the file; the
    /// OS error is the source).
    #[error("{path}")]
    Os {
        /// The file.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The input folder lacks what the format requires.
    #[error("{path}: {}", printable(.detail))]
    BadLayout {
        /// The folder or file.
        path: PathBuf,
        /// What is missing or wrong.
        detail: String,
    },
    /// A record is malformed.
    #[error("{path}: {}: {}: {}", printable(.record), printable(.field), printable(.detail))]
    BadRecord {
        /// The file.
        path: PathBuf,
        /// Which record, e.g. "azimuth row 17" or "line 5".
        record: String,
        /// The field, e.g. "timestamp (bytes 0-7)".
        field: String,
        /// What is wrong and what was expected.
        detail: String,
    },
    /// A sidecar file (TOML) is malformed or inconsistent.
    #[error("{path}: key `{}`: {}", printable(.key), printable(.detail))]
    BadSidecar {
        /// The sidecar file.
        path: PathBuf,
        /// The key at fault (`(syntax)` for a TOML syntax error).
        key: String,
        /// What is wrong and what was expected.
        detail: String,
    },
    /// The input needs a cargo feature this build was compiled without.
    #[error(
        "{path}: {input} needs mmtrack built with the `{feature}` cargo feature ({needs}): rebuild with \
         `--features {feature}`, e.g. `cargo build --release -p mmtrack-cli --features {feature}`"
    )]
    FeatureMissing {
        /// The file.
        path: PathBuf,
        /// What the file is, e.g. "a MATLAB v7.3 (HDF5) .mat file".
        input: String,
        /// The cargo feature (of `mmtrack-ingest` and `mmtrack-cli`).
        feature: &'static str,
        /// What the feature needs on the machine.
        needs: &'static str,
    },
    /// Writing the recording failed.
    #[error(transparent)]
    Io(#[from] mmtrack_io::IoError),
}

pub(crate) fn os_err(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> IngestError + '_ {
    move |source| IngestError::Os { path: path.to_path_buf(), source }
}
