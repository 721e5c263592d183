//! `--run-id` of every `mmtrack process` pipeline (mpc, beam: sweep trackers,
//! spebt and geometric, slam) and of the tasks of `process manifest`: two runs
//! with different ids into one `-o` directory give the partitions `run=a/...`
//! and `run=b/...` side by side, neither overwrites the other, the run
//! configuration in each table's metadata names its run, `--force` refusals
//! look at the run's own directory, and an id that is not one path component
//! is refused naming `--run-id`, before anything is written.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use mmtrack_core::{BeamSweep, Se2, StampedPose};
use mmtrack_io::recording::{PoseStream, TimeBase};
use mmtrack_io::table_kv::read_key_value_metadata;
use mmtrack_io::{RecordingMetadata, RecordingOptions, RecordingWriter};

use super::common::{files, mmtrack, root, text};

/// Runs `mmtrack args` in `dir`, asserting success.
fn ok(dir: &Path, args: &[&str]) {
    let out = mmtrack(dir, args);
    assert!(out.status.success(), "mmtrack {args:?}: {}", text(&out).1);
}

/// Every file under `dir` with its bytes.
fn contents(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    files(dir).into_iter().map(|f| (f.clone(), std::fs::read(dir.join(&f)).unwrap())).collect()
}

/// The `run_id` of the run configuration in the metadata of `file`.
fn recorded_run_id(file: &Path) -> serde_json::Value {
    let metadata = read_key_value_metadata(file).unwrap();
    let config: serde_json::Value = serde_json::from_str(&metadata["mmtrack.run_config"]).unwrap();
    assert!(config.get("run_id").is_some(), "{}: no run_id in {config}", file.display());
    config["run_id"].clone()
}

/// `pipeline` (a `mmtrack process` command line without `-o`) run with
/// `--run-id a` and `--run-id b` into `runs`: both runs' `tables` of
/// `sequence` sit in their own partitions with their id in the metadata,
/// run b leaves run a's files as they were, a repeat of run a without
/// `--force` is refused naming run a's file, a run without `--run-id` into
/// the same directory is not refused (another partition) and records a null
/// id, and bad ids are refused naming `--run-id` with nothing written.
fn check_two_runs(dir: &Path, pipeline: &[&str], tables: &[&str], sequence: &str) {
    let with = |rest: &[&'static str]| -> Vec<&str> { pipeline.iter().chain(rest).copied().collect() };
    ok(dir, &with(&["-o", "runs", "--run-id", "a", "-q"]));
    let run_a = contents(&dir.join("runs"));
    ok(dir, &with(&["-o", "runs", "--run-id", "b", "-q"]));
    let both = contents(&dir.join("runs"));
    for (file, bytes) in &run_a {
        assert_eq!(both.get(file), Some(bytes), "{pipeline:?}: run b changed {}", file.display());
    }
    assert!(
        both.keys().all(|f| f.starts_with("run=a") || f.starts_with("run=b")),
        "{pipeline:?}: files outside the run partitions: {:?}",
        both.keys().collect::<Vec<_>>()
    );
    for id in ["a", "b"] {
        for table in tables {
            let file = dir.join(format!("runs/run={id}/{table}/sequence={sequence}/part-0.parquet"));
            assert!(file.is_file(), "{pipeline:?}: {} missing", file.display());
            assert_eq!(recorded_run_id(&file), serde_json::json!(id), "{}", file.display());
        }
    }

    // Run a again without --force: refused on run a's partition, nothing changed.
    let again = mmtrack(dir, &with(&["-o", "runs", "--run-id", "a", "-q"]));
    let stderr = text(&again).1;
    assert_eq!(again.status.code(), Some(1), "{pipeline:?}: {stderr}");
    assert!(stderr.contains("run=a/") && stderr.contains("exists; use --force"), "{pipeline:?}: {stderr}");
    assert!(contents(&dir.join("runs")) == both, "{pipeline:?}: a refused run changed files");
    // Without --run-id: the directory's own partitions, which do not exist yet.
    ok(dir, &with(&["-o", "runs", "-q"]));
    let plain = dir.join(format!("runs/{}/sequence={sequence}/part-0.parquet", tables[0]));
    assert_eq!(recorded_run_id(&plain), serde_json::Value::Null, "{}", plain.display());

    for bad in ["../x", "a/b"] {
        let out = mmtrack(dir, &with(&["-o", "bad", "--run-id", bad, "-q"]));
        let stderr = text(&out).1;
        assert_eq!(out.status.code(), Some(1), "{pipeline:?} --run-id {bad}: {stderr}");
        assert!(stderr.contains(&format!("--run-id '{bad}': not a valid run id")), "{pipeline:?}: {stderr}");
        assert!(!dir.join("bad").exists() && !dir.join("x").exists(), "{pipeline:?} --run-id {bad}: wrote files");
    }
}

/// A short simulated convoy (12 sets of six CIRs, about 0.1 s) with both
/// cars' ground truth.
fn sounder(dir: &Path) {
    let scenario = root().join("data/sounder/convoy-tunnel.toml");
    ok(dir, &["simulate", "sounder", "--scenario", scenario.to_str().unwrap(), "-o", "c.mcap", "--sets", "12", "-q"]);
}

#[test]
fn mpc_runs_with_different_ids_sit_side_by_side() {
    let dir = tempfile::tempdir().unwrap();
    sounder(dir.path());
    check_two_runs(dir.path(), &["process", "mpc", "c.mcap"], &["mpc_sets", "mpc_detections", "mpc_snapshots"], "c");
}

/// A recording of 24 full sweeps of 16 beams (the best beam moving by one
/// every 4 sweeps) along a straight ground-truth drive at 8 m/s, 4 Hz.
fn beam_recording(path: &Path) {
    let metadata = RecordingMetadata {
        sequence_id: "beams".into(),
        source: "run_ids test".into(),
        time_base: TimeBase::UnixEpoch,
        extra: BTreeMap::new(),
    };
    let mut writer = RecordingWriter::create(path, &metadata, &RecordingOptions::default()).unwrap();
    for k in 0..24i64 {
        let t_ns = k * 250_000_000;
        let best = 4 + k / 4;
        let power = (0..16i64).map(|b| 1.0 / (1.0 + (b - best).pow(2) as f64)).collect();
        writer.write_beam_sweep(&BeamSweep::full(t_ns, power).unwrap(), None).unwrap();
        let pose = StampedPose { t_ns, parent_from_child: Se2::new(2.0 * k as f64, 0.0, 0.0) };
        writer.write_pose(PoseStream::GroundTruth, &pose, "world").unwrap();
    }
    writer.finish().unwrap();
}

#[test]
fn beam_runs_with_different_ids_sit_side_by_side_for_every_kind_of_tracker() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    beam_recording(&d.join("beams.mcap"));
    sounder(d);
    for (i, (pipeline, tables, sequence)) in [
        (
            &["process", "beam", "../beams.mcap", "--tracker", "window,last-full-sweep"][..],
            &["beam_sweeps_tracked"][..],
            "beams",
        ),
        (
            &["process", "beam", "../beams.mcap", "--tracker", "spebt"][..],
            &["spebt_summary", "spebt_per_slot"][..],
            "beams",
        ),
        (
            &["process", "beam", "../c.mcap", "--tracker", "geometric", "--epoch-ms", "10"][..],
            &["geometric_per_epoch"][..],
            "c",
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let sub = d.join(format!("case{i}"));
        std::fs::create_dir(&sub).unwrap();
        check_two_runs(&sub, pipeline, tables, sequence);
    }
}

#[test]
fn slam_runs_with_different_ids_sit_side_by_side() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(d, &["simulate", "slam", "--epochs", "8", "--seed", "3", "-o", "s.mcap", "-q"]);
    let pipeline = ["process", "slam", "s.mcap", "--particles", "200"];
    check_two_runs(d, &pipeline, &["slam_ue", "slam_map", "slam_associations", "slam_true_sources"], "s");
}

