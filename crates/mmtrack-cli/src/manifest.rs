//! `mmtrack process manifest`: a campaign of ingest, process and analyze
//! tasks ([`mmtrack_process::manifest`]), run locally level by level, one
//! task alone (`--task N`, a cluster job), printed for a scheduler, or
//! written from a dataset folder (`--from`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use mmtrack_io::Overwrite;
use mmtrack_process::manifest::from_dataset::{self, Layout};
use mmtrack_process::manifest::marker::{self, Record, Resume, State};
use mmtrack_process::manifest::{self, Manifest, Outcome, Task};

use crate::threads::ThreadsArg;

/// The dataset layouts of `--from`.
#[derive(Clone, Copy, ValueEnum)]
pub enum LayoutArg {
    /// Oxford Radar RobotCar: radar/<t_us>.png, radar.timestamps.
    Oxford,
    /// Boreas: radar/<t_us>.png, applanix/radar_poses.csv.
    Boreas,
    /// MulRan: sensor_data/radar/polar/<t_ns>.png, global_pose.csv.
    Mulran,
}

#[derive(Args)]
pub struct ManifestArgs {
    /// Manifest TOML: `[[task]]` tables with `args` (the words after `mmtrack <step>`), and optionally `step`
    /// (ingest, process, analyze; default process), `name` and `needs` (names of the tasks it waits for). Paths
    /// as typed in the directory you run from. With --from: the manifest to write.
    pub manifest: PathBuf,
    /// Output table directory every process task writes into (its own sequence partitions); `{tables}` in a
    /// task's args stands for it. The completion records of --skip-existing go to its .mmtrack-tasks/.
    #[arg(short, long, required_unless_present_any = ["print_commands", "print_tasks", "print_levels", "from"])]
    pub output: Option<PathBuf>,
    /// Pass --force to every task (replace their earlier outputs); with --from, replace the manifest file.
    #[arg(long)]
    pub force: bool,
    /// Resume a campaign: skip every task whose completion record says done with its outputs intact; redo the
    /// tasks an interrupted run left started, and those whose outputs changed or whose needs finished again since
    /// (replacing only their own outputs); run the others as given.
    #[arg(long, conflicts_with = "force")]
    pub skip_existing: bool,
    /// Run task N alone (from 0, manifest order), as a cluster job does; the tasks it needs must be done (their
    /// completion records say so).
    #[arg(long, value_name = "N")]
    pub task: Option<usize>,
    /// Print the command line of every task, one per line (mmtrack ...), and exit.
    #[arg(long)]
    pub print_commands: bool,
    /// Print every task as a line of JSON (index, name, step, level, needs, threads, command) for a scheduler,
    /// and exit.
    #[arg(long)]
    pub print_tasks: bool,
    /// Print the task indices of each level, comma-separated, one level per line (a level runs after the ones
    /// above it; e.g. one SLURM job array each), and exit.
    #[arg(long)]
    pub print_levels: bool,
    /// Write the manifest from a dataset folder instead of running it: per sequence found (the folder itself
    /// or its sub-folders), an ingest task and the odometry task that needs it. Needs --layout.
    #[arg(long, value_name = "DATASET", requires = "layout")]
    pub from: Option<PathBuf>,
    /// The layout of --from's sequences.
    #[arg(long, value_enum, requires = "from")]
    pub layout: Option<LayoutArg>,
    /// With --from: where the ingest tasks write their recordings (<DIR>/<sequence>.mcap).
    #[arg(long, value_name = "DIR", default_value = "recordings")]
    pub recordings: PathBuf,
    /// With --from: the odometry preset of the process tasks.
    #[arg(long, default_value = "cfear", value_parser = clap::builder::PossibleValuesParser::new(mmtrack_odometry::OdometryConfig::PRESETS))]
    pub preset: String,
    #[command(flatten)]
    pub threads: ThreadsArg,
}

