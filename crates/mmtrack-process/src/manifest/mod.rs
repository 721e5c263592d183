//! The manifest runner (`mmtrack process manifest`): many sequences, each an
//! independent task.
//!
//! A manifest lists `mmtrack process` command lines, one per sequence:
//!
//! ```toml
//! [[task]]
//! args = ["odometry", "out/demo/recording.mcap", "--preset", "cfear"]
//! [[task]]
//! args = ["mpc", "out/demo/sounder.mcap", "--gmphd"]
//! ```
//!
//! Every task gets `-o <tables>` (and `--force` when given) and runs as its
//! own task on the rayon pool; tasks write different sequence partitions
//! of the same table directory, each atomically, so the result does not
//! depend on the order or the number of threads. A failed task is reported
//! and the others still finish; the command then exits 1.
//!
//! A task's own flags pass through unchanged, `--run-id` included: tasks of
//! one sequence with different run ids write side by side under
//! `<tables>/run=<ID>/` ([`crate::output`]), each refusing only its own
//! existing partitions.
//!
//! The front end parses each task's command line ([`command_line`]) and
//! runs it with [`run_tasks`]; `--print-commands` prints the lines instead
//! ([`shell_word`]): exactly what a cluster runs, one job per line (see
//! `examples/ray_process.py`).

use std::path::Path;

use anyhow::{Context, bail};
use rayon::prelude::*;
use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    task: Vec<Task>,
}

/// One task: a `mmtrack process` command line without `mmtrack process`
/// and without `-o`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Task {
    /// The words, e.g. `["odometry", "runs/a.mcap", "--preset", "cfear"]`.
    pub args: Vec<String>,
}

/// The tasks of `path`, checked: at least one, each naming a pipeline and
/// leaving `-o` to the manifest command.
///
/// # Errors
/// The file cannot be read or parsed, has no task, a task is empty, runs
/// a manifest or gives `-o`; naming the file and the task.
pub fn read_manifest(path: &Path) -> anyhow::Result<Vec<Task>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("{}: cannot read the manifest", path.display()))?;
    let manifest: Manifest = toml::from_str(&text).with_context(|| path.display().to_string())?;
    if manifest.task.is_empty() {
        bail!("{}: no [[task]] entries", path.display());
    }
    for (i, task) in manifest.task.iter().enumerate() {
        let Some(pipeline) = task.args.first() else { bail!("{}: task {i}: empty args", path.display()) };
        if pipeline == "manifest" {
            bail!("{}: task {i}: a manifest cannot run a manifest", path.display());
        }
        if task.args.iter().any(|a| a == "-o" || a == "--output" || a.starts_with("--output=")) {
            bail!(
                "{}: task {i}: leave -o/--output out (the manifest command gives every task the same one)",
                path.display()
            );
        }
    }
    Ok(manifest.task)
}

/// One task's full command line after `mmtrack`.
#[must_use]
pub fn command_line(task: &Task, output: &str, force: bool) -> Vec<String> {
    let mut line = vec!["process".to_string()];
    line.extend(task.args.iter().cloned());
    line.extend(["-o".to_string(), output.to_string()]);
    if force {
        line.push("--force".into());
    }
    line
}

/// Shell-quotes `word` when it needs it.
#[must_use]
pub fn shell_word(word: &str) -> String {
    if !word.is_empty() && word.chars().all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@".contains(c)) {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}

/// Runs `run` on every task as its own task on the current rayon pool;
/// one result per task, in task order. A failed task does not stop the
/// others.
pub fn run_tasks<T: Sync>(
    tasks: &[T],
    run: impl Fn(&T) -> anyhow::Result<()> + Send + Sync,
) -> Vec<anyhow::Result<()>> {
    tasks.par_iter().map(run).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn manifests_are_checked_and_lines_built() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.toml");
        std::fs::write(&path, "[[task]]\nargs = [\"odometry\", \"a b.mcap\", \"--preset\", \"cfear\"]\n").unwrap();
        let tasks = read_manifest(&path).unwrap();
        let line = command_line(&tasks[0], "t", true);
        assert_eq!(line, ["process", "odometry", "a b.mcap", "--preset", "cfear", "-o", "t", "--force"]);
        assert_eq!(shell_word("a b.mcap"), "'a b.mcap'");
        for (text, message) in [
            ("task = []\n", "no [[task]] entries"),
            ("[[task]]\nargs = []\n", "task 0: empty args"),
            ("[[task]]\nargs = [\"mpc\", \"x.mcap\", \"-o\", \"y\"]\n", "leave -o/--output out"),
            ("[[task]]\nargs = [\"manifest\", \"m.toml\"]\n", "cannot run a manifest"),
        ] {
            std::fs::write(&path, text).unwrap();
            let err = read_manifest(&path).err().map(|e| format!("{e:#}")).unwrap_or_default();
            assert!(err.contains(message), "{text}: {err}");
        }
    }
}
