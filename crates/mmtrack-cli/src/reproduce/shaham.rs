//! `mmtrack reproduce shaham`: the arguments of
//! [`mmtrack_reproduce::shaham::run`] (valid beam tracking on the overpass
//! link, Shaham et al. 2020).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::request::{ExperimentRequest, run_experiment};
use mmtrack_reproduce::shaham;

use super::args::{ExperimentArgs, ExperimentTexts, MonteCarloArgs, MonteCarloTexts};
use super::outcome::finish;
use crate::progress::IndicatifProgress;

pub struct Shaham;

impl ExperimentTexts for Shaham {
    const OUTPUT_DIR: &'static str = "out/reproduce/shaham";
    const OUTPUT_HELP: &'static str = "Output directory (tables/, three SVG figures, reproduce.md)";
    const QUICK_HELP: &'static str = "The CI version: the experiment's quick_runs (200) runs per point";
}

impl MonteCarloTexts for Shaham {
    const RUNS_HELP: &'static str = "Monte Carlo runs per scenario point (default: the experiment's, 3000)";
    const README_HELP: &'static str = "Replace the block `<!-- reproduce-shaham:begin -->` ... `end` in this file \
                                       (docs/results/shaham.md) with the summary (checked before the run)";
}

#[derive(Args)]
pub struct ShahamArgs {
    #[command(flatten)]
    common: ExperimentArgs<Shaham>,
    #[command(flatten)]
    monte_carlo: MonteCarloArgs<Shaham>,
    /// Experiment file (TOML; default: the embedded data/reproduce/shaham.toml).
    #[arg(long, value_name = "EXPERIMENT.toml")]
    experiment: Option<PathBuf>,
}

pub fn run(args: &ShahamArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let request = ExperimentRequest {
        runs: args.monte_carlo.runs,
        readme: args.monte_carlo.readme.clone(),
        experiment_file: args.experiment.clone(),
        ..args.common.request()
    };
    let progress = IndicatifProgress::new(quiet);
    let outcome = args.common.threads.install(|| run_experiment(shaham::NAME, &request, &progress))??;
    Ok(finish(&outcome, &args.common.output, quiet))
}
