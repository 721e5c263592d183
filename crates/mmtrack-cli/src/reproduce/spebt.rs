//! `mmtrack reproduce spebt`: the arguments of
//! [`mmtrack_reproduce::spebt::run`] (SPEBT beam tracking driven by pose
//! estimates, Liu et al. 2024).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::common::DEFAULT_TRAJECTORY;
use mmtrack_reproduce::request::{ExperimentRequest, run_experiment};
use mmtrack_reproduce::spebt;

use super::args::{ExperimentArgs, ExperimentTexts, MonteCarloArgs, MonteCarloTexts};
use super::outcome::finish;
use crate::ingest::PoseFormat;
use crate::progress::IndicatifProgress;

pub struct Spebt;

impl ExperimentTexts for Spebt {
    const OUTPUT_DIR: &'static str = "out/reproduce/spebt";
    const OUTPUT_HELP: &'static str = "Output directory (tables/, fig5_*.svg, reproduce.md)";
    const QUICK_HELP: &'static str = "The CI version: 8 runs with the pose-error model, 4 with radar odometry on \
                                      the first 480 slots (two minutes of driving, the first 70 s standing)";
}

impl MonteCarloTexts for Spebt {
    const RUNS_HELP: &'static str = "Monte Carlo runs of each experiment (default: the experiment file's, 2000 with \
                                     the pose-error model and 100 with radar odometry, whose pose estimates are the \
                                     same in every run)";
    const README_HELP: &'static str = "Replace the block `<!-- reproduce-spebt:begin -->` ... `end` in this file \
                                       (docs/results/spebt.md) with the summary (checked before the run)";
}

#[derive(Args)]
pub struct SpebtArgs {
    #[command(flatten)]
    common: ExperimentArgs<Spebt>,
    #[command(flatten)]
    monte_carlo: MonteCarloArgs<Spebt>,
    /// Experiment file (TOML; default: the embedded data/reproduce/spebt.toml).
    #[arg(long, value_name = "EXPERIMENT.toml")]
    experiment: Option<PathBuf>,
    /// Run only experiment (a), the pose-error model (no radar simulation).
    #[arg(long)]
    skip_odometry: bool,
    /// Trajectory to drive along (its first `slots` poses, one slot each). The default is
    /// the Oxford full-sequence ground truth (gt/radar_odometry.csv) among the real-data
    /// samples beside the repository, a path relative to the current directory: run from
    /// the repository root, or pass --trajectory.
    #[arg(long, value_name = "FILE", default_value = DEFAULT_TRAJECTORY)]
    trajectory: PathBuf,
    /// Format of --trajectory.
    #[arg(long, value_enum, default_value_t = PoseFormat::Oxford)]
    trajectory_format: PoseFormat,
}

pub fn run(args: &SpebtArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let request = ExperimentRequest {
        runs: args.monte_carlo.runs,
        readme: args.monte_carlo.readme.clone(),
        experiment_file: args.experiment.clone(),
        trajectory: Some(args.trajectory.clone()),
        trajectory_format: Some(args.trajectory_format.trajectory_format().name().to_string()),
        skip_odometry: args.skip_odometry,
        ..args.common.request()
    };
    let progress = IndicatifProgress::new(quiet);
    let outcome = args.common.threads.install(|| run_experiment(spebt::NAME, &request, &progress))??;
    Ok(finish(&outcome, &args.common.output, quiet))
}
