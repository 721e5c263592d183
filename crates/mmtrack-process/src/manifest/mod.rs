//! The manifest runner (`mmtrack process manifest`): a campaign of ingest,
//! process and analyze steps, each an independent task.
//!
//! A manifest lists command lines, one per task:
//!
//! ```toml
//! [[task]]                      # step = "process" unless given
//! args = ["odometry", "out/demo/recording.mcap", "--preset", "cfear"]
//!
//! [[task]]
//! name = "ingest-a"
//! step = "ingest"
//! args = ["oxford", "data/a", "-o", "recordings/a.mcap"]
//! [[task]]
//! name = "odometry-a"
//! needs = ["ingest-a"]
//! args = ["odometry", "recordings/a.mcap"]
//! [[task]]
//! step = "analyze"
//! needs = ["odometry-a"]
//! args = ["{tables}", "-o", "analysis"]
//! ```
//!
//! - `step`: `ingest`, `process` (default) or `analyze`: the words after
//!   `mmtrack ingest` / `mmtrack process` / `mmtrack analyze`. Process
//!   tasks get `-o <tables>` from the manifest command; ingest and analyze
//!   tasks name their own `-o` (the recording, the analysis directory). The
//!   word `{tables}` in any task stands for the manifest's `-o`.
//! - `name`: optional, unique; what other tasks' `needs` refer to.
//! - `needs`: the names of the tasks whose outputs this one reads. A task
//!   runs after every task it needs finished; a step may need only steps of
//!   its own kind or an earlier one (ingest, process, analyze: a SPEBT run
//!   may need an odometry run), and cycles are refused ([`read_manifest`]).
//!   The dependencies are explicit rather than guessed from paths: a task
//!   names what it needs, and nothing else orders the tasks.
//!
//! Tasks run level by level ([`Manifest::levels`]: a task's level is one
//! more than the highest level it needs), each level's tasks as independent
//! tasks on the rayon pool; tasks write different sequence partitions (and
//! files) atomically, so the result does not depend on the order or the
//! number of threads. A failed task is reported, the tasks that need it are
//! not run, and the others still finish; the command then exits 1.
//!
//! # Resuming
//!
//! Every task run by the manifest command leaves a completion record
//! ([`marker`]) under `<tables>/.mmtrack-tasks/`: `started` before the task
//! runs, `done` with its output files and sizes once it succeeded, removed
//! when it failed (a failed task leaves no output of its own). With
//! `--skip-existing` a task whose record says `done` with every output
//! still there at its size is skipped; one whose record says `started` was
//! interrupted and is redone with `--force` (it replaces only what it
//! writes itself); one without a record runs as given, so an output that
//! task did not write is refused as without `--skip-existing`.
//!
//! `--print-commands` prints the command lines ([`shell_word`]), one per
//! task; `--task N` runs task N alone (what a cluster job runs, see
//! `examples/ray_process.py` and `examples/slurm_campaign.sh`).

pub mod from_dataset;
pub mod marker;

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, bail};
use rayon::prelude::*;
use serde::Deserialize;

/// Tasks of one manifest: far above any campaign (a task per sequence of
/// every public radar dataset is a few thousand), far below a table that
/// would take minutes to parse.
pub const MAX_TASKS: usize = 100_000;

/// Words of one task's command line.
pub const MAX_WORDS: usize = 1_000;

/// The placeholder of the manifest's `-o` in a task's words.
pub const TABLES_PLACEHOLDER: &str = "{tables}";

/// The kind of a task: which `mmtrack` command its words follow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Step {
    /// `mmtrack ingest ...`
    Ingest,
    /// `mmtrack process ...`
    Process,
    /// `mmtrack analyze ...`
    Analyze,
}

impl Step {
    /// The `mmtrack` subcommand.
    #[must_use]
    pub fn command(self) -> &'static str {
        match self {
            Self::Ingest => "ingest",
            Self::Process => "process",
            Self::Analyze => "analyze",
        }
    }
}

