//! `mmtrack simulate radar`: scenario and trajectory errors, cuts, ground truth
//! in the recording, and a drive along the real Oxford ground truth.

use mmtrack_io::recording::PoseStream;
use mmtrack_io::{RecordingEvent, RecordingReader};

use super::common::{mmtrack, realdata, text};

const SMALL: &str = r#"
seed = 3
max_scans = 3
[sensor]
bins = 300
[motion]
speed_mps = 8.0
yaw_rate_radps = 0.05
duration_s = 2.0
[generator]
"#;

fn simulate(dir: &std::path::Path, scenario: &str, extra: &[&str]) -> (bool, String, String) {
    std::fs::write(dir.join("s.toml"), scenario).unwrap();
    let mut args = vec!["simulate", "radar", "--scenario", "s.toml", "-o", "out.mcap", "--force", "--quiet"];
    args.extend_from_slice(extra);
    let out = mmtrack(dir, &args);
    let (stdout, stderr) = text(&out);
    (out.status.success(), stdout, stderr)
}

fn recording(path: &std::path::Path) -> (usize, Vec<mmtrack_core::StampedPose>) {
    let (mut scans, mut truth) = (0, Vec::new());
    for event in RecordingReader::open(path).unwrap() {
        match event.unwrap() {
            RecordingEvent::RadarScan(_) => scans += 1,
            RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } => truth.push(pose),
            _ => {}
        }
    }
    (scans, truth)
}

#[test]
fn a_recording_carries_one_ground_truth_pose_per_scan_and_the_cuts_apply() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, _, stderr) = simulate(dir.path(), SMALL, &[]);
    assert!(ok, "{stderr}");
    let (scans, truth) = recording(&dir.path().join("out.mcap"));
    assert_eq!((scans, truth.len()), (3, 3));
    assert_eq!(truth[1].t_ns - truth[0].t_ns, 250_000_000);
    // --max-distance-m 3: sweeps start at 0, 2, 4 m at 8 m/s; two are kept.
    let (ok, _, stderr) = simulate(dir.path(), SMALL, &["--max-distance-m", "3"]);
    assert!(ok, "{stderr}");
    assert_eq!(recording(&dir.path().join("out.mcap")).0, 2);
}

#[test]
fn bad_scenarios_are_named() {
    let dir = tempfile::tempdir().unwrap();
    for (edit, expected) in [
        (("bins = 300", "bins = 300\nrange_resolution_m = -0.05"), "sensor.range_resolution_m: -0.05 is invalid"),
        (("bins = 300", "bins = 300\nazimuths = 0"), "sensor.azimuths: 0 is invalid"),
        (("bins = 300", "bins = 300\nbeam_wdth_deg = 2.0"), "unknown field `beam_wdth_deg`"),
        (("duration_s = 2.0", "duration_s = 0.1"), "trajectory too short"),
        (("[generator]", "[generator]\nclearance_m = -1"), "generator.clearance_m"),
    ] {
        let (ok, _, stderr) = simulate(dir.path(), &SMALL.replace(edit.0, edit.1), &[]);
        assert!(!ok && stderr.contains(expected), "expected '{expected}' in: {stderr}");
        assert!(stderr.contains("s.toml"), "the error names the file: {stderr}");
    }
}

#[test]
fn bad_trajectory_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.tum"), "1.0 0 0 0 0 0 0 1\n1.5 1 0 zero 0 0 0 1\n").unwrap();
    let (ok, _, stderr) = simulate(dir.path(), SMALL, &["--trajectory", "t.tum", "--trajectory-format", "tum"]);
    assert!(!ok && stderr.contains("t.tum") && stderr.contains("line 2"), "{stderr}");
    // Well-formed but shorter than one sweep.
    std::fs::write(dir.path().join("t.tum"), "1.0 0 0 0 0 0 0 1\n1.1 1 0 0 0 0 0 1\n").unwrap();
    let (ok, _, stderr) = simulate(dir.path(), SMALL, &["--trajectory", "t.tum", "--trajectory-format", "tum"]);
    assert!(!ok && stderr.contains("t.tum") && stderr.contains("too short"), "{stderr}");
    let (ok, _, stderr) = simulate(dir.path(), SMALL, &["--trajectory", "t.kitti", "--trajectory-format", "kitti"]);
    assert!(!ok && stderr.contains("--times"), "{stderr}");
}

