//! Vehicle trajectories: constant-turn motion or a caller's list of stamped
//! poses, interpolated at any time, and the schedule of sweeps over them.
//!
//! Interpolation between two poses of a list is linear in x and y and along
//! the shortest arc in yaw: `yaw = yaw_0 + s * wrap(yaw_1 - yaw_0)` with
//! `s = (t - t_0) / (t_1 - t_0)`.

use mmtrack_core::{Se2, StampedPose, limits, wrap_angle_rad};
use serde::Deserialize;

use crate::SimError;
use crate::error::{ensure_finite, ensure_positive, invalid};

/// Constant speed and yaw rate from the origin, heading along world x.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantTurn {
    /// Forward speed, metres per second.
    pub speed_mps: f64,
    /// Yaw rate, radians per second, counter-clockwise positive.
    pub yaw_rate_radps: f64,
}

impl ConstantTurn {
    /// `world_from_vehicle` at `t_s` seconds after the start (exact arc).
    #[must_use]
    pub fn pose_at(&self, t_s: f64) -> Se2 {
        let (v, w) = (self.speed_mps, self.yaw_rate_radps);
        if w.abs() < 1e-12 {
            return Se2::new(v * t_s, 0.0, 0.0);
        }
        let yaw = w * t_s;
        Se2::new(v / w * yaw.sin(), v / w * (1.0 - yaw.cos()), yaw)
    }
}

/// A trajectory `world_from_vehicle(t)` over a time span.
#[derive(Debug, Clone, PartialEq)]
pub enum Trajectory {
    /// Constant-turn motion from `start_t_ns` for `duration_ns`.
    ConstantTurn {
        /// Speed and yaw rate.
        motion: ConstantTurn,
        /// Time of the start (pose = identity), nanoseconds.
        start_t_ns: i64,
        /// Length of the span, nanoseconds.
        duration_ns: i64,
    },
    /// Stamped poses (at least two, times strictly increasing), interpolated.
    Poses(Vec<StampedPose>),
}

impl Trajectory {
    /// Constant-turn motion over `duration_s` seconds from `start_t_ns`.
    pub fn constant_turn(motion: ConstantTurn, start_t_ns: i64, duration_s: f64) -> Result<Self, SimError> {
        ensure_finite("motion.yaw_rate_radps", motion.yaw_rate_radps)?;
        if !limits::SPEED_MPS.allows(motion.speed_mps.abs()) {
            return Err(invalid("motion.speed_mps", motion.speed_mps, limits::SPEED_MPS.expected));
        }
        ensure_positive("motion.duration_s", duration_s)?;
        if !limits::DURATION_S.allows(duration_s) {
            return Err(invalid("motion.duration_s", duration_s, limits::DURATION_S.expected));
        }
        if !limits::PATH_LENGTH_M.allows(motion.speed_mps.abs() * duration_s) {
            return Err(invalid("motion.duration_s", duration_s, limits::PATH_LENGTH_M.expected));
        }
        let duration_ns = (duration_s * 1e9).round() as i64;
        if start_t_ns.checked_add(duration_ns).is_none() {
            return Err(invalid(
                "start_t_ns",
                start_t_ns,
                "a start time whose drive ends before the year 2262 (i64 ns)",
            ));
        }
        Ok(Self::ConstantTurn { motion, start_t_ns, duration_ns })
    }

    /// A trajectory through `poses`; errors name the first bad pose.
    pub fn from_poses(poses: Vec<StampedPose>) -> Result<Self, SimError> {
        for (index, pose) in poses.iter().enumerate() {
            if !pose.parent_from_child.is_finite() {
                return Err(SimError::BadTrajectoryPose { index, t_ns: pose.t_ns, detail: "not finite".into() });
            }
            if let Some(previous) = index.checked_sub(1).and_then(|i| poses.get(i))
                && pose.t_ns <= previous.t_ns
            {
                return Err(SimError::BadTrajectoryPose {
                    index,
                    t_ns: pose.t_ns,
                    detail: format!("time does not increase (previous pose at {} ns)", previous.t_ns),
                });
            }
        }
        if poses.len() < 2 {
            return Err(SimError::TrajectoryTooShort { detail: format!("{} poses, need at least 2", poses.len()) });
        }
        Ok(Self::Poses(poses))
    }

