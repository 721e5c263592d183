//! Relative pose error (frame to frame) and absolute trajectory error.
//!
//! # References
//! - J. Sturm, N. Engelhard, F. Endres, W. Burgard, D. Cremers, "A benchmark
//!   for the evaluation of RGB-D SLAM systems", IROS 2012, Sec. VI: RPE
//!   (eq. 1, here with `Delta = 1` frame) and ATE (eq. 2, after alignment).
//! - S. Umeyama, "Least-squares estimation of transformation parameters
//!   between two point patterns", IEEE TPAMI 13(4), 1991 (without scale);
//!   B. K. P. Horn, "Closed-form solution of absolute orientation using unit
//!   quaternions", JOSA A 4(4), 1987. In 2D the rotation has the closed form
//!   used in [`align_se2`].
//! - C. Liu et al., "Successive pose estimation and beam tracking for mmWave
//!   vehicular communication systems" (SPEBT), 2024, Table II: unaligned
//!   per-axis position RMSE "(2.772, 4.083) m" and yaw RMSE "3.550 deg", as
//!   [`unaligned_errors`] computes them.

use mmtrack_core::{Se2, wrap_angle_rad};

use super::{TrajectoryError, trajectory_distances_m};

/// The error between consecutive frames `k - 1 -> k`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelativePoseError {
    /// Frame `k` (index into the associated poses, >= 1).
    pub frame: usize,
    /// Its time.
    pub t_ns: i64,
    /// Ground-truth path length from frame 0 to frame `k`, metres.
    pub distance_m: f64,
    /// `|t(E_k)|`, metres.
    pub translation_error_m: f64,
    /// `yaw(E_k)` wrapped to (-pi, pi], radians (signed).
    pub yaw_error_rad: f64,
}

/// RPE per frame: `E_k = (gt[k-1]^-1 gt[k])^-1 (est[k-1]^-1 est[k])`
/// (Sturm et al. 2012, eq. 1, `Delta = 1`).
pub fn relative_pose_errors(
    t_ns: &[i64],
    estimate: &[Se2],
    ground_truth: &[Se2],
) -> Result<Vec<RelativePoseError>, TrajectoryError> {
    check_lengths(estimate, ground_truth)?;
    if t_ns.len() != estimate.len() {
        return Err(TrajectoryError::LengthMismatch { estimate: t_ns.len(), ground_truth: estimate.len() });
    }
    let dist = trajectory_distances_m(ground_truth);
    Ok((1..estimate.len())
        .map(|k| {
            let step_gt = ground_truth[k - 1].inverse() * ground_truth[k];
            let step_est = estimate[k - 1].inverse() * estimate[k];
            let error = step_gt.inverse() * step_est;
            RelativePoseError {
                frame: k,
                t_ns: t_ns[k],
                distance_m: dist[k],
                translation_error_m: error.translation_norm_m(),
                yaw_error_rad: wrap_angle_rad(error.yaw_rad),
            }
        })
        .collect())
}

fn check_lengths(estimate: &[Se2], ground_truth: &[Se2]) -> Result<(), TrajectoryError> {
    if estimate.len() != ground_truth.len() {
        return Err(TrajectoryError::LengthMismatch { estimate: estimate.len(), ground_truth: ground_truth.len() });
    }
    if estimate.is_empty() {
        return Err(TrajectoryError::Empty { which: "estimate" });
    }
    Ok(())
}

/// The least-squares rigid motion (no scale) `gt_from_est` minimising
/// `sum_k |g_k - (R e_k + t)|^2` over positions `e_k` (estimate) and `g_k`
/// (ground truth).
///
/// With centroids `e̅`, `g̅` and centred points `e'`, `g'`, the optimal angle
/// is `atan2(sum e'_x g'_y - e'_y g'_x, sum e'_x g'_x + e'_y g'_y)` (the 2D
/// case of Umeyama 1991 / Horn 1987) and `t = g̅ - R e̅`.
pub fn align_se2(estimate: &[Se2], ground_truth: &[Se2]) -> Result<Se2, TrajectoryError> {
    check_lengths(estimate, ground_truth)?;
    let n = estimate.len() as f64;
    let centroid = |poses: &[Se2]| {
        let (sx, sy) = poses.iter().fold((0.0, 0.0), |(sx, sy), p| (sx + p.x_m, sy + p.y_m));
        (sx / n, sy / n)
    };
    let (ex, ey) = centroid(estimate);
    let (gx, gy) = centroid(ground_truth);
    let (mut sin_sum, mut cos_sum) = (0.0, 0.0);
    for (e, g) in estimate.iter().zip(ground_truth) {
        let (ax, ay, bx, by) = (e.x_m - ex, e.y_m - ey, g.x_m - gx, g.y_m - gy);
        sin_sum += ax * by - ay * bx;
        cos_sum += ax * bx + ay * by;
    }
    let yaw_rad = sin_sum.atan2(cos_sum);
    let rotation = Se2::new(0.0, 0.0, yaw_rad);
    let [rx, ry] = rotation.transform_point([ex, ey]);
    Ok(Se2::new(gx - rx, gy - ry, yaw_rad))
}

/// ATE after alignment (Sturm et al. 2012, eq. 2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AbsoluteTrajectoryError {
    /// The alignment applied to the estimate, `gt_from_est`.
    pub gt_from_est: Se2,
    /// `sqrt(mean |g_k - gt_from_est * e_k|^2)`, metres.
    pub position_rmse_m: f64,
    /// Largest position error after alignment, metres.
    pub position_max_m: f64,
}