const TASK_KEYS: &[&str] = &["name", "step", "needs", "args"];

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTask {
    name: Option<String>,
    step: Option<Step>,
    #[serde(default)]
    needs: Vec<String>,
    args: Vec<String>,
}

/// One task of a manifest, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Task {
    /// Its position in the manifest, from 0 (`--task N`).
    pub index: usize,
    /// Its `name`, if given.
    pub name: Option<String>,
    /// Which command its words follow.
    pub step: Step,
    /// The tasks it needs, as indices, in the order given.
    pub needs: Vec<usize>,
    /// The words after `mmtrack <step>`, e.g.
    /// `["odometry", "runs/a.mcap", "--preset", "cfear"]`.
    pub args: Vec<String>,
}

impl Task {
    /// `task N` or `task N (name)`, as errors and reports name it.
    #[must_use]
    pub fn label(&self) -> String {
        match &self.name {
            Some(name) => format!("task {} ({name})", self.index),
            None => format!("task {}", self.index),
        }
    }

    /// The `--threads` the task gives itself, if any.
    #[must_use]
    pub fn threads(&self) -> Option<usize> {
        threads_of(&self.args).and_then(|t| t.ok())
    }

    /// The task's full command line after `mmtrack`: `{tables}` replaced by
    /// `output`, and for process tasks `-o <output>` added; `--force` when
    /// `force`.
    #[must_use]
    pub fn command_line(&self, output: &str, force: bool) -> Vec<String> {
        let mut line = vec![self.step.command().to_string()];
        line.extend(self.args.iter().map(|w| if w == TABLES_PLACEHOLDER { output.to_string() } else { w.clone() }));
        if self.step == Step::Process {
            line.extend(["-o".to_string(), output.to_string()]);
        }
        if force {
            line.push("--force".into());
        }
        line
    }

    /// The output a task names itself (`-o`/`--output` of ingest and
    /// analyze tasks), `{tables}` replaced by `output`.
    #[must_use]
    pub fn own_output(&self, output: &str) -> Option<String> {
        let words = self.command_line(output, false);
        output_flag(&words[1..]).map(str::to_string)
    }
}

/// A checked manifest: its tasks in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct Manifest {
    /// The tasks, `tasks[i].index == i`.
    pub tasks: Vec<Task>,
}

impl Manifest {
    /// The tasks by level: level 0 needs nothing, level k+1 needs tasks of
    /// level k at most. Every task of a level can run once the levels before
    /// it finished; within a level, in index order.
    #[must_use]
    pub fn levels(&self) -> Vec<Vec<usize>> {
        // `read_manifest` refused cycles, so the needs form a DAG: in Kahn's
        // order (a task after everything it needs) each task's level is
        // final once its needs are; O(tasks + needs).
        let n = self.tasks.len();
        let mut level = vec![0_usize; n];
        let mut waiting: Vec<usize> = self.tasks.iter().map(|t| t.needs.len()).collect();
        let mut dependents = vec![Vec::new(); n];
        for task in &self.tasks {
            for &need in &task.needs {
                dependents[need].push(task.index);
            }
        }
        let mut ready: Vec<usize> = (0..n).filter(|&i| waiting[i] == 0).collect();
        while let Some(i) = ready.pop() {
            for &d in &dependents[i] {
                level[d] = level[d].max(level[i] + 1);
                waiting[d] -= 1;
                if waiting[d] == 0 {
                    ready.push(d);
                }
            }
        }
        let depth = level.iter().max().map_or(0, |&m| m + 1);
        let mut levels = vec![Vec::new(); depth];
        for (i, &l) in level.iter().enumerate() {
            levels[l].push(i);
        }
        levels
    }
}

