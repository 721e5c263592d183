//! `mmtrack process beam --tracker spebt`: SPEBT on a simulated radar drive,
//! driven by the `odometry` table of `process odometry` or by the ground
//! truth plus the pose-error model; bad odometry tables and recordings
//! without ground truth are named; odometry tables written with `--run-id`
//! are found in their `run=<ID>` folder.

use std::path::Path;

use mmtrack_core::OdometryEstimate;
use mmtrack_io::Overwrite;
use mmtrack_io::table::{RunInfo, read_table, write_table};
use mmtrack_io::table::{SpebtPooledRow, SpebtSlotRow, SpebtSummaryRow};
use mmtrack_io::table_kv::read_key_value_metadata;

use super::common::{mmtrack, text};

/// 6 s at 8 m/s, 4 Hz: 24 scans.
const DRIVE: &str = r#"
seed = 3
[sensor]
bins = 300
[motion]
speed_mps = 8.0
yaw_rate_radps = 0.05
duration_s = 6.0
[generator]
"#;

fn run(dir: &Path, args: &[&str]) -> (bool, String, String) {
    let out = mmtrack(dir, args);
    let (stdout, stderr) = text(&out);
    (out.status.success(), stdout, stderr)
}

fn tables(dir: &Path, out: &str) -> (SpebtSummaryRow, Vec<SpebtSlotRow>) {
    let root = dir.join(out);
    let summary = read_table::<SpebtSummaryRow>(&root.join("spebt_summary/sequence=drive/part-0.parquet")).unwrap();
    let slots = read_table::<SpebtSlotRow>(&root.join("spebt_per_slot/sequence=drive/part-0.parquet")).unwrap();
    assert_eq!(summary.len(), 1);
    (summary[0].clone(), slots)
}

const ODOMETRY: &str = "tables/odometry/sequence=drive/part-0.parquet";

/// Rewrites the drive's odometry table after `edit`.
fn corrupt(dir: &Path, edit: impl FnOnce(&mut Vec<OdometryEstimate>)) {
    let mut rows = read_table::<OdometryEstimate>(&dir.join(ODOMETRY)).unwrap();
    edit(&mut rows);
    let info = RunInfo::new("{}", mmtrack_io::recording::TimeBase::UnixEpoch)
        .with_frame(mmtrack_io::table::Frame::new("test_world", "a test world frame"));
    write_table(&dir.join("bad"), "drive", &rows, &info, Overwrite::Replace).unwrap();
}

