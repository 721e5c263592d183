//! `mmtrack process manifest`: many sequences as independent tasks; the
//! same tables for any thread count and as when each command runs alone;
//! the same again from another working directory (provenance records
//! canonical paths), after a killed campaign resumed with
//! `--skip-existing`, as SLURM array jobs (`examples/slurm_campaign.sh`) and
//! as Ray tasks on a Ray head started on the loopback address
//! (`examples/ray_process.py`, Ray installed from PyPI into a venv).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use mmtrack_io::table_kv::read_key_value_metadata;

use super::common::{files, mmtrack, realdata, root, text};

/// The deterministic tables under `dir` (timings hold wall-clock seconds;
/// the completion records of `--skip-existing` are not tables).
fn table_bytes(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out: Vec<_> = files(dir)
        .into_iter()
        .filter(|f| !f.starts_with(".mmtrack-tasks") && !f.components().any(|c| c.as_os_str() == "odometry_timing"))
        .map(|f| {
            let bytes = std::fs::read(dir.join(&f)).unwrap();
            (f, bytes)
        })
        .collect();
    out.sort();
    out
}

fn names(tables: &[(PathBuf, Vec<u8>)]) -> Vec<&PathBuf> {
    tables.iter().map(|t| &t.0).collect()
}

fn ok(dir: &Path, args: &[&str]) -> String {
    let out = mmtrack(dir, args);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "mmtrack {args:?}: {stdout}\n{stderr}");
    stdout
}

/// The target directory (venvs live there).
fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or_else(|| root().join("target"))
}

/// A campaign of all three steps on the demo: ingest the demo's Oxford
/// folder, odometry on that recording (needs the ingest), MPC on the
/// sounder recording, and an analysis of the tables (needs both).
const STEPS: &str = r#"[[task]]
name = "ingest-demo"
step = "ingest"
args = ["oxford", "demo/input/oxford-demo", "-o", "rec/demo.mcap", "--bins", "auto"]
[[task]]
name = "odometry-demo"
needs = ["ingest-demo"]
args = ["odometry", "rec/demo.mcap", "--preset", "fast-cfear"]
[[task]]
name = "mpc"
args = ["mpc", "demo/sounder.mcap", "--threads", "2"]
[[task]]
step = "analyze"
needs = ["odometry-demo", "mpc"]
args = ["{tables}", "-o", "analysis"]
"#;

#[test]
fn manifest_tasks_give_the_same_tables_for_any_thread_count_and_alone() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(mmtrack(d, &["demo", "--out", "demo", "--quiet"]).status.success());
    let manifest = "[[task]]\nargs = [\"odometry\", \"demo/recording.mcap\", \"--preset\", \"fast-cfear\"]\n\
                    [[task]]\nargs = [\"mpc\", \"demo/sounder.mcap\", \"--gmphd\"]\n";
    std::fs::write(d.join("campaign.toml"), manifest).unwrap();

    let stdout = ok(d, &["process", "manifest", "campaign.toml", "-o", "t1", "--threads", "1"]);
    assert!(stdout.contains("2 of 2 tasks done"), "{stdout}");
    ok(d, &["process", "manifest", "campaign.toml", "-o", "t2", "--threads", "2"]);
    ok(d, &["process", "odometry", "demo/recording.mcap", "--preset", "fast-cfear", "-o", "alone", "-q"]);
    ok(d, &["process", "mpc", "demo/sounder.mcap", "--gmphd", "-o", "alone", "-q"]);
    let reference = table_bytes(&d.join("alone"));
    assert!(reference.len() >= 10, "{:?}", names(&reference));
    assert!(table_bytes(&d.join("t1")) == reference, "--threads 1 differs from the commands run alone");
    assert!(table_bytes(&d.join("t2")) == reference, "--threads 2 differs from the commands run alone");

    // A failing task is named; the other one still writes its tables.
    std::fs::write(d.join("bad.toml"), format!("{manifest}[[task]]\nargs = [\"mpc\", \"missing.mcap\"]\n")).unwrap();
    let bad = mmtrack(d, &["process", "manifest", "bad.toml", "-o", "t3"]);
    let (stdout, stderr) = text(&bad);
    assert_eq!(bad.status.code(), Some(1));
    assert!(
        stderr.contains("failed  mmtrack process mpc missing.mcap -o t3") && stderr.contains("missing.mcap"),
        "{stderr}"
    );
    assert!(stdout.contains("2 of 3 tasks done"), "{stdout}");

    // The per-task commands a cluster runs.
    let lines = ok(d, &["process", "manifest", "campaign.toml", "-o", "ray", "--print-commands"]);
    assert_eq!(
        lines,
        "mmtrack process odometry demo/recording.mcap --preset fast-cfear -o ray\n\
         mmtrack process mpc demo/sounder.mcap --gmphd -o ray\n"
    );
}

