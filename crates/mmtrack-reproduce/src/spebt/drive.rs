//! Experiment (b) of the SPEBT experiment: the pose estimates come from our
//! own radar odometry instead of the pose-error model, as in the paper's
//! pipeline (Sec. III-A, Fast-CFEAR on Navtech scans).
//!
//! Oxford-size Navtech scans are rendered along the trajectory through the
//! generated street scene of the odometry experiment
//! ([`crate::odometry::DRIVE_SCENARIO`], its seed and sensor, without its
//! distance cap), and an odometry preset (`fast-cfear`, the paper's) runs on
//! them. The simulator's ground truth, one pose per scan, is the drive the
//! link follows; the odometry's estimates, moved into the ground truth's
//! frame at the first scan (`world_from_first_truth * first_estimate^-1 *
//! estimate`), drive the tracker.

use std::time::Instant;

use anyhow::Context;
use mmtrack_core::progress::Progress;
use mmtrack_core::{Se2, StampedPose, wrap_angle_rad};
use mmtrack_odometry::{OdometryConfig, RadarOdometry};
use mmtrack_process::beam::spebt::monte_carlo::into_truth_frame;
use mmtrack_process::simulate::radar::parse_scenario;
use mmtrack_sim::radar::{RadarSimulator, Trajectory};

use crate::odometry::config::{DRIVE_SCENARIO, DRIVE_SCENARIO_NAME};

/// The simulated drive and the odometry's estimates along it.
#[derive(Debug, Clone)]
pub struct OdometryDrive {
    /// The odometry preset.
    pub preset: String,
    /// Ground truth, one pose per scan (the link's slots).
    pub ground_truth: Vec<StampedPose>,
    /// The odometry's estimates in the ground truth's frame, one per scan.
    pub estimates: Vec<Se2>,
    /// Scans the odometry flagged low-confidence.
    pub low_confidence: usize,
    /// Wall-clock seconds of rendering and odometry.
    pub elapsed_s: f64,
}

impl OdometryDrive {
    /// RMSE of x, y (metres) and of the wrapped yaw (degrees) of the
    /// estimates against the ground truth, without alignment beyond the
    /// first scan (the paper's Table II).
    #[must_use]
    pub fn rmse(&self) -> (f64, f64, f64) {
        let n = self.estimates.len().max(1) as f64;
        let (mut x, mut y, mut yaw) = (0.0, 0.0, 0.0);
        for (e, t) in self.estimates.iter().zip(&self.ground_truth) {
            let t = &t.parent_from_child;
            x += (e.x_m - t.x_m).powi(2);
            y += (e.y_m - t.y_m).powi(2);
            yaw += wrap_angle_rad(e.yaw_rad - t.yaw_rad).powi(2);
        }
        ((x / n).sqrt(), (y / n).sqrt(), (yaw / n).sqrt().to_degrees())
    }
}

/// Renders scans along `poses` and runs `preset` on them; progress in scans.
///
/// # Errors
/// An unknown preset, a scene or simulator that cannot be built, an
/// odometry failure (naming the scan), a drive of fewer than two scans.
pub fn drive(poses: Vec<StampedPose>, preset: &str, progress: &dyn Progress) -> anyhow::Result<OdometryDrive> {
    let started = Instant::now();
    let mut scenario = parse_scenario(DRIVE_SCENARIO).with_context(|| format!("embedded {DRIVE_SCENARIO_NAME}"))?;
    scenario.max_distance_m = None;
    let trajectory = Trajectory::from_poses(poses)?;
    let world = scenario.build_world(&trajectory)?;
    let simulator = RadarSimulator::new(&world, &scenario.sensor, &trajectory, scenario.options())?;
    let config = OdometryConfig::preset(preset)
        .with_context(|| format!("odometry preset `{preset}` (expected one of {:?})", OdometryConfig::PRESETS))?;
    let mut odometry = RadarOdometry::new(config)?;
    progress.start("reproduce spebt: radar odometry", simulator.len() as u64, "scans");
    let (mut ground_truth, mut raw, mut low_confidence) = (Vec::new(), Vec::new(), 0);
    for (scan, pose) in simulator {
        let result = odometry
            .process(&scan)
            .with_context(|| format!("{preset}: scan {} (t_ns {})", ground_truth.len(), scan.header.t_ns))?;
        low_confidence += usize::from(result.estimate.low_confidence);
        raw.push(result.estimate.world_from_vehicle);
        ground_truth.push(pose);
        progress.advance(1);
        progress.check_cancelled()?;
    }
    progress.finish();
    anyhow::ensure!(ground_truth.len() >= 2, "the simulated drive gave {} scans; nothing to track", ground_truth.len());
    let estimates = into_truth_frame(ground_truth[0].parent_from_child, &raw);
    Ok(OdometryDrive {
        preset: preset.to_string(),
        ground_truth,
        estimates,
        low_confidence,
        elapsed_s: started.elapsed().as_secs_f64(),
    })
}