    /// First time of the span, nanoseconds.
    #[must_use]
    pub fn start_t_ns(&self) -> i64 {
        match self {
            Self::ConstantTurn { start_t_ns, .. } => *start_t_ns,
            Self::Poses(poses) => poses.first().map_or(0, |p| p.t_ns),
        }
    }

    /// Last time of the span, nanoseconds.
    #[must_use]
    pub fn end_t_ns(&self) -> i64 {
        match self {
            Self::ConstantTurn { start_t_ns, duration_ns, .. } => start_t_ns + duration_ns,
            Self::Poses(poses) => poses.last().map_or(0, |p| p.t_ns),
        }
    }

    /// `world_from_vehicle` at `t_ns`; times outside the span take the pose
    /// at the nearer end (constant turn: the arc continues).
    #[must_use]
    pub fn pose_at(&self, t_ns: i64) -> Se2 {
        match self {
            Self::ConstantTurn { motion, start_t_ns, .. } => motion.pose_at((t_ns - start_t_ns) as f64 * 1e-9),
            Self::Poses(poses) => interpolate(poses, t_ns),
        }
    }

    /// Poses every `step_m` metres of path (and at least every second), from
    /// start to end: what the world generator lines streets along.
    #[must_use]
    pub fn path_samples(&self, step_m: f64) -> Vec<Se2> {
        let (start, end) = (self.start_t_ns(), self.end_t_ns());
        let mut out = vec![self.pose_at(start)];
        let mut t_ns = start;
        let coarse_ns = 50_000_000; // 5 cm at 1 m/s, well below step_m at driving speeds
        while t_ns < end {
            t_ns = (t_ns + coarse_ns).min(end);
            let pose = self.pose_at(t_ns);
            let last = out[out.len() - 1];
            if (pose.x_m - last.x_m).hypot(pose.y_m - last.y_m) >= step_m || t_ns == end {
                out.push(pose);
            }
        }
        out
    }
}

fn interpolate(poses: &[StampedPose], t_ns: i64) -> Se2 {
    let after = poses.partition_point(|p| p.t_ns <= t_ns);
    match (after.checked_sub(1).and_then(|i| poses.get(i)), poses.get(after)) {
        (Some(a), Some(b)) => {
            let s = (t_ns - a.t_ns) as f64 / (b.t_ns - a.t_ns) as f64;
            let (pa, pb) = (a.parent_from_child, b.parent_from_child);
            Se2::new(
                pa.x_m + s * (pb.x_m - pa.x_m),
                pa.y_m + s * (pb.y_m - pa.y_m),
                wrap_angle_rad(pa.yaw_rad + s * wrap_angle_rad(pb.yaw_rad - pa.yaw_rad)),
            )
        }
        (Some(only), None) | (None, Some(only)) => only.parent_from_child,
        (None, None) => Se2::IDENTITY,
    }
}

/// Which sweeps of a trajectory to render.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ScanLimits {
    /// Render at most this many sweeps.
    pub max_scans: Option<usize>,
    /// Stop before the first sweep that starts more than this far along the path, metres.
    pub max_distance_m: Option<f64>,
}

