//! `mmtrack bench io`: the arguments of [`mmtrack_reproduce::bench::io`].

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::bench::io::{self, IoBenchOptions};

use super::output::{Finish, finish};

#[derive(Args)]
pub struct IoBenchArgs {
    /// Number of scans (1.5 MB each).
    #[arg(long, default_value_t = 60)]
    scans: usize,
    /// Runs per measurement; the best is reported.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// Exit 1 when a target is missed.
    #[arg(long)]
    check: bool,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Directory for the temporary files (default: the system temp dir).
    #[arg(long)]
    dir: Option<PathBuf>,
    /// Replace the block between `<!-- bench-io:begin -->` and `<!-- bench-io:end -->` in this file
    /// (docs/benchmarks.md).
    #[arg(long, value_name = "FILE.md")]
    readme: Option<PathBuf>,
}

pub fn run(args: &IoBenchArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let options = IoBenchOptions { scans: args.scans, repeats: args.repeats, dir: args.dir.clone() };
    let bench = io::run(&options)?;
    if args.json {
        println!("{}", io::json(&bench));
    }
    finish(&Finish {
        text: &io::markdown(&bench),
        print: !quiet && !args.json,
        readme: args.readme.as_deref().map(|r| (r, io::README_BLOCK)),
        check: args.check,
        target_met: bench.target_met(),
    })
}