/// Issue 27: the run configuration records the canonical absolute input
/// path, its size and CRC-32, so the same command from two working
/// directories writes byte-identical tables.
#[test]
fn the_same_command_from_two_working_directories_gives_identical_tables() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(d, &["demo", "--out", "demo", "--quiet"]);
    std::fs::create_dir(d.join("elsewhere")).unwrap();
    let here = d.join("elsewhere");
    for (cwd, recording, sounder, out) in [
        (d, "demo/recording.mcap", "demo/sounder.mcap", "a"),
        (here.as_path(), "../demo/recording.mcap", "../demo/sounder.mcap", "../b"),
    ] {
        ok(cwd, &["process", "odometry", recording, "--preset", "fast-cfear", "-o", out, "-q"]);
        ok(cwd, &["process", "mpc", sounder, "-o", out, "-q"]);
    }
    let a = table_bytes(&d.join("a"));
    assert!(a.len() >= 8, "{:?}", names(&a));
    assert!(table_bytes(&d.join("b")) == a, "the tables differ between the two working directories");

    let recording = d.join("demo/recording.mcap").canonicalize().unwrap();
    let metadata = read_key_value_metadata(&d.join("a/odometry/sequence=oxford-demo/part-0.parquet")).unwrap();
    let config: serde_json::Value = serde_json::from_str(&metadata["mmtrack.run_config"]).unwrap();
    assert_eq!(config["recording"], recording.display().to_string(), "{config}");
    let input = &config["inputs"][0];
    assert_eq!(input["path"], recording.display().to_string(), "{config}");
    assert_eq!(input["bytes"], std::fs::metadata(&recording).unwrap().len(), "{config}");
    let bytes = std::fs::read(&recording).unwrap();
    assert_eq!(input["crc32"], format!("{:08x}", crc32_ieee(&bytes)), "{config}");
}

/// Issue 27: recordings name their sources by canonical absolute path, so
/// ingesting (and simulating) the same input from two working directories,
/// one through `..`, writes byte-identical recordings.
#[test]
fn ingest_and_simulate_from_two_working_directories_give_identical_recordings() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fixture = super::common::root().join("data/demo/oxford-demo");
    std::fs::create_dir(d.join("in")).unwrap();
    copy_dir(&fixture, &d.join("in/oxford"));
    std::fs::copy(super::common::root().join("data/demo/fixture-scenario.toml"), d.join("in/s.toml")).unwrap();
    std::fs::create_dir(d.join("elsewhere")).unwrap();
    let here = d.join("elsewhere");
    for (cwd, prefix, out) in [(d, "in", "a"), (here.as_path(), "../elsewhere/../in", "../b")] {
        std::fs::create_dir_all(cwd.join(out)).unwrap();
        let input = format!("{prefix}/oxford");
        ok(cwd, &["ingest", "oxford", &input, "-o", &format!("{out}/o.mcap"), "--bins", "auto", "-q"]);
        let scenario = format!("{prefix}/s.toml");
        ok(cwd, &["simulate", "radar", "--scenario", &scenario, "-o", &format!("{out}/r.mcap"), "-q"]);
    }
    for name in ["o.mcap", "r.mcap"] {
        let (a, b) = (std::fs::read(d.join("a").join(name)).unwrap(), std::fs::read(d.join("b").join(name)).unwrap());
        assert!(a == b, "{name} differs between the two working directories");
    }
    let text = String::from_utf8_lossy(&std::fs::read(d.join("a/o.mcap")).unwrap()).into_owned();
    let canonical = d.join("in/oxford").canonicalize().unwrap();
    assert!(text.contains(&format!("oxford:{}", canonical.display())), "the source is not the canonical path");
}

fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

/// CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320) bit by bit: the
/// zlib checksum, computed independently of `crc32fast`.
fn crc32_ieee(bytes: &[u8]) -> u32 {
    let mut crc = !0_u32;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 == 1 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
        }
    }
    !crc
}

/// The state of the completion record of the task whose command line (after
/// `mmtrack`, without `--force`) is `command`, read from the records under
/// `tables`.
fn record_state(tables: &Path, command: &[&str]) -> Option<String> {
    let records = std::fs::read_dir(tables.join(".mmtrack-tasks")).ok()?;
    for entry in records {
        let text = std::fs::read_to_string(entry.ok()?.path()).ok()?;
        let record: serde_json::Value = serde_json::from_str(&text).ok()?;
        if record["command"] == serde_json::json!(command) {
            return record["state"].as_str().map(str::to_string);
        }
    }
    None
}

