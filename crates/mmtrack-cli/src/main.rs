//! # mmtrack
//!
//! The command-line tool: the only crate that wires the others together and the
//! only one that talks to the terminal (progress bars, messages, exit codes).
//!
//! Exit codes: 0 success; 1 error (bad input, I/O; one line on stderr naming
//! the file and the problem); 2 usage error; 3 the requested feature is not
//! built yet (the message names the issue that will build it); 130 / 143
//! interrupted by SIGINT / SIGTERM (the partial outputs removed first).

mod analyze;
mod bench;
mod check;
mod demo;
mod export;
mod ingest;
mod inspect;
mod manifest;
mod output_args;
mod process;
mod process_beam;
mod progress;
mod reproduce;
mod simulate;
mod simulate_sounder;
mod slam;
mod threads;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use mmtrack_core::error::printable;

#[derive(Parser)]
#[command(
    name = "mmtrack",
    version,
    about = "Vehicular mmWave sensing and links: ingest recordings, run the published trackers, analyze the results.",
    long_about = "mmtrack turns raw recordings (Navtech radar scans, channel-sounder impulse responses, GNSS/INS logs, \
ROS 2 bags) into canonical MCAP recordings, runs published algorithms on them (radar odometry, multipath tracking, \
beam tracking, mmWave SLAM) and writes Parquet tables and plots.\n\n\
Data flow: raw files --ingest--> recording.mcap --process--> tables (Parquet) --analyze--> metrics + plots.\n\n\
Exit codes: 0 success, 1 error (one line naming the file and the problem) or a missed paper target (reproduce, bench --check), 2 usage error, \
130/143/129 interrupted by SIGINT/SIGTERM/SIGHUP (partial outputs are removed; a run killed outright leaves a hidden \
.<name>.<pid>.<random>.partial file that the next run writing the same output removes).",
    after_help = "Start with `mmtrack demo`, then `mmtrack inspect out/demo/recording.mcap`."
)]
struct Cli {
    /// Print nothing but errors (no progress bars, no summaries).
    #[arg(long, short, global = true)]
    quiet: bool,

    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Turn a raw dataset into a canonical MCAP recording (one per sequence).
    Ingest(ingest::IngestArgs),
    /// Produce a recording (or a dataset-layout folder) from a scenario file, with ground truth.
    Simulate(simulate::SimulateArgs),
    /// Run a pipeline (odometry, mpc, beam, slam) on a recording and write Parquet tables.
    Process(process::ProcessArgs),
    /// Compute metrics, result tables and plots from Parquet tables.
    Analyze(analyze::AnalyzeArgs),
    /// Write trajectory tables as TUM, KITTI or Boreas text (evo, the KITTI devkit, pyboreas), or as MCAP: a copy of
    /// the recording with the estimate added (Foxglove).
    Export(export::ExportArgs),
    /// Re-run a paper's experiment and compare with its published numbers.
    Reproduce(reproduce::ReproduceArgs),
    /// Run a dataset regression suite: its steps on your fixtures, its metrics against their expectations.
    Check(check::CheckArgs),
    /// Show what a recording (.mcap, including ROS 2 bags) or a table directory contains.
    Inspect(inspect::InspectArgs),
    /// Run the whole chain on the embedded demo data and print where the outputs are.
    Demo(demo::DemoArgs),
    /// Write or check the schema documents (`schemas/`) generated from the code.
    ///
    /// Without options, checks `./schemas` (as `--check schemas`, from the project's root).
    Schemas {
        /// Directory to write the documents to.
        #[arg(long, value_name = "DIR", conflicts_with = "check")]
        write: Option<PathBuf>,
        /// Directory whose documents must match the code (exit 1 when stale).
        #[arg(long, value_name = "DIR")]
        check: Option<PathBuf>,
    },
    /// Measure throughput against a same-run baseline (no wall-clock assertions).
    Bench(bench::BenchArgs),
}

fn schemas(write: Option<PathBuf>, check: Option<PathBuf>, quiet: bool) -> anyhow::Result<ExitCode> {
    let documents = mmtrack_io::schema_docs::documents();
    if let Some(dir) = write {
        for (relative, contents) in &documents {
            let path = dir.join(relative);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent)?;
            }
            std::fs::write(&path, contents)?;
        }
        if !quiet {
            println!("wrote {} schema documents to {}", documents.len(), dir.display());
        }
        return Ok(ExitCode::SUCCESS);
    }
    let given = check.is_some();
    let dir = check.unwrap_or_else(|| PathBuf::from("schemas"));
    if !dir.is_dir() {
        if given {
            anyhow::bail!(
                "{}: no such folder to check; `mmtrack schemas --write {}` writes the documents there",
                dir.display(),
                dir.display()
            );
        }
        return Err(usage(
            "schemas: no such folder here (without options `mmtrack schemas` checks ./schemas, from the project's \
             root); pass --write DIR to write the documents or --check DIR to check them",
        ));
    }
    let stale: Vec<&String> = documents
        .iter()
        .filter(|(relative, contents)| std::fs::read_to_string(dir.join(relative)).ok().as_deref() != Some(contents))
        .map(|(relative, _)| relative)
        .collect();
    if stale.is_empty() {
        if !quiet {
            println!("{}: all {} schema documents match the code", dir.display(), documents.len());
        }
        Ok(ExitCode::SUCCESS)
    } else {
        anyhow::bail!(
            "{}: stale schema documents: {stale:?}; run `mmtrack schemas --write {}`",
            dir.display(),
            dir.display()
        )
    }
}

