//! `mmtrack reproduce zoechmann`: the arguments of
//! [`mmtrack_reproduce::zoechmann::run`] (geometric Doppler-bearing
//! tracking, Zoechmann et al. 2019).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::request::{ExperimentRequest, run_experiment};
use mmtrack_reproduce::zoechmann;

use super::args::{ExperimentArgs, ExperimentTexts, MonteCarloArgs, MonteCarloTexts};
use super::outcome::finish;
use crate::progress::IndicatifProgress;

pub struct Zoechmann;

impl ExperimentTexts for Zoechmann {
    const OUTPUT_DIR: &'static str = "out/reproduce/zoechmann";
    const OUTPUT_HELP: &'static str =
        "Output directory (tables/, one SVG figure per manoeuvre, nlos.svg, reproduce.md)";
    const QUICK_HELP: &'static str = "The CI version: the experiment's quick_runs (2000) runs per manoeuvre";
}

impl MonteCarloTexts for Zoechmann {
    const RUNS_HELP: &'static str = "Monte Carlo runs per manoeuvre (default: the experiment's, 100000)";
    const README_HELP: &'static str = "Replace the block `<!-- reproduce-zoechmann:begin -->` ... `end` in this \
                                       file (docs/results/zoechmann.md) with the summary (checked before the run)";
}

#[derive(Args)]
pub struct ZoechmannArgs {
    #[command(flatten)]
    common: ExperimentArgs<Zoechmann>,
    #[command(flatten)]
    monte_carlo: MonteCarloArgs<Zoechmann>,
    /// Experiment file (TOML; default: the embedded data/reproduce/zoechmann.toml).
    #[arg(long, value_name = "EXPERIMENT.toml")]
    experiment: Option<PathBuf>,
}

pub fn run(args: &ZoechmannArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let request = ExperimentRequest {
        runs: args.monte_carlo.runs,
        readme: args.monte_carlo.readme.clone(),
        experiment_file: args.experiment.clone(),
        ..args.common.request()
    };
    let progress = IndicatifProgress::new(quiet);
    let outcome = args.common.threads.install(|| run_experiment(zoechmann::NAME, &request, &progress))??;
    Ok(finish(&outcome, &args.common.output, quiet))
}