/// Issue 27: a campaign killed (SIGKILL) after its first task finished and
/// during its second resumes with `--skip-existing`: the finished task is
/// skipped (its table files untouched: same inode and modification time),
/// the interrupted and the missing ones run, and the tables are
/// byte-identical to an uninterrupted run.
#[test]
fn a_killed_campaign_resumes_with_skip_existing_running_only_the_missing_tasks() {
    use std::os::unix::fs::MetadataExt;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(d, &["demo", "--out", "demo", "--quiet"]);
    // One thread: the tasks run in manifest order. The SLAM task with many
    // particles takes seconds, so the kill lands inside it.
    let manifest = "[[task]]\nargs = [\"odometry\", \"demo/recording.mcap\", \"--preset\", \"fast-cfear\"]\n\
                    [[task]]\nargs = [\"slam\", \"demo/slam.mcap\", \"--particles\", \"50000\"]\n\
                    [[task]]\nargs = [\"mpc\", \"demo/sounder.mcap\"]\n";
    std::fs::write(d.join("campaign.toml"), manifest).unwrap();
    ok(d, &["process", "manifest", "campaign.toml", "-o", "whole", "--threads", "1", "-q"]);
    let reference = table_bytes(&d.join("whole"));

    let first = ["process", "odometry", "demo/recording.mcap", "--preset", "fast-cfear", "-o", "t"];
    let second = ["process", "slam", "demo/slam.mcap", "--particles", "50000", "-o", "t"];
    let mut campaign = Command::new(env!("CARGO_BIN_EXE_mmtrack"))
        .args(["process", "manifest", "campaign.toml", "-o", "t", "--threads", "1", "-q"])
        .current_dir(d)
        .spawn()
        .unwrap();
    let started = Instant::now();
    // On one thread the second task starts once the first finished.
    while record_state(&d.join("t"), &second).as_deref() != Some("started") {
        assert!(campaign.try_wait().unwrap().is_none(), "the campaign ended before its second task was seen");
        assert!(started.elapsed() < Duration::from_secs(120), "the second task did not start");
        std::thread::sleep(Duration::from_millis(5));
    }
    campaign.kill().unwrap(); // SIGKILL
    campaign.wait().unwrap();
    // Killed inside the second task: the first done, the second started
    // (its SLAM runs for seconds) with no tables of its own.
    assert_eq!(record_state(&d.join("t"), &first).as_deref(), Some("done"));
    assert_eq!(record_state(&d.join("t"), &second).as_deref(), Some("started"), "the kill missed the SLAM task");
    assert!(!d.join("t/slam_ue").exists() && !d.join("t/mpc_sets").exists());
    let odometry = d.join("t/odometry/sequence=oxford-demo/part-0.parquet");
    let before = std::fs::metadata(&odometry).unwrap();

    let resumed = ok(d, &["process", "manifest", "campaign.toml", "-o", "t", "--threads", "1", "--skip-existing"]);
    assert!(resumed.contains("skipped  mmtrack process odometry demo/recording.mcap"), "{resumed}");
    assert!(resumed.contains("ok       mmtrack process slam demo/slam.mcap"), "{resumed}");
    assert!(resumed.contains("ok       mmtrack process mpc demo/sounder.mcap"), "{resumed}");
    assert!(resumed.contains("3 of 3 tasks done (2 ran, 1 skipped as complete)"), "{resumed}");
    let after = std::fs::metadata(&odometry).unwrap();
    assert_eq!((after.ino(), after.mtime_nsec(), after.mtime()), (before.ino(), before.mtime_nsec(), before.mtime()));
    let tables = table_bytes(&d.join("t"));
    assert!(tables == reference, "{:?}\nvs\n{:?}", names(&tables), names(&reference));

    // Without --skip-existing every task refuses its existing tables, and
    // the refusal leaves their records as they were.
    let again = mmtrack(d, &["process", "manifest", "campaign.toml", "-o", "t"]);
    assert_eq!(again.status.code(), Some(1));
    assert_eq!(text(&again).1.matches("exists; use --force").count(), 3, "{}", text(&again).1);
    assert_eq!(record_state(&d.join("t"), &first).as_deref(), Some("done"));
    // Resumed again: nothing left to do.
    let idle = ok(d, &["process", "manifest", "campaign.toml", "-o", "t", "--skip-existing"]);
    assert!(idle.contains("3 of 3 tasks done (0 ran, 3 skipped as complete)"), "{idle}");
    // A finished task whose table went missing is redone.
    std::fs::remove_file(d.join("t/mpc_sets/sequence=sounder/part-0.parquet")).unwrap();
    let redo = ok(d, &["process", "manifest", "campaign.toml", "-o", "t", "--skip-existing"]);
    assert!(redo.contains("(1 ran, 2 skipped as complete)") && redo.contains("ok       mmtrack process mpc"), "{redo}");
    assert!(table_bytes(&d.join("t")) == reference);
}

