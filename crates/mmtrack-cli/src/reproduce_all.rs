//! `mmtrack reproduce --all [--smoke]`: the arguments of
//! [`mmtrack_reproduce::all::run_all`] (every paper experiment, each metric
//! checked against `data/reproduce/<experiment>.expected.toml`), its
//! printing and exit code (1 when a metric left its expected range).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
// The experiments still inside the CLI (odometry, spebt) write their
// metrics with these.
// TODO(issue 24): drop the re-export once they move to mmtrack-reproduce.
use mmtrack_reproduce::Tier;
use mmtrack_reproduce::all::{AllOptions, PendingExperiments, run_all};
pub use mmtrack_reproduce::model::{METRICS_FILE, Metric, write_metrics};

use crate::progress::IndicatifProgress;

/// Options of `reproduce --all`.
#[derive(Args, Debug, Clone)]
pub struct AllArgs {
    /// Run every experiment (odometry, mpc-artificial, shaham, spebt, zoechmann, kim) and check each metric against
    /// data/reproduce/<experiment>.expected.toml; exit 1 on a miss.
    #[arg(long)]
    pub all: bool,
    /// With --all: the CI versions (each experiment's --quick) against their smoke expectations.
    #[arg(long, requires = "all")]
    pub smoke: bool,
    /// With --all: output directory (one subdirectory per experiment, summary.md).
    #[arg(short, long, value_name = "DIR", default_value = "out/reproduce/all", requires = "all")]
    pub output: PathBuf,
    /// With --all (full runs only): rewrite the README blocks of the experiments and the
    /// `reproduce-all` table in this file.
    #[arg(long, value_name = "README.md", requires = "all", conflicts_with = "smoke")]
    pub readme: Option<PathBuf>,
}

/// `reproduce --all`; `pending` runs the experiments still in the CLI.
pub fn run(args: &AllArgs, quiet: bool, pending: &dyn PendingExperiments) -> anyhow::Result<ExitCode> {
    let options = AllOptions {
        tier: if args.smoke { Tier::Smoke } else { Tier::Full },
        output_dir: args.output.clone(),
        readme: args.readme.clone(),
    };
    let outcome = run_all(&options, pending, &IndicatifProgress::new(quiet))?;
    if !quiet {
        print!("{}", outcome.summary);
        println!("\noutputs: {}", args.output.display());
    }
    Ok(if outcome.misses() == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
