//! The Python package (`crates/mmtrack-py`) as a user installs it: a fresh
//! venv, `pip install crates/mmtrack-py` (maturin from PyPI builds the
//! extension), `import mmtrack; print(mmtrack.__version__)`, then the
//! package's pytest suite (`crates/mmtrack-py/tests`), which compares the
//! package's calls with this build's `mmtrack` binary.
//!
//! The build reuses what `cargo test --workspace` compiled: it runs in the
//! same `CARGO_TARGET_DIR` with the workspace's dev profile
//! (`[tool.maturin] profile = "dev"`), so only the pyo3 crates and the
//! extension itself are compiled here. Measured on the project's 2-core
//! machine with the workspace built and a warm pip cache: 67 s in all (venv
//! 8 s, requirements 27 s, `pip install crates/mmtrack-py` 19 s, pytest
//! 11 s), beside the other tests of this binary. Skips with a visible line
//! where Python or PyPI is unavailable.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use super::common::root;

/// PyPI packages of the suite, pinned (maturin comes from the package's
/// `build-system.requires`).
const REQUIREMENTS: &[&str] = &["polars==2.1.0", "numpy==2.4.6", "pytest==9.2.0", "pandas==3.1.1", "pyarrow==26.0.1"];

fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target"))
}

fn run(what: &str, command: &mut Command) -> Result<String, String> {
    let started = Instant::now();
    let out = command.output().map_err(|e| format!("{what}: cannot start: {e}"))?;
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    eprintln!("python package: {what}: {:.1} s", started.elapsed().as_secs_f64());
    if out.status.success() { Ok(text) } else { Err(format!("{what} failed ({}):\n{text}", out.status)) }
}

/// A fresh venv with the suite's requirements; `None` (after a visible
/// line) where Python or PyPI is unavailable.
fn fresh_venv(venv: &Path) -> Option<PathBuf> {
    let system = ["python3", "python"]
        .into_iter()
        .find(|p| Command::new(p).arg("--version").output().is_ok_and(|o| o.status.success()));
    let Some(system) = system else {
        eprintln!("skipped: python package: no Python 3");
        return None;
    };
    let python = venv.join("bin/python");
    let made = run("venv", Command::new(system).args(["-m", "venv", "--clear"]).arg(venv)).and_then(|_| {
        run(
            "pip install requirements",
            Command::new(&python)
                .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
                .args(REQUIREMENTS),
        )
    });
    match made {
        Ok(_) => Some(python),
        Err(e) => {
            eprintln!("skipped: python package: Python venv or PyPI unavailable: {e}");
            None
        }
    }
}

#[test]
fn pip_install_then_pytest_against_the_cli() {
    let venv = target_dir().join("py-package-venv");
    let Some(python) = fresh_venv(&venv) else { return };
    let package = root().join("crates/mmtrack-py");
    // The same target directory and profile as this test binary's build:
    // the dependencies are already compiled.
    run(
        "pip install crates/mmtrack-py",
        Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
            .arg(&package)
            .env("CARGO_TARGET_DIR", target_dir()),
    )
    .unwrap();
    let version = run(
        "import mmtrack",
        Command::new(&python).args(["-c", "import mmtrack; print(mmtrack.__version__)"]).current_dir(venv.as_path()),
    )
    .unwrap();
    assert_eq!(version.trim(), env!("CARGO_PKG_VERSION"));
    let report = run(
        "pytest crates/mmtrack-py/tests",
        Command::new(&python)
            .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "-rs"])
            .arg(package.join("tests"))
            .env("MMTRACK_BIN", env!("CARGO_BIN_EXE_mmtrack"))
            .current_dir(venv.as_path()),
    );
    let report = report.unwrap_or_else(|e| panic!("{e}"));
    eprintln!("{report}");
    assert!(report.contains(" passed"), "{report}");
    assert!(!report.contains(" failed"), "{report}");
}