#[test]
fn spebt_tracks_on_the_odometry_table_and_on_the_pose_error_model() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), DRIVE).unwrap();
    let (ok, _, stderr) = run(d, &["simulate", "radar", "--scenario", "s.toml", "-o", "drive.mcap", "-q"]);
    assert!(ok, "{stderr}");
    let (ok, _, stderr) = run(d, &["process", "odometry", "drive.mcap", "-o", "tables", "-q"]);
    assert!(ok, "{stderr}");

    // Driven by the odometry table.
    let spebt = ["process", "beam", "drive.mcap", "--tracker", "spebt"];
    let (ok, stdout, stderr) = run(d, &[&spebt[..], &["--odometry", "tables", "-o", "out"]].concat());
    assert!(ok, "{stderr}");
    assert!(stdout.contains("drive (radar-odometry, 24 slots, 1 run)"), "{stdout}");
    let (summary, slots) = tables(d, "out");
    assert_eq!((summary.experiment.as_str(), summary.slots, summary.runs), ("radar-odometry", 24, 1));
    for value in [summary.rmse_gain_pct, summary.rmse_aod_rad, summary.rmse_aoa_rad] {
        assert!(value.is_finite() && value >= 0.0, "{summary:?}");
    }
    // A short straight-ish drive 130 m from the BS: the AoD moves little;
    // the AoA error is the odometry's heading error plus the filter's.
    assert!(summary.rmse_aod_rad.to_degrees() < 2.0 && summary.rmse_aoa_rad.to_degrees() < 15.0, "{summary:?}");
    assert_eq!(slots.len(), 24);
    assert!(slots.iter().enumerate().all(|(k, s)| s.slot == k as u64 && s.run0_aoa_rad.is_finite()));
    assert!(slots.windows(2).all(|w| w[1].t_ns > w[0].t_ns));
    // Two recordings of one sequence: refused before any work (before, with
    // --force the second replaced the first's partitions, exit 0).
    std::fs::copy(d.join("drive.mcap"), d.join("again.mcap")).unwrap();
    let twice = ["process", "beam", "drive.mcap", "again.mcap", "--tracker", "spebt", "-o", "twice", "--force"];
    let (ok, _, stderr) = run(d, &twice);
    assert!(!ok && stderr.contains("again.mcap: both are sequence drive; give each sequence once"), "{stderr}");
    assert!(!d.join("twice").exists());
    // Again without --force: refused.
    let (ok, _, stderr) = run(d, &[&spebt[..], &["--odometry", "tables", "-o", "out"]].concat());
    assert!(!ok && stderr.contains("--force"), "{stderr}");

    // The estimates drive the tracker: a heading 30 degrees off at row 12
    // changes run 0's estimate from slot 12 on, and nothing before it.
    corrupt(d, |rows| rows[12].world_from_vehicle.yaw_rad += 30f64.to_radians());
    let (ok, _, stderr) = run(d, &[&spebt[..], &["--odometry", "bad", "-o", "turned"]].concat());
    assert!(ok, "{stderr}");
    let (_, turned) = tables(d, "turned");
    assert!(turned[..12].iter().zip(&slots[..12]).all(|(a, b)| a == b));
    assert!(
        (turned[12].run0_aoa_rad - slots[12].run0_aoa_rad).abs().to_degrees() > 1.0 || turned[12].run0_reinitialised
    );

    // Bad odometry tables: NaN, a gap, estimates outside the ground truth's span.
    corrupt(d, |rows| rows[7].world_from_vehicle.y_m = f64::NAN);
    let (ok, _, stderr) = run(d, &[&spebt[..], &["--odometry", "bad", "-o", "nan"]].concat());
    assert!(!ok, "{stderr}");
    assert!(stderr.contains("bad/odometry/sequence=drive/part-0.parquet: row 7") && stderr.contains("y_m is NaN"));
    corrupt(d, |rows| {
        rows.remove(10);
    });
    let (ok, _, stderr) = run(d, &[&spebt[..], &["--odometry", "bad", "-o", "gap"]].concat());
    assert!(!ok && stderr.contains("row 10: t_ns gap of 0.500 s") && stderr.contains("2.0 times"), "{stderr}");
    corrupt(d, |rows| rows.iter_mut().for_each(|r| r.t_ns += 100_000_000));
    let (ok, _, stderr) = run(d, &[&spebt[..], &["--odometry", "bad", "-o", "late"]].concat());
    assert!(!ok && stderr.contains("row 23") && stderr.contains("outside the ground truth's time span"), "{stderr}");
    assert!(!d.join("nan").exists() && !d.join("gap").exists() && !d.join("late").exists());

    // Ground truth plus the pose-error model, deterministic per seed.
    let model = [&spebt[..], &["--sigma-r-m", "0.5", "--sigma-theta-deg", "1", "--runs", "4", "--seed", "7"]].concat();
    let (ok, stdout, stderr) = run(d, &[&model[..], &["-o", "model"]].concat());
    assert!(ok, "{stderr}");
    assert!(stdout.contains("drive (pose-error-model, 24 slots, 4 runs)"), "{stdout}");
    let (summary, slots) = tables(d, "model");
    assert_eq!((summary.experiment.as_str(), summary.runs, summary.seed, slots.len()), ("pose-error-model", 4, 7, 24));
    assert!(
        summary.rmse_aod_rad.is_finite()
            && summary.rmse_aoa_rad.is_finite()
            && summary.rmse_aoa_rad.to_degrees() < 15.0
    );
    let (ok, _, stderr) = run(d, &[&model[..], &["-o", "model2"]].concat());
    assert!(ok, "{stderr}");
    assert_eq!(tables(d, "model2"), (summary.clone(), slots));

    // `analyze` checks the two tables against each other, pools and plots.
    let (ok, stdout, stderr) = run(d, &["analyze", "model", "-o", "analysis"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("spebt pose-error-model (1 sequences, 92 estimates)"), "{stdout}");
    let analysis = d.join("analysis");
    let pooled =
        read_table::<SpebtPooledRow>(&analysis.join("tables/spebt_pooled/sequence=all/part-0.parquet")).unwrap();
    assert_eq!((pooled.len(), pooled[0].tracked_estimates), (1, 23 * 4));
    assert!((pooled[0].rmse_aod_rad - summary.rmse_aod_rad).abs() <= 1e-12 * summary.rmse_aod_rad, "{pooled:?}");
    let copied = read_table::<SpebtSummaryRow>(&analysis.join("tables/spebt_summary/sequence=drive/part-0.parquet"));
    assert_eq!(copied.unwrap(), vec![summary]);
    let svg = std::fs::read_to_string(analysis.join("plots/drive/spebt_tracking.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("AoA (deg)"));
    let report = std::fs::read_to_string(analysis.join("report.md")).unwrap();
    assert!(report.contains("## SPEBT beam tracking") && report.contains("plots/drive/spebt_tracking.svg"), "{report}");
    // A summary that does not belong to its per-slot table is named.
    let mut other =
        read_table::<SpebtSummaryRow>(&d.join("model/spebt_summary/sequence=drive/part-0.parquet")).unwrap();
    other[0].rmse_aod_rad += 1f64.to_radians();
    let info = RunInfo::new("{}", mmtrack_io::recording::TimeBase::UnixEpoch)
        .with_frame(mmtrack_io::table::Frame::new("test_world", "a test world frame"));
    write_table(&d.join("model"), "drive", &other, &info, Overwrite::Replace).unwrap();
    let (ok, _, stderr) = run(d, &["analyze", "model", "-o", "mixed"]);
    assert!(!ok && stderr.contains("sequence drive: spebt_summary.rmse_aod_rad is"), "{stderr}");
    assert!(stderr.contains("not from the same run") && !d.join("mixed").exists(), "{stderr}");

    // The link from --link: a base station elsewhere; one on the path is refused.
    std::fs::write(d.join("far.toml"), "[scenario]\nbs_x_m = -300.0\n").unwrap();
    let (ok, _, stderr) = run(d, &[&spebt[..], &["--link", "far.toml", "-o", "far"]].concat());
    assert!(ok, "{stderr}");
    let (_, far) = tables(d, "far");
    // The vehicle starts at (0, 0): AoD atan2(0 + 125, 0 + 300).
    let expected = 125f64.atan2(300.0);
    assert!((far[0].true_aod_rad - expected).abs() < 1e-9, "{}", far[0].true_aod_rad);
    std::fs::write(d.join("on.toml"), "[scenario]\nbs_x_m = 0.0\nbs_y_m = 0.5\n").unwrap();
    let (ok, _, stderr) = run(d, &[&spebt[..], &["--link", "on.toml", "-o", "on"]].concat());
    assert!(!ok && stderr.contains("on.toml") && stderr.contains("passes 0.500 m from the base station"), "{stderr}");

    // Options that need spebt, spebt with the sweep trackers.
    let (ok, _, stderr) = run(d, &["process", "beam", "drive.mcap", "--odometry", "tables", "-o", "x"]);
    assert!(!ok && stderr.contains("--odometry is an option of --tracker spebt only"), "{stderr}");
    let (ok, _, stderr) = run(d, &["process", "beam", "drive.mcap", "--tracker", "spebt,window", "-o", "x"]);
    assert!(!ok && stderr.contains("spebt runs alone"), "{stderr}");
}

#[test]
fn a_recording_without_ground_truth_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = super::common::root().join("data/sounder/artificial.toml");
    let args = ["simulate", "sounder", "--scenario", scenario.to_str().unwrap(), "-o", "a.mcap", "-q", "--sets", "2"];
    let (ok, _, stderr) = run(dir.path(), &args);
    assert!(ok, "{stderr}");
    let (ok, _, stderr) = run(dir.path(), &["process", "beam", "a.mcap", "--tracker", "spebt", "-o", "out"]);
    assert!(!ok && stderr.contains("a.mcap: 0 ground-truth poses") && stderr.contains("ground truth"), "{stderr}");
    assert!(!dir.path().join("out").exists());
}

/// The odometry table that drove the spebt tables under `out`, as recorded
/// in their run configuration.
fn odometry_used(dir: &Path, out: &str) -> String {
    let file = dir.join(out).join("spebt_summary/sequence=drive/part-0.parquet");
    let metadata = read_key_value_metadata(&file).unwrap();
    let config: serde_json::Value = serde_json::from_str(&metadata["mmtrack.run_config"]).unwrap();
    config["odometry"].as_str().unwrap().to_string()
}

#[test]
fn the_odometry_table_is_found_in_its_run_folder_and_several_runs_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), DRIVE).unwrap();
    let (ok, _, stderr) = run(d, &["simulate", "radar", "--scenario", "s.toml", "-o", "drive.mcap", "-q"]);
    assert!(ok, "{stderr}");
    let (ok, _, stderr) = run(d, &["process", "odometry", "drive.mcap", "-o", "tables", "--run-id", "a", "-q"]);
    assert!(ok, "{stderr}");
    let spebt = ["process", "beam", "drive.mcap", "--tracker", "spebt", "-q"];
    let with = |rest: &[&str]| -> Vec<String> { spebt.iter().chain(rest).map(|s| s.to_string()).collect() };
    let go = |rest: &[&str]| {
        let args = with(rest);
        run(d, &args.iter().map(String::as_str).collect::<Vec<_>>())
    };

    // One run: found in tables/run=a, the same tables as pointing at it by hand.
    let (ok, _, stderr) = go(&["--odometry", "tables", "-o", "found"]);
    assert!(ok, "{stderr}");
    assert!(odometry_used(d, "found").ends_with("tables/run=a/odometry/sequence=drive/part-0.parquet"));
    let (ok, _, stderr) = go(&["--odometry", "tables/run=a", "-o", "by-hand"]);
    assert!(ok, "{stderr}");
    let run_a = tables(d, "found");
    assert_eq!(run_a, tables(d, "by-hand"));

    // A second run whose heading is 30 degrees off from row 12 on: which run
    // was read shows in the tracker's estimates.
    let mut rows =
        read_table::<OdometryEstimate>(&d.join("tables/run=a/odometry/sequence=drive/part-0.parquet")).unwrap();
    rows[12..].iter_mut().for_each(|r| r.world_from_vehicle.yaw_rad += 30f64.to_radians());
    let info = RunInfo::new("{}", mmtrack_io::recording::TimeBase::UnixEpoch)
        .with_frame(mmtrack_io::table::Frame::new("test_world", "a test world frame"));
    write_table(&d.join("tables/run=b"), "drive", &rows, &info, Overwrite::Refuse).unwrap();
    // A run of another sequence only does not count.
    write_table(&d.join("tables/run=other"), "elsewhere", &rows, &info, Overwrite::Refuse).unwrap();

    // Two runs hold the sequence: refused naming both ids, nothing written.
    let (ok, _, stderr) = go(&["--odometry", "tables", "-o", "ambiguous"]);
    assert!(!ok, "two runs were not refused");
    assert!(stderr.contains("tables: 2 runs hold an `odometry` table of sequence drive"), "{stderr}");
    assert!(stderr.contains("run ids a, b;") && stderr.contains("--odometry-run <ID>"), "{stderr}");
    assert!(!d.join("ambiguous").exists());

    // --odometry-run picks one: run b's tables differ from run a's from slot 12 on.
    let (ok, _, stderr) = go(&["--odometry", "tables", "--odometry-run", "b", "-o", "picked-b"]);
    assert!(ok, "{stderr}");
    assert!(odometry_used(d, "picked-b").ends_with("tables/run=b/odometry/sequence=drive/part-0.parquet"));
    let (_, run_b) = tables(d, "picked-b");
    assert_eq!(run_b[..12], run_a.1[..12]);
    assert!(
        (run_b[12].run0_aoa_rad - run_a.1[12].run0_aoa_rad).abs().to_degrees() > 1.0 || run_b[12].run0_reinitialised
    );
    let (ok, _, stderr) = go(&["--odometry", "tables", "--odometry-run", "a", "-o", "picked-a"]);
    assert!(ok, "{stderr}");
    assert_eq!(tables(d, "picked-a"), run_a);

    // A run without the table, a bad id, --odometry-run without --odometry or with the sweep trackers.
    let (ok, _, stderr) = go(&["--odometry", "tables", "--odometry-run", "other", "-o", "x"]);
    assert!(!ok && stderr.contains("run=other/odometry/sequence=drive/part-0.parquet: not found"), "{stderr}");
    assert!(stderr.contains("holding one: a, b"), "{stderr}");
    let (ok, _, stderr) = go(&["--odometry", "tables", "--odometry-run", "../a", "-o", "x"]);
    assert!(!ok && stderr.contains("--odometry-run '../a': not a valid run id"), "{stderr}");
    let (ok, _, stderr) = go(&["--odometry-run", "a", "-o", "x"]);
    assert!(!ok && stderr.contains("--odometry <TABLES>"), "{stderr}");
    let (ok, _, stderr) =
        run(d, &["process", "beam", "drive.mcap", "--odometry", "tables", "--odometry-run", "a", "-o", "x"]);
    assert!(!ok && stderr.contains("is an option of --tracker spebt only"), "{stderr}");
    assert!(!d.join("x").exists());

    // A table directly under the directory (no --run-id) is the one read, as before run folders.
    write_table(&d.join("tables"), "drive", &rows, &info, Overwrite::Refuse).unwrap();
    let (ok, _, stderr) = go(&["--odometry", "tables", "-o", "plain"]);
    assert!(ok, "{stderr}");
    assert!(odometry_used(d, "plain").ends_with("tables/odometry/sequence=drive/part-0.parquet"));
    assert_eq!(tables(d, "plain").1, run_b);
    // No table anywhere: the message says where it looked.
    let (ok, _, stderr) = go(&["--odometry", "nothing", "-o", "x"]);
    assert!(!ok && stderr.contains("nor in a run=<ID>/ folder of nothing"), "{stderr}");
}
