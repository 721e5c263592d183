//! Trajectory metrics: association of an estimate with ground truth, KITTI
//! drift, relative pose error and absolute trajectory error. Pure computation
//! on in-memory poses; no I/O.
//!
//! All metrics take an [`Association`]: the estimate and the ground truth at
//! the same instants, both re-expressed relative to their first associated
//! pose, so both start at the identity.

mod drift;
mod errors;

pub use drift::{
    DriftOptions, DriftSummary, FirstFrameStep, KITTI_SEGMENT_LENGTHS_M, KITTI_STEP_FRAMES, KittiDrift, LengthDrift,
    SegmentError, devkit_rotation_error_rad, kitti_drift, last_frame_from_segment_length, trajectory_distances_m,
};
pub use errors::{
    AbsoluteTrajectoryError, RelativePoseError, UnalignedErrors, absolute_trajectory_error, align_se2,
    relative_pose_errors, unaligned_errors,
};

use mmtrack_core::{Se2, StampedPose, interpolate_pose};

/// Why a trajectory cannot be evaluated. Rows are 0-based positions in the
/// slice given (= rows of the table it was read from).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TrajectoryError {
    /// No poses at all.
    #[error("{which}: no poses")]
    Empty {
        /// `estimate` or `ground truth`.
        which: &'static str,
    },
    /// Time does not strictly increase.
    #[error("{which}: row {row}: t_ns {t_ns} does not increase (previous row has {previous_t_ns})")]
    NonMonotonicTime {
        /// `estimate` or `ground truth`.
        which: &'static str,
        /// Offending row.
        row: usize,
        /// Its time.
        t_ns: i64,
        /// Time of the row before.
        previous_t_ns: i64,
    },
    /// A pose component is NaN or infinite.
    #[error("{which}: row {row} (t_ns {t_ns}): pose is not finite (x_m {x_m}, y_m {y_m}, yaw_rad {yaw_rad})")]
    NonFinitePose {
        /// `estimate` or `ground truth`.
        which: &'static str,
        /// Offending row.
        row: usize,
        /// Its time.
        t_ns: i64,
        /// Components as found.
        x_m: f64,
        /// Components as found.
        y_m: f64,
        /// Components as found.
        yaw_rad: f64,
    },
    /// Fewer than two estimate poses fall inside the ground-truth time span.
    #[error(
        "only {inside} estimate poses lie inside the ground-truth time span [{gt_first_ns}, {gt_last_ns}] ns \
         (estimate spans [{est_first_ns}, {est_last_ns}] ns); need at least 2"
    )]
    NoOverlap {
        /// Estimate poses inside the span.
        inside: usize,
        /// First and last estimate time.
        est_first_ns: i64,
        /// Last estimate time.
        est_last_ns: i64,
        /// First ground-truth time.
        gt_first_ns: i64,
        /// Last ground-truth time.
        gt_last_ns: i64,
    },
    /// Two pose lists that must be frame-aligned differ in length.
    #[error(
        "estimate has {estimate} poses but ground truth has {ground_truth}; they must be associated frame by frame"
    )]
    LengthMismatch {
        /// Estimate poses.
        estimate: usize,
        /// Ground-truth poses.
        ground_truth: usize,
    },
    /// Metric options out of range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
}

/// Checks that `poses` is non-empty, strictly increasing in time and finite.
pub fn validate_trajectory(which: &'static str, poses: &[StampedPose]) -> Result<(), TrajectoryError> {
    if poses.is_empty() {
        return Err(TrajectoryError::Empty { which });
    }
    for (row, pose) in poses.iter().enumerate() {
        let p = pose.parent_from_child;
        if !p.is_finite() {
            return Err(TrajectoryError::NonFinitePose {
                which,
                row,
                t_ns: pose.t_ns,
                x_m: p.x_m,
                y_m: p.y_m,
                yaw_rad: p.yaw_rad,
            });
        }
        if row > 0 && pose.t_ns <= poses[row - 1].t_ns {
            return Err(TrajectoryError::NonMonotonicTime {
                which,
                row,
                t_ns: pose.t_ns,
                previous_t_ns: poses[row - 1].t_ns,
            });
        }
    }
    Ok(())
}

