//! Helpers shared by the end-to-end tests.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The workspace root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

/// The real-data samples: `$MMTRACK_REALDATA` or `../shared/realdata` beside the
/// project root. `None` (and a visible skip line) when absent, as on a user's
/// fresh clone.
pub fn realdata(test: &str) -> Option<PathBuf> {
    let dir =
        std::env::var_os("MMTRACK_REALDATA").map(PathBuf::from).unwrap_or_else(|| root().join("../shared/realdata"));
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("skipped: {test}: real data not found at {} (set MMTRACK_REALDATA)", dir.display());
        None
    }
}

/// Runs `mmtrack` with `args` in `cwd`.
pub fn mmtrack(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mmtrack")).args(args).current_dir(cwd).output().unwrap()
}

/// Runs `mmtrack` with `args` in `cwd`, asserting it succeeds (the
/// failure names the arguments and shows stderr); returns stdout.
pub fn mmtrack_ok(cwd: &Path, args: &[&str]) -> String {
    let out = mmtrack(cwd, args);
    assert!(out.status.success(), "{args:?}: {}", text(&out).1);
    text(&out).0
}

/// Stdout and stderr as text.
pub fn text(output: &Output) -> (String, String) {
    (String::from_utf8_lossy(&output.stdout).into_owned(), String::from_utf8_lossy(&output.stderr).into_owned())
}

/// Every file under `dir`, relative, sorted.
pub fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                out.push(path.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// PyPI packages of the independent readers and writers, pinned.
const REQUIREMENTS: &str = "mcap==1.6.0 mcap-protobuf-support==0.6.0 protobuf==7.36.2 pyarrow==26.0.1 duckdb==2.0.0 numpy==2.4.6 resvg-py==0.5.0";

/// A Python with [`REQUIREMENTS`], in a venv under the target directory
/// (`$MMTRACK_PY_VENV` to put it elsewhere), made on first use; `None`
/// where Python or PyPI is unavailable.
pub fn venv_python() -> Option<PathBuf> {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target"));
    let venv = std::env::var_os("MMTRACK_PY_VENV").map(PathBuf::from).unwrap_or_else(|| target.join("py-venv"));
    let python = venv.join("bin/python");
    let stamp = venv.join("requirements.txt");
    // Tests run in parallel: one makes the venv, the others wait for it.
    static MADE: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _made = MADE.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    if std::fs::read_to_string(&stamp).ok().as_deref() == Some(REQUIREMENTS) && python.is_file() {
        return Some(python);
    }
    let system = ["python3", "python"]
        .into_iter()
        .find(|p| Command::new(p).arg("--version").output().is_ok_and(|o| o.status.success()))?;
    let ok = Command::new(system).args(["-m", "venv"]).arg(&venv).status().is_ok_and(|s| s.success())
        && Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
            .args(REQUIREMENTS.split(' '))
            .status()
            .is_ok_and(|s| s.success());
    if !ok {
        return None;
    }
    std::fs::write(&stamp, REQUIREMENTS).ok()?;
    Some(python)
}
