//! Result tables of `mmtrack analyze`, with units. Same layout and metadata as
//! every mmtrack table (`<out>/tables/<table>/sequence=<id>/part-0.parquet`).
//! The sequence is the Hive partition, not a column, so readers that add
//! partition columns (DuckDB, pyarrow, polars) see it once.

use mmtrack_io::table::TableSpec;

/// Every result table of this crate, for `schemas/`.
pub const TABLES: &[&TableSpec] = &[
    &TRAJECTORY_METRICS,
    &DRIFT_PER_LENGTH,
    &RELATIVE_POSE_ERRORS,
    &crate::mpc_tables::MPC_SUMMARY,
    &crate::mpc_tables::MPC_SET_METRICS,
    &crate::mpc_tables::MPC_COUNT_DISTRIBUTION,
    &crate::mpc_tables::MPC_TRACK_POWER_STD,
    &crate::mpc_tables::MPC_CHI_CLASSES,
    &crate::mpc_tables::MPC_FIRST_PATH,
    &mmtrack_io::table::BEAM_RMS_PER_BLOCK,
    &mmtrack_io::table::BEAM_VALID_TRACKING,
    &mmtrack_io::table::BEAM_SWEEP_SUMMARY,
    &mmtrack_io::table::BEAM_SWEEP_POOLED,
    &mmtrack_io::table::SPEBT_SUMMARY,
    &mmtrack_io::table::SPEBT_PER_SLOT,
    &mmtrack_io::table::SPEBT_POOLED,
    &mmtrack_io::table::ZOECHMANN_NMSE,
    &mmtrack_io::table::ZOECHMANN_SUMMARY,
    &mmtrack_io::table::ZOECHMANN_NLOS_ERROR,
    &mmtrack_io::table::ZOECHMANN_PATH_LABELS,
    &mmtrack_io::table::GEOMETRIC_PER_EPOCH,
    &mmtrack_io::table::GEOMETRIC_SUMMARY,
    &mmtrack_io::table::SLAM_SUMMARY,
    &mmtrack_io::table::SLAM_PER_EPOCH,
    &mmtrack_io::table::SLAM_UE,
    &mmtrack_io::table::SLAM_MAP,
    &mmtrack_io::table::SLAM_ASSOCIATIONS,
    &mmtrack_io::table::SLAM_TRUE_SOURCES,
    &crate::campaign::RUN_COMPARISON,
];

mmtrack_io::define_table! {
    /// `trajectory_metrics`: one row per sequence.
    pub const TRAJECTORY_METRICS = "trajectory_metrics",
        "Summary metrics of one estimated trajectory (table odometry) against its ground truth (table \
ground_truth), one row per sequence. Both are associated by time and start at the identity; KITTI drift follows the \
KITTI devkit (evaluate_odometry.cpp).";
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
        kitti_rotational_deg_per_m: Option<f64>, "deg/m",
            "KITTI rotational drift, mean over all segments; null without segments";
        kitti_rotational_deg_per_100m: Option<f64>, "deg/100m", "the same in degrees per 100 m";
        ate_rmse_m: f64, "m", "absolute trajectory error: position RMSE after least-squares SE(2) alignment";
        ate_max_m: f64, "m", "largest position error after alignment";
        x_rmse_m: f64, "m", "RMSE of x without alignment";
        y_rmse_m: f64, "m", "RMSE of y without alignment";
        position_rmse_m: f64, "m", "RMSE of the planar position without alignment";
        yaw_rmse_rad: f64, "rad", "RMSE of the wrapped yaw difference without alignment";
        final_position_error_m: f64, "m", "position error at the last associated pose, without alignment";
        rpe_translation_rmse_m: f64, "m", "RMSE of the frame-to-frame relative translation error";
        rpe_yaw_rmse_rad: f64, "rad", "RMSE of the frame-to-frame relative yaw error";
    }
}

mmtrack_io::define_table! {
    /// `drift_per_length`: KITTI drift per segment length.
    pub const DRIFT_PER_LENGTH = "drift_per_length",
        "KITTI drift of one sequence per segment length (the devkit's per-length plots), in segment-length \
order; lengths longer than the path are absent.";
    /// One row of [`DRIFT_PER_LENGTH`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct DriftPerLength {
        length_m: f64, "m", "nominal segment length";
        segments: u64, "", "segments of this length";
        translational_pct: f64, "%", "mean translational error / length";
        rotational_deg_per_m: f64, "deg/m", "mean rotational error / length";
    }
}

mmtrack_io::define_table! {
    /// `relative_pose_errors`: one row per frame.
    pub const RELATIVE_POSE_ERRORS = "relative_pose_errors",
        "Frame-to-frame relative pose error E_k = (gt_{k-1}^-1 gt_k)^-1 (est_{k-1}^-1 est_k) of one sequence, \
one row per associated frame k >= 1, in time order.";
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

#[cfg(test)]
mod tests {
    use mmtrack_io::Overwrite;
    use mmtrack_io::table::{RunInfo, read_table_dir, write_table};

    use super::*;

    /// The derived writer and reader of a result table with lists and
    /// nullable integers and floats give back every value, nulls included.
    #[test]
    fn trajectory_metrics_round_trip_with_and_without_nulls() {
        let full = TrajectoryMetrics {
            estimate_poses: u64::MAX,
            associated_poses: 7,
            interpolated_poses: 3,
            dropped_poses: 0,
            first_t_ns: i64::MIN,
            last_t_ns: i64::MAX,
            path_length_m: 812.5,
            estimate_path_length_m: -0.0,
            segment_lengths_m: vec![100.0, 200.0],
            step_frames: Some(10),
            step_m: None,
            kitti_segments: 12,
            kitti_translational_pct: Some(1.25),
            kitti_rotational_deg_per_m: Some(0.002),
            kitti_rotational_deg_per_100m: Some(0.2),
            ate_rmse_m: 1.0,
            ate_max_m: 2.0,
            x_rmse_m: 0.5,
            y_rmse_m: 0.25,
            position_rmse_m: f64::INFINITY,
            yaw_rmse_rad: 1e-300,
            final_position_error_m: 3.0,
            rpe_translation_rmse_m: 0.1,
            rpe_yaw_rmse_rad: 0.01,
        };
        let empty = TrajectoryMetrics {
            segment_lengths_m: Vec::new(),
            step_frames: None,
            step_m: Some(5.0),
            kitti_translational_pct: None,
            kitti_rotational_deg_per_m: None,
            kitti_rotational_deg_per_100m: None,
            ..full.clone()
        };
        let dir = tempfile::tempdir().unwrap();
        let run = RunInfo { config_json: "{}".into() };
        write_table(dir.path(), "seq", &[full.clone(), empty.clone()], &run, Overwrite::Refuse).unwrap();
        let read = read_table_dir::<TrajectoryMetrics>(dir.path()).unwrap();
        assert_eq!(read.get("seq").map(Vec::as_slice), Some(&[full, empty][..]));
    }
}