/// Issue 27: one manifest of ingest, process and analyze steps runs them in
/// the order of their `needs`; `--print-levels` lists that order; `--task N`
/// refuses to run before the tasks it needs are done.
#[test]
fn steps_run_in_the_order_of_their_needs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(d, &["demo", "--out", "demo", "--quiet"]);
    std::fs::write(d.join("steps.toml"), STEPS).unwrap();
    assert_eq!(ok(d, &["process", "manifest", "steps.toml", "--print-levels"]), "0,2\n1\n3\n");
    let early = mmtrack(d, &["process", "manifest", "steps.toml", "-o", "t", "--task", "1"]);
    let (_, stderr) = text(&early);
    assert_eq!(early.status.code(), Some(1));
    assert!(
        stderr.contains("steps.toml: task 1 (odometry-demo): needs task 0 (ingest-demo), which has not finished"),
        "{stderr}"
    );
    let stdout = ok(d, &["process", "manifest", "steps.toml", "-o", "t"]);
    assert!(stdout.contains("4 of 4 tasks done"), "{stdout}");
    assert!(d.join("rec/demo.mcap").is_file());
    assert!(d.join("t/odometry/sequence=oxford-demo/part-0.parquet").is_file());
    assert!(d.join("analysis/tables/trajectory_metrics/sequence=oxford-demo/part-0.parquet").is_file());
    // A re-run without --skip-existing fails (the outputs exist) and must not
    // make the complete tasks look stale: before, their records were put back
    // with a new time, and the resume below redid the 3 tasks after the ingest.
    let refused = mmtrack(d, &["process", "manifest", "steps.toml", "-o", "t"]);
    assert_eq!(refused.status.code(), Some(1));
    let idle = ok(d, &["process", "manifest", "steps.toml", "-o", "t", "--skip-existing"]);
    assert!(idle.contains("4 of 4 tasks done (0 ran, 4 skipped as complete)"), "{idle}");
    // Resumed after one output went missing: the odometry runs again, and
    // so does the analysis that reads it; the ingest and MPC are skipped.
    let before =
        std::fs::read(d.join("analysis/tables/trajectory_metrics/sequence=oxford-demo/part-0.parquet")).unwrap();
    std::fs::remove_file(d.join("t/ground_truth/sequence=oxford-demo/part-0.parquet")).unwrap();
    let resumed = ok(d, &["process", "manifest", "steps.toml", "-o", "t", "--skip-existing"]);
    assert!(resumed.contains("4 of 4 tasks done (2 ran, 2 skipped as complete)"), "{resumed}");
    assert!(resumed.contains("ok       mmtrack analyze t -o analysis"), "{resumed}");
    assert!(resumed.contains("skipped  mmtrack ingest oxford"), "{resumed}");
    let after =
        std::fs::read(d.join("analysis/tables/trajectory_metrics/sequence=oxford-demo/part-0.parquet")).unwrap();
    assert!(before == after, "the analysis of the same tables differs");
    // Refusals name the file, the task and the key.
    std::fs::write(d.join("typo.toml"), STEPS.replace("needs = [\"ingest-demo\"]", "need = [\"ingest-demo\"]"))
        .unwrap();
    let typo = mmtrack(d, &["process", "manifest", "typo.toml", "-o", "t"]);
    assert_eq!(typo.status.code(), Some(1));
    assert!(text(&typo).1.contains("typo.toml: task 1: unknown key `need`"), "{}", text(&typo).1);
    // Found before anything runs: a flag the command does not have (in the
    // last level), and two tasks writing the same partitions (the same
    // pipeline on the same recording into the same run: before, both ran and
    // with --force the one that finished last was kept).
    let cases = [
        (
            STEPS.replace("\"-o\", \"analysis\"", "\"-o\", \"analysis\", \"--frob\""),
            "task 3: key `args`: error: unexpected argument '--frob'",
        ),
        (
            STEPS.replace(
                "\"--threads\", \"2\"]",
                "\"--threads\", \"2\"]\n[[task]]\nargs = [\"mpc\", \"demo/sounder.mcap\"]",
            ),
            "task 3: writes what task 2 (mpc) writes (the same pipeline, recordings and run); give each its own --run-id",
        ),
        // --help in a task: its text was the error (the help's first line).
        (STEPS.replace("\"--threads\", \"2\"]", "\"--help\"]"), "task 2 (mpc): key `args`: --help and --version print text"),
        // Other spellings of the same recording or output are the same.
        (
            STEPS.replace("\"--threads\", \"2\"]", "\"--threads\", \"2\"]\n[[task]]\nargs = [\"mpc\", \"./demo//sounder.mcap\"]"),
            "task 3: writes what task 2 (mpc) writes",
        ),
        (
            STEPS.replace("\"fast-cfear\"]", "\"fast-cfear\"]\n[[task]]\nstep = \"ingest\"\nargs = [\"oxford\", \"x\", \"-o\", \"./rec//demo.mcap\"]"),
            "task 2: writes what task 0 (ingest-demo) writes (the same -o); give each its own -o",
        ),
        (
            STEPS.replace(
                "\"fast-cfear\"]",
                "\"fast-cfear\"]\n[[task]]\nargs = [\"odometry\", \"rec/demo.mcap\", \"--preset\", \"cfear\"]",
            ),
            "task 2: writes what task 1 (odometry-demo) writes",
        ),
    ];
    for (manifest, expected) in cases {
        std::fs::write(d.join("bad.toml"), manifest).unwrap();
        let out = mmtrack(d, &["process", "manifest", "bad.toml", "-o", "fresh", "--force"]);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains(&format!("bad.toml: {expected}")), "{stderr}");
        assert!(!d.join("fresh").exists(), "nothing ran");
    }
    // Into two runs, the same pipeline on the same recording is fine.
    let two_runs = STEPS.replace(
        "\"fast-cfear\"]",
        "\"fast-cfear\"]\n[[task]]\nargs = [\"odometry\", \"rec/demo.mcap\", \"--preset\", \"cfear\", \"--run-id\", \"b\"]",
    );
    std::fs::write(d.join("two.toml"), two_runs).unwrap();
    assert_eq!(ok(d, &["process", "manifest", "two.toml", "--print-levels"]), "0,2,3\n1\n4\n");
    let printed = mmtrack(d, &["process", "manifest", "two.toml", "-o", "t2", "--task", "2"]);
    assert!(printed.status.success(), "{}", text(&printed).1);
}

