//! `mmtrack reproduce kim`: the arguments of
//! [`mmtrack_reproduce::kim::run`] (5G mmWave vehicular SLAM, Kim et al.
//! 2018).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::kim;
use mmtrack_reproduce::request::{ExperimentRequest, run_experiment};

use super::args::{ExperimentArgs, ExperimentTexts, MonteCarloArgs, MonteCarloTexts};
use super::outcome::finish;
use crate::progress::IndicatifProgress;

pub struct Kim;

impl ExperimentTexts for Kim {
    const OUTPUT_DIR: &'static str = "out/reproduce/kim";
    const OUTPUT_HELP: &'static str = "Output directory (tables/, SVG figures, reproduce.md, metrics.json)";
    const QUICK_HELP: &'static str =
        "The CI version: the experiment's quick_runs runs with quick_particles particles, checked with quick_tolerance";
}

impl MonteCarloTexts for Kim {
    const RUNS_HELP: &'static str = "Monte Carlo runs per row (default: the experiment's, 20)";
    const README_HELP: &'static str = "Replace the block `<!-- reproduce-kim:begin -->` ... `end` in this file \
                                       (docs/results/kim.md) with the summary (checked before the run)";
}

#[derive(Args)]
pub struct KimArgs {
    #[command(flatten)]
    common: ExperimentArgs<Kim>,
    #[command(flatten)]
    monte_carlo: MonteCarloArgs<Kim>,
    /// Experiment file (TOML; default: the embedded data/reproduce/kim.toml).
    #[arg(long, value_name = "EXPERIMENT.toml")]
    experiment: Option<PathBuf>,
    /// UE particles (default: the filter's, 2000).
    #[arg(long)]
    particles: Option<usize>,
}

pub fn run(args: &KimArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let request = ExperimentRequest {
        runs: args.monte_carlo.runs,
        readme: args.monte_carlo.readme.clone(),
        experiment_file: args.experiment.clone(),
        particles: args.particles,
        ..args.common.request()
    };
    let progress = IndicatifProgress::new(quiet);
    let outcome = args.common.threads.install(|| run_experiment(kim::NAME, &request, &progress))??;
    Ok(finish(&outcome, &args.common.output, quiet))
}
