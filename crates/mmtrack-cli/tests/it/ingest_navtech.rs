//! `mmtrack ingest boreas` and `mmtrack ingest mulran` end to end, on small
//! synthetic folders in each dataset's layout: success, `--quiet`, refusal to
//! overwrite, and bad input as a one-line error with no partial output.

use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

use mmtrack_core::{AzimuthSample, PolarScan, PolarScanHeader};
use mmtrack_io::recording::PoseStream;
use mmtrack_io::{RecordingEvent, RecordingReader};

use super::common::{files, mmtrack, text};

fn scan(t_ns: i64, azimuths: usize, bins: usize) -> PolarScan {
    let azimuths: Vec<AzimuthSample> = (0..azimuths)
        .map(|a| AzimuthSample {
            t_ns: t_ns + a as i64 * 625_000,
            azimuth_rad: a as f64 * TAU / azimuths as f64,
            valid: true,
        })
        .collect();
    let power = (0..azimuths.len() * bins).map(|i| (i % 7 * 30) as u8).collect();
    let header =
        PolarScanHeader { t_ns, range_resolution_m: 1.0, range_offset_m: 0.0, bins_per_azimuth: bins, azimuths };
    PolarScan::new(header, power).unwrap()
}

const T0_US: i64 = 1_640_000_000_000_000;

fn boreas_folder(parent: &Path) -> PathBuf {
    let root = parent.join("boreas-2021-12-20-10-00");
    std::fs::create_dir_all(root.join("radar")).unwrap();
    std::fs::create_dir_all(root.join("applanix")).unwrap();
    let mut csv = String::from(
        "GPSTime,easting,northing,altitude,vel_east,vel_north,vel_up,roll,pitch,heading,angvel_z,angvel_y,angvel_x\n",
    );
    for i in 0..4 {
        let t_us = T0_US + i * 250_000;
        let png = mmtrack_ingest::oxford::encode_scan_png(&scan(t_us * 1000, 12, 30), &mmtrack_ingest::oxford::OXFORD)
            .unwrap();
        std::fs::write(root.join(format!("radar/{t_us}.png")), png).unwrap();
        csv.push_str(&format!("{t_us},{}.0,4800000.0,100.0,4,0,0,3.14159265358979,0,0,0,0,0\n", 620000 + i));
    }
    std::fs::write(root.join("applanix/radar_poses.csv"), csv).unwrap();
    root
}

fn mulran_folder(parent: &Path) -> PathBuf {
    let root = parent.join("DCC01");
    let polar = root.join("sensor_data/radar/polar");
    std::fs::create_dir_all(&polar).unwrap();
    let mut poses = String::new();
    for i in 0..4 {
        let t_ns = T0_US * 1000 + i * 250_000_000;
        let png = mmtrack_ingest::mulran::encode_mulran_png(&scan(t_ns, 12, 30)).unwrap();
        std::fs::write(polar.join(format!("{t_ns}.png")), png).unwrap();
        poses.push_str(&format!("{t_ns},1,0,0,{}.5,0,1,0,4000000,0,0,1,20\n", 350000 + i));
    }
    std::fs::write(root.join("global_pose.csv"), poses).unwrap();
    root
}

fn read(path: &Path) -> (Vec<PolarScan>, Vec<mmtrack_core::StampedPose>) {
    let (mut scans, mut poses) = (Vec::new(), Vec::new());
    for event in RecordingReader::open(path).unwrap() {
        match event.unwrap() {
            RecordingEvent::RadarScan(s) => scans.push(s),
            RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } => poses.push(pose),
            _ => {}
        }
    }
    (scans, poses)
}

