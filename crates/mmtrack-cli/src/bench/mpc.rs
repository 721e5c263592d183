//! `mmtrack bench mpc`: the arguments of [`mmtrack_reproduce::bench::mpc`].

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::bench::mpc::{self, MPC_TARGET_SNAPSHOTS, MpcBenchOptions};

use super::output::{Finish, finish};

#[derive(Args)]
pub struct MpcBenchArgs {
    /// Snapshots to process (sets of 6; the last set may be shorter).
    #[arg(long, default_value_t = MPC_TARGET_SNAPSHOTS)]
    snapshots: usize,
    /// Paths per snapshot.
    #[arg(long, default_value_t = 40)]
    mpcs: usize,
    /// Thread counts to measure, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    threads: Vec<usize>,
    /// Exit 1 when the one-thread row misses the target (time, FFT ratio and detections per path; docs/benchmarks.md).
    #[arg(long)]
    check: bool,
    /// Replace the block `<!-- bench-mpc:begin -->` ... `end` in this file (docs/benchmarks.md).
    #[arg(long, value_name = "FILE.md")]
    readme: Option<PathBuf>,
}

pub fn run(args: &MpcBenchArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let options = MpcBenchOptions { snapshots: args.snapshots, mpcs: args.mpcs, threads: args.threads.clone() };
    let bench = mpc::run(&options)?;
    finish(&Finish {
        text: &mpc::markdown(&bench),
        print: !quiet,
        readme: args.readme.as_deref().map(|r| (r, mpc::README_BLOCK)),
        check: args.check,
        target_met: bench.target_met(),
    })
}
