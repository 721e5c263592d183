use std::f64::consts::TAU;
use std::path::Path;

use mmtrack_core::{AzimuthSample, PolarScan, PolarScanHeader};
use mmtrack_io::recording::PoseStream;
use mmtrack_io::{RecordingEvent, RecordingOptions, RecordingReader};

use super::*;
use crate::oxford::encode_scan_png;

const POSES_HEADER: &str =
    "GPSTime,easting,northing,altitude,vel_east,vel_north,vel_up,roll,pitch,heading,angvel_z,angvel_y,angvel_x";

/// A scan of `azimuths` rows and `bins` bins whose middle azimuth is at `t_us`,
/// with the valid byte 0 (Boreas leaves it unused).
fn scan(t_us: i64, azimuths: usize, bins: usize) -> PolarScan {
    let step_ns = 625_000;
    let first_ns = t_us * 1000 - (azimuths as i64 / 2 - 1) * step_ns;
    let azimuths: Vec<AzimuthSample> = (0..azimuths)
        .map(|a| AzimuthSample {
            t_ns: first_ns + a as i64 * step_ns,
            azimuth_rad: a as f64 * TAU / azimuths as f64,
            valid: false,
        })
        .collect();
    let power = (0..azimuths.len() * bins).map(|i| (i % 253) as u8).collect();
    let header = PolarScanHeader {
        t_ns: t_us * 1000,
        range_resolution_m: 1.0,
        range_offset_m: 0.0,
        bins_per_azimuth: bins,
        azimuths,
    };
    PolarScan::new(header, power).unwrap()
}

/// A Boreas folder of three scans and a radar_poses.csv; returns its path.
fn folder(parent: &Path, name: &str, bins: usize) -> PathBuf {
    folder_shifted(parent, name, bins, 0)
}

/// [`folder`] with every time (scans, poses, GNSS) `shift_s` seconds later.
fn folder_shifted(parent: &Path, name: &str, bins: usize, shift_s: i64) -> PathBuf {
    let root = parent.join(name);
    std::fs::create_dir_all(root.join("radar")).unwrap();
    std::fs::create_dir_all(root.join("applanix")).unwrap();
    let mut csv = format!("{POSES_HEADER}\n");
    for (i, t_us) in [1_630_597_345_560_134i64, 1_630_597_345_810_747, 1_630_597_346_061_361].iter().enumerate() {
        let t_us = t_us + shift_s * 1_000_000;
        let png = encode_scan_png(&scan(t_us, 16, bins), &OXFORD).unwrap();
        std::fs::write(root.join("radar").join(format!("{t_us}.png")), png).unwrap();
        csv.push_str(&format!("{t_us},{},4848823.0,154.5,4,0,0,3.14159,0,0.1,0,0,0\n", 623450.0 + i as f64));
    }
    std::fs::write(root.join("applanix/radar_poses.csv"), csv).unwrap();
    // GNSS at 4 Hz from before the first scan to after the last: 3 of 6 rows in span.
    let mut gps = String::from(
        "GPSTime,easting,northing,altitude,vel_east,vel_north,vel_up,roll,pitch,heading,angvel_z,angvel_y,angvel_x,accelz,accely,accelx,latitude,longitude\n",
    );
    for (whole_s, fraction) in [(345, "3"), (345, "6"), (345, "85"), (346, "05"), (346, "3"), (346, "55")] {
        let t_s = 1_630_597_000 + whole_s + shift_s;
        gps.push_str(&format!("{t_s}.{fraction},0,0,154.5,0,0,0,0,0,0,0,0,0,0,0,0,0.7641224,-1.3869569\n"));
    }
    std::fs::write(root.join("applanix/gps_post_process.csv"), gps).unwrap();
    root
}

fn ingest(root: &Path, out: &Path, options: &BoreasOptions) -> Result<BoreasReport, IngestError> {
    let folder = BoreasFolder::open(root)?;
    ingest_boreas(&folder, out, options, &RecordingOptions::default(), &mut |_, _| {})
}

