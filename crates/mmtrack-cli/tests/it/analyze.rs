//! `mmtrack analyze` and `mmtrack export` end to end, and an independent check
//! of the KITTI drift: a Python re-implementation of the devkit
//! (`tests/python/kitti_devkit.py`) reads the exported KITTI files.

use std::path::Path;
use std::process::Command;

use mmtrack_core::{OdometryEstimate, Se2, StampedPose};
use mmtrack_io::Overwrite;
use mmtrack_io::table::{
    DriftPerLength, GroundTruthPose, RelativePoseErrorRow, RunInfo, TrajectoryMetrics, read_table, table_path,
    write_table,
};

use super::common::{mmtrack, text};

const T0_NS: i64 = 1_600_000_000_123_456_789;

fn estimate_row(t_ns: i64, pose: Se2) -> OdometryEstimate {
    OdometryEstimate {
        t_ns,
        world_from_vehicle: pose,
        filtered_points: 0,
        surface_points: 0,
        correspondences: 0,
        iterations: 0,
        cost_m2: 0.0,
        low_confidence: false,
    }
}

/// A ~`frames * 2` m drive: ground truth at 10 Hz with a varying turn rate;
/// the estimate at 4 Hz, 30 ms after ground-truth samples (so ground truth
/// is interpolated), composed from the true motion with a 2 % scale error,
/// a yaw bias and deterministic wobble; its first pose precedes the ground
/// truth (so it is dropped).
fn drive(gt_frames: usize) -> (Vec<OdometryEstimate>, Vec<GroundTruthPose>) {
    let step_ns = 100_000_000;
    let mut gt = vec![Se2::IDENTITY];
    for k in 1..gt_frames {
        let s = k as f64;
        let step = Se2::new(0.8 + 0.2 * (0.013 * s).sin(), 0.0, 0.02 * (0.021 * s).sin() + 0.004);
        gt.push(gt[k - 1] * step);
    }
    let world_from_gt0 = Se2::new(1234.5, -678.25, 2.0);
    let truth: Vec<GroundTruthPose> = gt
        .iter()
        .enumerate()
        .map(|(k, p)| {
            GroundTruthPose(StampedPose { t_ns: T0_NS + k as i64 * step_ns, parent_from_child: world_from_gt0 * *p })
        })
        .collect();
    let mut estimate = vec![estimate_row(T0_NS - 50_000_000, Se2::IDENTITY)];
    let mut pose = Se2::IDENTITY;
    let mut previous_truth = gt[0];
    for (j, k) in (0..gt_frames - 1).step_by(5).enumerate().skip(1) {
        // Between gt k and k + 1, 30 ms past k (k steps by 2.5 samples on average).
        let t = T0_NS + k as i64 * step_ns + 30_000_000;
        let truth_at =
            gt[k] * Se2::new(0.3 * (gt[k].inverse() * gt[k + 1]).x_m, 0.0, 0.3 * (gt[k].inverse() * gt[k + 1]).yaw_rad);
        let true_step = previous_truth.inverse() * truth_at;
        let wobble = (0.7 * j as f64).sin();
        pose = pose
            * Se2::new(1.02 * true_step.x_m, true_step.y_m + 0.01 * wobble, true_step.yaw_rad + 2e-3 + 2e-3 * wobble);
        estimate.push(estimate_row(t, pose));
        previous_truth = truth_at;
    }
    (estimate, truth)
}

fn write_pair(root: &Path, sequence: &str, estimate: &[OdometryEstimate], truth: Option<&[GroundTruthPose]>) {
    let run = RunInfo::new("{}", mmtrack_io::recording::TimeBase::UnixEpoch)
        .with_frame(mmtrack_io::table::Frame::new("test_world", "a test world frame"));
    write_table(root, sequence, estimate, &run, Overwrite::Refuse).unwrap();
    if let Some(truth) = truth {
        write_table(root, sequence, truth, &run, Overwrite::Refuse).unwrap();
    }
}