/// A Boreas and a MulRan dataset folder of two sequences each beside a
/// folder that is none (file names as the ingest tests use; `--from` only
/// lists them).
fn dataset_fixtures(d: &Path) {
    for name in ["boreas-2021-09-02-11-42", "boreas-2021-10-05-15-35"] {
        let radar = d.join("boreas").join(name).join("radar");
        std::fs::create_dir_all(&radar).unwrap();
        for t_us in [1_630_597_345_560_134_i64, 1_630_597_345_810_747] {
            std::fs::write(radar.join(format!("{t_us}.png")), b"").unwrap();
        }
    }
    for name in ["KAIST01", "Sejong02"] {
        let polar = d.join("mulran").join(name).join("sensor_data/radar/polar");
        std::fs::create_dir_all(&polar).unwrap();
        for t_ns in [1_561_000_000_000_000_000_i64, 1_561_000_000_250_000_000] {
            std::fs::write(polar.join(format!("{t_ns}.png")), b"").unwrap();
        }
    }
    std::fs::create_dir_all(d.join("boreas/calib")).unwrap();
    std::fs::create_dir_all(d.join("mulran/calib")).unwrap();
}

/// Issue 27: `--from <dataset> --layout ...` writes one ingest task and one
/// odometry task (needing it) per sequence found; on the real Oxford sample
/// the manifest runs.
#[test]
fn manifests_are_written_from_dataset_folders() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    dataset_fixtures(d);
    for (layout, first, second) in
        [("boreas", "boreas-2021-09-02-11-42", "boreas-2021-10-05-15-35"), ("mulran", "KAIST01", "Sejong02")]
    {
        let file = format!("{layout}.toml");
        let stdout = ok(d, &["process", "manifest", &file, "--from", layout, "--layout", layout]);
        assert!(stdout.contains(&format!("wrote {file}: 2 {layout} sequence(s), 4 tasks")), "{stdout}");
        assert!(stdout.contains(&format!("skipped {layout}/calib")), "{stdout}");
        let printed = ok(d, &["process", "manifest", &file, "-o", "t", "--print-commands"]);
        assert_eq!(
            printed,
            format!(
                "mmtrack ingest {layout} {layout}/{first} -o recordings/{first}.mcap\n\
                 mmtrack process odometry recordings/{first}.mcap --preset cfear -o t\n\
                 mmtrack ingest {layout} {layout}/{second} -o recordings/{second}.mcap\n\
                 mmtrack process odometry recordings/{second}.mcap --preset cfear -o t\n"
            )
        );
        assert_eq!(ok(d, &["process", "manifest", &file, "--print-levels"]), "0,2\n1,3\n");
        // Written once; replaced only with --force.
        let again = mmtrack(d, &["process", "manifest", &file, "--from", layout, "--layout", layout]);
        assert_eq!(again.status.code(), Some(1), "{}", text(&again).1);
    }
    // A folder that looks like a sequence but does not open is named.
    std::fs::create_dir_all(d.join("boreas/boreas-2022-01-01-00-00/radar")).unwrap();
    let broken = mmtrack(d, &["process", "manifest", "x.toml", "--from", "boreas", "--layout", "boreas"]);
    assert_eq!(broken.status.code(), Some(1));
    assert!(text(&broken).1.contains("boreas-2022-01-01-00-00/radar"), "{}", text(&broken).1);
    let none = mmtrack(d, &["process", "manifest", "x.toml", "--from", "mulran", "--layout", "oxford"]);
    assert!(text(&none).1.contains("mulran: no oxford sequence found"), "{}", text(&none).1);

    let Some(real) = realdata("manifest --from on the Oxford sample") else { return };
    let sample = real.join("oxford-radar-tiny");
    let sample = sample.to_str().unwrap();
    ok(d, &["process", "manifest", "oxford.toml", "--from", sample, "--layout", "oxford", "--recordings", "rec"]);
    let stdout = ok(d, &["process", "manifest", "oxford.toml", "-o", "tables"]);
    assert!(stdout.contains("2 of 2 tasks done"), "{stdout}");
    assert!(d.join("rec/oxford-radar-tiny.mcap").is_file());
    assert!(d.join("tables/odometry/sequence=oxford-radar-tiny/part-0.parquet").is_file());
}

/// Issue 27: `examples/slurm_campaign.sh` run as the array tasks of each
/// level (SLURM_ARRAY_TASK_ID set, no SLURM needed) gives the tables of the
/// local run.
#[test]
fn slurm_array_tasks_give_the_local_tables() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(d, &["demo", "--out", "demo", "--quiet"]);
    // The local run reads the same recording paths; its ingest goes elsewhere.
    std::fs::write(d.join("steps.toml"), STEPS).unwrap();
    ok(d, &["process", "manifest", "steps.toml", "-o", "local", "-q"]);
    let reference = table_bytes(&d.join("local"));
    assert!(reference.len() >= 10, "{:?}", names(&reference));
    std::fs::remove_dir_all(d.join("rec")).unwrap();
    std::fs::remove_dir_all(d.join("analysis")).unwrap();

    let levels = ok(d, &["process", "manifest", "steps.toml", "--print-levels"]);
    let script = root().join("examples/slurm_campaign.sh");
    let mut runs = 0;
    for level in levels.lines() {
        for id in level.split(',') {
            let out = Command::new("bash")
                .arg(&script)
                .args(["steps.toml", "slurm"])
                .env("SLURM_ARRAY_TASK_ID", id)
                .env("SLURM_CPUS_PER_TASK", "1")
                .env("MMTRACK", env!("CARGO_BIN_EXE_mmtrack"))
                .current_dir(d)
                .output()
                .unwrap();
            let (stdout, stderr) = text(&out);
            assert!(out.status.success(), "task {id}: {stdout}\n{stderr}");
            runs += 1;
        }
    }
    assert_eq!(runs, 4);
    assert!(table_bytes(&d.join("slurm")) == reference, "the SLURM array's tables differ from the local run");
    assert!(d.join("analysis/report.md").is_file());
    // Re-submitted, every array task finds its task complete.
    let out = Command::new("bash")
        .arg(&script)
        .args(["steps.toml", "slurm"])
        .env("SLURM_ARRAY_TASK_ID", "2")
        .env("MMTRACK", env!("CARGO_BIN_EXE_mmtrack"))
        .current_dir(d)
        .output()
        .unwrap();
    assert!(text(&out).0.starts_with("skipped"), "{}", text(&out).0);
}

