//! The `odometry` table is written in the ground truth's frame, so a plain
//! join of `odometry` and `ground_truth` on `(sequence, t_ns)` in DuckDB gives
//! the position RMSE that `mmtrack analyze` reports (real Oxford scans;
//! Oxford Radar RobotCar Dataset, Barnes et al., ICRA 2020, CC BY-NC-SA 4.0).
//! Runs given `--run-id` sit side by side and read back with a `run` column.

use std::process::Command;

use super::common::{mmtrack, realdata, text, venv_python};

/// DuckDB over the tables: the joined RMSE, analyze's, the frame named in
/// the key-value metadata, and the runs found under `runs/`.
const QUERY: &str = r#"
import json, sys, duckdb
root = sys.argv[1]
con = duckdb.connect()
def parquet(path):
    return f"read_parquet('{root}/{path}', hive_partitioning=true)"
joined = con.execute(f"""
    SELECT sqrt(avg((o.x_m - g.x_m) ^ 2 + (o.y_m - g.y_m) ^ 2)), count(*)
    FROM {parquet('tables/odometry/*/*.parquet')} o
    JOIN {parquet('tables/ground_truth/*/*.parquet')} g USING (sequence, t_ns)
""").fetchone()
analyze = con.execute(f"""
    SELECT position_rmse_m, associated_poses, interpolated_poses
    FROM {parquet('analysis/tables/trajectory_metrics/*/*.parquet')}
""").fetchone()
config = con.execute(f"""
    SELECT value FROM parquet_kv_metadata('{root}/tables/odometry/*/*.parquet')
    WHERE key = 'mmtrack.run_config'
""").fetchone()[0]
runs = con.execute(f"""
    SELECT run, sequence, count(*) FROM {parquet('runs/*/odometry/*/*.parquet')} GROUP BY ALL ORDER BY ALL
""").fetchall()
print(json.dumps({
    "joined_rmse_m": joined[0], "joined_rows": joined[1],
    "analyze_rmse_m": analyze[0], "associated": analyze[1], "interpolated": analyze[2],
    "frame": json.loads(config)["frame"],
    "runs": [list(r) for r in runs],
}))
"#;

#[test]
fn duckdb_join_of_odometry_and_ground_truth_gives_analyze_position_rmse() {
    let Some(realdata) = realdata("odometry_frames") else { return };
    let python = venv_python().expect("Python 3 with pip access to PyPI (duckdb) is needed");
    let input = realdata.join("oxford-radar-tiny");
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = |args: &[&str]| {
        super::common::mmtrack_ok(d, args);
    };
    run(&["ingest", "oxford", input.to_str().unwrap(), "-o", "rec.mcap", "-q"]);
    run(&["process", "odometry", "rec.mcap", "-o", "tables", "--preset", "fast-cfear", "-q"]);
    run(&["analyze", "tables", "-o", "analysis", "-q"]);
    run(&["process", "odometry", "rec.mcap", "-o", "runs", "--preset", "fast-cfear", "--run-id", "fast", "-q"]);
    run(&["process", "odometry", "rec.mcap", "-o", "runs", "--preset", "cfear", "--run-id", "cfear", "-q"]);
    let out = mmtrack(d, &["process", "odometry", "rec.mcap", "-o", "runs", "--run-id", "../x", "-q"]);
    assert_eq!(out.status.code(), Some(1), "a run id that is not one path component is refused");

    let script = d.join("query.py");
    std::fs::write(&script, QUERY).unwrap();
    let out = Command::new(python).arg(&script).arg(d).output().unwrap();
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    // Every scan has a ground-truth pose of its own time (radar_odometry.csv
    // is keyed on the scan stamps), so the join keeps all 11 rows and
    // analyze interpolates none.
    assert_eq!((json["joined_rows"].as_u64(), json["associated"].as_u64()), (Some(11), Some(11)), "{json}");
    assert_eq!(json["interpolated"], 0, "{json}");
    let (joined, analyze) = (json["joined_rmse_m"].as_f64().unwrap(), json["analyze_rmse_m"].as_f64().unwrap());
    // Rounding only: the table holds truth(t0) * est(t0)^-1 * est(t) in a
    // frame some 150 m from its origin, analyze re-expresses both relative
    // to their first pose; 1e-9 m is 1e6 ulps of 150 m, far below any error.
    assert!((joined - analyze).abs() < 1e-9, "joined {joined} m vs analyze {analyze} m");
    // Not trivially zero: 11 scans of real odometry drift by centimetres.
    assert!(analyze > 1e-3, "{analyze}");
    assert_eq!(json["frame"]["world"], "ground_truth", "{json}");
    assert_eq!(
        json["runs"],
        serde_json::json!([["cfear", "oxford-radar-tiny", 11], ["fast", "oxford-radar-tiny", 11]]),
        "{json}"
    );
}
