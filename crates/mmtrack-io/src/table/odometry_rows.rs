//! Tables of the odometry pipeline: estimates, their stage timings, and the
//! ground truth they are compared with.

use std::sync::Arc;

use arrow_array::{ArrayRef, BooleanArray};
use mmtrack_core::{OdometryEstimate, OdometryTiming, Se2, StampedPose};

use super::rows::{POSES, col, f64s, i64s, u32s};
use super::{ColumnType, Columns, TableRow, TableSpec};

use ColumnType::{Boolean, Float64, Int64, UInt32};

fn bools(values: impl Iterator<Item = bool>) -> ArrayRef {
    Arc::new(values.map(Some).collect::<BooleanArray>())
}

/// A ground-truth pose: the same columns as `poses`, in its own table so an
/// output directory can hold an estimate and its reference side by side.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundTruthPose(pub StampedPose);

/// `ground_truth`: the reference trajectory of a recording.
pub const GROUND_TRUTH: TableSpec = TableSpec {
    name: "ground_truth",
    description: "One ground-truth pose world_from_vehicle per row, in time order, as the recording gives it.",
    columns: POSES.columns,
};

impl TableRow for GroundTruthPose {
    const SPEC: &'static TableSpec = &GROUND_TRUTH;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        let poses: Vec<StampedPose> = rows.iter().map(|r| r.0.clone()).collect();
        StampedPose::to_columns(&poses)
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        Ok(StampedPose::from_columns(c)?.into_iter().map(GroundTruthPose).collect())
    }
}

/// `odometry`: one radar odometry estimate per scan.
pub const ODOMETRY: TableSpec = TableSpec {
    name: "odometry",
    description: "One odometry estimate world_from_vehicle per radar scan, in time order, with registration diagnostics; \
the world frame is the pose of the first scan.",
    columns: &[
        col("t_ns", Int64, "ns", "scan time"),
        col("x_m", Float64, "m", "estimated x of the vehicle in the world frame"),
        col("y_m", Float64, "m", "estimated y of the vehicle in the world frame"),
        col("yaw_rad", Float64, "rad", "estimated heading, counter-clockwise from world x"),
        col("filtered_points", UInt32, "", "points kept by the k-strongest filter"),
        col("surface_points", UInt32, "", "oriented surface points of the scan"),
        col("correspondences", UInt32, "", "point-to-line correspondences in the last association round"),
        col("iterations", UInt32, "", "solver iterations over all association rounds"),
        col("cost_m2", Float64, "m^2", "final robust (Huber) cost"),
        col("low_confidence", Boolean, "", "true when the estimate fell back to the motion prediction"),
    ],
};

impl TableRow for OdometryEstimate {
    const SPEC: &'static TableSpec = &ODOMETRY;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![
            i64s(rows.iter().map(|r| r.t_ns)),
            f64s(rows.iter().map(|r| r.world_from_vehicle.x_m)),
            f64s(rows.iter().map(|r| r.world_from_vehicle.y_m)),
            f64s(rows.iter().map(|r| r.world_from_vehicle.yaw_rad)),
            u32s(rows.iter().map(|r| r.filtered_points)),
            u32s(rows.iter().map(|r| r.surface_points)),
            u32s(rows.iter().map(|r| r.correspondences)),
            u32s(rows.iter().map(|r| r.iterations)),
            f64s(rows.iter().map(|r| r.cost_m2)),
            bools(rows.iter().map(|r| r.low_confidence)),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (t, x, y, yaw) = (c.i64("t_ns")?, c.f64("x_m")?, c.f64("y_m")?, c.f64("yaw_rad")?);
        let (filtered, surface) = (c.u32("filtered_points")?, c.u32("surface_points")?);
        let (correspondences, iterations) = (c.u32("correspondences")?, c.u32("iterations")?);
        let (cost, low) = (c.f64("cost_m2")?, c.bool("low_confidence")?);
        Ok((0..c.num_rows())
            .map(|i| OdometryEstimate {
                t_ns: t.value(i),
                world_from_vehicle: Se2::new(x.value(i), y.value(i), yaw.value(i)),
                filtered_points: filtered.value(i),
                surface_points: surface.value(i),
                correspondences: correspondences.value(i),
                iterations: iterations.value(i),
                cost_m2: cost.value(i),
                low_confidence: low.value(i),
            })
            .collect())
    }
}

/// `odometry_timing`: per-stage time of each scan (varies run to run).
pub const ODOMETRY_TIMING: TableSpec = TableSpec {
    name: "odometry_timing",
    description: "Wall-clock time of each odometry stage per scan. Unlike every other table this one is not \
deterministic; it is kept apart so the result tables are.",
    columns: &[
        col("t_ns", Int64, "ns", "scan time"),
        col("filter_s", Float64, "s", "k-strongest filter and motion compensation"),
        col("surface_s", Float64, "s", "grid downsampling and oriented surface points"),
        col("register_s", Float64, "s", "registration, all association rounds"),
    ],
};

impl TableRow for OdometryTiming {
    const SPEC: &'static TableSpec = &ODOMETRY_TIMING;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![
            i64s(rows.iter().map(|r| r.t_ns)),
            f64s(rows.iter().map(|r| r.filter_s)),
            f64s(rows.iter().map(|r| r.surface_s)),
            f64s(rows.iter().map(|r| r.register_s)),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (t, filter, surface, register) =
            (c.i64("t_ns")?, c.f64("filter_s")?, c.f64("surface_s")?, c.f64("register_s")?);
        Ok((0..c.num_rows())
            .map(|i| OdometryTiming {
                t_ns: t.value(i),
                filter_s: filter.value(i),
                surface_s: surface.value(i),
                register_s: register.value(i),
            })
            .collect())
    }
}