/// Before: `slurm_campaign.sh --submit` read `--print-levels` through a
/// process substitution, so a broken manifest printed its error and exited
/// 0 with nothing submitted; a level was one `--array` of task ids, however
/// many (SLURM's MaxArraySize is 1001 by default). Now the broken manifest
/// fails the script before any `sbatch`, and a level larger than
/// `MMTRACK_MAX_ARRAY_SIZE` is split into arrays `0-<n-1>` given their task
/// lists, each level depending on every array of the previous one. `sbatch`
/// is a stand-in on PATH that records its arguments.
#[test]
fn slurm_submit_fails_on_a_broken_manifest_and_splits_large_levels() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bin = d.join("bin");
    std::fs::create_dir(&bin).unwrap();
    let log = d.join("sbatch.log");
    let sbatch = bin.join("sbatch");
    // Prints job ids 101, 102, ... as `sbatch --parsable` would.
    std::fs::write(
        &sbatch,
        "#!/usr/bin/env bash
echo \"$*\" >> \"$SBATCH_LOG\"
wc -l < \"$SBATCH_LOG\" | awk '{print $1 + 100}'
",
    )
    .unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&sbatch, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let script = root().join("examples/slurm_campaign.sh");
    let submit = |manifest: &str, max_array: &str| {
        Command::new("bash")
            .arg(&script)
            .args(["--submit", manifest, "tables"])
            .env("PATH", &path)
            .env("SBATCH_LOG", &log)
            .env("MMTRACK", env!("CARGO_BIN_EXE_mmtrack"))
            .env("MMTRACK_MAX_ARRAY_SIZE", max_array)
            .current_dir(d)
            .output()
            .unwrap()
    };
    std::fs::write(d.join("broken.toml"), "[[task]]\nargs = [\"odometry\", \"x.mcap\"]\nneeds = [\"nope\"]\n").unwrap();
    let out = submit("broken.toml", "1001");
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stdout}\n{stderr}");
    assert!(stderr.contains("no task is named 'nope'"), "{stderr}");
    assert!(!log.exists(), "nothing submitted");

    // Levels 0,2 / 1 / 3; at most one task per array.
    std::fs::write(d.join("steps.toml"), STEPS).unwrap();
    let out = submit("steps.toml", "1");
    assert!(out.status.success(), "{:?}", text(&out));
    let calls = std::fs::read_to_string(&log).unwrap();
    let script = script.display();
    let expected = [
        format!("--parsable --array=0-0 {script} steps.toml tables 0"),
        format!("--parsable --array=0-0 {script} steps.toml tables 2"),
        format!("--parsable --array=0-0 --dependency=afterok:101:102 {script} steps.toml tables 1"),
        format!("--parsable --array=0-0 --dependency=afterok:103 {script} steps.toml tables 3"),
    ];
    assert_eq!(calls.lines().collect::<Vec<_>>(), expected);
    std::fs::remove_file(&log).unwrap();
    // The default: one array per level, indices 0..n-1 over the level's tasks.
    assert!(submit("steps.toml", "1001").status.success());
    let calls = std::fs::read_to_string(&log).unwrap();
    assert_eq!(calls.lines().next(), Some(format!("--parsable --array=0-1 {script} steps.toml tables 0,2").as_str()));

    // In the job, an index past its task list is refused.
    let out = Command::new("bash")
        .arg(root().join("examples/slurm_campaign.sh"))
        .args(["steps.toml", "tables", "0,2"])
        .env("SLURM_ARRAY_TASK_ID", "2")
        .env("MMTRACK", env!("CARGO_BIN_EXE_mmtrack"))
        .current_dir(d)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out).1.contains("array index 2: the task list '0,2' has 2 tasks"), "{:?}", text(&out));
}

/// Before: `ray_process.py` without a reachable binary (no `--mmtrack`, none
/// on PATH, as after `pip install crates/mmtrack-py`) ended in a Python
/// traceback with exit 1. Now it is a usage problem (exit 2) naming
/// `--mmtrack`, told before Ray is imported (so no Ray is needed here).
#[test]
fn ray_example_without_the_binary_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let example = root().join("examples/ray_process.py");
    for extra in [&["--mmtrack", "/nonexistent/mmtrack"][..], &[]] {
        let out = Command::new("python3")
            .arg(&example)
            .args(["campaign.toml", "tables"])
            .args(extra)
            .env("PATH", "/usr/bin:/bin")
            .current_dir(dir.path())
            .output()
            .unwrap();
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains("cannot run the mmtrack binary") && stderr.contains("--mmtrack PATH"), "{stderr}");
        assert!(!stderr.contains("Traceback"), "{stderr}");
    }
}