/// The value of the last `-o`/`--output` flag among `words`.
fn output_flag(words: &[String]) -> Option<&str> {
    let mut found = None;
    let mut it = words.iter();
    while let Some(word) = it.next() {
        if word == "-o" || word == "--output" {
            found = it.next().map(String::as_str);
        } else if let Some(value) = word.strip_prefix("--output=") {
            found = Some(value);
        }
    }
    found
}

/// The `--threads` value among `words`: none, or the parsed number.
fn threads_of(words: &[String]) -> Option<Result<usize, String>> {
    let mut found = None;
    let mut it = words.iter();
    while let Some(word) = it.next() {
        let value =
            if word == "--threads" { it.next().cloned() } else { word.strip_prefix("--threads=").map(str::to_string) };
        if let Some(value) = value {
            found = Some(value.parse::<usize>().map_err(|_| value));
        }
    }
    found
}

/// The checked manifest at `path`.
///
/// # Errors
/// The file cannot be read or parsed; it has a key other than `task`, no
/// task or more than [`MAX_TASKS`]; a task has an unknown key, no `args` or
/// more than [`MAX_WORDS`] words, a bad or duplicate `name`, a `needs` that
/// names no task, itself, or a later step, a `--threads` beyond
/// [`mmtrack_core::limits::THREADS`], a process task that runs a manifest
/// or gives `-o`, an ingest or analyze task without `-o`; or the needs form
/// a cycle. Each error names the file, the task and the key.
pub fn read_manifest(path: &Path) -> anyhow::Result<Manifest> {
    let file = path.display();
    let text = mmtrack_io::paths::read_config_text(path).context("cannot read the manifest")?;
    let table: toml::Table = toml::from_str(&text).with_context(|| file.to_string())?;
    if let Some(key) = table.keys().find(|k| *k != "task") {
        bail!("{file}: unknown key `{key}` (a manifest holds [[task]] tables only)");
    }
    let Some(entries) = table.get("task") else { bail!("{file}: no [[task]] entries") };
    let Some(entries) = entries.as_array() else { bail!("{file}: key `task`: expected [[task]] tables") };
    if entries.is_empty() {
        bail!("{file}: no [[task]] entries");
    }
    if entries.len() > MAX_TASKS {
        bail!("{file}: key `task`: {} tasks; expected at most {MAX_TASKS}", entries.len());
    }
    let mut raw = Vec::with_capacity(entries.len());
    for (i, entry) in entries.iter().enumerate() {
        let Some(keys) = entry.as_table() else { bail!("{file}: task {i}: expected a [[task]] table") };
        if let Some(key) = keys.keys().find(|k| !TASK_KEYS.contains(&k.as_str())) {
            bail!("{file}: task {i}: unknown key `{key}` (expected one of {})", TASK_KEYS.join(", "));
        }
        // Each key's type named (serde's message named none: "invalid type: string, expected a sequence").
        for (key, value) in keys {
            let strings = value.as_array().is_some_and(|a| a.iter().all(toml::Value::is_str));
            let (ok, expected) = match key.as_str() {
                "name" => (value.is_str(), "a string"),
                "step" => (
                    matches!(value.as_str(), Some("ingest" | "process" | "analyze")),
                    "\"ingest\", \"process\" or \"analyze\"",
                ),
                _ => (strings, "an array of strings"),
            };
            if !ok {
                bail!("{file}: task {i}: key `{key}`: {value}, expected {expected}");
            }
        }
        let task: RawTask = entry
            .clone()
            .try_into()
            .map_err(|e: toml::de::Error| anyhow::anyhow!("{file}: task {i}: {}", e.message()))?;
        raw.push(task);
    }
    let mut names = BTreeMap::new();
    for (i, task) in raw.iter().enumerate() {
        if let Some(name) = &task.name {
            let valid = !name.is_empty()
                && name.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
                && name.parse::<usize>().is_err();
            if !valid {
                bail!("{file}: task {i}: key `name`: '{name}' (use letters, digits, '-', '_', '.'; not a bare number)");
            }
            if let Some(first) = names.insert(name.clone(), i) {
                bail!("{file}: task {i}: key `name`: '{name}' is already task {first}'s");
            }
        }
    }
    let mut tasks = Vec::with_capacity(raw.len());
    for (i, task) in raw.into_iter().enumerate() {
        let step = task.step.unwrap_or(Step::Process);
        let label = match &task.name {
            Some(name) => format!("{file}: task {i} ({name})"),
            None => format!("{file}: task {i}"),
        };
        let mut needs = Vec::with_capacity(task.needs.len());
        for need in &task.needs {
            let Some(&n) = names.get(need) else { bail!("{label}: key `needs`: no task is named '{need}'") };
            if n == i {
                bail!("{label}: key `needs`: a task cannot need itself");
            }
            if needs.contains(&n) {
                bail!("{label}: key `needs`: '{need}' listed twice");
            }
            needs.push(n);
        }
        check_args(&label, step, &task.args)?;
        tasks.push(Task { index: i, name: task.name, step, needs, args: task.args });
    }
    for task in &tasks {
        for &n in &task.needs {
            if tasks[n].step > task.step {
                bail!(
                    "{file}: {}: key `needs`: {} is a later step ({}); steps run ingest, then process, then analyze",
                    task.label(),
                    tasks[n].label(),
                    tasks[n].step.command()
                );
            }
        }
    }
    if let Some(cycle) = find_cycle(&tasks) {
        // At most the first 8 tasks of a long cycle (one of 100 000 printed a 2.3 MB line).
        let mut path: Vec<String> = cycle.iter().take(8).map(|&i| tasks[i].label()).collect();
        if cycle.len() > 9 {
            path.push(format!("... ({} tasks in all)", cycle.len() - 1));
        }
        if cycle.len() > 8 {
            path.push(tasks[cycle[0]].label());
        }
        bail!("{file}: {}: key `needs`: a cycle: {}", tasks[cycle[0]].label(), path.join(" -> "));
    }
    Ok(Manifest { tasks })
}

