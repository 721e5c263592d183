//! Issue 28, "Tables": every table explains itself. pyarrow reads every
//! Parquet file `mmtrack demo` writes (ingest, process of every pipeline,
//! analyze, and the compared runs) and finds in each its time base, its frame
//! and, on every field, a unit and a description
//! (`tests/python/table_metadata.py`); the same script fails on a file that
//! lacks one of them.

use std::process::Command;

use super::common::{mmtrack, root, text, venv_python};

#[test]
fn every_demo_table_states_time_base_frame_and_per_field_unit_and_description() {
    let dir = tempfile::tempdir().unwrap();
    let out = mmtrack(dir.path(), &["demo", "--out", "d", "--quiet"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let python = venv_python().expect("Python 3 with pip access to PyPI (pyarrow) is needed");
    let script = root().join("tests/python/table_metadata.py");
    let d = dir.path().join("d");
    let checked = Command::new(&python).arg(&script).arg(&d).output().unwrap();
    let (stdout, stderr) = text(&checked);
    assert!(checked.status.success(), "{stdout}{stderr}");
    println!("{stdout}");
    // Every pipeline's tables, the analysis's and the comparison's, each named. The demo's radar drive
    // is simulated (its Oxford folder says so): the simulator's clock, not UNIX dates.
    for (file, time_base, frame) in [
        ("tables/odometry/sequence=oxford-demo/part-0.parquet", "scenario_start", "ground_truth"),
        ("tables/ground_truth/sequence=oxford-demo/part-0.parquet", "scenario_start", "ground_truth"),
        ("tables/odometry_timing/sequence=oxford-demo/part-0.parquet", "scenario_start", "not_applicable"),
        ("tables/spebt_per_slot/sequence=oxford-demo/part-0.parquet", "scenario_start", "first_pose"),
        ("tables/slam_ue/sequence=slam/part-0.parquet", "scenario_start", "recording_world"),
        ("analysis/tables/trajectory_metrics/sequence=oxford-demo/part-0.parquet", "scenario_start", "not_applicable"),
        ("analysis/tables/mpc_summary/sequence=sounder/part-0.parquet", "scenario_start", "not_applicable"),
    ] {
        let line = format!("{file}: time_base={time_base} frame={frame} ");
        assert!(stdout.contains(&line), "{line}\n{stdout}");
    }
    for table in ["mpc_tracks", "ground_truth_tx", "slam_map", "spebt_pooled", "run_comparison"] {
        assert!(stdout.contains(&format!("/{table}/")), "{table}: {stdout}");
    }
    let files: usize = stdout.lines().last().unwrap().split(' ').nth(1).unwrap().parse().unwrap();
    assert!(files >= 40, "{stdout}");

    // A file without the time base, and one whose field lost its description, fail by name.
    let bad = dir.path().join("bad");
    for (name, strip) in [
        (
            "no_time_base",
            "table.replace_schema_metadata({k: v for k, v in table.schema.metadata.items() if k != b'time_base'})",
        ),
        (
            "no_description",
            "table.cast(pa.schema([f.with_metadata({b'unit': b'm'}) if f.name == 'x_m' else f for f in table.schema], metadata=table.schema.metadata))",
        ),
    ] {
        let target = bad.join(name);
        std::fs::create_dir_all(&target).unwrap();
        let source = d.join("tables/odometry/sequence=oxford-demo/part-0.parquet");
        let rewrite = format!(
            "import pyarrow as pa, pyarrow.parquet as pq\ntable = pq.read_table({source:?})\ntable = {strip}\npq.write_table(table, {:?})\n",
            target.join("part-0.parquet")
        );
        let rewritten = Command::new(&python).arg("-c").arg(&rewrite).output().unwrap();
        assert!(rewritten.status.success(), "{}", text(&rewritten).1);
        let refused = Command::new(&python).arg(&script).arg(&target).output().unwrap();
        let (stdout, stderr) = text(&refused);
        assert!(!refused.status.success(), "{name}: accepted\n{stdout}");
        let expected = if name == "no_time_base" {
            "part-0.parquet: no 'time_base' in the table's key-value metadata"
        } else {
            "part-0.parquet: field 'x_m' has no 'description' in its metadata"
        };
        assert!(stderr.contains(expected), "{name}: {stderr}");
    }
}
