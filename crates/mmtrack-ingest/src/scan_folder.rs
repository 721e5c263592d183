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

/// Earliest plausible scan time, ns: 2000-01-01 00:00 UTC.
const EARLIEST_SCAN_T_NS: i64 = 946_684_800 * 1_000_000_000;
/// Latest plausible scan time, ns: 2100-01-01 00:00 UTC.
const LATEST_SCAN_T_NS: i64 = 4_102_444_800 * 1_000_000_000;

impl StampUnit {
    /// Parses a file-name stamp into nanoseconds. A stamp outside 2000-2100
    /// is refused: it is in another unit (or not a time at all, like
    /// `000001`), and taking it would misplace the scan by decades.
    pub fn parse(self, path: &Path, record: &str, raw: &str) -> Result<i64, IngestError> {
        let (factor, name, example) = match self {
            Self::Micros => (1000, "microsecond", "16 digits, e.g. 1547131046353776"),
            Self::Nanos => (1, "nanosecond", "19 digits, e.g. 1561000000000000000"),
        };
        let bad = |detail: String| IngestError::BadRecord {
            path: path.to_path_buf(),
            record: record.into(),
            field: "timestamp".into(),
            detail,
        };
        let t_ns = raw
            .parse::<i64>()
            .ok()
            .and_then(|t| t.checked_mul(factor))
            .ok_or_else(|| bad(format!("'{raw}' is not a {name} UNIX timestamp")))?;
        if !(EARLIEST_SCAN_T_NS..LATEST_SCAN_T_NS).contains(&t_ns) {
            return Err(bad(format!(
                "'{raw}' is not a plausible {name} UNIX timestamp: expected a time between 2000 and 2100 \
                 ({example})"
            )));
        }
        Ok(t_ns)
    }
}

/// Checks that every scan of a folder has the size of the first one, for
/// layouts that take the size from the files.
#[derive(Debug, Default)]
pub struct SameSize {
    first: Option<(PathBuf, usize, usize)>,
}

impl SameSize {
    /// Records the first scan's azimuth rows and range bins; fails when a
    /// later scan differs, naming both files.
    pub fn check(&mut self, path: &Path, azimuths: usize, bins: usize) -> Result<(), IngestError> {
        match &self.first {
            None => self.first = Some((path.to_path_buf(), azimuths, bins)),
            Some((first, a, b)) if (*a, *b) != (azimuths, bins) => {
                return Err(IngestError::BadRecord {
                    path: path.to_path_buf(),
                    record: "image".into(),
                    field: "size".into(),
                    detail: format!(
                        "{azimuths} azimuths x {bins} range bins; the folder's first scan {} has {a} x {b}",
                        first.display()
                    ),
                });
            }
            Some(_) => {}
        }
        Ok(())
    }
}

/// What is wrong with `path` as an input file: `None` for a regular file
/// (or a symbolic link to one) that opens for reading, else what it is
/// ("does not exist", "is a directory", "is a broken symbolic link to ...",
/// "is a device", "cannot be opened: ..."). Nothing is read: a FIFO or a
/// device is named, never opened.
#[must_use]
pub fn not_a_readable_file(path: &Path) -> Option<String> {
    let link = match std::fs::symlink_metadata(path) {
        Ok(link) => link,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Some("does not exist".into()),
        Err(e) => return Some(format!("cannot be examined: {e}")),
    };
    let target = match std::fs::metadata(path) {
        Ok(target) => target,
        Err(_) if link.is_symlink() => {
            let to = std::fs::read_link(path).map(|t| t.display().to_string()).unwrap_or_default();
            return Some(format!("is a broken symbolic link (to '{to}'), not a file"));
        }
        Err(e) => return Some(format!("cannot be examined: {e}")),
    };
    let kind = if target.is_file() {
        return std::fs::File::open(path).err().map(|e| format!("cannot be opened for reading: {e}"));
    } else if target.is_dir() {
        "a directory"
    } else if mmtrack_io::paths::is_device(&target) {
        "a device"
    } else {
        "a FIFO, socket or other special file"
    };
    Some(format!("is {kind}, not a regular file"))
}