/// Checks one task's words: at most [`MAX_WORDS`], a plausible `--threads`,
/// and the `-o` rule of its step.
fn check_args(label: &str, step: Step, args: &[String]) -> anyhow::Result<()> {
    let Some(first) = args.first() else { bail!("{label}: key `args`: empty") };
    if args.len() > MAX_WORDS {
        bail!("{label}: key `args`: {} words; expected at most {MAX_WORDS}", args.len());
    }
    if let Some(threads) = threads_of(args) {
        let limit = mmtrack_core::limits::THREADS;
        match threads {
            Ok(t) if limit.allows_count(t as u64) => {}
            Ok(t) => bail!("{label}: key `args`: --threads {t}: expected {}", limit.expected),
            Err(raw) => bail!("{label}: key `args`: --threads '{raw}': expected a number"),
        }
    }
    let has_output = output_flag(args).is_some();
    match step {
        Step::Process => {
            if first == "manifest" {
                bail!("{label}: key `args`: a manifest cannot run a manifest");
            }
            if has_output {
                bail!(
                    "{label}: key `args`: leave -o/--output out of a process task (the manifest command gives \
                     every process task the same one)"
                );
            }
        }
        Step::Ingest | Step::Analyze => {
            if !has_output {
                bail!("{label}: key `args`: an {} task names its output with -o", step.command());
            }
        }
    }
    Ok(())
}