/// A flag value found wrong after parsing, as a usage error (exit 2, see
/// [`mmtrack_core::error::UsageError`]).
fn usage(message: impl Into<String>) -> anyhow::Error {
    mmtrack_core::error::UsageError::new(message).into()
}

/// Exit 2 for a usage error anywhere in `error`'s chain, 1 for any other.
fn exit_code_of(error: &anyhow::Error) -> ExitCode {
    if error.chain().any(|cause| cause.is::<mmtrack_core::error::UsageError>()) {
        ExitCode::from(2)
    } else {
        ExitCode::FAILURE
    }
}

/// `path` as a command-line word.
///
/// # Errors
/// A path that is not UTF-8, naming it.
fn path_word(path: &std::path::Path) -> anyhow::Result<String> {
    path.to_str().map(str::to_string).ok_or_else(|| anyhow::anyhow!("{}: expected a UTF-8 path", path.display()))
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    let quiet = cli.quiet;
    match cli.command {
        Command::Ingest(args) => ingest::run(args, quiet),
        Command::Simulate(args) => simulate::run(args, quiet),
        Command::Process(args) => process::run(&args, quiet),
        Command::Analyze(args) => analyze::run(&args, quiet),
        Command::Export(args) => export::run(&args, quiet),
        Command::Reproduce(args) => reproduce::run(&args, quiet),
        Command::Check(args) => check::run(&args, quiet),
        Command::Inspect(args) => inspect::run(&args, quiet),
        Command::Demo(args) => demo::run(&args, quiet),
        Command::Schemas { write, check } => schemas(write, check, quiet),
        Command::Bench(args) => bench::run(&args, quiet),
    }
}

/// Runs the words (after `mmtrack`) of a user's command line from a file (a
/// manifest task, a suite step), quietly, on the current pool: the one
/// interface those files share with the shell. `allowed` names the
/// commands the file may run. For a process command, the table files it
/// wrote.
///
/// # Errors
/// A usage error (one line), a command not in `allowed`, or the command's
/// own error.
fn run_words(words: &[String], allowed: &[&str]) -> anyhow::Result<Option<Vec<PathBuf>>> {
    let command = words.first().map_or("", String::as_str);
    if !allowed.contains(&command) {
        anyhow::bail!("`{command}`: runs one of {}", allowed.join(", "));
    }
    let argv = std::iter::once("mmtrack").chain(words.iter().map(String::as_str)).chain(["--quiet"]);
    let cli = Cli::try_parse_from(argv).map_err(|e| anyhow::anyhow!("{}", e.to_string().trim()))?;
    if let Command::Process(args) = &cli.command {
        return process::run_pipeline(args, true).map(Some);
    }
    let code = run(cli)?;
    if code != ExitCode::SUCCESS {
        anyhow::bail!("exited with {code:?}");
    }
    Ok(None)
}

/// Ends the process quietly when stdout is a pipe whose reader has gone
/// (`mmtrack inspect x.mcap | head -1`): Rust ignores SIGPIPE, so `println!`
/// panics on the EPIPE error; every other panic keeps the default report.
fn exit_quietly_on_a_closed_pipe() {
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload.downcast_ref::<String>().map(String::as_str).or(payload.downcast_ref::<&str>().copied());
        if message.is_some_and(|m| m.contains("failed printing to stdout") && m.contains("Broken pipe")) {
            std::process::exit(0);
        }
        default_hook(info);
    }));
}

/// The error and its causes as one line ([`mmtrack_core::error::one_line`]).
fn one_line(error: &anyhow::Error) -> String {
    mmtrack_core::error::one_line(error.chain())
}

/// On SIGINT, SIGTERM or SIGHUP (a closed terminal): removes the partial outputs this run is writing
/// (`mmtrack_io::atomic`), says so on stderr (unless `quiet`; failures
/// always) and exits with 128 + the signal (130, 143, 129), as a shell reports a
/// process the signal killed. Partials of runs killed outright (SIGKILL, an
/// aborted allocation) are removed by the next run that writes the same
/// output.
fn remove_partial_outputs_on_interrupt(quiet: bool) {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    // Without the handler (it could not be installed) the signals keep
    // their default action; the next run still removes the partials.
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else { return };
    std::thread::spawn(move || {
        let Some(signal) = signals.forever().next() else { return };
        let name = match signal {
            SIGINT => "SIGINT",
            SIGHUP => "SIGHUP",
            _ => "SIGTERM",
        };
        // Holds the registry until the exit: no new partial starts meanwhile.
        let cleanup = mmtrack_io::atomic::remove_partial_outputs();
        for (path, error) in &cleanup.failed {
            eprintln!(
                "error: {}: cannot remove this partial output: {error}",
                printable(path.as_os_str().as_encoded_bytes())
            );
        }
        if !quiet && cleanup.removed > 0 {
            let plural = if cleanup.removed == 1 { "" } else { "s" };
            eprintln!("\ninterrupted ({name}): removed {} partial output{plural}", cleanup.removed);
        }
        std::process::exit(128 + signal);
    });
}

fn main() -> ExitCode {
    exit_quietly_on_a_closed_pipe();
    let cli = Cli::parse();
    remove_partial_outputs_on_interrupt(cli.quiet);
    // Every command runs on a thread of a rayon pool of the default size
    // (RAYON_NUM_THREADS, else one per core); `--threads N` gives a command
    // a pool of its own.
    let result = threads::ThreadsArg::default().install(|| run(cli)).and_then(|result| result);
    // An interruption being handled exits with its own code once its clean-up is done.
    mmtrack_io::atomic::wait_for_interruption();
    match result {
        Ok(code) => code,
        Err(error) => {
            eprintln!("error: {}", one_line(&error));
            exit_code_of(&error)
        }
    }
}