fn relative_diff(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

#[test]
fn analyze_agrees_with_an_independent_devkit_on_exported_kitti_files() {
    let dir = tempfile::tempdir().unwrap();
    let (estimate, truth) = drive(4000);
    write_pair(&dir.path().join("tables"), "drive-a", &estimate, Some(&truth));
    let lengths = "50,100,150,200,250,300,350,400";
    let out = mmtrack(dir.path(), &["analyze", "tables", "-o", "analysis", "--segment-lengths-m", lengths]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stdout.contains("drive-a:") && stdout.contains("KITTI") && stdout.contains("analysis/report.md"),
        "{stdout}"
    );
    assert!(stdout.contains("1 estimate pose outside the ground-truth span dropped"), "{stdout}");
    for plot in ["trajectory.svg", "errors_vs_distance.svg", "drift_per_length.svg"] {
        let svg = std::fs::read_to_string(dir.path().join("analysis/plots/drive-a").join(plot)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("polyline"), "{plot}");
    }
    let report = std::fs::read_to_string(dir.path().join("analysis/report.md")).unwrap();
    assert!(report.contains("| drive-a | `odometry` |") && report.contains("plots/drive-a/trajectory.svg"), "{report}");

    let tables = dir.path().join("analysis/tables");
    let metrics: Vec<TrajectoryMetrics> =
        read_table(&table_path(&tables, "trajectory_metrics", "drive-a").unwrap()).unwrap();
    let per_length: Vec<DriftPerLength> =
        read_table(&table_path(&tables, "drift_per_length", "drive-a").unwrap()).unwrap();
    let rpe: Vec<RelativePoseErrorRow> =
        read_table(&table_path(&tables, "relative_pose_errors", "drive-a").unwrap()).unwrap();
    let m = &metrics[0];
    assert_eq!((m.dropped_poses, m.associated_poses as usize), (1, estimate.len() - 1));
    assert_eq!(rpe.len(), estimate.len() - 2);
    assert!(m.path_length_m > 3000.0 && m.kitti_segments > 100, "{m:?}");
    // The 2 % scale error dominates the translational drift.
    let t_pct = m.kitti_translational_pct.unwrap();
    assert!(t_pct > 1.5 && t_pct < 10.0, "{t_pct}");

    let export = mmtrack(dir.path(), &["export", "--format", "kitti", "tables", "-o", "kitti"]);
    assert!(export.status.success(), "{}", text(&export).1);
    let kitti = dir.path().join("kitti");
    let times = std::fs::read_to_string(kitti.join("drive-a.times.txt")).unwrap();
    assert_eq!(times.lines().count(), estimate.len() - 1);
    assert!(times.starts_with("0.000000000\n"), "{}", &times[..40]);

    let Some(python) = super::common::venv_python() else {
        eprintln!("skipped: independent KITTI devkit check: no Python venv (python3 or PyPI unavailable)");
        return;
    };
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/kitti_devkit.py");
    let run = Command::new(python)
        .arg(script)
        .arg(kitti.join("drive-a.ground_truth.kitti.txt"))
        .arg(kitti.join("drive-a.estimate.kitti.txt"))
        .arg(lengths)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let devkit: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    assert_eq!(devkit["segments"].as_u64().unwrap(), m.kitti_segments);
    // 1e-9 relative: both sides read the same f64s; they differ only in the
    // rounding of the matrix products (ulps), amplified by acos near 1.
    let t = devkit["t_err"].as_f64().unwrap() * 100.0;
    let r = devkit["r_err"].as_f64().unwrap().to_degrees();
    assert!(relative_diff(t, t_pct) < 1e-9, "translational {t} % (devkit) vs {t_pct} %");
    // The devkit's deg/m, ours per 100 m.
    let ours_r = m.kitti_rotational_deg_per_100m.unwrap() / 100.0;
    assert!(relative_diff(r, ours_r) < 1e-9, "rotational {r} deg/m (devkit) vs {ours_r} deg/m");
    let theirs = devkit["per_length"].as_array().unwrap();
    assert_eq!(theirs.len(), per_length.len());
    for (d, ours) in theirs.iter().zip(&per_length) {
        assert_eq!(d["segments"].as_u64().unwrap(), ours.segments);
        let t = d["t_err"].as_f64().unwrap() * 100.0;
        assert!(relative_diff(t, ours.translational_pct) < 1e-9, "{d} vs {ours:?}");
        let r = d["r_err"].as_f64().unwrap().to_degrees();
        assert!(relative_diff(r, ours.rotational_deg_per_100m / 100.0) < 1e-9, "{d} vs {ours:?}");
    }
}

#[test]
fn analyze_refuses_to_overwrite_and_force_replaces_only_results() {
    let dir = tempfile::tempdir().unwrap();
    let (estimate, truth) = drive(300);
    write_pair(&dir.path().join("tables"), "s1", &estimate, Some(&truth));
    let args = ["analyze", "tables", "-o", "res", "--segment-lengths-m", "10,20,40", "--quiet"];
    assert!(mmtrack(dir.path(), &args).status.success());
    let report = std::fs::read(dir.path().join("res/report.md")).unwrap();
    let again = mmtrack(dir.path(), &args);
    assert_eq!(again.status.code(), Some(1));
    assert!(text(&again).1.contains("--force"), "{}", text(&again).1);
    let forced = mmtrack(dir.path(), &[&args[..], &["--force"]].concat());
    assert!(forced.status.success(), "{}", text(&forced).1);
    // Deterministic: the same input gives the same report.
    assert_eq!(std::fs::read(dir.path().join("res/report.md")).unwrap(), report);
    // A directory with other files is never replaced, even with --force.
    std::fs::write(dir.path().join("res/notes.txt"), "mine").unwrap();
    let refused = mmtrack(dir.path(), &[&args[..], &["--force"]].concat());
    assert_eq!(refused.status.code(), Some(1));
    assert!(text(&refused).1.contains("notes.txt"), "{}", text(&refused).1);
    assert!(dir.path().join("res/notes.txt").is_file() && dir.path().join("res/report.md").is_file());
    // No staging directory is left behind.
    let hidden: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
}

#[test]
fn analyze_says_what_it_looked_for_and_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("empty")).unwrap();
    let out = mmtrack(dir.path(), &["analyze", "empty", "-o", "res"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr.contains("odometry") && stderr.contains("ground_truth") && stderr.contains("found no tables"),
        "{stderr}"
    );

    let (estimate, truth) = drive(300);
    write_pair(&dir.path().join("only-est"), "s1", &estimate, None);
    let out = mmtrack(dir.path(), &["analyze", "only-est", "-o", "res"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("sequence s1") && stderr.contains("no ground_truth table"), "{stderr}");
    assert!(!dir.path().join("res").exists());

    let mut backwards = estimate.clone();
    backwards[7].t_ns = backwards[5].t_ns;
    write_pair(&dir.path().join("bad-time"), "s2", &backwards, Some(&truth));
    let out = mmtrack(dir.path(), &["analyze", "bad-time", "-o", "res"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr.contains("sequence s2") && stderr.contains("row 7") && stderr.contains("does not increase"),
        "{stderr}"
    );

    // A run's output directory (tables inside `tables/`), one table's folder
    // and one sequence's: the error says where the tables are.
    write_pair(&dir.path().join("run").join("tables"), "s4", &estimate, Some(&truth));
    for (given, hint) in [
        ("run", "(the tables are in run/tables: pass that directory)"),
        (
            "run/tables/odometry",
            "(run/tables/odometry is one table's folder; pass the directory that holds the tables, run/tables)",
        ),
        (
            "run/tables/odometry/sequence=s4",
            "(run/tables/odometry/sequence=s4 is one sequence of one table; pass the directory that holds the tables, \
             run/tables)",
        ),
    ] {
        let out = mmtrack(dir.path(), &["analyze", given, "-o", "res"]);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(1), "{given}");
        assert!(stderr.contains("found no tables") && stderr.contains(hint), "{given}: {stderr}");
    }
    assert!(!dir.path().join("res").exists());

    let mut nan_truth = truth.clone();
    nan_truth[3].0.parent_from_child.y_m = f64::NAN;
    write_pair(&dir.path().join("nan"), "s3", &estimate, Some(&nan_truth));
    let out = mmtrack(dir.path(), &["analyze", "nan", "-o", "res"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr.contains("ground_truth/sequence=s3/part-0.parquet: row 3: y_m: NaN is not a coordinate"),
        "{stderr}"
    );
    assert!(!dir.path().join("res").exists());
}

#[test]
fn short_drive_reports_no_kitti_segment_instead_of_nan() {
    let dir = tempfile::tempdir().unwrap();
    let (estimate, truth) = drive(100);
    write_pair(&dir.path().join("tables"), "s1", &estimate, Some(&truth));
    let out = mmtrack(dir.path(), &["analyze", "tables", "-o", "res"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stdout.contains("KITTI n/a") && stdout.contains("shorter than the shortest segment length 100 m"),
        "{stdout}"
    );
    let metrics: Vec<TrajectoryMetrics> =
        read_table(&table_path(&dir.path().join("res/tables"), "trajectory_metrics", "s1").unwrap()).unwrap();
    assert_eq!((metrics[0].kitti_segments, metrics[0].kitti_translational_pct), (0, None));
    assert!(metrics[0].ate_rmse_m.is_finite());
    // No drift-per-length figure of a sentence without axes: the report says why in its place.
    assert!(dir.path().join("res/plots/s1/trajectory.svg").exists());
    assert!(!dir.path().join("res/plots/s1/drift_per_length.svg").exists());
    let report = std::fs::read_to_string(dir.path().join("res/report.md")).unwrap();
    assert!(!report.contains("drift_per_length.svg") && report.contains("No KITTI segment"), "{report}");
}

#[test]
fn export_writes_tum_and_boreas_files_that_parse_back() {
    let dir = tempfile::tempdir().unwrap();
    let (estimate, truth) = drive(300);
    write_pair(&dir.path().join("tables"), "s1", &estimate, Some(&truth));
    write_pair(&dir.path().join("tables"), "s2", &estimate, None);
    let out = mmtrack(dir.path(), &["export", "--format", "tum", "tables", "-o", "tum"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("s2: no ground_truth table"), "{stdout}");
    let tum = std::fs::read_to_string(dir.path().join("tum/s1.estimate.tum.txt")).unwrap();
    assert_eq!(tum.lines().count(), estimate.len());
    let second: Vec<&str> = tum.lines().nth(1).unwrap().split(' ').collect();
    assert_eq!(second.len(), 8);
    assert_eq!(second[0], format!("{}.{:09}", estimate[1].t_ns / 1_000_000_000, estimate[1].t_ns % 1_000_000_000));
    assert_eq!(second[1].parse::<f64>().unwrap(), estimate[1].world_from_vehicle.x_m);
    let gt = std::fs::read_to_string(dir.path().join("tum/s1.ground_truth.tum.txt")).unwrap();
    assert_eq!(gt.lines().count(), truth.len());
    // Refuses to overwrite; one sequence on request.
    let again = mmtrack(dir.path(), &["export", "--format", "tum", "tables", "-o", "tum", "--sequence", "s1"]);
    assert_eq!(again.status.code(), Some(1));
    let missing = mmtrack(dir.path(), &["export", "--format", "tum", "tables", "-o", "x", "--sequence", "nope"]);
    assert!(text(&missing).1.contains("sequences: s1, s2"), "{}", text(&missing).1);

    let out = mmtrack(dir.path(), &["export", "--format", "boreas", "tables", "-o", "b", "--sequence", "s1"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let boreas = std::fs::read_to_string(dir.path().join("b/boreas/estimate/s1.txt")).unwrap();
    let first: Vec<f64> = boreas.lines().next().unwrap().split(' ').map(|v| v.parse().unwrap()).collect();
    assert_eq!(first.len(), 13);
    assert_eq!(first[0], (estimate[1].t_ns / 1000) as f64);
    assert!(dir.path().join("b/boreas/ground_truth/s1.txt").is_file());
}

/// DuckDB over the campaign output, independent of polars: per run, the
/// pooled trajectory values computed from the runs' own `trajectory_metrics`
/// by the stated rules, and the same values read from `run_comparison`.
const CAMPAIGN_QUERY: &str = r#"
import json, sys, duckdb
root = sys.argv[1]
con = duckdb.connect()
metrics = f"read_parquet('{root}/run=*/tables/trajectory_metrics/*/*.parquet', hive_partitioning=true)"
comparison = f"read_parquet('{root}/tables/run_comparison/*/*.parquet', hive_partitioning=true)"
mine = con.execute(f"""
    SELECT run,
        sum(kitti_translational_pct * kitti_segments) / sum(kitti_segments),
        sqrt(sum(associated_poses * ate_rmse_m ^ 2) / sum(associated_poses)),
        sqrt(sum((associated_poses - 1) * rpe_translation_rmse_m ^ 2) / sum(associated_poses - 1)),
        avg(position_rmse_m),
        count(*)
    FROM {metrics} GROUP BY run HAVING count(*) > 1 ORDER BY run
""").fetchall()
theirs = con.execute(f"""
    SELECT run,
        max(CASE WHEN sequence = 'all' AND metric = 'kitti_translational_pct' THEN value END),
        max(CASE WHEN sequence = 'all' AND metric = 'ate_rmse_m' THEN value END),
        max(CASE WHEN sequence = 'all' AND metric = 'rpe_translation_rmse_m' THEN value END),
        max(CASE WHEN sequence = 'mean' AND metric = 'position_rmse_m' THEN value END),
        count(DISTINCT sequence) - 2
    FROM {comparison} WHERE source_table = 'trajectory_metrics' GROUP BY run
    HAVING count(CASE WHEN sequence IN ('all', 'mean') THEN 1 END) > 0 ORDER BY run
""").fetchall()
# Issue 28: filtering on the sequence (the Hive column) finds the rows, in DuckDB and in pyarrow.
import pyarrow.dataset as ds
dataset = ds.dataset(f"{root}/tables/run_comparison", format="parquet", partitioning="hive")
filtered = {}
for sequence in ["long", "short", "all", "mean"]:
    duck = con.execute(f"SELECT count(*) FROM {comparison} WHERE sequence = '{sequence}'").fetchone()[0]
    arrow = dataset.to_table(filter=ds.field("sequence") == sequence).num_rows
    filtered[sequence] = [duck, arrow]
print(json.dumps({"duckdb": [list(r) for r in mine], "run_comparison": [list(r) for r in theirs], "filtered": filtered}))
"#;

#[test]
fn analyze_puts_runs_side_by_side_with_pooled_rows_a_duckdb_query_reproduces() {
    let python = super::common::venv_python().expect("Python 3 with pip access to PyPI (duckdb) is needed");
    let dir = tempfile::tempdir().unwrap();
    // Two runs of two sequences of different lengths (so the pooling weights
    // matter); run b's estimates are run a's with a different yaw bias.
    for (run, yaw_bias_rad) in [("a", 0.0), ("b", 1e-3)] {
        for (sequence, frames) in [("long", 2400), ("short", 900)] {
            let (mut estimate, truth) = drive(frames);
            let mut bias = Se2::IDENTITY;
            for e in &mut estimate {
                bias = bias * Se2::new(0.0, 0.0, yaw_bias_rad);
                e.world_from_vehicle = e.world_from_vehicle * bias;
            }
            write_pair(&dir.path().join("runs").join(format!("run={run}")), sequence, &estimate, Some(&truth));
        }
    }
    // A third run given as a plain directory, named after it.
    let (estimate, truth) = drive(900);
    write_pair(&dir.path().join("baseline"), "short", &estimate, Some(&truth));
    let lengths = "50,100,150,200";
    let out = mmtrack(dir.path(), &["analyze", "runs", "baseline", "-o", "cmp", "--segment-lengths-m", lengths]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("run a: long:") && stdout.contains("3 runs side by side"), "{stdout}");
    for run in ["a", "b", "baseline"] {
        let report = dir.path().join(format!("cmp/run={run}/report.md"));
        assert!(report.is_file() && dir.path().join(format!("cmp/run={run}/report.html")).is_file(), "{run}");
    }
    let report = std::fs::read_to_string(dir.path().join("cmp/report.md")).unwrap();
    assert!(
        report.contains("## Runs side by side")
            && report.contains("| a | b | b - a | b vs a | baseline | baseline - a | baseline vs a |"),
        "{report}"
    );
    assert!(report.contains("| all | KITTI t (%) |"), "{report}");
    // Run baseline has no `long` sequence: no value, no difference.
    let long_ate = report.lines().find(|l| l.starts_with("| long | ATE (m) |")).unwrap();
    assert!(long_ate.ends_with("| - | - | - |"), "{long_ate}");
    // The runs' curves overlaid, per sequence.
    for sequence in ["long", "short"] {
        for plot in ["trajectory_overlay.svg", "errors_overlay.svg"] {
            assert!(report.contains(&format!("](plots/{sequence}/{plot})")), "{sequence} {plot}: {report}");
            assert!(dir.path().join(format!("cmp/plots/{sequence}/{plot}")).is_file(), "{sequence} {plot}");
        }
    }

    // Independent check: DuckDB pools the runs' own tables by the stated rules.
    let checked = Command::new(python).args(["-c", CAMPAIGN_QUERY]).arg(dir.path().join("cmp")).output().unwrap();
    assert!(checked.status.success(), "{}", String::from_utf8_lossy(&checked.stderr));
    let json: serde_json::Value = serde_json::from_slice(&checked.stdout).unwrap();
    let (duckdb, ours) = (json["duckdb"].as_array().unwrap(), json["run_comparison"].as_array().unwrap());
    // The pooled rows are those of the runs with several sequences (a, b; baseline has one, which they
    // would repeat).
    assert_eq!((duckdb.len(), ours.len()), (2, 2), "{json}");
    for (d, o) in duckdb.iter().zip(ours) {
        assert_eq!(d[0], o[0]);
        for k in 1..5 {
            let (d, o) = (d[k].as_f64().unwrap(), o[k].as_f64().unwrap());
            assert!(relative_diff(d, o) < 1e-12, "{json}");
        }
        assert_eq!(d[5], o[5], "sequences per run: {json}");
    }
    // The runs differ where they should: run b's heading bias (orientations
    // only, positions untouched) shows in KITTI drift and RPE, not in the ATE.
    // `WHERE sequence = ...` (DuckDB, Hive partitioning) and a pyarrow
    // dataset filter find every row of the sequence: the trajectory metrics
    // compared, once per run that has the sequence (`long`: runs a and b;
    // `short`: all three; `all`, `mean`: a and b, the runs of several sequences).
    let per_run = mmtrack_analysis::campaign::TRAJECTORY_COMPARED.len() as u64;
    for (sequence, runs) in [("long", 2), ("short", 3), ("all", 2), ("mean", 2)] {
        let counts = &json["filtered"][sequence];
        assert_eq!(counts[0].as_u64(), Some(runs * per_run), "DuckDB WHERE sequence = '{sequence}': {json}");
        assert_eq!(counts[1].as_u64(), Some(runs * per_run), "pyarrow sequence == '{sequence}': {json}");
    }
    let value = |run: usize, k: usize| duckdb[run][k].as_f64().unwrap();
    assert!(value(1, 1) > value(0, 1) && value(1, 3) > value(0, 3), "{json}");
    assert_eq!(value(1, 2), value(0, 2), "{json}");

    // Deterministic, and replaced only with --force.
    let again = mmtrack(dir.path(), &["analyze", "runs", "baseline", "-o", "cmp", "--segment-lengths-m", lengths]);
    assert_eq!(again.status.code(), Some(1));
    let forced =
        mmtrack(dir.path(), &["analyze", "runs", "baseline", "-o", "cmp", "--segment-lengths-m", lengths, "--force"]);
    assert!(forced.status.success(), "{}", text(&forced).1);
    assert_eq!(std::fs::read_to_string(dir.path().join("cmp/report.md")).unwrap(), report);

    // Two runs with one name are refused, naming both.
    let clash = dir.path().join("clash");
    write_pair(&clash.join("run=a"), "short", &estimate, Some(&truth));
    let out = mmtrack(dir.path(), &["analyze", "runs", "clash", "-o", "cmp2"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out).1.contains("run id `a` twice"), "{}", text(&out).1);
    assert!(!dir.path().join("cmp2").exists());
}

/// Before: `analyze` on coordinates of 1e308 wrote NaN and infinite metrics
/// and exited 0. Now the pose is refused naming file, row and column, and
/// `export` refuses it the same way.
#[test]
fn analyze_and_export_refuse_implausible_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let (mut estimate, truth) = drive(200);
    estimate[7].world_from_vehicle = Se2::new(1e308, 0.0, 0.0);
    write_pair(&dir.path().join("tables"), "drive-a", &estimate, Some(&truth));
    for args in [&["analyze", "tables", "-o", "analysis"][..], &["export", "--format", "tum", "tables", "-o", "tum"]] {
        let out = mmtrack(dir.path(), args);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.contains("odometry/sequence=drive-a/part-0.parquet: row 7: x_m: 1e308 is not a coordinate"),
            "{args:?}: {stderr}"
        );
    }
    assert!(!dir.path().join("analysis").exists() && !dir.path().join("tum").exists());
}
