//! The Python package (`crates/mmtrack-py`) as a user installs it: a fresh
//! venv, `pip install crates/mmtrack-py` (maturin from PyPI builds the
//! extension), `import mmtrack; print(mmtrack.__version__)`, then the
//! package's pytest suite (`crates/mmtrack-py/tests`), which compares the
//! package's calls with this build's `mmtrack` binary, and the quickstart
//! notebook (`examples/quickstart.ipynb`) executed top to bottom (nbclient).
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
/// `build-system.requires`); DuckDB runs the documented snippets.
const REQUIREMENTS: &[&str] =
    &["polars==2.1.0", "numpy==2.4.6", "pytest==9.2.0", "pandas==3.1.1", "pyarrow==26.0.1", "duckdb==2.0.1"];

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

/// A fresh venv with the suite's requirements. Python 3 with pip access to
/// PyPI is required, as for every Python-reader test: without it the test
/// fails, naming what is missing (it never passes by skipping).
fn fresh_venv(venv: &Path) -> PathBuf {
    let system = ["python3", "python"]
        .into_iter()
        .find(|p| Command::new(p).arg("--version").output().is_ok_and(|o| o.status.success()))
        .expect("python package: Python 3 is needed (e.g. apt-get install python3 python3-venv)");
    let python = venv.join("bin/python");
    run("venv", Command::new(system).args(["-m", "venv", "--clear"]).arg(venv))
        .and_then(|_| {
            run(
                "pip install requirements",
                Command::new(&python)
                    .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
                    .args(REQUIREMENTS),
            )
        })
        .unwrap_or_else(|e| panic!("python package: a venv with pip access to PyPI is needed: {e}"));
    python
}

#[test]
fn pip_install_then_pytest_against_the_cli() {
    let venv = target_dir().join("py-package-venv");
    let python = fresh_venv(&venv);
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
    quickstart_notebook_runs_top_to_bottom(&python);
}

/// The notebook runner and the notebook's plotting, pinned.
const NOTEBOOK_REQUIREMENTS: &[&str] =
    &["nbclient==0.11.0", "nbformat==5.11.1", "ipykernel==7.4.0", "matplotlib==3.11.2"];

/// Runs every cell of `examples/quickstart.ipynb` in a kernel of this venv
/// (nbclient; a cell's error fails the run), from `examples/` as Jupyter
/// would, on the real samples; keeps the executed notebook beside the venv
/// and checks its plots and numbers came out.
const RUN_NOTEBOOK: &str = r#"
import json, sys
import nbformat
from nbclient import NotebookClient

notebook, executed = sys.argv[1], sys.argv[2]
nb = nbformat.read(notebook, as_version=4)
NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": sys.argv[3]}}).execute()
nbformat.write(nb, executed)
outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
errors = [o for o in outputs if o.output_type == "error"]
images = sum("image/png" in o.get("data", {}) for o in outputs)
text = "\n".join(str(o.get("text", "")) + str(o.get("data", {}).get("text/plain", "")) for o in outputs)
print(json.dumps({"cells": len(nb.cells), "errors": len(errors), "images": images, "text": text}))
"#;

fn quickstart_notebook_runs_top_to_bottom(python: &Path) {
    run(
        "pip install notebook requirements",
        Command::new(python)
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
            .args(NOTEBOOK_REQUIREMENTS),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let venv = python.parent().and_then(Path::parent).unwrap();
    let script = venv.join("run_notebook.py");
    std::fs::write(&script, RUN_NOTEBOOK).unwrap();
    let examples = root().join("examples");
    let executed = venv.join("quickstart.executed.ipynb");
    let realdata =
        std::env::var_os("MMTRACK_REALDATA").map(PathBuf::from).unwrap_or_else(|| root().join("../shared/realdata"));
    let out = run(
        "execute examples/quickstart.ipynb",
        Command::new(python)
            .arg(&script)
            .arg(examples.join("quickstart.ipynb"))
            .arg(&executed)
            .arg(&examples)
            .env("MMTRACK_REALDATA", &realdata)
            .current_dir(&examples),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let json: serde_json::Value =
        serde_json::from_str(out.lines().find(|l| l.starts_with("{\"cells\"")).unwrap_or_default())
            .unwrap_or_else(|e| panic!("{e}: {out}"));
    eprintln!(
        "quickstart notebook: {} cells, {} plots; executed copy {}",
        json["cells"],
        json["images"],
        executed.display()
    );
    assert_eq!(json["errors"], 0, "{json}");
    // Two figures: the Oxford path and error, the DeepSense loss CDF.
    assert_eq!(json["images"], 2, "{json}");
    let text = json["text"].as_str().unwrap();
    // The Oxford tables' time base, and both trackers' rows of the DeepSense passes.
    assert!(text.contains("time base: unix_epoch"), "{text}");
    assert!(text.contains("window") && text.contains("last-full-sweep"), "{text}");
    // Before: every run left its temporary outputs in /tmp. The last cell removes them.
    let removed = text.lines().find_map(|l| l.strip_prefix("removed ")).unwrap_or_else(|| panic!("{text}"));
    assert!(!Path::new(removed.trim()).exists(), "{removed}");
}
