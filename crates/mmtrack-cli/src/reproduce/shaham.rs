//! `mmtrack reproduce shaham`: the arguments of
//! [`mmtrack_reproduce::shaham::run`] (valid beam tracking on the overpass
//! link, Shaham et al. 2020).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
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
    let options = args.common.run_options(args.monte_carlo.runs, args.monte_carlo.readme.as_deref());
    shaham::check_start(&options.output_dir, args.common.force, options.readme.as_deref())?;
    let config = shaham::Config::load(args.experiment.as_deref())?;
    let progress = IndicatifProgress::new(quiet);
    let outcome = args.common.threads.install(|| shaham::run(&config, &options, &progress))??;
    finish(&outcome, &options, quiet)
}
