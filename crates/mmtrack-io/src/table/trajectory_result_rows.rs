//! Result tables of the trajectory evaluation (`mmtrack analyze` on the
//! tables of `process odometry`), with units: one partition per sequence.

use super::TableFrame;

crate::define_table! {
    /// `trajectory_metrics`: one row per sequence.
    pub const TRAJECTORY_METRICS = "trajectory_metrics",
        "Summary metrics of one estimated trajectory (table odometry) against its ground truth (table \
ground_truth), one row per sequence. Both are associated by time and start at the identity; KITTI drift follows the \
KITTI devkit (evaluate_odometry.cpp).",
        frame: TableFrame::NotApplicable;
    /// One row of [`TRAJECTORY_METRICS`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct TrajectoryMetrics {
        estimate_poses: u64, "", "poses in the estimate";
        associated_poses: u64, "", "estimate poses inside the ground-truth time span (evaluated)";
        interpolated_poses: u64, "", "associated poses whose ground truth was interpolated in time";
        dropped_poses: u64, "", "estimate poses outside the ground-truth time span (not evaluated)";
        first_t_ns: i64, "ns", "time of the first associated pose";
        last_t_ns: i64, "ns", "time of the last associated pose";
        path_length_m: f64, "m", "ground-truth path length over the associated poses";
        estimate_path_length_m: f64, "m", "estimated path length over the associated poses";
        segment_lengths_m: Vec<f64>, "m", "KITTI segment lengths used";
        step_frames: Option<u64>, "",
            "frames between segment starts (the devkit's step_size); null when step_m is set";
        step_m: Option<f64>, "m", "ground-truth metres between segment starts; null when step_frames is set";
        kitti_segments: u64, "", "segments evaluated; 0 when the path is shorter than every length";
        kitti_translational_pct: Option<f64>, "%",
            "KITTI translational drift, mean over all segments; null without segments";
        kitti_rotational_deg_per_100m: Option<f64>, "deg/100m",
            "KITTI rotational drift, mean over all segments, in degrees per 100 m (the unit the radar-odometry \
papers report, CFEAR's 0.60 deg/100 m; the devkit's deg/m times 100); null without segments";
        ate_rmse_m: f64, "m", "absolute trajectory error: position RMSE after least-squares SE(2) alignment";
        ate_max_m: f64, "m", "largest position error after alignment";
        x_rmse_m: f64, "m",
            "RMSE of x without alignment, both trajectories moved to start at the identity (x along the first \
pose's heading)";
        y_rmse_m: f64, "m",
            "RMSE of y without alignment, both trajectories moved to start at the identity (y to the left of the \
first pose's heading)";
        position_rmse_m: f64, "m", "RMSE of the planar position without alignment";
        yaw_rmse_rad: f64, "rad", "RMSE of the wrapped yaw difference without alignment";
        final_position_error_m: f64, "m", "position error at the last associated pose, without alignment";
        rpe_translation_rmse_m: f64, "m", "RMSE of the frame-to-frame relative translation error";
        rpe_yaw_rmse_rad: f64, "rad", "RMSE of the frame-to-frame relative yaw error";
    }
}

crate::define_table! {
    /// `drift_per_length`: KITTI drift per segment length.
    pub const DRIFT_PER_LENGTH = "drift_per_length",
        "KITTI drift of one sequence per segment length (the devkit's per-length plots), in segment-length \
order; lengths longer than the path are absent.",
        frame: TableFrame::NotApplicable;
    /// One row of [`DRIFT_PER_LENGTH`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct DriftPerLength {
        length_m: f64, "m", "nominal segment length";
        segments: u64, "", "segments of this length";
        translational_pct: f64, "%", "mean translational error / length";
        rotational_deg_per_100m: f64, "deg/100m", "mean rotational error / length, in degrees per 100 m";
    }
}

crate::define_table! {
    /// `relative_pose_errors`: one row per frame.
    pub const RELATIVE_POSE_ERRORS = "relative_pose_errors",
        "Frame-to-frame relative pose error E_k = (gt_{k-1}^-1 gt_k)^-1 (est_{k-1}^-1 est_k) of one sequence, \
one row per associated frame k >= 1, in time order.",
        frame: TableFrame::NotApplicable;
    /// One row of [`RELATIVE_POSE_ERRORS`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct RelativePoseErrorRow {
        frame: u64, "", "index k among the associated poses";
        t_ns: i64, "ns", "time of frame k";
        distance_m: f64, "m", "ground-truth path length from the first associated pose to frame k";
        translation_error_m: f64, "m", "length of the translation of E_k";
        yaw_error_rad: f64, "rad", "rotation of E_k, wrapped to (-pi, pi]";
    }
}