/// A Python venv with Ray from PyPI, made on first use under the target
/// directory. Ray is a requirement of the test: no skip.
fn ray_python() -> PathBuf {
    let venv = target_dir().join("py-venv-ray");
    let python = venv.join("bin/python");
    let ok = |p: &Path| Command::new(p).args(["-c", "import ray"]).output().is_ok_and(|o| o.status.success());
    if ok(&python) {
        return python;
    }
    let made = Command::new("python3").args(["-m", "venv"]).arg(&venv).status().is_ok_and(|s| s.success());
    assert!(made, "python3 -m venv {} failed", venv.display());
    let installed = Command::new(&python)
        .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "ray==2.52.1"])
        .status()
        .is_ok_and(|s| s.success());
    assert!(installed && ok(&python), "ray 2.52.1 could not be installed from PyPI into {}", venv.display());
    python
}

/// A free TCP port on the loopback address (bound, then released).
fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// A Ray head started with `ray start --head` on the loopback address, with
/// its own temporary directory and ports; stopped when dropped, also when
/// the test fails.
///
/// It is stopped by process id, not with `ray stop`: `ray stop` ends every
/// Ray process of the user on the machine, also other clusters (other test
/// runs, a user's own). The head's processes are those whose command line
/// names its temporary directory, and their descendants (the workers rename
/// themselves `ray::...`).
struct RayHead {
    temp_dir: PathBuf,
    address: String,
}

impl RayHead {
    fn start(python: &Path) -> Self {
        let temp_dir = PathBuf::from(format!("/tmp/mmtrack-ray-{}-{}", std::process::id(), free_port()));
        let port = free_port();
        let head = Self { temp_dir: temp_dir.clone(), address: format!("127.0.0.1:{port}") };
        let ray = python.with_file_name("ray");
        let port_flags: Vec<String> = [
            "--dashboard-port",
            "--dashboard-agent-listen-port",
            "--dashboard-agent-grpc-port",
            "--runtime-env-agent-port",
            "--metrics-export-port",
        ]
        .iter()
        .map(|flag| format!("{flag}={}", free_port()))
        .collect();
        let out = Command::new(ray)
            .args(["start", "--head", "--node-ip-address", "127.0.0.1", "--num-cpus", "2"])
            .arg(format!("--port={port}"))
            .args(&port_flags)
            .args(["--include-dashboard=false", "--disable-usage-stats"])
            .arg(format!("--temp-dir={}", temp_dir.display()))
            .output()
            .unwrap();
        let (stdout, stderr) = text(&out);
        assert!(out.status.success(), "ray start --head failed:\n{stdout}\n{stderr}");
        head
    }

    /// The head's processes: command lines naming its temporary directory,
    /// and their descendants.
    fn processes(&self) -> Vec<u32> {
        let needle = self.temp_dir.display().to_string();
        let mut parent_of = Vec::new();
        let mut ours = Vec::new();
        for entry in std::fs::read_dir("/proc").unwrap().flatten() {
            let Some(pid) = entry.file_name().to_str().and_then(|n| n.parse::<u32>().ok()) else { continue };
            let cmdline = std::fs::read(entry.path().join("cmdline")).unwrap_or_default();
            if pid != std::process::id() && String::from_utf8_lossy(&cmdline).contains(&needle) {
                ours.push(pid);
            }
            let stat = std::fs::read_to_string(entry.path().join("stat")).unwrap_or_default();
            // `pid (name) state ppid ...`: the name may hold spaces.
            let ppid = stat.rsplit_once(')').and_then(|(_, rest)| rest.split_whitespace().nth(1)?.parse::<u32>().ok());
            if let Some(ppid) = ppid {
                parent_of.push((pid, ppid));
            }
        }
        let mut i = 0;
        while i < ours.len() {
            let parent = ours[i];
            for &(pid, ppid) in &parent_of {
                if ppid == parent && !ours.contains(&pid) {
                    ours.push(pid);
                }
            }
            i += 1;
        }
        ours
    }
}

impl Drop for RayHead {
    fn drop(&mut self) {
        for signal in ["-TERM", "-KILL"] {
            let pids: Vec<String> = self.processes().iter().map(u32::to_string).collect();
            if pids.is_empty() {
                break;
            }
            let _ = Command::new("kill").arg(signal).args(&pids).output();
            let deadline = Instant::now() + Duration::from_secs(5);
            while !self.processes().is_empty() && Instant::now() < deadline {
                std::thread::sleep(Duration::from_millis(100));
            }
        }
        let _ = std::fs::remove_dir_all(&self.temp_dir);
    }
}