fn read(out: &Path) -> (Vec<PolarScan>, Vec<mmtrack_core::StampedPose>, BTreeMap<String, String>) {
    let mut reader = RecordingReader::open(out).unwrap();
    let (mut scans, mut poses) = (Vec::new(), Vec::new());
    for event in reader.by_ref() {
        match event.unwrap() {
            RecordingEvent::RadarScan(s) => scans.push(s),
            RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } => poses.push(pose),
            _ => {}
        }
    }
    let metadata = reader.metadata().unwrap().clone();
    (scans, poses, metadata)
}

#[test]
fn sequence_dates_parse_only_from_the_boreas_pattern() {
    assert_eq!(sequence_date("boreas-2021-09-02-11-42"), Some((2021, 9, 2)));
    assert_eq!(sequence_date("boreas-2021-13-02-11-42"), None);
    assert_eq!(sequence_date("boreas-2021-09-02"), None);
    assert_eq!(sequence_date("oxford-2021-09-02-11-42"), None);
}

#[test]
fn folder_gives_scans_with_width_from_file_resolution_by_date_and_local_poses() {
    let dir = tempfile::tempdir().unwrap();
    // The second drive 19 days (1 641 600 s) later: 2021-09-21.
    for (name, bins, resolution_m, shift_s) in
        [("boreas-2021-09-02-11-42", 40, 0.0596, 0), ("boreas-2021-09-21-08-00", 57, 0.04381, 1_641_600)]
    {
        let root = folder_shifted(dir.path(), name, bins, shift_s);
        let out = dir.path().join(format!("{name}.mcap"));
        let report = ingest(&root, &out, &BoreasOptions::default()).unwrap();
        assert_eq!((report.scans, report.ground_truth_poses, report.gnss_fixes), (3, 3, 3));
        assert_eq!(report.range_resolution_m, resolution_m);
        let (scans, poses, metadata) = read(&out);
        assert_eq!(scans.len(), 3);
        for s in &scans {
            assert_eq!(s.header.bins_per_azimuth, bins);
            assert_eq!(s.header.range_resolution_m, resolution_m);
            assert_eq!(s.header.range_offset_m, -0.31);
            // The valid byte is 0 in these files and ignored: every azimuth valid.
            assert!(s.header.azimuths.iter().all(|a| a.valid));
            s.header.check_azimuth_times().unwrap();
        }
        // Middle azimuth (index 16 / 2 - 1) at the file's stamp.
        assert_eq!(scans[1].header.azimuths[7].t_ns, 1_630_597_345_810_747_000 + shift_s * 1_000_000_000);
        assert_eq!(metadata["radar.range_offset_m"], "-0.31");
        assert_eq!(metadata["ground_truth.origin_east_m"], "623450");
        assert!(metadata["radar.range_resolution_source"].contains("folder date"));
        let last = poses[2].parent_from_child;
        assert_eq!((last.x_m, last.y_m), (2.0, 0.0));
        // Radar frame with roll = pi: the planar yaw is the heading (up to the
        // 2.65e-6 rad by which 3.14159 misses pi, times pitch 0: exactly 0.1).
        assert!((last.yaw_rad - 0.1).abs() < 1e-12, "{}", last.yaw_rad);
    }
}

#[test]
fn renamed_folder_falls_back_to_scan_time_and_resolution_can_be_given() {
    let dir = tempfile::tempdir().unwrap();
    let root = folder(dir.path(), "my-drive", 20);
    let report = ingest(&root, &dir.path().join("a.mcap"), &BoreasOptions::default()).unwrap();
    assert_eq!(report.range_resolution_m, 0.0596);
    assert!(report.range_resolution_source.contains("first scan time"), "{}", report.range_resolution_source);
    let options = BoreasOptions { range_resolution_m: Some(0.05), ..BoreasOptions::default() };
    let report = ingest(&root, &dir.path().join("b.mcap"), &options).unwrap();
    assert_eq!(report.range_resolution_m, 0.05);
    // Without poses the recording has scans only.
    std::fs::remove_file(root.join("applanix/radar_poses.csv")).unwrap();
    let report = ingest(&root, &dir.path().join("c.mcap"), &BoreasOptions::default()).unwrap();
    assert_eq!(report.ground_truth_poses, 0);
}

