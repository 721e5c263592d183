//! Outputs that must never be replaced (a FIFO or device node, a directory
//! where a file goes, the command's own input) and usage errors found after
//! parsing (exit 2, as clap's), end to end.

use std::path::Path;

use super::common::{mmtrack, text};

/// A small TUM trajectory: the quickest input that writes a recording.
fn trajectory(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("traj.tum");
    std::fs::write(&path, "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n").unwrap();
    path
}

/// A FIFO stands in for a device node: the audit's `-o /dev/full --force`
/// turned /dev/full into a regular file; never test on real ones.
fn fifo(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("pipe");
    assert!(std::process::Command::new("mkfifo").arg(&path).status().unwrap().success());
    path
}

fn is_fifo(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::symlink_metadata(path).unwrap().file_type().is_fifo()
}

/// Before: `--force` renamed the new recording over the FIFO, and a
/// directory output failed only at the final rename.
#[test]
fn outputs_that_are_not_regular_files_are_refused_with_or_without_force() {
    let dir = tempfile::tempdir().unwrap();
    trajectory(dir.path());
    let pipe = fifo(dir.path());
    std::fs::create_dir(dir.path().join("folder")).unwrap();
    for (output, kind) in [("pipe", "a FIFO"), ("folder", "a directory")] {
        for force in [false, true] {
            let mut args = vec!["ingest", "poses", "traj.tum", "--format", "tum", "-o", output];
            if force {
                args.push("--force");
            }
            let out = mmtrack(dir.path(), &args);
            let (_, stderr) = text(&out);
            assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
            assert!(stderr.contains(&format!("{output}: exists and is {kind}, not a regular file")), "{stderr}");
        }
    }
    assert!(is_fifo(&pipe), "the FIFO is still a FIFO");
    // A folder output (simulate radar --format oxford) that is the FIFO.
    let scenario = super::common::root().join("data/demo/radar-scenario.toml");
    {
        let args = ["simulate", "radar", "--scenario", scenario.to_str().unwrap(), "--format", "oxford", "-o", "pipe"];
        let out = mmtrack(dir.path(), &[&args[..], &["--force", "--max-scans", "1"]].concat());
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains("pipe: exists and is a FIFO, not a directory"), "{stderr}");
        assert!(is_fifo(&pipe));
    }
}

/// Before: `-o <the input> --force` replaced the input with the recording.
#[test]
fn an_output_that_is_the_input_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let input = trajectory(dir.path());
    let before = std::fs::read(&input).unwrap();
    let out = mmtrack(dir.path(), &["ingest", "poses", "traj.tum", "--format", "tum", "-o", "./traj.tum", "--force"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("is also this command's input"), "{stderr}");
    assert_eq!(std::fs::read(&input).unwrap(), before);
}

/// Before: these flag values were refused after parsing with exit 1 (a
/// data failure), while clap's own range checks exit 2.
#[test]
fn bad_flag_values_found_after_parsing_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    trajectory(dir.path());
    let cases: [&[&str]; 7] = [
        &["ingest", "oxford", "nowhere", "-o", "o.mcap", "--threads", "1000000"],
        &["simulate", "slam", "-o", "s.mcap", "--epochs", "1000000000"],
        &["process", "mpc", "nowhere.mcap", "-o", "t", "--link", "abc"],
        &["ingest", "oxford", "nowhere", "-o", "o.mcap", "--range-resolution-m", "0"],
        &["ingest", "oxford", "nowhere", "-o", "o.mcap", "--radar-cartesian-m-per-px", "0"],
        &["ingest", "beams", "nowhere", "--format", "deepsense", "-o", "out", "--sweep-period-s", "0"],
        &["export", "--format", "kitti", ".", "-o", "k", "--recording", "x.mcap"],
    ];
    for args in cases {
        let out = mmtrack(dir.path(), args);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.starts_with("error: --"), "{args:?}: one line naming the flag: {stderr}");
    }
    // A failure on data keeps exit 1.
    let out = mmtrack(dir.path(), &["ingest", "poses", "missing.tum", "--format", "tum", "-o", "o.mcap"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out).1);
}

/// Before: `--max-scans 0` wrote an empty recording (exit 0) and `--sets
/// 1000000000000` silently gave the scenario's 1666 sets.
#[test]
fn simulations_asked_for_nothing_or_too_much_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let radar = super::common::root().join("data/demo/radar-scenario.toml");
    let out = mmtrack(
        dir.path(),
        &["simulate", "radar", "--scenario", radar.to_str().unwrap(), "--max-scans", "0", "-o", "r.mcap"],
    );
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--max-scans 0") && !dir.path().join("r.mcap").exists(), "{stderr}");
    let convoy = super::common::root().join("data/sounder/convoy-tunnel.toml");
    let args =
        ["simulate", "sounder", "--scenario", convoy.to_str().unwrap(), "--sets", "1000000000000", "-o", "s.mcap"];
    let out = mmtrack(dir.path(), &args);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--sets 1000000000000") && stderr.contains("at most"), "{stderr}");
    assert!(!dir.path().join("s.mcap").exists());
}