/// Issue 27: `examples/ray_process.py` against a Ray head started on the
/// loopback address (`RAY_ADDRESS`), on a campaign of ingest, process and
/// analyze steps: the tables are byte-identical to the local `process
/// manifest`; a task that fails once is retried and succeeds. Run again
/// with `--skip-existing` and without `RAY_ADDRESS` (a local Ray of its
/// own), every task is skipped.
#[test]
fn ray_script_on_a_loopback_head_gives_the_local_tables() {
    let python = ray_python();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(d, &["demo", "--out", "demo", "--quiet"]);
    std::fs::write(d.join("steps.toml"), STEPS).unwrap();
    ok(d, &["process", "manifest", "steps.toml", "-o", "local", "-q"]);
    let reference = table_bytes(&d.join("local"));
    std::fs::remove_dir_all(d.join("rec")).unwrap();
    std::fs::remove_dir_all(d.join("analysis")).unwrap();
    // A wrapper that logs every call and fails the first attempt of task 2.
    let wrapper = d.join("flaky-mmtrack");
    std::fs::write(
        &wrapper,
        format!(
            "#!/bin/sh\necho \"$*\" >> \"{log}\"\n\
             case \"$*\" in *\"--task 2 \"*) if [ ! -e \"{flag}\" ]; then touch \"{flag}\"; exit 1; fi;; esac\n\
             exec \"{bin}\" \"$@\"\n",
            log = d.join("calls.log").display(),
            flag = d.join("failed-once").display(),
            bin = env!("CARGO_BIN_EXE_mmtrack"),
        ),
    )
    .unwrap();
    assert!(Command::new("chmod").arg("+x").arg(&wrapper).status().unwrap().success());

    let started = Instant::now();
    let head = RayHead::start(&python);
    let head_started_s = started.elapsed().as_secs_f64();
    let example = root().join("examples/ray_process.py");
    let run = |extra: &[&str], address: Option<&str>| {
        let mut command = Command::new(&python);
        command
            .arg(&example)
            .args(["steps.toml", "ray", "--mmtrack", wrapper.to_str().unwrap(), "--retries", "2"])
            .args(extra)
            .current_dir(d);
        match address {
            Some(address) => command.env("RAY_ADDRESS", address),
            None => command.env_remove("RAY_ADDRESS"),
        };
        let out = command.output().unwrap();
        let (stdout, stderr) = text(&out);
        assert!(out.status.success(), "{stdout}\n{stderr}");
        stdout
    };
    let stdout = run(&[], Some(&head.address));
    assert!(stdout.contains("4 of 4 tasks done on Ray (0 skipped as complete)"), "{stdout}");
    assert!(table_bytes(&d.join("ray")) == reference, "the Ray run differs from the local one");
    assert!(d.join("analysis/report.md").is_file());
    let calls = std::fs::read_to_string(d.join("calls.log")).unwrap();
    let task2 = calls.lines().filter(|l| l.contains("--task 2 ")).count();
    assert_eq!(task2, 2, "task 2 should have run twice (failed once, retried): {calls}");
    // Task 2 gives itself --threads 2: its Ray task asked for 2 CPUs.
    assert!(calls.contains("--task 2 --threads 2"), "{calls}");
    assert!(calls.contains("--task 0 --threads 1"), "{calls}");

    drop(head);
    // Without RAY_ADDRESS the script starts a Ray of its own; resumed, every
    // task is complete.
    let again = run(&["--skip-existing", "--num-cpus", "2"], None);
    assert!(again.contains("4 of 4 tasks done on Ray (4 skipped as complete)"), "{again}");
    eprintln!("ray head started in {head_started_s:.1} s; test {:.1} s", started.elapsed().as_secs_f64());
}

/// `examples/campaign_figures.py` (polars + matplotlib from PyPI in a venv)
/// loads the demo's tables and draws its figures. Polars older than 1.43
/// cannot read parquet-rs 60 footers ("Invalid thrift: bad data"), so the
/// version is pinned to a current one.
#[test]
fn campaign_figures_example_draws_the_demo_tables_with_polars() {
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map(std::path::PathBuf::from).unwrap_or_else(|| root().join("target"));
    let venv = target.join("py-venv-examples");
    let python = venv.join("bin/python");
    let ready = |p: &Path| {
        Command::new(p)
            .args(["-c", "import polars, matplotlib; assert polars.__version__ == '2.1.0'"])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if !ready(&python) {
        let made = Command::new("python3").args(["-m", "venv"]).arg(&venv).status().is_ok_and(|s| s.success())
            && Command::new(&python)
                .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
                .args(["polars==2.1.0", "matplotlib==3.10.7"])
                .status()
                .is_ok_and(|s| s.success());
        if !made || !ready(&python) {
            eprintln!("skipped: examples/campaign_figures.py: polars and matplotlib could not be installed from PyPI");
            return;
        }
    }
    let dir = tempfile::tempdir().unwrap();
    assert!(mmtrack(dir.path(), &["demo", "-o", "d", "--quiet"]).status.success());
    let run = Command::new(&python)
        .arg(root().join("examples/campaign_figures.py"))
        .args(["d/tables", "d/analysis/tables", "-o", "figures"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let (stdout, stderr) = text(&run);
    assert!(run.status.success(), "{stdout}\n{stderr}");
    assert!(stdout.contains("oxford-demo"), "the summary table: {stdout}");
    for figure in ["trajectories.png", "drift_per_length.png", "mpcs_per_set.png", "spebt_errors.png"] {
        let bytes = std::fs::read(dir.path().join("figures").join(figure)).unwrap();
        assert!(bytes.starts_with(b"\x89PNG") && bytes.len() > 5000, "{figure}");
    }
}