/// Aligns the estimate ([`align_se2`]) and returns the position RMSE.
pub fn absolute_trajectory_error(
    estimate: &[Se2],
    ground_truth: &[Se2],
) -> Result<AbsoluteTrajectoryError, TrajectoryError> {
    let gt_from_est = align_se2(estimate, ground_truth)?;
    let (mut sum, mut max) = (0.0_f64, 0.0_f64);
    for (e, g) in estimate.iter().zip(ground_truth) {
        let [x, y] = gt_from_est.transform_point([e.x_m, e.y_m]);
        let d2 = (x - g.x_m).powi(2) + (y - g.y_m).powi(2);
        sum += d2;
        max = max.max(d2.sqrt());
    }
    Ok(AbsoluteTrajectoryError {
        gt_from_est,
        position_rmse_m: (sum / estimate.len() as f64).sqrt(),
        position_max_m: max,
    })
}

/// Errors without alignment (both trajectories start at the identity), as
/// SPEBT Table II reports them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnalignedErrors {
    /// RMSE of `x_est - x_gt`, metres.
    pub x_rmse_m: f64,
    /// RMSE of `y_est - y_gt`, metres.
    pub y_rmse_m: f64,
    /// RMSE of the planar position error, metres.
    pub position_rmse_m: f64,
    /// RMSE of `wrap(yaw_est - yaw_gt)`, radians.
    pub yaw_rmse_rad: f64,
    /// Position error at the last frame, metres.
    pub final_position_error_m: f64,
}

/// Per-axis position RMSE, yaw RMSE and end-point error without alignment.
pub fn unaligned_errors(estimate: &[Se2], ground_truth: &[Se2]) -> Result<UnalignedErrors, TrajectoryError> {
    check_lengths(estimate, ground_truth)?;
    let n = estimate.len() as f64;
    let (mut sx, mut sy, mut syaw) = (0.0, 0.0, 0.0);
    for (e, g) in estimate.iter().zip(ground_truth) {
        sx += (e.x_m - g.x_m).powi(2);
        sy += (e.y_m - g.y_m).powi(2);
        syaw += wrap_angle_rad(e.yaw_rad - g.yaw_rad).powi(2);
    }
    let (last_e, last_g) = (estimate[estimate.len() - 1], ground_truth[ground_truth.len() - 1]);
    Ok(UnalignedErrors {
        x_rmse_m: (sx / n).sqrt(),
        y_rmse_m: (sy / n).sqrt(),
        position_rmse_m: ((sx + sy) / n).sqrt(),
        yaw_rmse_rad: (syaw / n).sqrt(),
        final_position_error_m: (last_e.x_m - last_g.x_m).hypot(last_e.y_m - last_g.y_m),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drive() -> Vec<Se2> {
        (0..100).map(f64::from).map(|s| Se2::new(s, 5.0 * (0.1 * s).sin(), 0.3 * (0.1 * s).cos())).collect()
    }

    #[test]
    fn identical_trajectories_have_zero_errors() {
        let gt = drive();
        let t: Vec<i64> = (0..100).collect();
        let rpe = relative_pose_errors(&t, &gt, &gt).unwrap();
        assert_eq!(rpe.len(), 99);
        assert!(rpe.iter().all(|e| e.translation_error_m == 0.0 && e.yaw_error_rad == 0.0));
        let u = unaligned_errors(&gt, &gt).unwrap();
        assert_eq!((u.x_rmse_m, u.y_rmse_m, u.yaw_rmse_rad, u.final_position_error_m), (0.0, 0.0, 0.0, 0.0));
        // Alignment of identical clouds: rounding only.
        assert!(absolute_trajectory_error(&gt, &gt).unwrap().position_rmse_m < 1e-12);
    }

    #[test]
    fn rigidly_moved_copy_has_zero_ate_after_alignment() {
        let gt = drive();
        let moved_from_gt = Se2::new(-120.0, 43.0, 2.4);
        let est: Vec<Se2> = gt.iter().map(|g| moved_from_gt * *g).collect();
        let ate = absolute_trajectory_error(&est, &gt).unwrap();
        // 1e-9 m: rounding of O(100) m coordinates over 100 points.
        assert!(ate.position_rmse_m < 1e-9 && ate.position_max_m < 1e-9, "{ate:?}");
        let expected = moved_from_gt.inverse();
        assert!((ate.gt_from_est.x_m - expected.x_m).abs() < 1e-9);
        assert!(wrap_angle_rad(ate.gt_from_est.yaw_rad - expected.yaw_rad).abs() < 1e-12);
        // Without alignment the offset shows.
        assert!(unaligned_errors(&est, &gt).unwrap().position_rmse_m > 100.0);
    }

    #[test]
    fn known_offsets_give_known_rmse() {
        let gt = drive();
        let est: Vec<Se2> = gt.iter().map(|g| Se2::new(g.x_m + 3.0, g.y_m - 4.0, g.yaw_rad + 0.1)).collect();
        let u = unaligned_errors(&est, &gt).unwrap();
        // 1e-12: one rounding per term of O(100) values.
        assert!((u.x_rmse_m - 3.0).abs() < 1e-12 && (u.y_rmse_m - 4.0).abs() < 1e-12);
        assert!((u.position_rmse_m - 5.0).abs() < 1e-12 && (u.yaw_rmse_rad - 0.1).abs() < 1e-12);
        // A pure translation aligns away.
        assert!(absolute_trajectory_error(&est, &gt).unwrap().position_rmse_m < 1e-9);
        let t: Vec<i64> = (0..100).collect();
        let rpe = relative_pose_errors(&t, &est, &gt).unwrap();
        // Step yaws equal but positions rotated by 0.1 in their own frame:
        // the translation error of each step is |R(-yaw_est) d - R(-yaw_gt) d|.
        assert!(rpe.iter().all(|e| e.yaw_error_rad.abs() < 1e-12));
        assert!(relative_pose_errors(&t[1..], &est, &gt).is_err());
    }
}
