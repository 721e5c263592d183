//! `mmtrack process odometry`: tables from a recording, refusal without
//! --force, clear errors for recordings without scans and bad configs.

use mmtrack_core::OdometryEstimate;
use mmtrack_io::table::{GroundTruthPose, read_table_dir};

use super::common::{mmtrack, root, text};

#[test]
fn real_oxford_recording_gives_odometry_and_ground_truth_tables() {
    let Some(realdata) = super::common::realdata("process_odometry") else { return };
    let input = realdata.join("oxford-radar-tiny");
    let dir = tempfile::tempdir().unwrap();
    let out = mmtrack(dir.path(), &["ingest", "oxford", input.to_str().unwrap(), "-o", "tiny.mcap", "--quiet"]);
    assert!(out.status.success(), "{}", text(&out).1);

    let out = mmtrack(dir.path(), &["process", "odometry", "tiny.mcap", "-o", "tables"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("11 scans") && stdout.contains("odometry/sequence=oxford-radar-tiny"), "{stdout}");

    let estimates = read_table_dir::<OdometryEstimate>(&dir.path().join("tables")).unwrap();
    let truth = read_table_dir::<GroundTruthPose>(&dir.path().join("tables")).unwrap();
    let (estimates, truth) = (&estimates["oxford-radar-tiny"], &truth["oxford-radar-tiny"]);
    assert_eq!((estimates.len(), truth.len()), (11, 11));
    assert!(estimates.iter().all(|e| !e.low_confidence && e.world_from_vehicle.is_finite()));
    // The table is in the ground truth's frame: the first scan sits at its
    // ground-truth pose (1e-9 m: rounding of poses some 150 m from the origin).
    let (start, true_start) = (estimates[0].world_from_vehicle, truth[0].0.parent_from_child);
    assert!((true_start.inverse() * start).translation_norm_m() < 1e-9, "{start:?} vs {true_start:?}");
    // End point within 1 m of the ground truth's after 19.4 m (per-pair errors are in the odometry crate's test).
    let (end, true_end) = (estimates[10].world_from_vehicle, truth[10].0.parent_from_child);
    assert!((true_end.inverse() * end).translation_norm_m() < 1.0, "{end:?} vs {true_end:?}");

    // Again without --force: refused, nothing changed.
    let again = mmtrack(dir.path(), &["process", "odometry", "tiny.mcap", "-o", "tables"]);
    assert_eq!(again.status.code(), Some(1));
    assert!(text(&again).1.contains("--force"));

    // Same input, same config: identical deterministic table.
    let forced = mmtrack(dir.path(), &["process", "odometry", "tiny.mcap", "-o", "tables", "--force", "-q"]);
    assert!(forced.status.success());
    let again = read_table_dir::<OdometryEstimate>(&dir.path().join("tables")).unwrap();
    assert_eq!(&again["oxford-radar-tiny"], estimates);
}

#[test]
fn a_recording_without_radar_scans_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("poses.tum"), "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n").unwrap();
    let out = mmtrack(dir.path(), &["ingest", "poses", "poses.tum", "--format", "tum", "-o", "poses.mcap", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let out = mmtrack(dir.path(), &["process", "odometry", "poses.mcap", "-o", "tables"]);
    assert_eq!(out.status.code(), Some(1));
    let (_, stderr) = text(&out);
    assert!(stderr.contains("poses.mcap") && stderr.contains("no radar scans"), "{stderr}");
    assert!(!dir.path().join("tables").exists());
}

#[test]
fn config_overrides_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.toml"), "grid_meters = 3.0\n").unwrap();
    let out =
        mmtrack(dir.path(), &["process", "odometry", "x.mcap", "-o", "t", "--config", "bad.toml", "--print-config"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out).1.contains("unknown odometry parameter 'grid_meters'"), "{}", text(&out).1);
    std::fs::write(dir.path().join("ok.toml"), "k_strongest = 12\n").unwrap();
    let out =
        mmtrack(dir.path(), &["process", "odometry", "x.mcap", "-o", "t", "--config", "ok.toml", "--print-config"]);
    assert!(out.status.success(), "{}", text(&out).1);
    assert!(text(&out).0.contains("k_strongest = 12"));
}

/// An existing table of the recording's own sequence is refused before the
/// work (its id is read from the recording's metadata), not after it: on a
/// recording without radar scans the refusal, not the odometry's "no radar
/// scans", is what the user sees.
#[test]
fn an_existing_table_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = root().join("data/sounder/convoy-tunnel.toml");
    let sim = mmtrack(
        dir.path(),
        &["simulate", "sounder", "--scenario", scenario.to_str().unwrap(), "-o", "rec.mcap", "--sets", "3", "-q"],
    );
    assert!(sim.status.success(), "{}", text(&sim).1);
    let fresh = mmtrack(dir.path(), &["process", "odometry", "rec.mcap", "-o", "t"]);
    assert!(text(&fresh).1.contains("no radar scans"), "{}", text(&fresh).1);
    let part = dir.path().join("t/odometry/sequence=rec");
    std::fs::create_dir_all(&part).unwrap();
    std::fs::write(part.join("part-0.parquet"), b"earlier results").unwrap();
    let again = mmtrack(dir.path(), &["process", "odometry", "rec.mcap", "-o", "t"]);
    let (_, stderr) = text(&again);
    assert_eq!(again.status.code(), Some(1));
    assert!(stderr.contains("exists; use --force") && !stderr.contains("no radar scans"), "{stderr}");
    assert_eq!(std::fs::read(part.join("part-0.parquet")).unwrap(), b"earlier results");
}
