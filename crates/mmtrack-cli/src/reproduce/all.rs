//! `mmtrack reproduce --all [--smoke]`: the arguments of
//! [`mmtrack_reproduce::all::run_all`] (every paper experiment: its claims
//! judged against the paper, each metric checked against
//! `data/reproduce/<experiment>.expected.toml`), its printing and exit code
//! (1 when a metric left its expected range).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::all::{AllOptions, run_all};

use crate::progress::IndicatifProgress;

/// Options of `reproduce --all`.
#[derive(Args, Debug, Clone)]
pub struct AllArgs {
    /// Run every experiment (odometry, mpc-artificial, mpc-convoy, shaham, spebt, zoechmann, kim): print "N of M paper claims
    /// met" with every claim's rule and verdict, then check each metric against
    /// data/reproduce/<experiment>.expected.toml (our earlier runs); exit 1 when a metric moved (a regression), not
    /// on a missed paper claim (which the table shows).
    #[arg(long)]
    pub all: bool,
    /// With --all: the CI versions (each experiment's --quick) against their smoke expectations.
    #[arg(long, requires = "all")]
    pub smoke: bool,
    /// With --all: output directory (one subdirectory per experiment, summary.md).
    #[arg(short, long, value_name = "DIR", default_value = "out/reproduce/all", requires = "all")]
    pub output: PathBuf,
    /// With --all (full runs only): rewrite the `reproduce-all` table in this file (docs/results/README.md) and
    /// each experiment's block in the Markdown file beside it that holds it (docs/results/<experiment>.md).
    #[arg(long, value_name = "FILE.md", requires = "all", conflicts_with = "smoke")]
    pub readme: Option<PathBuf>,
}

/// `reproduce --all`.
pub fn run(args: &AllArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let options = AllOptions {
        tier: super::args::tier(args.smoke),
        output_dir: args.output.clone(),
        readme: args.readme.clone(),
    };
    let outcome = run_all(&options, &IndicatifProgress::new(quiet))?;
    if !quiet {
        print!("{}", outcome.summary);
        println!("\noutputs: {}", args.output.display());
    }
    Ok(if outcome.misses() == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