/// Stamps (time of the first azimuth) of the sweeps: one every `sweep_ns`
/// from the trajectory's start, each sweep lying wholly inside the span, cut
/// by `limits`.
pub fn scan_stamps(trajectory: &Trajectory, sweep_ns: i64, limits: ScanLimits) -> Result<Vec<i64>, SimError> {
    if let Some(d) = limits.max_distance_m {
        crate::error::ensure_non_negative("max_distance_m", d)?;
    }
    let (start, end) = (trajectory.start_t_ns(), trajectory.end_t_ns());
    if end - start < sweep_ns {
        return Err(SimError::TrajectoryTooShort {
            detail: format!(
                "spans {:.3} s, one sweep takes {:.3} s",
                (end - start) as f64 * 1e-9,
                sweep_ns as f64 * 1e-9
            ),
        });
    }
    let mut stamps = Vec::new();
    let mut travelled_m = 0.0;
    let mut last = trajectory.pose_at(start);
    let mut t_ns = start;
    while t_ns + sweep_ns <= end && limits.max_scans.is_none_or(|n| stamps.len() < n) {
        let pose = trajectory.pose_at(t_ns);
        travelled_m += (pose.x_m - last.x_m).hypot(pose.y_m - last.y_m);
        last = pose;
        if limits.max_distance_m.is_some_and(|d| travelled_m > d) {
            break;
        }
        stamps.push(t_ns);
        t_ns += sweep_ns;
    }
    Ok(stamps)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sp(t_ns: i64, x: f64, y: f64, yaw: f64) -> StampedPose {
        StampedPose { t_ns, parent_from_child: Se2::new(x, y, yaw) }
    }

    #[test]
    fn constant_turn_is_an_exact_arc() {
        let m = ConstantTurn { speed_mps: 10.0, yaw_rate_radps: std::f64::consts::FRAC_PI_2 };
        let p = m.pose_at(1.0);
        let r = 10.0 / std::f64::consts::FRAC_PI_2;
        assert!((p.x_m - r).abs() < 1e-12 && (p.y_m - r).abs() < 1e-12);
    }

    #[test]
    fn interpolation_is_linear_and_takes_the_short_way_round() {
        let t = Trajectory::from_poses(vec![sp(0, 0.0, 0.0, 3.0), sp(1_000, 10.0, -2.0, -3.0)]).unwrap();
        let p = t.pose_at(250);
        assert!((p.x_m - 2.5).abs() < 1e-12 && (p.y_m + 0.5).abs() < 1e-12);
        // From 3.0 to -3.0 the short arc crosses pi (0.283 rad), not zero (6 rad).
        let expected = wrap_angle_rad(3.0 + 0.25 * (2.0 * std::f64::consts::PI - 6.0));
        assert!((p.yaw_rad - expected).abs() < 1e-12, "{}", p.yaw_rad);
    }

    #[test]
    fn bad_trajectories_are_named() {
        let err = Trajectory::from_poses(vec![sp(0, 0.0, 0.0, 0.0), sp(0, 1.0, 0.0, 0.0)]).unwrap_err();
        assert!(err.to_string().contains("pose 1") && err.to_string().contains("does not increase"), "{err}");
        let err = Trajectory::from_poses(vec![sp(0, f64::NAN, 0.0, 0.0), sp(5, 1.0, 0.0, 0.0)]).unwrap_err();
        assert!(err.to_string().contains("pose 0") && err.to_string().contains("not finite"), "{err}");
        let err = Trajectory::from_poses(vec![sp(0, 0.0, 0.0, 0.0)]).unwrap_err();
        assert!(err.to_string().contains("1 poses, need at least 2"), "{err}");
        let short = Trajectory::from_poses(vec![sp(0, 0.0, 0.0, 0.0), sp(100, 1.0, 0.0, 0.0)]).unwrap();
        let err = scan_stamps(&short, 250_000_000, ScanLimits::default()).unwrap_err();
        assert!(err.to_string().contains("too short"), "{err}");
    }

    #[test]
    fn stamps_cover_the_span_and_respect_limits() {
        let motion = ConstantTurn { speed_mps: 10.0, yaw_rate_radps: 0.0 };
        let t = Trajectory::constant_turn(motion, 0, 2.0).unwrap();
        let all = scan_stamps(&t, 250_000_000, ScanLimits::default()).unwrap();
        assert_eq!(all.len(), 8); // the 8th sweep ends exactly at 2 s
        let by_count = scan_stamps(&t, 250_000_000, ScanLimits { max_scans: Some(3), ..Default::default() }).unwrap();
        assert_eq!(by_count, vec![0, 250_000_000, 500_000_000]);
        // 10 m/s: sweeps start at 0, 2.5, 5, 7.5 m, ...; 6 m keeps three.
        let by_distance =
            scan_stamps(&t, 250_000_000, ScanLimits { max_distance_m: Some(6.0), ..Default::default() }).unwrap();
        assert_eq!(by_distance.len(), 3);
    }
}
