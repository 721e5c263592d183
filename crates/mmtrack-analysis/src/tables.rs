//! Result tables of `mmtrack analyze`, with units. Same layout and metadata as
//! every mmtrack table (`<out>/tables/<table>/sequence=<id>/part-0.parquet`).
//! The sequence is the Hive partition, not a column, so readers that add
//! partition columns (DuckDB, pyarrow, polars) see it once.

use std::sync::Arc;

use arrow_array::builder::{Float64Builder, ListBuilder};
use arrow_array::{Array, ArrayRef, Float64Array, Int64Array, UInt64Array};
use mmtrack_io::table::{ColumnSpec, ColumnType, Columns, TableRow, TableSpec};

use ColumnType::{Float64, Int64, ListFloat64, UInt64};

const fn col(name: &'static str, ty: ColumnType, unit: &'static str, meaning: &'static str) -> ColumnSpec {
    ColumnSpec { name, ty, nullable: false, unit, meaning }
}

const fn opt(name: &'static str, ty: ColumnType, unit: &'static str, meaning: &'static str) -> ColumnSpec {
    ColumnSpec { name, ty, nullable: true, unit, meaning }
}

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
];

/// `trajectory_metrics`: one row per sequence.
pub const TRAJECTORY_METRICS: TableSpec = TableSpec {
    name: "trajectory_metrics",
    description: "Summary metrics of one estimated trajectory (table odometry) against its ground truth (table \
ground_truth), one row per sequence. Both are associated by time and start at the identity; KITTI drift follows the \
KITTI devkit (evaluate_odometry.cpp).",
    columns: &[
        col("estimate_poses", UInt64, "", "poses in the estimate"),
        col("associated_poses", UInt64, "", "estimate poses inside the ground-truth time span (evaluated)"),
        col("interpolated_poses", UInt64, "", "associated poses whose ground truth was interpolated in time"),
        col("dropped_poses", UInt64, "", "estimate poses outside the ground-truth time span (not evaluated)"),
        col("first_t_ns", Int64, "ns", "time of the first associated pose"),
        col("last_t_ns", Int64, "ns", "time of the last associated pose"),
        col("path_length_m", Float64, "m", "ground-truth path length over the associated poses"),
        col("estimate_path_length_m", Float64, "m", "estimated path length over the associated poses"),
        col("segment_lengths_m", ListFloat64, "m", "KITTI segment lengths used"),
        opt(
            "step_frames",
            UInt64,
            "",
            "frames between segment starts (the devkit's step_size); null when step_m is set",
        ),
        opt("step_m", Float64, "m", "ground-truth metres between segment starts; null when step_frames is set"),
        col("kitti_segments", UInt64, "", "segments evaluated; 0 when the path is shorter than every length"),
        opt(
            "kitti_translational_pct",
            Float64,
            "%",
            "KITTI translational drift, mean over all segments; null without segments",
        ),
        opt(
            "kitti_rotational_deg_per_m",
            Float64,
            "deg/m",
            "KITTI rotational drift, mean over all segments; null without segments",
        ),
        opt("kitti_rotational_deg_per_100m", Float64, "deg/100m", "the same in degrees per 100 m"),
        col("ate_rmse_m", Float64, "m", "absolute trajectory error: position RMSE after least-squares SE(2) alignment"),
        col("ate_max_m", Float64, "m", "largest position error after alignment"),
        col("x_rmse_m", Float64, "m", "RMSE of x without alignment"),
        col("y_rmse_m", Float64, "m", "RMSE of y without alignment"),
        col("position_rmse_m", Float64, "m", "RMSE of the planar position without alignment"),
        col("yaw_rmse_rad", Float64, "rad", "RMSE of the wrapped yaw difference without alignment"),
        col("final_position_error_m", Float64, "m", "position error at the last associated pose, without alignment"),
        col("rpe_translation_rmse_m", Float64, "m", "RMSE of the frame-to-frame relative translation error"),
        col("rpe_yaw_rmse_rad", Float64, "rad", "RMSE of the frame-to-frame relative yaw error"),
    ],
};

/// One row of [`TRAJECTORY_METRICS`].
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)] // Fields are documented by the column meanings of the spec.
pub struct TrajectoryMetrics {
    pub estimate_poses: u64,
    pub associated_poses: u64,
    pub interpolated_poses: u64,
    pub dropped_poses: u64,
    pub first_t_ns: i64,
    pub last_t_ns: i64,
    pub path_length_m: f64,
    pub estimate_path_length_m: f64,
    pub segment_lengths_m: Vec<f64>,
    pub step_frames: Option<u64>,
    pub step_m: Option<f64>,
    pub kitti_segments: u64,
    pub kitti_translational_pct: Option<f64>,
    pub kitti_rotational_deg_per_m: Option<f64>,
    pub kitti_rotational_deg_per_100m: Option<f64>,
    pub ate_rmse_m: f64,
    pub ate_max_m: f64,
    pub x_rmse_m: f64,
    pub y_rmse_m: f64,
    pub position_rmse_m: f64,
    pub yaw_rmse_rad: f64,
    pub final_position_error_m: f64,
    pub rpe_translation_rmse_m: f64,
    pub rpe_yaw_rmse_rad: f64,
}

