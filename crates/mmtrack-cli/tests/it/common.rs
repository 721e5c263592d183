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
