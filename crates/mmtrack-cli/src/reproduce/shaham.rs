//! `mmtrack reproduce shaham`: the arguments of
//! [`mmtrack_reproduce::shaham::run`] (valid beam tracking on the overpass
//! link, Shaham et al. 2020).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::{RunOptions, shaham};

use super::outcome::{finish, tier};
use crate::progress::IndicatifProgress;
use crate::threads::ThreadsArg;

#[derive(Args)]
pub struct ShahamArgs {
    /// Output directory (tables/, three SVG figures, reproduce.md).
    #[arg(short, long, default_value = "out/reproduce/shaham")]
    output: PathBuf,
    /// Replace a previous run's output directory.
    #[arg(long)]
    force: bool,
    /// Experiment file (TOML; default: the embedded data/reproduce/shaham.toml).
    #[arg(long, value_name = "EXPERIMENT.toml")]
    experiment: Option<PathBuf>,
    /// Monte Carlo runs per scenario point (default: the experiment's, 3000).
    #[arg(long)]
    runs: Option<u64>,
    /// The CI version: the experiment's quick_runs (200) runs per point.
    #[arg(long)]
    quick: bool,
    /// Replace the block `<!-- reproduce-shaham:begin -->` ... `end` in this
    /// file with the summary (checked before the run).
    #[arg(long, value_name = "README.md")]
    readme: Option<PathBuf>,
    #[command(flatten)]
    threads: ThreadsArg,
}

pub fn run(args: &ShahamArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    shaham::check_start(&args.output, args.force, args.readme.as_deref())?;
    let config = shaham::Config::load(args.experiment.as_deref())?;
    let options = RunOptions {
        tier: tier(args.quick),
        runs: args.runs,
        output_dir: args.output.clone(),
        readme: args.readme.clone(),
    };
    let progress = IndicatifProgress::new(quiet);
    let outcome = args.threads.install(|| shaham::run(&config, &options, &progress))??;
    finish(&outcome, args.readme.as_deref(), &args.output, quiet)
}