#[test]
fn bad_input_names_file_record_and_field_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let root = folder(dir.path(), "boreas-2021-09-02-11-42", 20);
    let out = dir.path().join("out.mcap");
    let scans = list_scan_pngs(&root.join("radar"), StampUnit::Micros).unwrap();

    // Truncated PNG.
    let good = std::fs::read(&scans[1].path).unwrap();
    std::fs::write(&scans[1].path, &good[..good.len() / 2]).unwrap();
    let err = ingest(&root, &out, &BoreasOptions::default()).unwrap_err().to_string();
    assert!(err.contains(&scans[1].path.display().to_string()) && err.contains("PNG"), "{err}");
    assert!(!out.exists(), "no partial output");

    // Too narrow for the row header.
    let narrow = PolarScan::new(PolarScanHeader { bins_per_azimuth: 0, ..scan(1, 4, 1).header }, Vec::new()).unwrap();
    std::fs::write(&scans[1].path, encode_scan_png(&narrow, &OXFORD).unwrap()).unwrap();
    let err = ingest(&root, &out, &BoreasOptions::default()).unwrap_err().to_string();
    assert!(err.contains("image: width") && err.contains("11 header columns"), "{err}");

    // An azimuth time going backwards.
    let mut backwards = scan(1_630_597_345_810_747, 16, 20);
    backwards.header.azimuths[5].t_ns = backwards.header.azimuths[4].t_ns - 1000;
    std::fs::write(&scans[1].path, encode_scan_png(&backwards, &OXFORD).unwrap()).unwrap();
    let err = ingest(&root, &out, &BoreasOptions::default()).unwrap_err().to_string();
    assert!(err.contains("azimuth row 5") && err.contains("timestamp") && err.contains("does not increase"), "{err}");
    std::fs::write(&scans[1].path, &good).unwrap();

    // A renamed column and a NaN in the poses.
    let poses = root.join("applanix/radar_poses.csv");
    let text = std::fs::read_to_string(&poses).unwrap();
    std::fs::write(&poses, text.replacen("heading", "yaw", 1)).unwrap();
    let err = ingest(&root, &out, &BoreasOptions::default()).unwrap_err().to_string();
    assert!(err.contains("radar_poses.csv") && err.contains("heading") && err.contains("missing column"), "{err}");
    std::fs::write(&poses, text.replacen(",154.5,", ",NaN,", 1)).unwrap();
    let err = ingest(&root, &out, &BoreasOptions::default()).unwrap_err().to_string();
    assert!(err.contains("line 2") && err.contains("altitude"), "{err}");
    assert!(!out.exists(), "no partial output");
    std::fs::write(&poses, &text).unwrap();

    // GNSS latitude in degrees instead of radians.
    let gps = root.join("applanix/gps_post_process.csv");
    let text = std::fs::read_to_string(&gps).unwrap();
    std::fs::write(&gps, text.replacen(",0.7641224,", ",43.78,", 1)).unwrap();
    let err = ingest(&root, &out, &BoreasOptions::default()).unwrap_err().to_string();
    assert!(err.contains("gps_post_process.csv") && err.contains("line 2") && err.contains("radians"), "{err}");
    assert!(!out.exists(), "no partial output");

    // Empty radar folder, and no radar folder.
    let empty = dir.path().join("boreas-2021-01-01-00-00");
    std::fs::create_dir_all(empty.join("radar")).unwrap();
    assert!(BoreasFolder::open(&empty).unwrap_err().to_string().contains("no scans found"));
    assert!(BoreasFolder::open(dir.path()).unwrap_err().to_string().contains("no radar/ folder"));
}

#[test]
fn nanosecond_radar_poses_match_the_microsecond_scan_names() {
    let dir = tempfile::tempdir().unwrap();
    let root = folder(dir.path(), "boreas-2021-09-02-11-42", 20);
    let (_, micro_poses, _) = {
        let out = dir.path().join("us.mcap");
        ingest(&root, &out, &BoreasOptions::default()).unwrap();
        read(&out)
    };
    // The same file with GPSTime in nanoseconds (19 digits), as newer Boreas
    // releases write it.
    let poses = root.join("applanix/radar_poses.csv");
    let text = std::fs::read_to_string(&poses).unwrap();
    let nanos: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| match l.split_once(',') {
            Some((t, rest)) if i > 0 => format!("{t}000,{rest}\n"),
            _ => format!("{l}\n"),
        })
        .collect();
    std::fs::write(&poses, nanos).unwrap();
    let out = dir.path().join("ns.mcap");
    let report = ingest(&root, &out, &BoreasOptions::default()).unwrap();
    assert_eq!(report.ground_truth_poses, 3);
    assert_eq!(read(&out).1, micro_poses);
}

