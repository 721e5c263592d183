//! Every parallel stage writes the same bytes with `--threads 1` and
//! `--threads 2`: the radar and sounder simulators (recordings), ingest of an
//! Oxford folder (recording), radar odometry and MPC detection and tracking
//! (tables).

use std::path::Path;

use super::common::{files, mmtrack, realdata, root, text};

/// Radar scenario: enough sweeps for several rayon batches at two threads.
const RADAR: &str = r#"
seed = 11
start_t_ns = 1_700_000_000_000_000_000
max_scans = 9
[sensor]
bins = 600
[motion]
speed_mps = 8.0
yaw_rate_radps = 0.05
duration_s = 4.0
[generator]
"#;

/// Runs `args` twice, with `--threads 1` in `dir/t1` and with `--threads 2`
/// in `dir/t2` (the same output names, since recordings take their sequence
/// id from the output file's name; inputs are given from `dir` as `../x`).
fn run_with_1_and_2_threads(dir: &Path, args: &[&str]) {
    for threads in ["1", "2"] {
        let cwd = dir.join(format!("t{threads}"));
        std::fs::create_dir_all(&cwd).unwrap();
        let mut args = args.to_vec();
        args.extend(["--threads", threads]);
        super::common::mmtrack_ok(&cwd, &args);
    }
}

/// `dir/t1/path` and `dir/t2/path` hold the same bytes.
fn assert_same_bytes(dir: &Path, path: &str) {
    let (one, two) = (dir.join("t1").join(path), dir.join("t2").join(path));
    let (left, right) = (std::fs::read(&one).unwrap(), std::fs::read(&two).unwrap());
    assert!(!left.is_empty(), "{} is empty", one.display());
    assert!(left == right, "{} and {} differ", one.display(), two.display());
}

/// Every table file of the two runs' output directories `dir/t1/tables` and
/// `dir/t2/tables` is identical, but those of `except` (tables holding
/// wall-clock measurements). Returns the number of files compared.
fn assert_same_tables(dir: &Path, except: &[&str]) -> usize {
    let listed = files(&dir.join("t1/tables"));
    assert_eq!(listed, files(&dir.join("t2/tables")), "the same tables");
    let compared: Vec<_> = listed.iter().filter(|f| !except.iter().any(|e| f.starts_with(e))).collect();
    for file in &compared {
        assert_same_bytes(dir, &Path::new("tables").join(file).to_string_lossy());
    }
    compared.len()
}

#[test]
fn radar_simulation_ingest_and_odometry_write_the_same_bytes_on_1_and_2_threads() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), RADAR).unwrap();

    // Simulator, straight into a recording.
    run_with_1_and_2_threads(d, &["simulate", "radar", "--scenario", "../s.toml", "-o", "sim.mcap", "-q"]);
    assert_same_bytes(d, "sim.mcap");

    // Simulator into an Oxford folder, then ingest (PNG decoding on the pool).
    let out = mmtrack(d, &["simulate", "radar", "--scenario", "s.toml", "--format", "oxford", "-o", "oxford", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
    run_with_1_and_2_threads(d, &["ingest", "oxford", "../oxford", "--bins", "auto", "-o", "ingest.mcap", "-q"]);
    assert_same_bytes(d, "ingest.mcap");

    // Radar odometry (scans decoded on the pool while the odometry runs).
    // `odometry_timing` holds wall-clock seconds per stage, different in
    // every run; every other table must match.
    run_with_1_and_2_threads(d, &["process", "odometry", "../t1/ingest.mcap", "-o", "tables", "-q"]);
    let compared = assert_same_tables(d, &["odometry_timing"]);
    assert!(compared >= 2, "odometry and ground_truth compared, got {compared}");
}

#[test]
fn real_oxford_ingest_and_odometry_write_the_same_bytes_on_1_and_2_threads() {
    let Some(realdata) = realdata("threads_real_oxford") else { return };
    let input = realdata.join("oxford-radar-tiny");
    let input = input.to_str().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    run_with_1_and_2_threads(d, &["ingest", "oxford", input, "-o", "real.mcap", "-q"]);
    assert_same_bytes(d, "real.mcap");
    let args = ["process", "odometry", "../t1/real.mcap", "-o", "tables", "-q", "--preset", "fast-cfear"];
    run_with_1_and_2_threads(d, &args);
    assert_same_tables(d, &["odometry_timing"]);
}

#[test]
fn sounder_simulation_and_mpc_processing_write_the_same_bytes_on_1_and_2_threads() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scenario = root().join("data/sounder/convoy-tunnel.toml");
    let scenario = scenario.to_str().unwrap();
    // 20 sets: several batches of the simulator at two threads.
    run_with_1_and_2_threads(
        d,
        &["simulate", "sounder", "--scenario", scenario, "--sets", "20", "-o", "conv.mcap", "-q"],
    );
    assert_same_bytes(d, "conv.mcap");

    run_with_1_and_2_threads(d, &["process", "mpc", "../t1/conv.mcap", "-o", "tables", "--gmphd", "-q"]);
    let compared = assert_same_tables(d, &[]);
    assert!(compared >= 7, "every MPC table compared, got {compared}");
}