#[test]
fn a_tum_trajectory_is_followed() {
    let dir = tempfile::tempdir().unwrap();
    // 10 m/s along world y (yaw 90 deg: qz = qw = sqrt(1/2)) for 2 s.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let tum: String =
        (0..=20).map(|k| format!("{}.{:02} 0 {} 0 0 0 {h} {h}\n", 100 + k / 10, (k % 10) * 10, k)).collect();
    std::fs::write(dir.path().join("t.tum"), tum).unwrap();
    let (ok, _, stderr) = simulate(dir.path(), SMALL, &["--trajectory", "t.tum", "--trajectory-format", "tum"]);
    assert!(ok, "{stderr}");
    let (_, truth) = recording(&dir.path().join("out.mcap"));
    assert_eq!(truth[0].t_ns, 100_000_000_000);
    let p = truth[2].parent_from_child;
    // Linear interpolation of the file: 0.5 s in, 5 m along y, heading 90 deg.
    assert!(p.x_m.abs() < 1e-9 && (p.y_m - 5.0).abs() < 1e-9, "{p:?}");
    assert!((p.yaw_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
}

#[test]
fn a_drive_along_the_real_oxford_ground_truth() {
    let Some(realdata) = realdata("simulate_along_oxford_ground_truth") else { return };
    let gt = realdata.join("oxford-gt-full-seq/radar_odometry.csv");
    let dir = tempfile::tempdir().unwrap();
    let gt_arg = gt.to_str().unwrap();
    let (ok, _, stderr) =
        simulate(dir.path(), SMALL, &["--trajectory", gt_arg, "--max-scans", "4", "--max-distance-m", "1000"]);
    assert!(ok, "{stderr}");
    let (scans, truth) = recording(&dir.path().join("out.mcap"));
    assert_eq!((scans, truth.len()), (4, 4));
    // The first scan is stamped at the first pose of the file (the chain's identity).
    assert_eq!(truth[0].parent_from_child, mmtrack_core::Se2::IDENTITY);
    assert!(truth[0].t_ns > 1_500_000_000_000_000_000, "a UNIX time: {}", truth[0].t_ns);
}

/// Issue 26: `--force` over a folder holding files mmtrack never wrote
/// refuses by name and deletes nothing; over its own Oxford output it
/// replaces it.
#[test]
fn oxford_force_never_deletes_foreign_files() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.toml"), SMALL).unwrap();
    let oxford = ["simulate", "radar", "--scenario", "s.toml", "--format", "oxford", "-o", "v", "--quiet"];
    let forced: Vec<&str> = oxford.iter().copied().chain(["--force"]).collect();
    let out = mmtrack(dir.path(), &oxford);
    assert!(out.status.success(), "{}", text(&out).1);
    let scans = std::fs::read_dir(dir.path().join("v/radar")).unwrap().count();
    assert_eq!(scans, 3);

    // Its own output is replaced.
    let out = mmtrack(dir.path(), &forced);
    assert!(out.status.success(), "{}", text(&out).1);

    // A foreign file at the top and one inside radar/: refused, both kept.
    std::fs::create_dir_all(dir.path().join("v/sub")).unwrap();
    std::fs::write(dir.path().join("v/notes.txt"), "precious").unwrap();
    std::fs::write(dir.path().join("v/radar/readme.md"), "mine").unwrap();
    let out = mmtrack(dir.path(), &forced);
    let (_, stderr) = text(&out);
    assert!(!out.status.success());
    assert!(stderr.contains("notes.txt") && stderr.contains("radar/readme.md") && stderr.contains("sub"), "{stderr}");
    assert!(stderr.contains("refusing to replace"), "{stderr}");
    assert_eq!(std::fs::read_to_string(dir.path().join("v/notes.txt")).unwrap(), "precious");
    assert_eq!(std::fs::read_to_string(dir.path().join("v/radar/readme.md")).unwrap(), "mine");
    assert_eq!(std::fs::read_dir(dir.path().join("v/radar")).unwrap().count(), scans + 1);
    assert!(dir.path().join("v/sub").is_dir());
    // Nothing left beside it.
    let hidden: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
}
