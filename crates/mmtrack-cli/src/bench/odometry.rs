//! `mmtrack bench odometry`: the arguments of
//! [`mmtrack_reproduce::bench::odometry`]; the memory check's child process
//! is this binary's `process odometry`.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use clap::Args;
use mmtrack_reproduce::bench::odometry::{self, OdometryBenchOptions};

use super::output::{Finish, finish};

/// Default `--from`: the Oxford sample beside the repository.
const DEFAULT_FROM: &str = "../shared/realdata/oxford-radar-tiny";

#[derive(Args)]
pub struct OdometryBenchArgs {
    /// Oxford folder whose real scans are used. The default is the Oxford sample among the
    /// real-data samples beside the repository, a path relative to the current directory: run
    /// from the repository root, or pass --from.
    #[arg(long, value_name = "OXFORD_FOLDER", default_value = DEFAULT_FROM)]
    from: PathBuf,
    /// Passes over the sequence per preset (each pass starts a fresh pipeline).
    #[arg(long, default_value_t = 20)]
    passes: usize,
    /// Exit 1 when the target is missed.
    #[arg(long)]
    check: bool,
    /// Scans of the long simulated drive of the memory check (laps of 100 scans; one lap is the short drive).
    #[arg(long, default_value_t = 1200)]
    memory_scans: usize,
    /// Replace the block `<!-- bench-odometry:begin -->` ... `end` in this file (docs/benchmarks.md).
    #[arg(long, value_name = "FILE.md")]
    readme: Option<PathBuf>,
}

pub fn run(args: &OdometryBenchArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    if args.from == Path::new(DEFAULT_FROM) && !args.from.exists() {
        anyhow::bail!(
            "default {DEFAULT_FROM} not found (the Oxford sample among the real-data samples beside the \
             repository; run from the repository root); pass --from PATH"
        );
    }
    let options =
        OdometryBenchOptions { from: args.from.clone(), passes: args.passes, memory_scans: args.memory_scans };
    let exe = std::env::current_exe()?;
    let process_odometry = |recording: &Path, tables: &Path| {
        let mut command = Command::new(&exe);
        command.args(["--quiet", "process", "odometry", "--preset", "cfear", "-o"]).arg(tables).arg(recording);
        command
    };
    let bench = odometry::run(&options, &process_odometry)?;
    finish(&Finish {
        text: &odometry::markdown(&bench),
        print: !quiet,
        readme: args.readme.as_deref().map(|r| (r, odometry::README_BLOCK)),
        check: args.check,
        target_met: bench.target_met(),
    })
}
