//! Records the git commit this crate is built from, for the provenance of
//! `report.html` (`MMTRACK_BUILD_COMMIT`): `git rev-parse HEAD` when the
//! sources are a git checkout, else `unknown`. Never fails the build: a
//! source tarball, or a machine without git, gives `unknown`.

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8(out.stdout).ok()?.trim().to_string();
    (!text.is_empty()).then_some(text)
}

fn main() {
    let commit = git(&["rev-parse", "HEAD"]).unwrap_or_else(|| "unknown".to_string());
    println!("cargo:rustc-env=MMTRACK_BUILD_COMMIT={commit}");
    println!("cargo:rerun-if-changed=build.rs");
    // Rebuilt when HEAD moves: the HEAD file (a branch switch), the branch's
    // ref (a commit) and packed refs. Paths from git, so worktrees work too.
    let mut watched = vec!["HEAD".to_string(), "packed-refs".to_string()];
    if let Some(reference) = git(&["symbolic-ref", "-q", "HEAD"]) {
        watched.push(reference);
    }
    for path in watched {
        // Only files that exist: a missing one would rerun this script on every build.
        if let Some(file) = git(&["rev-parse", "--git-path", &path]).filter(|f| std::path::Path::new(f).exists()) {
            println!("cargo:rerun-if-changed={file}");
        }
    }
}