pub fn run(args: &ManifestArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    if let (Some(root), Some(layout)) = (&args.from, args.layout) {
        write_from_dataset(args, root, layout, quiet)?;
        return Ok(ExitCode::SUCCESS);
    }
    let manifest = manifest::read_manifest(&args.manifest)?;
    let output = match &args.output {
        Some(o) => crate::path_word(o)?,
        None => "<tables>".to_string(),
    };
    if args.print_commands {
        for task in &manifest.tasks {
            println!("mmtrack {}", shown(&task.command_line(&output, args.force)));
        }
        return Ok(ExitCode::SUCCESS);
    }
    if args.print_tasks {
        for line in manifest::task_lines(&manifest, &output) {
            println!("{line}");
        }
        return Ok(ExitCode::SUCCESS);
    }
    if args.print_levels {
        for level in manifest.levels() {
            println!("{}", level.iter().map(usize::to_string).collect::<Vec<_>>().join(","));
        }
        return Ok(ExitCode::SUCCESS);
    }
    let file = args.manifest.display();
    check_tasks(&manifest, &output, &file.to_string())?;
    if let Some(n) = args.task {
        let Some(task) = manifest.tasks.get(n) else {
            bail!("{file}: --task {n}: the manifest has tasks 0 to {}", manifest.tasks.len() - 1);
        };
        check_needs_done(&manifest, task, &output, &file.to_string())?;
        let outcome = args.threads.install(|| run_one(&manifest, task, &output, args))?;
        let line = shown(&task.command_line(&output, false));
        return match outcome {
            Ok(ran) => {
                if !quiet {
                    println!("{}  mmtrack {line}", if ran { "ok     " } else { "skipped" });
                }
                Ok(ExitCode::SUCCESS)
            }
            Err(e) => Err(e.context(format!("{}: mmtrack {line}", task.label()))),
        };
    }
    let outcomes =
        args.threads.install(|| manifest::run_levels(&manifest, |task| run_one(&manifest, task, &output, args)))?;
    let (mut ran, mut skipped, mut failed) = (0, 0, 0);
    for (task, outcome) in manifest.tasks.iter().zip(&outcomes) {
        let line = shown(&task.command_line(&output, false));
        match outcome {
            Outcome::Done => {
                ran += 1;
                if !quiet {
                    println!("ok       mmtrack {line}");
                }
            }
            Outcome::Skipped => {
                skipped += 1;
                if !quiet {
                    println!("skipped  mmtrack {line} (complete)");
                }
            }
            Outcome::Failed(e) => {
                failed += 1;
                eprintln!("failed  mmtrack {line}: {}", crate::one_line(e));
            }
            Outcome::NotRun(need) => {
                failed += 1;
                let need = manifest.tasks.get(*need).map_or_else(|| "a task".to_string(), Task::label);
                eprintln!("not run mmtrack {line}: it needs {need}, which did not finish");
            }
        }
    }
    if !quiet {
        let resumed =
            if args.skip_existing { format!(" ({ran} ran, {skipped} skipped as complete)") } else { String::new() };
        println!("{} of {} tasks done{resumed}; tables under {output}", ran + skipped, manifest.tasks.len());
    }
    Ok(if failed == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// Before any task runs: every task's words parse (a typo in a late level was found after the others ran),
/// and no two tasks write the same output (the same `-o`, or the same pipeline on the same recordings into
/// the same run: with `--force` the one that finished last was kept).
fn check_tasks(manifest: &Manifest, output: &str, file: &str) -> anyhow::Result<()> {
    use clap::CommandFactory;
    let cli = crate::Cli::command();
    let mut writers: std::collections::BTreeMap<Vec<String>, &Task> = std::collections::BTreeMap::new();
    for task in &manifest.tasks {
        let words = task.command_line(output, false);
        let argv = std::iter::once("mmtrack").chain(words.iter().map(String::as_str));
        let matches = cli.clone().try_get_matches_from(argv).map_err(|e| {
            use clap::error::ErrorKind::{DisplayHelp, DisplayHelpOnMissingArgumentOrSubcommand, DisplayVersion};
            let message = match e.kind() {
                DisplayHelp | DisplayVersion => "--help and --version print text; a task runs a command".to_string(),
                DisplayHelpOnMissingArgumentOrSubcommand => "names no subcommand (e.g. odometry)".to_string(),
                _ => e.to_string().lines().next().unwrap_or("").trim().to_string(),
            };
            anyhow::anyhow!("{file}: {}: key `args`: {message}", task.label())
        })?;
        let (mut command, mut at, mut key) = (&cli, &matches, Vec::new());
        while let Some((name, sub)) = at.subcommand() {
            key.push(name.to_string());
            command = command.find_subcommand(name).context("a parsed subcommand")?;
            at = sub;
        }
        let path = |p: &std::ffi::OsStr| manifest::path_key(Path::new(p));
        if task.step == manifest::Step::Process {
            let raw = |id: &str| at.try_get_raw(id).ok().flatten().into_iter().flatten();
            // `--sequence` names the partitions instead of the recordings' ids.
            match raw("sequence").next() {
                Some(sequence) => key.push(format!("sequence={}", sequence.to_string_lossy())),
                None => command.get_positionals().for_each(|a| key.extend(raw(a.get_id().as_str()).map(path))),
            }
            key.extend(raw("run_id").map(|v| format!("run={}", v.to_string_lossy())));
        } else {
            key.extend(task.own_output(output).map(|o| path(o.as_ref())));
        }
        let (same, own) = if task.step == manifest::Step::Process {
            ("pipeline, recordings and run", "--run-id")
        } else {
            ("-o", "-o")
        };
        if let Some(first) = writers.insert(key, task) {
            bail!(
                "{file}: {}: writes what {} writes (the same {same}); give each its own {own}",
                task.label(),
                first.label()
            );
        }
    }
    Ok(())
}

/// A command line as a shell would take it.
fn shown(line: &[String]) -> String {
    line.iter().map(|w| manifest::shell_word(w)).collect::<Vec<_>>().join(" ")
}

/// With `--task`: every task `task` needs has a `done` record.
fn check_needs_done(manifest: &Manifest, task: &Task, output: &str, file: &str) -> anyhow::Result<()> {
    for &n in &task.needs {
        let need = &manifest.tasks[n];
        let record = marker::read(Path::new(output), &need.command_line(output, false))?;
        if !record.is_some_and(|r| r.state == State::Done) {
            bail!(
                "{file}: {}: needs {}, which has not finished (no done record under {output}/{}); run the levels \
                 of --print-levels in order",
                task.label(),
                need.label(),
                marker::DIR
            );
        }
    }
    Ok(())
}

/// Runs one task with its completion record ([`marker`]); `Ok(false)` when
/// `--skip-existing` skipped it: complete, and no task it needs finished
/// after it (a need redone since means its inputs changed: it is redone).
fn run_one(manifest: &Manifest, task: &Task, output: &str, args: &ManifestArgs) -> anyhow::Result<bool> {
    let tables = Path::new(output);
    let key = task.command_line(output, false);
    let previous = marker::read(tables, &key)?;
    let previous_written = marker::written_at(tables, &key);
    let mut force = args.force;
    if args.skip_existing {
        match marker::resume(previous.as_ref()) {
            Resume::Skip => {
                let own = marker::written_at(tables, &key);
                let stale = task
                    .needs
                    .iter()
                    .any(|&n| marker::written_at(tables, &manifest.tasks[n].command_line(output, false)) > own);
                if !stale {
                    return Ok(false);
                }
                force = true;
            }
            Resume::Redo => force = true,
            Resume::Run => {}
        }
    }
    marker::write(tables, &Record { command: key.clone(), state: State::Started, outputs: Vec::new() })?;
    match run_words(task, &task.command_line(output, force), output) {
        Ok(outputs) => {
            let record = Record { command: key, state: State::Done, outputs: marker::outputs_of(&outputs) };
            marker::write(tables, &record)?;
            Ok(true)
        }
        Err(e) => {
            // A failed task removed its own partial outputs: what was there
            // before is still there, and so is its record.
            let _ = match &previous {
                Some(record) => marker::restore(tables, record, previous_written),
                None => marker::remove(tables, &key),
            };
            Err(e)
        }
    }
}

/// Runs one task's words (after `mmtrack`) quietly; returns what it wrote:
/// a process task's table files, an ingest or analyze task's `-o`.
fn run_words(task: &Task, words: &[String], output: &str) -> anyhow::Result<Vec<PathBuf>> {
    let words: Vec<String> = words.iter().filter(|w| *w != "--quiet" && *w != "-q").cloned().collect();
    let written = crate::run_words(&words, &["ingest", "process", "analyze"])?;
    Ok(written.unwrap_or_else(|| task.own_output(output).into_iter().map(PathBuf::from).collect()))
}

/// `--from`: writes the manifest of the sequences under `root`.
fn write_from_dataset(args: &ManifestArgs, root: &Path, layout: LayoutArg, quiet: bool) -> anyhow::Result<()> {
    let layout = match layout {
        LayoutArg::Oxford => Layout::Oxford,
        LayoutArg::Boreas => Layout::Boreas,
        LayoutArg::Mulran => Layout::Mulran,
    };
    let found = from_dataset::find_sequences(root, layout)?;
    let text = from_dataset::manifest_text(layout, &found.sequences, &args.recordings, &args.preset);
    let target = &args.manifest;
    let overwrite = if args.force { Overwrite::Replace } else { Overwrite::Refuse };
    let context = || format!("{}: cannot write the manifest", target.display());
    mmtrack_io::atomic::write_file(target, text.as_bytes(), overwrite).with_context(context)?;
    if !quiet {
        println!(
            "wrote {}: {} {} sequence(s), {} tasks (ingest, then odometry)",
            target.display(),
            found.sequences.len(),
            layout.name(),
            2 * found.sequences.len()
        );
        for dir in &found.skipped {
            println!("  skipped {} (not a {} sequence folder)", dir.display(), layout.name());
        }
    }
    Ok(())
}