/// A cycle among the tasks' needs, as task indices from its first task
/// back to it, if there is one.
fn find_cycle(tasks: &[Task]) -> Option<Vec<usize>> {
    // Iterative depth-first search; 0 unvisited, 1 on the stack, 2 done.
    let mut state = vec![0_u8; tasks.len()];
    for start in 0..tasks.len() {
        if state[start] != 0 {
            continue;
        }
        let mut stack: Vec<(usize, usize)> = vec![(start, 0)];
        state[start] = 1;
        while let Some(&mut (task, ref mut next)) = stack.last_mut() {
            if let Some(&need) = tasks[task].needs.get(*next) {
                *next += 1;
                match state[need] {
                    0 => {
                        state[need] = 1;
                        stack.push((need, 0));
                    }
                    1 => {
                        let from = stack.iter().position(|&(t, _)| t == need).unwrap_or(0);
                        let mut cycle: Vec<usize> = stack[from..].iter().map(|&(t, _)| t).collect();
                        cycle.push(need);
                        return Some(cycle);
                    }
                    _ => {}
                }
            } else {
                state[task] = 2;
                stack.pop();
            }
        }
    }
    None
}

/// One spelling of a path for comparing tasks' inputs and outputs: absolute
/// and without `.` or repeated separators (`./a.mcap`, `a.mcap`, its absolute
/// path and `rec//a.mcap` are one; links and `..` are not resolved).
#[must_use]
pub fn path_key(path: &Path) -> String {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    absolute.components().collect::<std::path::PathBuf>().display().to_string()
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

/// What became of one task of a run.
#[derive(Debug)]
pub enum Outcome {
    /// It ran and succeeded.
    Done,
    /// `--skip-existing` found it complete ([`marker`]).
    Skipped,
    /// It ran and failed.
    Failed(anyhow::Error),
    /// It did not run: a task it needs (this one) did not finish.
    NotRun(usize),
}

/// Runs the tasks of `manifest` level by level ([`Manifest::levels`]), each
/// level's tasks as independent tasks on the current rayon pool; `run`
/// runs one task and says whether it ran or was skipped. A task whose
/// need did not finish is not run. One outcome per task, in task order.
pub fn run_levels(manifest: &Manifest, run: impl Fn(&Task) -> anyhow::Result<bool> + Send + Sync) -> Vec<Outcome> {
    let mut outcomes: Vec<Option<Outcome>> = (0..manifest.tasks.len()).map(|_| None).collect();
    for level in manifest.levels() {
        let ready: Vec<(usize, Option<usize>)> = level
            .iter()
            .map(|&i| {
                let blocked = manifest.tasks[i]
                    .needs
                    .iter()
                    .copied()
                    .find(|&n| !matches!(outcomes[n], Some(Outcome::Done | Outcome::Skipped)));
                (i, blocked)
            })
            .collect();
        let results: Vec<(usize, Outcome)> = ready
            .par_iter()
            .map(|&(i, blocked)| {
                let outcome = match blocked {
                    Some(n) => Outcome::NotRun(n),
                    None => match run(&manifest.tasks[i]) {
                        Ok(true) => Outcome::Done,
                        Ok(false) => Outcome::Skipped,
                        Err(e) => Outcome::Failed(e),
                    },
                };
                (i, outcome)
            })
            .collect();
        for (i, outcome) in results {
            outcomes[i] = Some(outcome);
        }
    }
    outcomes.into_iter().map(|o| o.unwrap_or(Outcome::NotRun(usize::MAX))).collect()
}

/// The manifest's tasks as lines of JSON, one per task: index, name, step,
/// level, needs (indices), threads (the task's own `--threads`, else
/// null) and the command line after `mmtrack` (what
/// `--print-tasks` prints for a scheduler).
#[must_use]
pub fn task_lines(manifest: &Manifest, output: &str) -> Vec<String> {
    let mut level_of = vec![0; manifest.tasks.len()];
    for (l, level) in manifest.levels().iter().enumerate() {
        for &i in level {
            level_of[i] = l;
        }
    }
    manifest
        .tasks
        .iter()
        .map(|t| {
            serde_json::json!({
                "index": t.index,
                "name": t.name,
                "step": t.step.command(),
                "level": level_of[t.index],
                "needs": t.needs,
                "threads": t.threads(),
                "command": t.command_line(output, false),
            })
            .to_string()
        })
        .collect()
}

#[cfg(test)]
mod tests;
