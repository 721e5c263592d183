//! `mmtrack reproduce zoechmann`: the arguments of
//! [`mmtrack_reproduce::zoechmann::run`] (geometric Doppler-bearing
//! tracking, Zoechmann et al. 2019).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::{RunOptions, zoechmann};

use super::outcome::{finish, tier};
use crate::progress::IndicatifProgress;
use crate::threads::ThreadsArg;

#[derive(Args)]
pub struct ZoechmannArgs {
    /// Output directory (tables/, one SVG figure per manoeuvre, nlos.svg, reproduce.md).
    #[arg(short, long, default_value = "out/reproduce/zoechmann")]
    output: PathBuf,
    /// Replace a previous run's output directory.
    #[arg(long)]
    force: bool,
    /// Experiment file (TOML; default: the embedded data/reproduce/zoechmann.toml).
    #[arg(long, value_name = "EXPERIMENT.toml")]
    experiment: Option<PathBuf>,
    /// Monte Carlo runs per manoeuvre (default: the experiment's, 100000).
    #[arg(long)]
    runs: Option<u64>,
    /// The CI version: the experiment's quick_runs (2000) runs per manoeuvre.
    #[arg(long)]
    quick: bool,
    /// Replace the block `<!-- reproduce-zoechmann:begin -->` ... `end` in
    /// this file with the summary (checked before the run).
    #[arg(long, value_name = "README.md")]
    readme: Option<PathBuf>,
    #[command(flatten)]
    threads: ThreadsArg,
}

pub fn run(args: &ZoechmannArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    zoechmann::check_start(&args.output, args.force, args.readme.as_deref())?;
    let config = zoechmann::Config::load(args.experiment.as_deref())?;
    let options = RunOptions {
        tier: tier(args.quick),
        runs: args.runs,
        output_dir: args.output.clone(),
        readme: args.readme.clone(),
    };
    let progress = IndicatifProgress::new(quiet);
    let outcome = args.threads.install(|| zoechmann::run(&config, &options, &progress))??;
    finish(&outcome, args.readme.as_deref(), &args.output, quiet)
}
