//! `mmtrack process manifest`: many sequences, each an independent task.
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
//! `<tables>/run=<ID>/` (`crate::run_id`), each refusing only its own
//! existing partitions.
//!
//! `--print-commands` prints the per-sequence command lines instead of
//! running them: exactly what a cluster runs, one job per line (see
//! `examples/ray_process.py`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::Args;
use rayon::prelude::*;
use serde::Deserialize;

use crate::threads::ThreadsArg;

#[derive(Args)]
pub struct ManifestArgs {
    /// Manifest TOML: `[[task]]` tables, each with `args`, a `mmtrack process` command line without `mmtrack
    /// process` and without `-o` (paths as typed in the directory you run from).
    pub manifest: PathBuf,
    /// Output table directory every task writes into (its own sequence partitions).
    #[arg(short, long, required_unless_present = "print_commands")]
    pub output: Option<PathBuf>,
    /// Pass --force to every task (replace their earlier partitions).
    #[arg(long)]
    pub force: bool,
    /// Print the per-sequence command lines (what a cluster runs, one job each) and exit.
    #[arg(long)]
    pub print_commands: bool,
    #[command(flatten)]
    pub threads: ThreadsArg,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    task: Vec<Task>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Task {
    args: Vec<String>,
}

/// The tasks of `path`, checked: at least one, each naming a pipeline and
/// leaving `-o` to the manifest command.
fn read_manifest(path: &Path) -> anyhow::Result<Vec<Task>> {
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
fn command_line(task: &Task, output: &str, force: bool) -> Vec<String> {
    let mut line = vec!["process".to_string()];
    line.extend(task.args.iter().cloned());
    line.extend(["-o".to_string(), output.to_string()]);
    if force {
        line.push("--force".into());
    }
    line
}

/// Shell-quotes `word` when it needs it.
fn shell_word(word: &str) -> String {
    if !word.is_empty() && word.chars().all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@".contains(c)) {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}

pub fn run(args: &ManifestArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let tasks = read_manifest(&args.manifest)?;
    let output = match &args.output {
        Some(o) => crate::path_word(o)?,
        None => "<tables>".to_string(),
    };
    let lines: Vec<Vec<String>> = tasks.iter().map(|t| command_line(t, &output, args.force)).collect();
    if args.print_commands {
        for line in &lines {
            println!("mmtrack {}", line.iter().map(|w| shell_word(w)).collect::<Vec<_>>().join(" "));
        }
        return Ok(ExitCode::SUCCESS);
    }
    let outcomes: Vec<anyhow::Result<ExitCode>> = args.threads.install(|| {
        lines
            .par_iter()
            .map(|line| {
                let mut words = line.clone();
                words.push("--quiet".into());
                crate::run_words(&words)
            })
            .collect()
    })?;
    let mut failed = 0;
    for (line, outcome) in lines.iter().zip(&outcomes) {
        let shown = line.iter().map(|w| shell_word(w)).collect::<Vec<_>>().join(" ");
        match outcome {
            Ok(code) if *code == ExitCode::SUCCESS => {
                if !quiet {
                    println!("ok      mmtrack {shown}");
                }
            }
            Ok(_) => {
                failed += 1;
                eprintln!("failed  mmtrack {shown}: exit 1");
            }
            Err(e) => {
                failed += 1;
                eprintln!("failed  mmtrack {shown}: {}", crate::one_line(e));
            }
        }
    }
    if !quiet {
        println!("{} of {} tasks done; tables under {output}", tasks.len() - failed, tasks.len());
    }
    Ok(if failed == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE })
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