/// An estimate and its ground truth at the same instants.
#[derive(Debug, Clone, PartialEq)]
pub struct Association {
    /// Times of the associated estimate poses.
    pub t_ns: Vec<i64>,
    /// `first_from_vehicle` of the estimate: `est0.inverse() * est_k`.
    pub estimate: Vec<Se2>,
    /// `first_from_vehicle` of the ground truth: `gt0.inverse() * gt_k`.
    pub ground_truth: Vec<Se2>,
    /// `est0`: the first associated estimate pose in the estimate table's
    /// frame (`est0 * estimate[k]` is pose k as the table holds it).
    pub estimate_first: Se2,
    /// `gt0`: the first associated ground-truth pose in the ground-truth
    /// table's frame.
    pub ground_truth_first: Se2,
    /// Estimate poses whose time matched a ground-truth time exactly.
    pub exact_matches: usize,
    /// Estimate poses whose ground truth was interpolated.
    pub interpolated: usize,
    /// Estimate poses before the first ground-truth time (dropped).
    pub dropped_before: usize,
    /// Estimate poses after the last ground-truth time (dropped).
    pub dropped_after: usize,
}

impl Association {
    /// The estimate as its table holds it (`est0 * estimate[k]`).
    #[must_use]
    pub fn estimate_in_table_frame(&self) -> Vec<Se2> {
        self.estimate.iter().map(|p| self.estimate_first * *p).collect()
    }

    /// The ground truth as its table holds it (`gt0 * ground_truth[k]`,
    /// interpolated at the estimate's times).
    #[must_use]
    pub fn ground_truth_in_table_frame(&self) -> Vec<Se2> {
        self.ground_truth.iter().map(|p| self.ground_truth_first * *p).collect()
    }

    /// Number of associated poses.
    #[must_use]
    pub fn len(&self) -> usize {
        self.t_ns.len()
    }

    /// True when nothing was associated.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.t_ns.is_empty()
    }

    /// Estimate poses dropped for lying outside the ground-truth span.
    #[must_use]
    pub fn dropped(&self) -> usize {
        self.dropped_before + self.dropped_after
    }
}

/// Associates an estimate with ground truth by time.
///
/// For each estimate pose: a ground-truth pose with the same `t_ns` is used
/// as is; otherwise ground truth is interpolated ([`interpolate_pose`])
/// between its neighbours; estimate poses outside the ground-truth span are
/// dropped and counted. Both trajectories are then re-expressed relative to
/// their first associated pose (`p0.inverse() * p_k`), so both start at the
/// identity; a first pose that is exactly the identity is kept bit for bit.
///
/// This is the nearest-in-time association of the TUM benchmark tools
/// (Sturm et al., "A benchmark for the evaluation of RGB-D SLAM systems",
/// IROS 2012, Sec. VI) made exact by interpolation, since radar scans and
/// GNSS/INS poses are not sampled together.
pub fn associate(estimate: &[StampedPose], ground_truth: &[StampedPose]) -> Result<Association, TrajectoryError> {
    validate_trajectory("estimate", estimate)?;
    validate_trajectory("ground truth", ground_truth)?;
    let (gt_first, gt_last) = (ground_truth[0].t_ns, ground_truth[ground_truth.len() - 1].t_ns);
    let mut out = Association {
        t_ns: Vec::new(),
        estimate: Vec::new(),
        ground_truth: Vec::new(),
        estimate_first: Se2::IDENTITY,
        ground_truth_first: Se2::IDENTITY,
        exact_matches: 0,
        interpolated: 0,
        dropped_before: 0,
        dropped_after: 0,
    };
    for pose in estimate {
        let t = pose.t_ns;
        if t < gt_first {
            out.dropped_before += 1;
            continue;
        }
        if t > gt_last {
            out.dropped_after += 1;
            continue;
        }
        let truth = match ground_truth.binary_search_by_key(&t, |g| g.t_ns) {
            Ok(i) => {
                out.exact_matches += 1;
                ground_truth[i].parent_from_child
            }
            // gt_first < t < gt_last, so 0 < i < len.
            Err(i) => {
                out.interpolated += 1;
                interpolate_pose(&ground_truth[i - 1], &ground_truth[i], t)
            }
        };
        out.t_ns.push(t);
        out.estimate.push(pose.parent_from_child);
        out.ground_truth.push(truth);
    }
    if out.len() < 2 {
        return Err(TrajectoryError::NoOverlap {
            inside: out.len(),
            est_first_ns: estimate[0].t_ns,
            est_last_ns: estimate[estimate.len() - 1].t_ns,
            gt_first_ns: gt_first,
            gt_last_ns: gt_last,
        });
    }
    out.estimate_first = out.estimate[0];
    out.ground_truth_first = out.ground_truth[0];
    relative_to_first(&mut out.estimate);
    relative_to_first(&mut out.ground_truth);
    Ok(out)
}