/// Before: a folder named for one date whose scans are stamped on another
/// was ingested with the folder date's range bin and no word.
#[test]
fn a_folder_date_that_contradicts_the_scans_is_refused_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    // Scans of 2021-09-02 in a folder that says 2021-09-21 (after the upgrade).
    let root = folder(dir.path(), "boreas-2021-09-21-08-00", 20);
    let err = ingest(&root, &dir.path().join("a.mcap"), &BoreasOptions::default()).unwrap_err().to_string();
    assert!(
        err.contains("boreas-2021-09-21-08-00: the folder name says the drive started on 2021-09-21")
            && err.contains("on 2021-09-02 UTC")
            && err.contains("--range-resolution-m"),
        "{err}"
    );
    assert!(!dir.path().join("a.mcap").exists());
    // The range bin given: the date no longer matters.
    let options = BoreasOptions { range_resolution_m: Some(0.0596), ..BoreasOptions::default() };
    assert!(ingest(&root, &dir.path().join("b.mcap"), &options).is_ok());
    // A local evening start is the next UTC day: accepted.
    let evening = folder(dir.path(), "boreas-2021-09-01-20-30", 20);
    assert!(ingest(&evening, &dir.path().join("c.mcap"), &BoreasOptions::default()).is_ok());
}

/// Before: poses whose times missed every scan were all dropped ("0
/// ground-truth poses") without a warning.
#[test]
fn poses_or_fixes_that_miss_every_scan_are_refused_naming_both_spans() {
    let dir = tempfile::tempdir().unwrap();
    let root = folder(dir.path(), "boreas-2021-09-02-11-42", 20);
    // The poses file of a drive an hour later.
    let other = folder_shifted(&dir.path().join("other"), "boreas-2021-09-02-11-42", 20, 3600);
    std::fs::copy(other.join("applanix/radar_poses.csv"), root.join("applanix/radar_poses.csv")).unwrap();
    let err = ingest(&root, &dir.path().join("a.mcap"), &BoreasOptions::default()).unwrap_err().to_string();
    assert!(
        err.contains("radar_poses.csv: none of its 3 poses falls within the scans' time span")
            && err.contains("1630597345560134000 to 1630597346061361000 ns")
            && err.contains("1630600945560134000 to 1630600946061361000 ns"),
        "{err}"
    );
    assert!(!dir.path().join("a.mcap").exists());
    std::fs::copy(other.join("applanix/gps_post_process.csv"), root.join("applanix/gps_post_process.csv")).unwrap();
    std::fs::remove_file(root.join("applanix/radar_poses.csv")).unwrap();
    let err = ingest(&root, &dir.path().join("b.mcap"), &BoreasOptions::default()).unwrap_err().to_string();
    assert!(err.contains("gps_post_process.csv: none of its 6 fixes falls within"), "{err}");
}

/// Before: `applanix/radar_poses.csv` or `applanix/gps_post_process.csv` as
/// a directory was taken as absent (exit 0 without poses or GNSS).
#[test]
fn an_optional_file_that_is_a_directory_is_an_error_naming_it() {
    for optional in ["applanix/radar_poses.csv", "applanix/gps_post_process.csv"] {
        let dir = tempfile::tempdir().unwrap();
        let root = folder(dir.path(), "boreas-2021-09-02-11-42", 20);
        let path = root.join(optional);
        let _ = std::fs::remove_file(&path);
        std::fs::create_dir(&path).unwrap();
        let err = BoreasFolder::open(&root).unwrap_err().to_string();
        assert!(err.contains(optional) && err.contains("is a directory, not a regular file"), "{err}");
    }
}
