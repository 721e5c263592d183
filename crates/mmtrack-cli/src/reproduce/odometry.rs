//! `mmtrack reproduce odometry`: the arguments of
//! [`mmtrack_reproduce::odometry::run`] (radar odometry drift on a
//! simulated drive along a real trajectory, Liu et al. 2024).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::common::DEFAULT_TRAJECTORY;
use mmtrack_reproduce::odometry;
use mmtrack_reproduce::request::{ExperimentRequest, run_experiment};

use super::args::{ExperimentArgs, ExperimentTexts};
use super::outcome::finish;
use crate::ingest::PoseFormat;
use crate::progress::IndicatifProgress;

pub struct Odometry;

impl ExperimentTexts for Odometry {
    const OUTPUT_DIR: &'static str = "out/reproduce/odometry";
    const OUTPUT_HELP: &'static str = "Output directory (tables/, analysis/, reproduce.md)";
    const QUICK_HELP: &'static str = "The CI version: a 300 m drive, KITTI segments of 100 and 200 m";
}

#[derive(Args)]
pub struct OdometryArgs {
    #[command(flatten)]
    common: ExperimentArgs<Odometry>,
    /// Drive scenario (TOML; default: the embedded data/reproduce/odometry-drive.toml).
    #[arg(long, value_name = "SCENARIO.toml")]
    scenario: Option<PathBuf>,
    /// Trajectory to drive along. The default is the Oxford full-sequence ground truth
    /// (gt/radar_odometry.csv) among the real-data samples beside the repository, a path
    /// relative to the current directory: run from the repository root, or pass --trajectory.
    #[arg(long, value_name = "FILE", default_value = DEFAULT_TRAJECTORY)]
    trajectory: PathBuf,
    /// Format of --trajectory.
    #[arg(long, value_enum, default_value_t = PoseFormat::Oxford)]
    trajectory_format: PoseFormat,
    /// Length of the drive, metres (default: the scenario's, 2000 m).
    #[arg(long, value_name = "METRES")]
    max_distance_m: Option<f64>,
}

pub fn run(args: &OdometryArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let request = ExperimentRequest {
        scenario: args.scenario.clone(),
        trajectory: Some(args.trajectory.clone()),
        trajectory_format: Some(args.trajectory_format.trajectory_format().name().to_string()),
        max_distance_m: args.max_distance_m,
        ..args.common.request()
    };
    let progress = IndicatifProgress::new(quiet);
    let outcome = args.common.threads.install(|| run_experiment(odometry::NAME, &request, &progress))??;
    Ok(finish(&outcome, &args.common.output, quiet))
}