fn u64s(v: impl Iterator<Item = u64>) -> ArrayRef {
    Arc::new(UInt64Array::from_iter_values(v))
}
fn i64s(v: impl Iterator<Item = i64>) -> ArrayRef {
    Arc::new(Int64Array::from_iter_values(v))
}
fn f64s(v: impl Iterator<Item = f64>) -> ArrayRef {
    Arc::new(Float64Array::from_iter_values(v))
}
fn opt_f64s(v: impl Iterator<Item = Option<f64>>) -> ArrayRef {
    Arc::new(v.collect::<Float64Array>())
}
fn list_f64s<'a>(rows: impl Iterator<Item = &'a [f64]>) -> ArrayRef {
    let mut b = ListBuilder::new(Float64Builder::new());
    for row in rows {
        b.values().append_slice(row);
        b.append(true);
    }
    Arc::new(b.finish())
}
fn opt_value(a: &Float64Array, i: usize) -> Option<f64> {
    if a.is_null(i) { None } else { Some(a.value(i)) }
}
fn opt_u64(a: &UInt64Array, i: usize) -> Option<u64> {
    if a.is_null(i) { None } else { Some(a.value(i)) }
}

impl TableRow for TrajectoryMetrics {
    const SPEC: &'static TableSpec = &TRAJECTORY_METRICS;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        let f = |g: fn(&Self) -> f64| f64s(rows.iter().map(g));
        let o = |g: fn(&Self) -> Option<f64>| opt_f64s(rows.iter().map(g));
        vec![
            u64s(rows.iter().map(|r| r.estimate_poses)),
            u64s(rows.iter().map(|r| r.associated_poses)),
            u64s(rows.iter().map(|r| r.interpolated_poses)),
            u64s(rows.iter().map(|r| r.dropped_poses)),
            i64s(rows.iter().map(|r| r.first_t_ns)),
            i64s(rows.iter().map(|r| r.last_t_ns)),
            f(|r| r.path_length_m),
            f(|r| r.estimate_path_length_m),
            list_f64s(rows.iter().map(|r| r.segment_lengths_m.as_slice())),
            Arc::new(rows.iter().map(|r| r.step_frames).collect::<UInt64Array>()),
            o(|r| r.step_m),
            u64s(rows.iter().map(|r| r.kitti_segments)),
            o(|r| r.kitti_translational_pct),
            o(|r| r.kitti_rotational_deg_per_m),
            o(|r| r.kitti_rotational_deg_per_100m),
            f(|r| r.ate_rmse_m),
            f(|r| r.ate_max_m),
            f(|r| r.x_rmse_m),
            f(|r| r.y_rmse_m),
            f(|r| r.position_rmse_m),
            f(|r| r.yaw_rmse_rad),
            f(|r| r.final_position_error_m),
            f(|r| r.rpe_translation_rmse_m),
            f(|r| r.rpe_yaw_rmse_rad),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let u = |n: &str| c.u64(n);
        let f = |n: &str| c.f64(n);
        let (step_frames, step_m) = (u("step_frames")?, f("step_m")?);
        let (kt, kr, kr100) =
            (f("kitti_translational_pct")?, f("kitti_rotational_deg_per_m")?, f("kitti_rotational_deg_per_100m")?);
        let cols = [
            "path_length_m",
            "estimate_path_length_m",
            "ate_rmse_m",
            "ate_max_m",
            "x_rmse_m",
            "y_rmse_m",
            "position_rmse_m",
            "yaw_rmse_rad",
            "final_position_error_m",
            "rpe_translation_rmse_m",
            "rpe_yaw_rmse_rad",
        ]
        .map(f);
        let [pl, epl, ate, atemax, xr, yr, pr, yawr, fin, rpet, rpey] = cols;
        let (pl, epl, ate, atemax, xr, yr, pr, yawr, fin, rpet, rpey) =
            (pl?, epl?, ate?, atemax?, xr?, yr?, pr?, yawr?, fin?, rpet?, rpey?);
        let (n_est, n_assoc, n_interp, n_drop, n_seg) = (
            u("estimate_poses")?,
            u("associated_poses")?,
            u("interpolated_poses")?,
            u("dropped_poses")?,
            u("kitti_segments")?,
        );
        let (t0, t1) = (c.i64("first_t_ns")?, c.i64("last_t_ns")?);
        (0..c.num_rows())
            .map(|i| {
                Ok(TrajectoryMetrics {
                    estimate_poses: n_est.value(i),
                    associated_poses: n_assoc.value(i),
                    interpolated_poses: n_interp.value(i),
                    dropped_poses: n_drop.value(i),
                    first_t_ns: t0.value(i),
                    last_t_ns: t1.value(i),
                    path_length_m: pl.value(i),
                    estimate_path_length_m: epl.value(i),
                    segment_lengths_m: c.list_f64("segment_lengths_m", i)?,
                    step_frames: opt_u64(step_frames, i),
                    step_m: opt_value(step_m, i),
                    kitti_segments: n_seg.value(i),
                    kitti_translational_pct: opt_value(kt, i),
                    kitti_rotational_deg_per_m: opt_value(kr, i),
                    kitti_rotational_deg_per_100m: opt_value(kr100, i),
                    ate_rmse_m: ate.value(i),
                    ate_max_m: atemax.value(i),
                    x_rmse_m: xr.value(i),
                    y_rmse_m: yr.value(i),
                    position_rmse_m: pr.value(i),
                    yaw_rmse_rad: yawr.value(i),
                    final_position_error_m: fin.value(i),
                    rpe_translation_rmse_m: rpet.value(i),
                    rpe_yaw_rmse_rad: rpey.value(i),
                })
            })
            .collect()
    }
}

