//! Tables of the odometry pipeline: estimates, their stage timings, and the
//! ground truth they are compared with.

use super::TableFrame;

use mmtrack_core::{OdometryEstimate, OdometryTiming, Se2, StampedPose};

/// A ground-truth pose: the same columns as `poses`, in its own table so an
/// output directory can hold an estimate and its reference side by side.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundTruthPose(pub StampedPose);

crate::define_table! {
    /// `ground_truth`: the reference trajectory of a recording.
    pub const GROUND_TRUTH = "ground_truth",
        "One ground-truth pose world_from_vehicle per row, in time order, as the recording gives it.",
        frame: TableFrame::Run;
    GroundTruthPose(StampedPose);
}

crate::define_table! {
    /// `odometry`: one radar odometry estimate per scan.
    pub const ODOMETRY = "odometry",
        "One odometry estimate world_from_vehicle per radar scan, in time order, with registration diagnostics; \
the world frame is the ground truth's when the recording has ground truth (the first estimate inside its time span \
sits at the ground-truth pose of that time), else the vehicle's pose at the first scan: the run config's `frame` \
says which.",
        frame: TableFrame::Run;
    OdometryEstimate {
        t_ns: i64, "ns", "scan time";
        x_m: f64, "m", "estimated x of the vehicle in the world frame", |r| r.world_from_vehicle.x_m;
        y_m: f64, "m", "estimated y of the vehicle in the world frame", |r| r.world_from_vehicle.y_m;
        yaw_rad: f64, "rad", "estimated heading, counter-clockwise from world x", |r| r.world_from_vehicle.yaw_rad;
        filtered_points: u32, "", "points kept by the k-strongest filter";
        surface_points: u32, "", "oriented surface points of the scan";
        correspondences: u32, "", "point-to-line correspondences in the last association round";
        iterations: u32, "", "solver iterations over all association rounds";
        cost_m2: f64, "m^2", "final robust (Huber) cost";
        low_confidence: bool, "", "true when the estimate fell back to the motion prediction";
    } => {
        let world_from_vehicle = Se2::new(x_m, y_m, yaw_rad);
        OdometryEstimate {
            t_ns, world_from_vehicle, filtered_points, surface_points, correspondences, iterations, cost_m2,
            low_confidence,
        }
    }
}

crate::define_table! {
    /// `odometry_timing`: per-stage time of each scan (varies run to run).
    pub const ODOMETRY_TIMING = "odometry_timing",
        "Wall-clock time of each odometry stage per scan. Unlike every other table this one is not \
deterministic; it is kept apart so the result tables are.",
        frame: TableFrame::NotApplicable;
    OdometryTiming {
        t_ns: i64, "ns", "scan time";
        filter_s: f64, "s", "k-strongest filter and motion compensation";
        surface_s: f64, "s", "grid downsampling and oriented surface points";
        register_s: f64, "s", "registration, all association rounds";
    }
}
