//! Output of a radar odometry pipeline: one pose estimate per scan, with the
//! diagnostics a user needs to tell a good registration from a doubtful one.

use crate::pose::Se2;

/// One odometry estimate: the vehicle pose at a scan's time, plus what the
/// registration saw. Stage timings are not here (they vary run to run and
/// would make result tables non-deterministic); they go to a separate table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometryEstimate {
    /// Scan time (the scan's stamp), nanoseconds.
    pub t_ns: i64,
    /// Estimated `world_from_vehicle`; the world frame is the first scan's pose.
    pub world_from_vehicle: Se2,
    /// Points kept by the k-strongest filter.
    pub filtered_points: u32,
    /// Oriented surface points of the scan's sparse representation.
    pub surface_points: u32,
    /// Correspondences used in the final registration round.
    pub correspondences: u32,
    /// Solver iterations summed over all association rounds.
    pub iterations: u32,
    /// Final robust cost (sum of Huber losses), metres squared.
    pub cost_m2: f64,
    /// True when the estimate is doubtful (too few correspondences, a
    /// degenerate scene, or a scan without returns); the pose then follows the
    /// constant-velocity prediction.
    pub low_confidence: bool,
}

/// How long each stage of one scan took; for benchmarks and profiling only.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OdometryTiming {
    /// Scan time, nanoseconds.
    pub t_ns: i64,
    /// k-strongest filtering (and motion compensation), seconds.
    pub filter_s: f64,
    /// Grid downsampling and surface-point estimation, seconds.
    pub surface_s: f64,
    /// Registration (all association rounds), seconds.
    pub register_s: f64,
}