/// `--run-id` inside a manifest task's args: two tasks of the same sequence
/// with different ids both write, each into its own run partition.
#[test]
fn manifest_tasks_with_different_run_ids_write_the_same_sequence_side_by_side() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sounder(d);
    let manifest = "[[task]]\nargs = [\"mpc\", \"c.mcap\", \"--run-id\", \"a\"]\n\
                    [[task]]\nargs = [\"mpc\", \"c.mcap\", \"--run-id\", \"b\", \"--gmphd\"]\n";
    std::fs::write(d.join("m.toml"), manifest).unwrap();
    let out = mmtrack(d, &["process", "manifest", "m.toml", "-o", "t", "--threads", "2"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("2 of 2 tasks done"), "{stdout}");
    for (id, gmphd) in [("a", false), ("b", true)] {
        let file = d.join(format!("t/run={id}/mpc_sets/sequence=c/part-0.parquet"));
        assert_eq!(recorded_run_id(&file), serde_json::json!(id), "{}", file.display());
        assert_eq!(d.join(format!("t/run={id}/mpc_tracks_gmphd/sequence=c/part-0.parquet")).exists(), gmphd, "{id}");
    }
    // Beside the runs only the manifest's completion records (a hidden directory).
    assert!(
        files(&d.join("t"))
            .iter()
            .all(|f| f.starts_with("run=a") || f.starts_with("run=b") || f.starts_with(".mmtrack-tasks"))
    );
    // The same manifest again: both tasks refused on their own partitions.
    let again = mmtrack(d, &["process", "manifest", "m.toml", "-o", "t"]);
    let stderr = text(&again).1;
    assert_eq!(again.status.code(), Some(1));
    assert!(stderr.contains("t/run=a/") && stderr.contains("t/run=b/"), "{stderr}");
    let printed = text(&mmtrack(d, &["process", "manifest", "m.toml", "-o", "t", "--print-commands"])).0;
    assert_eq!(
        printed,
        "mmtrack process mpc c.mcap --run-id a -o t\nmmtrack process mpc c.mcap --run-id b --gmphd -o t\n"
    );
}

#[test]
fn every_pipeline_help_shows_run_id() {
    let dir = tempfile::tempdir().unwrap();
    for pipeline in ["odometry", "mpc", "beam", "slam"] {
        let out = mmtrack(dir.path(), &["process", pipeline, "--help"]);
        let stdout = text(&out).0;
        assert!(out.status.success() && stdout.contains("--run-id <ID>"), "{pipeline}: {stdout}");
        assert!(stdout.contains("<output>/run=<ID>/"), "{pipeline}: {stdout}");
    }
}