#[test]
fn boreas_folder_ingests_with_date_resolution_and_poses() {
    let dir = tempfile::tempdir().unwrap();
    let root = boreas_folder(dir.path());
    let out = mmtrack(dir.path(), &["ingest", "boreas", root.to_str().unwrap(), "-o", "b.mcap"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stdout.contains("4 scans") && stdout.contains("0.04381") && stdout.contains("4 ground-truth poses"),
        "{stdout}"
    );
    let (scans, poses) = read(&dir.path().join("b.mcap"));
    assert_eq!((scans.len(), poses.len()), (4, 4));
    assert_eq!((scans[0].header.bins_per_azimuth, scans[0].header.range_offset_m), (30, -0.31));
    assert_eq!(poses[3].parent_from_child.x_m, 3.0);

    // Refused without --force, output untouched; --quiet prints nothing.
    let again = mmtrack(dir.path(), &["ingest", "boreas", root.to_str().unwrap(), "-o", "b.mcap", "--quiet"]);
    assert_eq!(again.status.code(), Some(1));
    assert!(text(&again).1.contains("--force"), "{}", text(&again).1);
    let forced = mmtrack(
        dir.path(),
        &[
            "ingest",
            "boreas",
            root.to_str().unwrap(),
            "-o",
            "b.mcap",
            "--quiet",
            "--force",
            "--range-resolution-m",
            "0.05",
        ],
    );
    assert!(forced.status.success() && text(&forced).0.is_empty(), "{}", text(&forced).1);
    assert_eq!(read(&dir.path().join("b.mcap")).0[0].header.range_resolution_m, 0.05);
}

#[test]
fn mulran_folder_ingests_with_spread_azimuth_times() {
    let dir = tempfile::tempdir().unwrap();
    let root = mulran_folder(dir.path());
    let args = ["ingest", "mulran", root.to_str().unwrap(), "-o", "m.mcap", "--stamp-at", "start", "--quiet"];
    let out = mmtrack(dir.path(), &args);
    assert!(out.status.success(), "{}", text(&out).1);
    let (scans, poses) = read(&dir.path().join("m.mcap"));
    assert_eq!((scans.len(), poses.len()), (4, 4));
    let first = &scans[0];
    assert_eq!((first.header.azimuths.len(), first.header.bins_per_azimuth), (12, 30));
    // --stamp-at start: the first azimuth at the file time, 250 ms / 12 apart.
    assert_eq!(first.header.azimuths[0].t_ns, T0_US * 1000);
    assert_eq!(first.header.azimuths[1].t_ns - first.header.azimuths[0].t_ns, 20_833_333);
    // The power survives the transposition both ways.
    assert_eq!(first.power, scan(0, 12, 30).power);
    assert_eq!(poses[1].parent_from_child.x_m, 1.0);
}

#[test]
fn bad_boreas_and_mulran_input_is_one_line_naming_the_file_with_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let boreas = boreas_folder(dir.path());
    let mulran = mulran_folder(dir.path());
    let csv = boreas.join("applanix/radar_poses.csv");
    let text_csv = std::fs::read_to_string(&csv).unwrap();
    std::fs::write(&csv, text_csv.replacen("northing", "north", 1)).unwrap();
    let last_png = files(&mulran.join("sensor_data/radar/polar")).pop().unwrap();
    let last_png = mulran.join("sensor_data/radar/polar").join(last_png);
    let bytes = std::fs::read(&last_png).unwrap();
    std::fs::write(&last_png, &bytes[..bytes.len() / 2]).unwrap();

    for (args, expected) in [
        (vec!["ingest", "boreas", boreas.to_str().unwrap(), "-o", "out/b.mcap"], "northing"),
        (vec!["ingest", "mulran", mulran.to_str().unwrap(), "-o", "out/m.mcap"], "PNG"),
        (vec!["ingest", "mulran", boreas.to_str().unwrap(), "-o", "out/x.mcap"], "sensor_data/radar/polar"),
        (vec!["ingest", "mulran", mulran.to_str().unwrap(), "-o", "out/y.mcap", "--scan-period-s", "0"], "scan-period"),
    ] {
        let out = mmtrack(dir.path(), &args);
        let (_, stderr) = text(&out);
        // A flag's value is a usage error (2); bad files exit 1.
        let code = if args.contains(&"--scan-period-s") { 2 } else { 1 };
        assert_eq!(out.status.code(), Some(code), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
    let leftovers = if dir.path().join("out").exists() { files(&dir.path().join("out")) } else { vec![] };
    assert!(leftovers.is_empty(), "partial output left: {leftovers:?}");
}

#[test]
fn ros2_radar_topic_needs_a_range_resolution_and_an_image_type() {
    let dir = tempfile::tempdir().unwrap();
    let out = mmtrack(dir.path(), &["ingest", "ros2", "bag.mcap", "-o", "r.mcap", "--radar-topic", "/radar"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out).1);
    assert!(text(&out).1.contains("--radar-range-resolution-m"), "{}", text(&out).1);

    // On the real bag (MichaelGrupp/evo test data, GPL-3.0), /odom is not an image topic.
    let Some(realdata) = super::common::realdata("ros2_radar_topic") else { return };
    let bag = realdata.join("ros2-mcap");
    let bag = std::fs::read_dir(&bag)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "mcap"))
        .unwrap();
    let args = [
        "ingest",
        "ros2",
        bag.to_str().unwrap(),
        "-o",
        "r.mcap",
        "--pose-topic",
        "none",
        "--radar-topic",
        "/odom",
        "--radar-range-resolution-m",
        "0.0438",
    ];
    let out = mmtrack(dir.path(), &args);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("radar topic /odom has type nav_msgs/msg/Odometry; expected sensor_msgs/msg/Image"),
        "{stderr}"
    );
    assert!(!dir.path().join("r.mcap").exists());
}
