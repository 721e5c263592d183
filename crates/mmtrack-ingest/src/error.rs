use std::path::PathBuf;

use mmtrack_core::error::printable;
use mmtrack_io::paths::is_device;
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
    /// A record is malformed. A field named as its record (the `data` of a
    /// `.npy` file's `data`) is said once.
    #[error("{path}: {}: {}", record_and_field(.record, .field), printable(.detail))]
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
        /// The key at fault.
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

impl IngestError {
    /// [`IngestError::BadRecord`] of a text file's line `line` (1-based).
    #[must_use]
    pub fn bad_line(path: &std::path::Path, line: usize, field: &str, detail: String) -> Self {
        Self::BadRecord { path: path.to_path_buf(), record: format!("line {line}"), field: field.into(), detail }
    }
}

pub(crate) fn os_err(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> IngestError + '_ {
    move |source| IngestError::Os { path: path.to_path_buf(), source }
}

/// `value` if it is within `bound` (see [`mmtrack_core::plausible`]), else
/// the error naming the file, the record and the field. Every reader checks
/// positions, angles, latitudes and altitudes through this.
pub(crate) fn check_plausible(
    path: &std::path::Path,
    record: impl FnOnce() -> String,
    field: &str,
    bound: &mmtrack_core::plausible::Bound,
    value: f64,
) -> Result<f64, IngestError> {
    bound.check(value).map_err(|e| IngestError::BadRecord {
        path: path.to_path_buf(),
        record: record(),
        field: field.to_string(),
        detail: e.to_string(),
    })
}

/// Opens an input file that will be read up to `limit` bytes, refusing a
/// device (`/dev/zero`) and a file the OS reports over `limit` before reading
/// anything; the file size with it (`None` for a pipe).
pub(crate) fn open_capped(
    path: &std::path::Path,
    limit: &mmtrack_core::limits::Limit,
) -> Result<(std::fs::File, u64), IngestError> {
    let file = std::fs::File::open(path).map_err(os_err(path))?;
    let metadata = file.metadata().map_err(os_err(path))?;
    if is_device(&metadata) {
        return Err(IngestError::BadLayout {
            path: path.to_path_buf(),
            detail: "is a device, not a file or a pipe: nothing to read a recording from".into(),
        });
    }
    let size = metadata.len();
    if size > limit.max as u64 {
        return Err(too_large(path, limit, size.to_string()));
    }
    Ok((file, size))
}

fn too_large(path: &std::path::Path, limit: &mmtrack_core::limits::Limit, size: String) -> IngestError {
    IngestError::BadLayout {
        path: path.to_path_buf(),
        detail: format!("{size} bytes is too large: expected {}", limit.expected),
    }
}

/// Reads a whole input file, refusing one over `limit` before reading it, and
/// stopping one byte past the limit where the OS reports no size (a pipe,
/// `/dev/zero`), so no input makes the reader allocate beyond its limit.
pub(crate) fn read_capped(path: &std::path::Path, limit: &mmtrack_core::limits::Limit) -> Result<Vec<u8>, IngestError> {
    use std::io::Read as _;
    let max_bytes = limit.max as u64;
    let (file, size) = open_capped(path, limit)?;
    let mut bytes = Vec::with_capacity(usize::try_from(size).unwrap_or(0));
    file.take(max_bytes + 1).read_to_end(&mut bytes).map_err(os_err(path))?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(path, limit, format!("more than {max_bytes}")));
    }
    Ok(bytes)
}

/// [`read_capped`] at [`mmtrack_core::limits::TEXT_FILE_BYTES`], as UTF-8
/// text; invalid UTF-8 is an error naming the byte offset.
pub(crate) fn read_text(path: &std::path::Path) -> Result<String, IngestError> {
    let bytes = read_capped(path, &mmtrack_core::limits::TEXT_FILE_BYTES)?;
    String::from_utf8(bytes).map_err(|e| IngestError::BadLayout {
        path: path.to_path_buf(),
        detail: format!("not UTF-8 text: invalid byte at offset {}", e.utf8_error().valid_up_to()),
    })
}

