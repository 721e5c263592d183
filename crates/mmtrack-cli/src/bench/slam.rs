//! `mmtrack bench slam`: the arguments of [`mmtrack_reproduce::bench::slam`].

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::bench::slam::{self, SlamBenchOptions};

use super::output::{Finish, finish};

#[derive(Args)]
pub struct SlamBenchArgs {
    /// UE particle counts, comma-separated: one pair of rows (one thread, the pool) each; the targets
    /// apply at 2000.
    #[arg(long, value_delimiter = ',', default_values_t = [500, 2000, 8000])]
    particles: Vec<usize>,
    /// Message-passing iterations (tempering stages and EKF relinearisations).
    #[arg(long, default_value_t = 10)]
    iterations: usize,
    /// Epochs of the drive (100: one lap of the paper's road).
    #[arg(long, default_value_t = 100)]
    epochs: usize,
    /// Runs per measurement; the best is reported.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// Worker threads of the measured run (0: one per core).
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Exit 1 when the target is missed.
    #[arg(long)]
    check: bool,
    /// Replace the block `<!-- bench-slam:begin -->` ... `end` in this file (docs/benchmarks.md).
    #[arg(long, value_name = "FILE.md")]
    readme: Option<PathBuf>,
}

pub fn run(args: &SlamBenchArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let options = SlamBenchOptions {
        particles: args.particles.clone(),
        iterations: args.iterations,
        epochs: args.epochs,
        repeats: args.repeats,
        threads: args.threads,
    };
    let bench = slam::run(&options)?;
    finish(&Finish {
        text: &slam::markdown(&bench),
        print: !quiet,
        readme: args.readme.as_deref().map(|r| (r, slam::README_BLOCK)),
        check: args.check,
        target_met: bench.target_met(),
    })
}
