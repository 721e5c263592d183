//! What the Navtech folder layouts (Oxford, Boreas, MulRan) share: a folder of
//! `<stamp>.png` scans named by their time, listed in time order, and decoded
//! on the rayon pool while the caller writes them in order.

use std::path::{Path, PathBuf};

use crate::IngestError;
use crate::error::os_err;

/// One scan file of a folder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScanFile {
    /// Scan stamp from the file name, nanoseconds.
    pub t_ns: i64,
    /// The PNG.
    pub path: PathBuf,
}

/// Unit of the numbers in scan file names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StampUnit {
    /// UNIX microseconds (Oxford, Boreas).
    Micros,
    /// UNIX nanoseconds (MulRan).
    Nanos,
}

impl StampUnit {
    /// Parses a file-name stamp into positive nanoseconds.
    pub fn parse(self, path: &Path, record: &str, raw: &str) -> Result<i64, IngestError> {
        let (factor, name) = match self {
            Self::Micros => (1000, "microsecond"),
            Self::Nanos => (1, "nanosecond"),
        };
        raw.parse::<i64>().ok().and_then(|t| t.checked_mul(factor)).filter(|t| *t > 0).ok_or_else(|| {
            IngestError::BadRecord {
                path: path.to_path_buf(),
                record: record.into(),
                field: "timestamp".into(),
                detail: format!("'{raw}' is not a {name} UNIX timestamp"),
            }
        })
    }
}

/// Every `*.png` of `dir` whose name is all digits, in time order. Fails when
/// the folder holds none or two files carry the same stamp.
pub fn list_scan_pngs(dir: &Path, unit: StampUnit) -> Result<Vec<ScanFile>, IngestError> {
    let mut scans = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(os_err(dir))? {
        let path = entry.map_err(os_err(dir))?.path();
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        if path.extension().is_some_and(|e| e == "png") && !stem.is_empty() && stem.bytes().all(|b| b.is_ascii_digit())
        {
            let t_ns = unit.parse(&path, "file name", stem)?;
            scans.push(ScanFile { t_ns, path });
        }
    }
    sort_and_check(dir, scans)
}

/// Sorts scans by time; fails on an empty list or a repeated stamp.
pub fn sort_and_check(dir: &Path, mut scans: Vec<ScanFile>) -> Result<Vec<ScanFile>, IngestError> {
    scans.sort_by_key(|s| s.t_ns);
    if let Some(w) = scans.windows(2).find(|w| w[0].t_ns == w[1].t_ns) {
        return Err(IngestError::BadLayout { path: w[1].path.clone(), detail: "scan timestamp listed twice".into() });
    }
    if scans.is_empty() {
        return Err(IngestError::BadLayout {
            path: dir.to_path_buf(),
            detail: "no scans found (empty folder?)".into(),
        });
    }
    Ok(scans)
}

/// The folder's own name (after resolving `.` and links), or `sequence`.
#[must_use]
pub fn folder_name(root: &Path) -> String {
    root.canonicalize()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "sequence".into())
}

/// Scans decoded ahead of the writer, per thread of the pool.
const DECODED_PER_THREAD: usize = 2;

/// Reads and decodes the scans on the current rayon pool and hands them to
/// `write` in file order.
///
/// Up to [`DECODED_PER_THREAD`] scans per thread are decoded ahead while
/// `write` takes them in order ([`mmtrack_core::parallel::map_in_order`]), so
/// at most `DECODED_PER_THREAD * threads` decoded scans are in memory whatever
/// the folder size, and the output is the same for any thread count. PNG
/// decoding (inflate and unfilter, needed to reach the row headers) is most of
/// an ingest's time.
pub fn decode_in_order<T: Send>(
    scans: &[ScanFile],
    decode: &(dyn Fn(&ScanFile) -> Result<T, IngestError> + Sync),
    write: &mut (dyn FnMut(usize, T) -> Result<(), IngestError> + Send),
) -> Result<(), IngestError> {
    mmtrack_core::parallel::map_in_order(
        scans.iter().enumerate(),
        DECODED_PER_THREAD,
        |(index, scan)| (index, decode(scan)),
        |(index, decoded)| write(index, decoded?),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn listing_takes_numeric_pngs_in_time_order_and_names_bad_stamps() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["30.png", "10.png", "20.png", "notes.txt", "cart.png.bak"] {
            std::fs::write(dir.path().join(name), b"x").unwrap();
        }
        let scans = list_scan_pngs(dir.path(), StampUnit::Nanos).unwrap();
        assert_eq!(scans.iter().map(|s| s.t_ns).collect::<Vec<_>>(), vec![10, 20, 30]);
        let scans = list_scan_pngs(dir.path(), StampUnit::Micros).unwrap();
        assert_eq!(scans[0].t_ns, 10_000);

        std::fs::write(dir.path().join("0.png"), b"x").unwrap();
        let err = list_scan_pngs(dir.path(), StampUnit::Nanos).unwrap_err().to_string();
        assert!(err.contains("0.png") && err.contains("timestamp") && err.contains("nanosecond"), "{err}");

        let empty = tempfile::tempdir().unwrap();
        let err = list_scan_pngs(empty.path(), StampUnit::Nanos).unwrap_err().to_string();
        assert!(err.contains("no scans found"), "{err}");
    }

    #[test]
    fn decode_in_order_keeps_file_order_and_stops_on_the_first_error() {
        let scans: Vec<ScanFile> =
            (1..=9).map(|i| ScanFile { t_ns: i, path: PathBuf::from(format!("{i}.png")) }).collect();
        let mut seen = Vec::new();
        decode_in_order(&scans, &|s: &ScanFile| Ok(s.t_ns * 10), &mut |index, value| {
            seen.push((index, value));
            Ok(())
        })
        .unwrap();
        assert_eq!(seen, (0..9).map(|i| (i, (i as i64 + 1) * 10)).collect::<Vec<_>>());

        let failing = |s: &ScanFile| {
            if s.t_ns == 5 {
                Err(IngestError::BadLayout { path: s.path.clone(), detail: "broken".into() })
            } else {
                Ok(s.t_ns)
            }
        };
        let mut written = 0;
        let err = decode_in_order(&scans, &failing, &mut |_, _| {
            written += 1;
            Ok(())
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains("5.png") && err.contains("broken"), "{err}");
        assert_eq!(written, 4, "scans after the failing one are not written");
    }
}
