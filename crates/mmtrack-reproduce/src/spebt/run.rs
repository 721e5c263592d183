//! The Monte Carlo of the SPEBT experiment: experiment (a) on the
//! trajectory with the pose-error model, experiment (b) on the simulated
//! drive with our radar odometry ([`super::drive`]).
//!
//! Runs are split into fixed chunks computed on rayon and merged in chunk
//! order ([`monte_carlo`]), so the numbers do not depend on the thread count.

use std::time::Instant;

use anyhow::Context;
use mmtrack_beam::SpebtConfig;
use mmtrack_core::StampedPose;
use mmtrack_core::progress::Progress;
use mmtrack_process::beam::spebt::monte_carlo::{
    ExperimentResult, POSE_ERROR_MODEL, PoseSource, RADAR_ODOMETRY, into_link_frame, monte_carlo, tracker_config,
};
use mmtrack_sim::beam::spebt_link::SpebtLink;

use super::config::Config;
use super::drive::{OdometryDrive, drive};
use crate::common::{read_drive, run_count};
use crate::model::Tier;

/// One of the two experiments: its link, where its pose estimates come
/// from, and what its runs measured.
pub struct ExperimentRun {
    /// Sequence partition of its tables (`pose-error-model`, `radar-odometry`).
    pub name: &'static str,
    /// The link the vehicle drives.
    pub link: SpebtLink,
    /// Experiment (b)'s drive; `None` for the pose-error model.
    pub drive: Option<OdometryDrive>,
    /// What its runs measured.
    pub result: ExperimentResult,
}

/// Experiment (a) at another pilot power (`[sensitivity]`).
pub struct PilotVariant {
    /// The variant's pilot power, dBm.
    pub pilot_power_dbm: f64,
    /// Its link (the same trajectory, another pilot power).
    pub link: SpebtLink,
    /// What its runs measured.
    pub result: ExperimentResult,
}

/// What the whole Monte Carlo measured, and how long it took.
pub struct Measured {
    /// (a), then (b) unless skipped.
    pub experiments: Vec<ExperimentRun>,
    /// (a) at the `[sensitivity]` pilot powers, in the file's order.
    pub pilot_variants: Vec<PilotVariant>,
    /// Wall time, seconds.
    pub elapsed_s: f64,
    /// Threads of the rayon pool.
    pub threads: usize,
}

/// Runs experiment (a) and, unless [`Config::skip_odometry`], (b) at
/// `tier` (`runs` replacing the file's count of both).
///
/// # Errors
/// Zero runs, fewer than two slots, a missing or bad trajectory (naming the
/// file and pose), a link that cannot be built, a tracker or odometry
/// failure.
pub fn measure(config: &Config, tier: Tier, runs: Option<u64>, progress: &dyn Progress) -> anyhow::Result<Measured> {
    let (source, experiment) = (&config.source, &config.experiment);
    let runs_a = run_count(runs, tier, experiment.quick_runs, experiment.runs)?;
    let runs_b = run_count(runs, tier, experiment.odometry.quick_runs, experiment.odometry.runs)?;
    anyhow::ensure!(experiment.slots >= 2, "{source}: slots = {} (need at least 2)", experiment.slots);
    let mut poses = read_drive(&config.trajectory, config.trajectory_format)?;
    poses.truncate(experiment.slots);
    let link = SpebtLink::new(&experiment.scenario, &poses)
        .with_context(|| config.trajectory.display().to_string())
        .with_context(|| format!("{source}: [scenario]"))?;
    let tracker = tracker_config(experiment);

    let started = Instant::now();
    let result = monte_carlo(&link, &tracker, experiment.seed, runs_a, PoseSource::ErrorModel, progress)?;
    let mut pilot_variants = Vec::new();
    let sensitivity = &experiment.sensitivity;
    let runs_variant = if sensitivity.pilot_power_dbm.is_empty() {
        0
    } else {
        run_count(runs, tier, sensitivity.quick_runs, sensitivity.runs)?
    };
    for &pilot_power_dbm in &sensitivity.pilot_power_dbm {
        let mut variant = experiment.clone();
        variant.scenario.pilot_power_dbm = pilot_power_dbm;
        let link = SpebtLink::new(&variant.scenario, &poses)
            .with_context(|| format!("{source}: [sensitivity] pilot_power_dbm = {pilot_power_dbm}"))?;
        let tracker = tracker_config(&variant);
        let result = monte_carlo(&link, &tracker, experiment.seed, runs_variant, PoseSource::ErrorModel, progress)?;
        pilot_variants.push(PilotVariant { pilot_power_dbm, link, result });
    }
    let mut experiments = vec![ExperimentRun { name: POSE_ERROR_MODEL, link, drive: None, result }];
    if !config.skip_odometry {
        experiments.push(radar_odometry(config, tier, &tracker, poses, runs_b, progress)?);
    }
    Ok(Measured {
        experiments,
        pilot_variants,
        elapsed_s: started.elapsed().as_secs_f64(),
        threads: rayon::current_num_threads(),
    })
}

/// Experiment (b): radar odometry along the first slots of the trajectory
/// (`quick_slots` at the smoke tier), then the Monte Carlo runs on its link.
fn radar_odometry(
    config: &Config,
    tier: Tier,
    tracker: &SpebtConfig,
    mut poses: Vec<StampedPose>,
    runs: u64,
    progress: &dyn Progress,
) -> anyhow::Result<ExperimentRun> {
    let experiment = &config.experiment;
    if tier.is_smoke() {
        poses.truncate(experiment.odometry.quick_slots);
    }
    let trajectory = config.trajectory.display();
    let drive = drive(poses, &experiment.odometry.preset, progress)
        .with_context(|| format!("radar odometry along {trajectory}"))?;
    let link = SpebtLink::new(&experiment.scenario, &drive.ground_truth)
        .with_context(|| format!("the simulated drive along {trajectory}"))?;
    // The link's positions are relative to the first true position: so are the estimates'.
    let estimates = into_link_frame(drive.ground_truth[0].parent_from_child, &drive.estimates);
    let result = monte_carlo(&link, tracker, experiment.seed, runs, PoseSource::Fixed(&estimates), progress)?;
    Ok(ExperimentRun { name: RADAR_ODOMETRY, link, drive: Some(drive), result })
}
