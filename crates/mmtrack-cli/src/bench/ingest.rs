//! `mmtrack bench ingest`: the arguments of
//! [`mmtrack_reproduce::bench::ingest`]; the simulated folders come from this
//! binary's `simulate radar` in a child process.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use clap::Args;
use mmtrack_reproduce::bench::ingest::{self, IngestBenchOptions};

use super::output::{Finish, finish};

#[derive(Args)]
pub struct IngestBenchArgs {
    /// Scans in the large folder (400 x 3768 each).
    #[arg(long, default_value_t = 200)]
    scans: usize,
    /// Runs per measurement; the best is reported.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// Exit 1 when a target is missed.
    #[arg(long)]
    check: bool,
    /// Directory for the temporary files (default: the system temp dir).
    #[arg(long)]
    dir: Option<PathBuf>,
    /// Replace the block `<!-- bench-ingest-real:begin -->` (with --from) or `bench-ingest-simulated` in this file
    /// (docs/benchmarks.md).
    #[arg(long, value_name = "FILE.md")]
    readme: Option<PathBuf>,
    /// Build the folders from this Oxford folder's real PNG bytes, repeated under new
    /// stamps (e.g. ../shared/realdata/oxford-radar-tiny); default: simulated scans.
    #[arg(long, value_name = "OXFORD_FOLDER")]
    from: Option<PathBuf>,
}

pub fn run(args: &IngestBenchArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let options =
        IngestBenchOptions { scans: args.scans, repeats: args.repeats, dir: args.dir.clone(), from: args.from.clone() };
    let exe = std::env::current_exe()?;
    let simulate_oxford = |scenario: &Path, folder: &Path| {
        let mut command = Command::new(&exe);
        command
            .args(["simulate", "radar", "--format", "oxford", "--quiet", "--force", "--scenario"])
            .arg(scenario)
            .arg("-o")
            .arg(folder);
        command
    };
    let bench = ingest::run(&options, &simulate_oxford)?;
    finish(&Finish {
        text: &ingest::markdown(&bench),
        print: !quiet,
        readme: args.readme.as_deref().map(|r| (r, ingest::readme_block(&bench))),
        check: args.check,
        target_met: bench.target_met,
    })
}
