//! The drive of the odometry experiment: Navtech scans rendered along the
//! trajectory through the scenario's street scene, both presets on the same
//! scans, and KITTI drift of each against the simulator's ground truth.

use std::time::Instant;

use anyhow::Context;
use mmtrack_analysis::pipeline::{TrajectoryResult, analyze_trajectory};
use mmtrack_analysis::trajectory::DriftOptions;
use mmtrack_core::progress::Progress;
use mmtrack_core::{OdometryEstimate, OdometryTiming, StampedPose};
use mmtrack_odometry::{OdometryConfig, RadarOdometry};
use mmtrack_sim::radar::{RadarSimulator, Scenario, Trajectory};

use super::config::{Config, PRESETS};
use crate::common::read_drive;
use crate::model::Tier;

/// What one preset measured over the drive.
pub struct PresetResult {
    /// The preset.
    pub preset: &'static str,
    /// Its configuration.
    pub config: OdometryConfig,
    /// One estimate per scan.
    pub estimates: Vec<OdometryEstimate>,
    /// Stage timings per scan.
    pub timings: Vec<OdometryTiming>,
    /// Drift and errors against the ground truth.
    pub result: TrajectoryResult,
    /// Scans the odometry flagged low-confidence.
    pub low_confidence: usize,
}

/// What the drive measured.
pub struct Measured {
    /// The scenario driven (with the tier's distance cap).
    pub scenario: Scenario,
    /// KITTI drift options of the tier.
    pub drift: DriftOptions,
    /// Ground truth, one pose per scan.
    pub ground_truth: Vec<StampedPose>,
    /// One per preset, in [`PRESETS`] order.
    pub presets: Vec<PresetResult>,
    /// Wall-clock seconds of the simulation and both presets.
    pub elapsed_s: f64,
}

/// Estimates and timings of one preset, while the scans come.
struct Running {
    preset: &'static str,
    config: OdometryConfig,
    odometry: RadarOdometry,
    estimates: Vec<OdometryEstimate>,
    timings: Vec<OdometryTiming>,
}

/// Renders the drive of `config` at `tier` and runs both presets on each
/// scan; progress in scans.
///
/// # Errors
/// A missing or unreadable trajectory, a scene that cannot be built, an
/// odometry failure (naming the preset and scan), a drive of fewer than two
/// scans, a drift that cannot be measured.
pub fn measure(config: &Config, tier: Tier, progress: &dyn Progress) -> anyhow::Result<Measured> {
    let scenario = config.scenario_for(tier);
    let drift = Config::drift_options(tier);
    let trajectory_name = config.trajectory.display().to_string();
    let poses = read_drive(&config.trajectory, config.trajectory_format)?;
    let trajectory = Trajectory::from_poses(poses).with_context(|| trajectory_name.clone())?;
    let world = scenario.build_world(&trajectory).with_context(|| config.source.clone())?;
    let simulator = RadarSimulator::new(&world, &scenario.sensor, &trajectory, scenario.options())
        .with_context(|| trajectory_name.clone())?;

    let mut running = Vec::new();
    for preset in PRESETS {
        let config = OdometryConfig::preset(preset).context("unknown preset")?;
        let odometry = RadarOdometry::new(config.clone())?;
        running.push(Running { preset, config, odometry, estimates: Vec::new(), timings: Vec::new() });
    }
    let started = Instant::now();
    progress.start("reproduce odometry", simulator.len() as u64, "scans");
    let mut ground_truth: Vec<StampedPose> = Vec::new();
    for (scan, pose) in simulator {
        for run in &mut running {
            let result = run
                .odometry
                .process(&scan)
                .with_context(|| format!("{}: scan {} (t_ns {})", run.preset, ground_truth.len(), scan.header.t_ns))?;
            run.estimates.push(result.estimate);
            run.timings.push(result.timing);
        }
        ground_truth.push(pose);
        progress.advance(1);
        progress.check_cancelled()?;
    }
    progress.finish();
    let elapsed_s = started.elapsed().as_secs_f64();
    anyhow::ensure!(
        ground_truth.len() >= 2,
        "{trajectory_name}: the drive gave {} scans; nothing to measure",
        ground_truth.len()
    );

    let mut presets = Vec::new();
    for run in running {
        let sequence = sequence_of(run.preset);
        let estimate: Vec<StampedPose> = run
            .estimates
            .iter()
            .map(|e| StampedPose { t_ns: e.t_ns, parent_from_child: e.world_from_vehicle })
            .collect();
        let result = analyze_trajectory(&sequence, &estimate, &ground_truth, &drift)
            .with_context(|| format!("sequence {sequence}"))?;
        let low_confidence = run.estimates.iter().filter(|e| e.low_confidence).count();
        presets.push(PresetResult {
            preset: run.preset,
            config: run.config,
            estimates: run.estimates,
            timings: run.timings,
            result,
            low_confidence,
        });
    }
    Ok(Measured { scenario, drift, ground_truth, presets, elapsed_s })
}

/// The sequence partition of a preset's tables.
#[must_use]
pub fn sequence_of(preset: &str) -> String {
    format!("simulated-drive-{preset}")
}
