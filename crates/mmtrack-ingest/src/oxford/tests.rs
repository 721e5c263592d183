use std::path::Path;

use mmtrack_core::{AzimuthSample, PolarScan, PolarScanHeader};

use super::*;

/// Time of the first scan of [`scan_folder`], microseconds.
pub(super) const T0_US: i64 = 1_547_131_000_000_000;

/// Writes an Oxford folder of `count` 4 x 5 scans 0.25 s apart from
/// [`T0_US`] (PNGs and `radar.timestamps`), no optional files; returns its
/// layout. Shared with the INS tests (`ins.rs`).
pub(super) fn scan_folder(root: &Path, count: i64) -> NavtechLayout {
    let scans: Vec<PolarScan> = (0..count)
        .map(|i| {
            let t_ns = (T0_US + i * 250_000) * 1000;
            let azimuths =
                (0..4).map(|a| AzimuthSample { t_ns: t_ns + a * 1000, azimuth_rad: a as f64, valid: true }).collect();
            let header = PolarScanHeader {
                t_ns,
                range_resolution_m: 0.0432,
                range_offset_m: 0.0,
                bins_per_azimuth: 5,
                azimuths,
            };
            PolarScan::new(header, vec![7; 20]).unwrap()
        })
        .collect();
    let layout = NavtechLayout { expected_bins: Some(5), expected_azimuths: Some(4), ..OXFORD };
    write_oxford_folder(root, &scans, &[], &layout).unwrap();
    layout
}

fn open_err(root: &Path) -> String {
    OxfordFolder::open(root).unwrap_err().to_string()
}

/// Before: `open` asked `is_file()`, so a directory, a broken link or a
/// device where an optional file belongs was taken as "no such file" and the
/// ingest wrote "0 ground-truth poses" / "0 GNSS fixes" (or listed the PNGs
/// instead of `radar.timestamps`) with exit 0.
#[test]
fn an_optional_file_that_exists_but_is_no_readable_file_is_an_error_naming_it() {
    for optional in ["gt/radar_odometry.csv", "gps/gps.csv", "gps/ins.csv", "radar.timestamps"] {
        let dir = tempfile::tempdir().unwrap();
        scan_folder(dir.path(), 2);
        let folder = OxfordFolder::open(dir.path()).unwrap();
        assert_eq!(folder.scans.len(), 2, "absent optional files stay optional");
        assert!(folder.ground_truth.is_none() && folder.gps.is_none() && folder.ins.is_none());
        let path = dir.path().join(optional);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        let _ = std::fs::remove_file(&path);

        std::fs::create_dir(&path).unwrap();
        let err = open_err(dir.path());
        assert!(err.contains(optional) && err.contains("is a directory, not a regular file"), "{optional}: {err}");
        std::fs::remove_dir(&path).unwrap();

        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(dir.path().join("nowhere.csv"), &path).unwrap();
            let err = open_err(dir.path());
            assert!(err.contains(optional) && err.contains("is a broken symbolic link"), "{optional}: {err}");
            std::fs::remove_file(&path).unwrap();
            if Path::new("/dev/null").exists() {
                std::os::unix::fs::symlink("/dev/null", &path).unwrap();
                let err = open_err(dir.path());
                assert!(err.contains(optional) && err.contains("is a device"), "{optional}: {err}");
                std::fs::remove_file(&path).unwrap();
            }
        }
        assert!(!err.contains('\n'), "{err}");
    }
}

/// A symbolic link to a readable file is that file.
#[cfg(unix)]
#[test]
fn an_optional_file_reached_through_a_symlink_is_taken() {
    let dir = tempfile::tempdir().unwrap();
    scan_folder(dir.path(), 2);
    std::fs::create_dir(dir.path().join("gps")).unwrap();
    let real = dir.path().join("elsewhere.csv");
    std::fs::write(&real, "").unwrap();
    std::os::unix::fs::symlink(&real, dir.path().join("gps/gps.csv")).unwrap();
    let folder = OxfordFolder::open(dir.path()).unwrap();
    assert_eq!(folder.gps, Some(dir.path().join("gps/gps.csv")));
}

/// Before: a listed PNG replaced by a directory "does not exist", and a
/// folder that does not exist had "no radar/ folder".
#[test]
fn a_listed_png_that_is_a_directory_and_a_missing_folder_say_what_they_are() {
    let dir = tempfile::tempdir().unwrap();
    scan_folder(dir.path(), 2);
    let png = dir.path().join("radar/1547131000000000.png");
    std::fs::remove_file(&png).unwrap();
    std::fs::create_dir(&png).unwrap();
    let err = open_err(dir.path());
    assert!(
        err.contains("radar.timestamps: line 1 lists scan 1547131000000000")
            && err.contains("1547131000000000.png is a directory, not a regular file"),
        "{err}"
    );

    let missing = dir.path().join("no-such-drive");
    let err = open_err(&missing);
    assert!(err.starts_with(&format!("{}: does not exist", missing.display())), "{err}");
    let err = open_err(&dir.path().join("radar.timestamps"));
    assert!(err.contains("radar.timestamps: is not a folder"), "{err}");
}

/// Before: any valid flag but `0` (a 7, none, a third field) counted as
/// valid. The SDK writes `<t_us> 1` or `<t_us> 0`; anything else is named.
#[test]
fn a_valid_flag_other_than_0_or_1_is_named_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    scan_folder(dir.path(), 2);
    let timestamps = dir.path().join("radar.timestamps");
    let first = T0_US;
    let second = T0_US + 250_000;
    for (text, found) in [
        (format!("{first} 1\n{second} 7\n"), "`7`"),
        (format!("{first} 1\n{second}\n"), "``"),
        (format!("{first} 1\n{second} 1 2\n"), "`1 2`"),
    ] {
        std::fs::write(&timestamps, text).unwrap();
        let err = open_err(dir.path());
        assert!(
            err.contains("radar.timestamps: line 2: valid flag: ")
                && err.contains(found)
                && err.contains("expected 0 or 1"),
            "{err}"
        );
    }
    std::fs::write(&timestamps, format!("{first} 1\n{second} 0\n")).unwrap();
    let folder = OxfordFolder::open(dir.path()).unwrap();
    assert_eq!((folder.scans.len(), folder.skipped_invalid), (1, 1));
}