/// `drift_per_length`: KITTI drift per segment length.
pub const DRIFT_PER_LENGTH: TableSpec = TableSpec {
    name: "drift_per_length",
    description: "KITTI drift of one sequence per segment length (the devkit's per-length plots), in segment-length \
order; lengths longer than the path are absent.",
    columns: &[
        col("length_m", Float64, "m", "nominal segment length"),
        col("segments", UInt64, "", "segments of this length"),
        col("translational_pct", Float64, "%", "mean translational error / length"),
        col("rotational_deg_per_m", Float64, "deg/m", "mean rotational error / length"),
    ],
};

/// One row of [`DRIFT_PER_LENGTH`].
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)] // Fields are documented by the column meanings of the spec.
pub struct DriftPerLength {
    pub length_m: f64,
    pub segments: u64,
    pub translational_pct: f64,
    pub rotational_deg_per_m: f64,
}

impl TableRow for DriftPerLength {
    const SPEC: &'static TableSpec = &DRIFT_PER_LENGTH;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![
            f64s(rows.iter().map(|r| r.length_m)),
            u64s(rows.iter().map(|r| r.segments)),
            f64s(rows.iter().map(|r| r.translational_pct)),
            f64s(rows.iter().map(|r| r.rotational_deg_per_m)),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (l, n, t, r) =
            (c.f64("length_m")?, c.u64("segments")?, c.f64("translational_pct")?, c.f64("rotational_deg_per_m")?);
        Ok((0..c.num_rows())
            .map(|i| DriftPerLength {
                length_m: l.value(i),
                segments: n.value(i),
                translational_pct: t.value(i),
                rotational_deg_per_m: r.value(i),
            })
            .collect())
    }
}

/// `relative_pose_errors`: one row per frame.
pub const RELATIVE_POSE_ERRORS: TableSpec = TableSpec {
    name: "relative_pose_errors",
    description: "Frame-to-frame relative pose error E_k = (gt_{k-1}^-1 gt_k)^-1 (est_{k-1}^-1 est_k) of one sequence, \
one row per associated frame k >= 1, in time order.",
    columns: &[
        col("frame", UInt64, "", "index k among the associated poses"),
        col("t_ns", Int64, "ns", "time of frame k"),
        col("distance_m", Float64, "m", "ground-truth path length from the first associated pose to frame k"),
        col("translation_error_m", Float64, "m", "length of the translation of E_k"),
        col("yaw_error_rad", Float64, "rad", "rotation of E_k, wrapped to (-pi, pi]"),
    ],
};

/// One row of [`RELATIVE_POSE_ERRORS`].
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)] // Fields are documented by the column meanings of the spec.
pub struct RelativePoseErrorRow {
    pub frame: u64,
    pub t_ns: i64,
    pub distance_m: f64,
    pub translation_error_m: f64,
    pub yaw_error_rad: f64,
}

impl TableRow for RelativePoseErrorRow {
    const SPEC: &'static TableSpec = &RELATIVE_POSE_ERRORS;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![
            u64s(rows.iter().map(|r| r.frame)),
            i64s(rows.iter().map(|r| r.t_ns)),
            f64s(rows.iter().map(|r| r.distance_m)),
            f64s(rows.iter().map(|r| r.translation_error_m)),
            f64s(rows.iter().map(|r| r.yaw_error_rad)),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (k, t, d, e, y) = (
            c.u64("frame")?,
            c.i64("t_ns")?,
            c.f64("distance_m")?,
            c.f64("translation_error_m")?,
            c.f64("yaw_error_rad")?,
        );
        Ok((0..c.num_rows())
            .map(|i| RelativePoseErrorRow {
                frame: k.value(i),
                t_ns: t.value(i),
                distance_m: d.value(i),
                translation_error_m: e.value(i),
                yaw_error_rad: y.value(i),
            })
            .collect())
    }
}