fn relative_to_first(poses: &mut [Se2]) {
    let Some(&first) = poses.first() else { return };
    if first == Se2::IDENTITY {
        return;
    }
    let first_inv = first.inverse();
    for p in poses.iter_mut() {
        *p = first_inv * *p;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stamped(t_ns: i64, x: f64, y: f64, yaw: f64) -> StampedPose {
        StampedPose { t_ns, parent_from_child: Se2::new(x, y, yaw) }
    }

    #[test]
    fn association_matches_interpolates_and_drops() {
        let gt = vec![stamped(10, 0.0, 0.0, 3.0), stamped(20, 10.0, 0.0, -3.0), stamped(30, 20.0, 5.0, -3.0)];
        let est = vec![stamped(5, 0.0, 0.0, 0.0), stamped(10, 0.0, 0.0, 0.0), stamped(15, 1.0, 0.0, 0.0)];
        let a = associate(&est, &gt).unwrap();
        assert_eq!((a.len(), a.exact_matches, a.interpolated, a.dropped_before, a.dropped_after), (2, 1, 1, 1, 0));
        // Midway between yaw 3 and -3 along the short arc (through pi), then
        // relative to the first ground-truth pose (yaw 3): +(2 pi - 6) / 2.
        let expected_dyaw = std::f64::consts::PI - 3.0;
        // 1e-12: a few ulps of the O(10) values involved.
        assert!((a.ground_truth[1].yaw_rad - expected_dyaw).abs() < 1e-12, "{:?}", a.ground_truth[1]);
        assert!((a.ground_truth[1].translation_norm_m() - 5.0).abs() < 1e-12);
        assert_eq!(a.estimate[0], Se2::IDENTITY);
    }

    #[test]
    fn bad_input_names_the_row() {
        let gt = vec![stamped(10, 0.0, 0.0, 0.0), stamped(10, 1.0, 0.0, 0.0)];
        let err = associate(&gt.clone(), &gt).unwrap_err();
        assert!(matches!(err, TrajectoryError::NonMonotonicTime { which: "estimate", row: 1, .. }), "{err}");
        let nan = vec![stamped(10, 0.0, 0.0, 0.0), stamped(20, f64::NAN, 0.0, 0.0)];
        let err = validate_trajectory("ground truth", &nan).unwrap_err();
        assert!(err.to_string().contains("row 1") && err.to_string().contains("NaN"), "{err}");
        let late = vec![stamped(100, 0.0, 0.0, 0.0), stamped(200, 0.0, 0.0, 0.0)];
        let early = vec![stamped(1, 0.0, 0.0, 0.0), stamped(2, 0.0, 0.0, 0.0)];
        assert!(matches!(associate(&late, &early), Err(TrajectoryError::NoOverlap { inside: 0, .. })));
    }
}
