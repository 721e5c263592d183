//! `mmtrack process manifest`: many sequences as independent tasks; the
//! same tables for any thread count and as when each command runs alone;
//! the per-sequence command lines run on a local Ray cluster give the same
//! tables again (`examples/ray_process.py`; skipped visibly where Ray cannot
//! be installed from PyPI).

use std::path::Path;
use std::process::Command;

use super::common::{files, mmtrack, root, text};

/// The deterministic tables under `dir` (timings hold wall-clock seconds).
fn table_bytes(dir: &Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    let mut out: Vec<_> = files(dir)
        .into_iter()
        .filter(|f| !f.starts_with("odometry_timing"))
        .map(|f| {
            let bytes = std::fs::read(dir.join(&f)).unwrap();
            (f, bytes)
        })
        .collect();
    out.sort();
    out
}

/// A Python venv with Ray, made on first use under the target directory.
fn ray_python() -> Option<std::path::PathBuf> {
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map(std::path::PathBuf::from).unwrap_or_else(|| root().join("target"));
    let venv = target.join("py-venv-ray");
    let python = venv.join("bin/python");
    let ok = |p: &Path| Command::new(p).args(["-c", "import ray"]).output().is_ok_and(|o| o.status.success());
    if ok(&python) {
        return Some(python);
    }
    let made = Command::new("python3").args(["-m", "venv"]).arg(&venv).status().is_ok_and(|s| s.success())
        && Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "ray==2.52.1"])
            .status()
            .is_ok_and(|s| s.success());
    (made && ok(&python)).then_some(python)
}

#[test]
fn manifest_tasks_give_the_same_tables_for_any_thread_count_and_alone() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(mmtrack(d, &["demo", "--out", "demo", "--quiet"]).status.success());
    let manifest = "[[task]]\nargs = [\"odometry\", \"demo/recording.mcap\", \"--preset\", \"fast-cfear\"]\n\
                    [[task]]\nargs = [\"mpc\", \"demo/sounder.mcap\", \"--gmphd\"]\n";
    std::fs::write(d.join("campaign.toml"), manifest).unwrap();

    let one = mmtrack(d, &["process", "manifest", "campaign.toml", "-o", "t1", "--threads", "1"]);
    let (stdout, stderr) = text(&one);
    assert!(one.status.success(), "{stderr}");
    assert!(stdout.contains("2 of 2 tasks done"), "{stdout}");
    let two = mmtrack(d, &["process", "manifest", "campaign.toml", "-o", "t2", "--threads", "2"]);
    assert!(two.status.success(), "{}", text(&two).1);
    for args in [
        &["process", "odometry", "demo/recording.mcap", "--preset", "fast-cfear", "-o", "alone", "-q"][..],
        &["process", "mpc", "demo/sounder.mcap", "--gmphd", "-o", "alone", "-q"][..],
    ] {
        assert!(mmtrack(d, args).status.success());
    }
    let reference = table_bytes(&d.join("alone"));
    assert!(reference.len() >= 10, "{:?}", reference.iter().map(|r| &r.0).collect::<Vec<_>>());
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

    // The per-sequence commands a cluster runs.
    let printed = mmtrack(d, &["process", "manifest", "campaign.toml", "-o", "ray", "--print-commands"]);
    let lines = text(&printed).0;
    assert_eq!(
        lines,
        "mmtrack process odometry demo/recording.mcap --preset fast-cfear -o ray\n\
         mmtrack process mpc demo/sounder.mcap --gmphd -o ray\n"
    );
    let Some(python) = ray_python() else {
        eprintln!("skipped: the Ray example: Ray could not be installed from PyPI into a venv");
        return;
    };
    let example = root().join("examples/ray_process.py");
    let ray = Command::new(python)
        .arg(example)
        .args(["campaign.toml", "ray", "--mmtrack", env!("CARGO_BIN_EXE_mmtrack")])
        .current_dir(d)
        .output()
        .unwrap();
    let (stdout, stderr) = text(&ray);
    assert!(ray.status.success(), "{stdout}\n{stderr}");
    assert!(stdout.contains("2 of 2 sequences done on Ray"), "{stdout}");
    assert!(table_bytes(&d.join("ray")) == reference, "the Ray run differs from the local one");
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
    assert!(mmtrack(dir.path(), &["demo", "--out", "d", "--quiet"]).status.success());
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