/// An optional input file of a folder layout: `None` when nothing exists at
/// `path`, the path when it is a readable regular file (or a symbolic link to
/// one), and an error naming the path and what it is otherwise. A directory
/// or a broken link where `gps/gps.csv` belongs is a damaged folder, not a
/// folder without GNSS: taking it as absent would write "0 GNSS fixes"
/// without a word.
pub fn optional_file(path: &Path) -> Result<Option<PathBuf>, IngestError> {
    if std::fs::symlink_metadata(path).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound) {
        return Ok(None);
    }
    match not_a_readable_file(path) {
        None => Ok(Some(path.to_path_buf())),
        Some(what) => Err(IngestError::BadLayout {
            path: path.to_path_buf(),
            detail: format!("{what}: expected a readable file here or nothing at all (the file is optional)"),
        }),
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

/// The sequence id a folder ingest writes into its recording: `given`
/// (`--sequence-id`) or else the folder's name ([`folder_name`]), checked
/// with the rule the table writer applies to partition names
/// ([`mmtrack_io::table::check_partition_name`]), so that a recording
/// `process` would refuse is refused when it is made. The error names the
/// folder, where the id came from, and the flag that sets it.
pub fn checked_sequence_id(root: &Path, given: Option<&str>) -> Result<String, IngestError> {
    let (id, from) = match given {
        Some(id) => (id.to_string(), "--sequence-id"),
        None => (folder_name(root), "the folder name"),
    };
    mmtrack_io::table::check_partition_name(&id).map_err(|detail| IngestError::BadLayout {
        path: root.to_path_buf(),
        detail: format!(
            "sequence id (from {from}): {detail}; pass --sequence-id with a valid name (nothing was written)"
        ),
    })?;
    Ok(id)
}

/// The sequence id of a recording named after a file: the file's name
/// without its extension (the output of `ingest poses / nmea / cir`, a ROS 2
/// bag), checked like [`checked_sequence_id`]. `role` says which file in
/// the error ("output", "bag"), which also says to rename it.
pub fn sequence_id_of_file(path: &Path, role: &str) -> Result<String, IngestError> {
    let id = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    mmtrack_io::table::check_partition_name(&id).map_err(|detail| IngestError::BadLayout {
        path: path.to_path_buf(),
        detail: format!(
            "sequence id (the {role}'s file name without its extension): {detail}; rename the {role} (nothing was \
             written)"
        ),
    })?;
    Ok(id)
}

/// Scans decoded ahead of the writer, per thread of the pool.
const DECODED_PER_THREAD: usize = 2;

/// Memory the scans being decoded and those waiting for the writer may hold
/// together, bytes: one image at the decoder's cap
/// ([`mmtrack_io::MAX_GRAY8_BYTES`]). Real scans (1.5 MB for Oxford, 2.7 MB
/// for Boreas) still decode [`DECODED_PER_THREAD`] per thread side by side;
/// scans near the cap go one at a time, from the first read of their file
/// until the writer has taken them, whatever the thread count.
pub(crate) const SCAN_MEMORY_BUDGET_BYTES: usize = mmtrack_io::MAX_GRAY8_BYTES;

/// Reads and decodes the scans on the current rayon pool and hands them to
/// `write` in file order.
///
/// Up to [`DECODED_PER_THREAD`] scans per thread are decoded ahead while
/// `write` takes them in order
/// ([`mmtrack_core::parallel::map_in_order_within`]), and those decoding or
/// waiting hold at most [`SCAN_MEMORY_BUDGET_BYTES`] together by `cost` (what
/// one scan holds from its first read until `write` has taken it; a scan over
/// the budget goes alone), so memory grows neither with the folder size nor
/// with the thread count, and the output is the same for any thread count.
/// PNG decoding (inflate and unfilter, needed to reach the row headers) is
/// most of an ingest's time.
pub fn decode_in_order<T: Send>(
    scans: &[ScanFile],
    cost: &(dyn Fn(&ScanFile) -> usize + Sync),
    decode: &(dyn Fn(&ScanFile) -> Result<T, IngestError> + Sync),
    write: &mut (dyn FnMut(usize, T) -> Result<(), IngestError> + Send),
) -> Result<(), IngestError> {
    mmtrack_core::parallel::map_in_order_within(
        scans.iter().enumerate(),
        DECODED_PER_THREAD,
        SCAN_MEMORY_BUDGET_BYTES,
        |(_, scan)| cost(scan),
        |(index, scan)| (index, decode(scan)),
        |(index, decoded)| write(index, decoded?),
    )
}

/// The bytes of the image a scan PNG's header announces (pixels plus a
/// filter byte per row: the decoder's buffer), read from its first 24 bytes;
/// 0 for a file that is no PNG or an image over the decoder's cap (refused
/// before a pixel is allocated).
pub(crate) fn png_image_bytes(path: &Path) -> usize {
    use std::io::Read as _;
    let mut head = [0u8; 24];
    let read = std::fs::File::open(path).and_then(|mut f| f.read_exact(&mut head));
    if read.is_err() || &head[..8] != b"\x89PNG\r\n\x1a\n" || &head[12..16] != b"IHDR" {
        return 0;
    }
    let width = u32::from_be_bytes([head[16], head[17], head[18], head[19]]) as usize;
    let height = u32::from_be_bytes([head[20], head[21], head[22], head[23]]) as usize;
    width.checked_mul(height).filter(|&n| n <= mmtrack_io::MAX_GRAY8_BYTES).map_or(0, |n| n + height)
}

/// The size of a file, bytes (0 if it cannot be read: its reader says why).
pub(crate) fn file_bytes(path: &Path) -> usize {
    std::fs::metadata(path).map_or(0, |m| usize::try_from(m.len()).unwrap_or(usize::MAX))
}

/// The items of a ground-truth or GNSS file that fall within the scans'
/// time span (first to last scan stamp), which is what a recording keeps.
///
/// A file with items but none within the span is refused, naming both
/// spans: its times are in another unit, on another clock or of another
/// drive, and a recording without them would look complete (issue 26: Boreas
/// poses that missed every scan became "0 ground-truth poses" without a word).
pub(crate) fn within_scan_span<'a, T>(
    scans: &[ScanFile],
    what: &str,
    source: &str,
    items: &'a [T],
    t_ns: impl Fn(&T) -> i64,
) -> Result<Vec<&'a T>, IngestError> {
    let (Some(first), Some(last)) = (scans.first(), scans.last()) else { return Ok(Vec::new()) };
    let kept: Vec<&T> = items.iter().filter(|item| (first.t_ns..=last.t_ns).contains(&t_ns(item))).collect();
    if let (true, Some(earliest), Some(latest)) = (kept.is_empty(), items.first(), items.last()) {
        return Err(IngestError::BadLayout {
            path: PathBuf::from(source),
            detail: format!(
                "none of its {} {what} falls within the scans' time span ({} to {} ns): its times run from {} to {} ns \
                 (another unit, clock or drive?)",
                items.len(),
                first.t_ns,
                last.t_ns,
                t_ns(earliest),
                t_ns(latest),
            ),
        });
    }
    Ok(kept)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn listing_takes_numeric_pngs_in_time_order_and_names_bad_stamps() {
        let dir = tempfile::tempdir().unwrap();
        let stamps_ns = ["1561000000500000000", "1561000000000000000", "1561000000250000000"];
        for name in stamps_ns.iter().map(|s| format!("{s}.png")).chain(["notes.txt".into(), "cart.png.bak".into()]) {
            std::fs::write(dir.path().join(name), b"x").unwrap();
        }
        let scans = list_scan_pngs(dir.path(), StampUnit::Nanos).unwrap();
        let t0_ns = 1_561_000_000_000_000_000;
        assert_eq!(scans.iter().map(|s| s.t_ns - t0_ns).collect::<Vec<_>>(), vec![0, 250_000_000, 500_000_000]);

        let micros = tempfile::tempdir().unwrap();
        std::fs::write(micros.path().join("1547131046353776.png"), b"x").unwrap();
        let scans = list_scan_pngs(micros.path(), StampUnit::Micros).unwrap();
        assert_eq!(scans[0].t_ns, 1_547_131_046_353_776_000);

        std::fs::write(dir.path().join("0.png"), b"x").unwrap();
        let err = list_scan_pngs(dir.path(), StampUnit::Nanos).unwrap_err().to_string();
        assert!(err.contains("0.png") && err.contains("timestamp") && err.contains("nanosecond"), "{err}");

        let empty = tempfile::tempdir().unwrap();
        let err = list_scan_pngs(empty.path(), StampUnit::Nanos).unwrap_err().to_string();
        assert!(err.contains("no scans found"), "{err}");
    }

    /// Before: a folder named "my drive" ingested, and `process` then failed
    /// with "not a valid partition name" without naming the flag.
    #[test]
    fn sequence_ids_that_cannot_name_a_partition_are_refused_naming_the_flag() {
        let parent = tempfile::tempdir().unwrap();
        let root = parent.path().join("my drive");
        std::fs::create_dir(&root).unwrap();
        let err = checked_sequence_id(&root, None).unwrap_err().to_string();
        assert!(
            err.contains("my drive: sequence id (from the folder name): 'my drive' is not a valid partition name")
                && err.ends_with("pass --sequence-id with a valid name (nothing was written)"),
            "{err}"
        );
        for bad in ["", "a=b", "../../evil", ".."] {
            let err = checked_sequence_id(&root, Some(bad)).unwrap_err().to_string();
            assert!(err.contains(&format!("(from --sequence-id): '{bad}' is not a valid partition name")), "{err}");
        }
        assert_eq!(checked_sequence_id(&root, Some("drive-1_a.b")).unwrap(), "drive-1_a.b");
        let good = parent.path().join("2019-01-10-14-36-48");
        std::fs::create_dir(&good).unwrap();
        assert_eq!(checked_sequence_id(&good, None).unwrap(), "2019-01-10-14-36-48");
        // Before: `ingest poses -o "my drive.mcap"` wrote a recording that
        // `process` refused for its sequence id "my drive".
        let err = sequence_id_of_file(Path::new("out/my drive.mcap"), "output").unwrap_err().to_string();
        assert!(
            err.starts_with("out/my drive.mcap: sequence id (the output's file name")
                && err.contains("rename the output"),
            "{err}"
        );
        assert_eq!(sequence_id_of_file(Path::new("out/drive-1.mcap"), "output").unwrap(), "drive-1");
    }

    /// MulRan names scans by 19-digit nanoseconds; `000001.png` is not a
    /// scan at 1 ns, and microseconds given as nanoseconds (1970) or
    /// nanoseconds as microseconds (beyond 2100) are refused too.
    #[test]
    fn implausible_stamps_are_refused_naming_the_file() {
        let path = Path::new("polar/000001.png");
        let err = StampUnit::Nanos.parse(path, "file name", "000001").unwrap_err().to_string();
        assert!(
            err.contains("polar/000001.png: file name: timestamp: '000001' is not a plausible nanosecond")
                && err.contains("19 digits"),
            "{err}"
        );
        assert!(StampUnit::Nanos.parse(path, "file name", "1547131046353776").is_err(), "microseconds as ns");
        assert!(StampUnit::Micros.parse(path, "line 3", "1561000000000000000").is_err(), "ns as microseconds");
        assert!(StampUnit::Micros.parse(path, "line 3", "-1547131046353776").is_err());
        assert_eq!(StampUnit::Nanos.parse(path, "file name", "946684800000000000").unwrap(), 946_684_800_000_000_000);
        assert!(StampUnit::Nanos.parse(path, "file name", "946684799999999999").is_err(), "1999");

        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("000001.png"), b"x").unwrap();
        let err = list_scan_pngs(dir.path(), StampUnit::Nanos).unwrap_err().to_string();
        assert!(err.contains("000001.png") && err.contains("plausible"), "{err}");
    }

    #[test]
    fn a_scan_of_another_size_than_the_first_is_named() {
        let mut same = SameSize::default();
        same.check(Path::new("a.png"), 400, 3360).unwrap();
        same.check(Path::new("b.png"), 400, 3360).unwrap();
        let err = same.check(Path::new("c.png"), 399, 3360).unwrap_err().to_string();
        assert!(err.contains("c.png: image: size: 399 azimuths x 3360 range bins") && err.contains("a.png"), "{err}");
    }

    #[test]
    fn decode_in_order_keeps_file_order_and_stops_on_the_first_error() {
        let scans: Vec<ScanFile> =
            (1..=9).map(|i| ScanFile { t_ns: i, path: PathBuf::from(format!("{i}.png")) }).collect();
        let mut seen = Vec::new();
        decode_in_order(&scans, &|_| 0, &|s: &ScanFile| Ok(s.t_ns * 10), &mut |index, value| {
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
        let err = decode_in_order(&scans, &|_| 0, &failing, &mut |_, _| {
            written += 1;
            Ok(())
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains("5.png") && err.contains("broken"), "{err}");
        assert_eq!(written, 4, "scans after the failing one are not written");
    }
}