/// [`read_text`] for files of line records (CSV, timestamps, TUM / KITTI
/// poses): a last line without its line end is refused, naming it. Every
/// writer of these formats ends each record with a newline, so a file that
/// stops inside a line was cut off (a copy or download interrupted), and
/// its last number may be shortened ("12.3" of "12.345") without any parse
/// error to show it.
pub(crate) fn read_line_records(path: &std::path::Path) -> Result<String, IngestError> {
    let text = read_text(path)?;
    let tail = text.rsplit_once('\n').map_or(text.as_str(), |(_, tail)| tail);
    if !tail.trim().is_empty() {
        let line = text.lines().count();
        let shown: String = tail.chars().take(60).collect();
        return Err(IngestError::bad_line(
            path,
            line,
            "line end",
            format!(
                "the file ends inside this line (\"{shown}\" has no newline after it): it looks cut off, and its \
                 last record may be shortened; if the file is complete, end it with a newline"
            ),
        ));
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mmtrack_core::limits::Limit;

    /// Every text reader goes through the capped read (or streams, NMEA):
    /// `/dev/zero` given as any of them is a one-line error naming it, at once.
    #[test]
    fn every_text_reader_refuses_an_endless_device_naming_it() {
        let zero = std::path::Path::new("/dev/zero");
        if !zero.exists() {
            return;
        }
        type Reader = Box<dyn Fn() -> Option<IngestError>>;
        let readers: [(&str, Reader); 10] = [
            ("oxford gps.csv", Box::new(|| crate::oxford::gps::read_gps_csv(zero).err())),
            ("oxford ins.csv", Box::new(|| crate::oxford::ins::read_ins_csv(zero).err())),
            ("oxford radar_odometry.csv", Box::new(|| crate::oxford::odometry::read_radar_odometry(zero).err())),
            ("boreas gps", Box::new(|| crate::boreas::gps::read_boreas_gps(zero).err())),
            ("mulran gps.csv", Box::new(|| crate::mulran::gps::read_mulran_gps(zero).err())),
            ("TUM/KITTI poses", Box::new(|| crate::poses::read_text(zero).err())),
            ("DecaWave log", Box::new(|| crate::cir::read_decawave_log(zero, &Default::default()).err())),
            ("CIR CSV", Box::new(|| crate::cir::read_cir_file(crate::cir::CirFormat::Csv, zero, None).err())),
            ("CIR sidecar", Box::new(|| crate::cir::CirSidecar::read(zero).err())),
            ("NMEA", Box::new(|| crate::nmea::read_nmea(zero).err())),
        ];
        for (reader, read) in readers {
            let start = std::time::Instant::now();
            let err = read().map(|e| e.to_string()).unwrap_or_default();
            assert!(err.starts_with("/dev/zero") && !err.contains('\n'), "{reader}: {err:?}");
            assert!(err.contains("is a device") || err.contains("longer than 4096 bytes"), "{reader}: {err}");
            println!("{reader}: {err} ({:.1} ms)", start.elapsed().as_secs_f64() * 1e3);
        }
    }

    /// Before: a CSV cut off inside its last number ingested the shortened
    /// number without a word.
    #[test]
    fn a_record_file_cut_off_inside_its_last_line_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("radar_odometry.csv");
        std::fs::write(&path, "a,b\n1,2.5\n3,4.12").unwrap();
        let err = read_line_records(&path).unwrap_err().to_string();
        assert!(err.contains("radar_odometry.csv: line 3: line end") && err.contains("\"3,4.12\""), "{err}");
        for complete in ["a,b\n1,2.5\n3,4.125\n", "a,b\n1,2\n  ", "a,b\r\n1,2\r\n", ""] {
            std::fs::write(&path, complete).unwrap();
            assert_eq!(read_line_records(&path).unwrap(), complete);
        }
    }

    /// Before: text inputs were read whole whatever their size; `/dev/zero`
    /// as an input grew without bound.
    #[test]
    fn inputs_over_their_limit_and_devices_are_refused_before_reading() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("gt.csv");
        std::fs::write(&path, "0123456789").unwrap();
        let ten = Limit { max: 10.0, expected: "at most 10 bytes" };
        let nine = Limit { max: 9.0, expected: "at most 9 bytes" };
        assert_eq!(read_capped(&path, &ten).unwrap(), b"0123456789");
        let err = read_capped(&path, &nine).unwrap_err().to_string();
        assert!(err.contains("gt.csv") && err.contains("10 bytes is too large: expected at most 9 bytes"), "{err}");
        if std::path::Path::new("/dev/zero").exists() {
            let err = read_text(std::path::Path::new("/dev/zero")).unwrap_err().to_string();
            assert!(err.starts_with("/dev/zero") && err.contains("is a device"), "{err}");
        }
        std::fs::write(&path, b"ok\xff").unwrap();
        let err = read_text(&path).unwrap_err().to_string();
        assert!(err.contains("not UTF-8 text: invalid byte at offset 2"), "{err}");
    }
}

/// `record: field`, or `record` alone when the field is the record itself
/// (before: "data: data: truncated").
fn record_and_field(record: &str, field: &str) -> String {
    if record == field {
        printable(record).into_owned()
    } else {
        format!("{}: {}", printable(record), printable(field))
    }
}

#[cfg(test)]
mod record_field_tests {
    use super::*;

    #[test]
    fn a_field_named_as_its_record_is_said_once() {
        let error = |record: &str, field: &str| {
            IngestError::BadRecord {
                path: "x.npy".into(),
                record: record.into(),
                field: field.into(),
                detail: "truncated".into(),
            }
            .to_string()
        };
        assert_eq!(error("data", "data"), "x.npy: data: truncated");
        assert_eq!(error("header", "header"), "x.npy: header: truncated");
        assert_eq!(error("line 5", "t_ns"), "x.npy: line 5: t_ns: truncated");
    }
}
