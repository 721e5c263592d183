//! Coordinate frames of a recording as Foxglove sees them: `/tf`
//! ([`super::channels::TF_TOPIC`]) carries `foxglove.FrameTransforms`
//! messages, so the 3D panel can place the vehicle, its sensors and the
//! estimates.
//!
//! The tree:
//!
//! ```text
//! world ─┬─ base_link ─┬─ radar      (static mount)
//!        │             └─ gnss       (static mount)
//!        ├─ estimate                 (the estimated vehicle pose)
//!        ├─ tx, rx                   (the two cars of a channel-sounder recording)
//! ```
//!
//! `world -> base_link` is each ground-truth pose (`/ground_truth/pose`), at
//! its time; `world -> estimate` each estimated pose (`/estimate/pose`);
//! `world -> tx` / `world -> rx` the sounder cars' poses. The parent is the
//! parent frame the pose is written with (`world` for every writer of ours;
//! a ROS 2 bag's poses keep their own, e.g. `odom`); the child is always the
//! stream's frame ([`vehicle_frame`]), also in the poses' own `child_frame`
//! field. The sensor mounts are written once, at the recording's first log
//! time, on `/tf_static` ([`super::channels::TF_STATIC_TOPIC`]), as
//! identity transforms: the ground truth of our sources is the pose of the
//! radar itself (Oxford `radar_odometry.csv`, the simulators), so
//! `base_link` and `radar` coincide. Where the ground truth is another
//! sensor's pose (Oxford `ins.csv`) the dataset's lever arm between the two
//! is not applied; the recording metadata says which sensor the ground truth
//! is (`ground_truth.frame`).

use foxglove::schemas::{FrameTransform, Quaternion, Timestamp, Vector3};
use mmtrack_core::Se2;

use super::channels::PoseStream;

/// The fixed frame of poses and ground truth.
pub const WORLD_FRAME: &str = "world";
/// The vehicle, as the ground truth places it.
pub const VEHICLE_FRAME: &str = "base_link";
/// The vehicle as the estimate places it.
pub const ESTIMATE_FRAME: &str = "estimate";
/// The radar (frame of `/radar/image` and `/radar/cartesian`).
pub const RADAR_FRAME: &str = "radar";
/// The GNSS antenna (frame of `/viz/gnss`).
pub const GNSS_FRAME: &str = "gnss";

/// The child frame that poses of `stream` move in `/tf`.
#[must_use]
pub fn vehicle_frame(stream: PoseStream) -> &'static str {
    match stream {
        PoseStream::GroundTruth => VEHICLE_FRAME,
        PoseStream::Estimate => ESTIMATE_FRAME,
        PoseStream::GroundTruthTx => "tx",
        PoseStream::GroundTruthRx => "rx",
    }
}

/// Nanoseconds as a Foxglove timestamp; `None` before the epoch or past 2106.
#[must_use]
pub fn timestamp(t_ns: i64) -> Option<Timestamp> {
    let t_ns = u64::try_from(t_ns).ok()?;
    let sec = u32::try_from(t_ns / 1_000_000_000).ok()?;
    Some(Timestamp::new(sec, (t_ns % 1_000_000_000) as u32))
}

/// The quaternion of a rotation by `yaw_rad` about z.
#[must_use]
pub fn yaw_quaternion(yaw_rad: f64) -> Quaternion {
    let half = 0.5 * yaw_rad;
    Quaternion { x: 0.0, y: 0.0, z: half.sin(), w: half.cos() }
}

/// `parent_from_child` as a Foxglove transform at `t_ns`.
#[must_use]
pub fn frame_transform(t_ns: i64, parent: &str, child: &str, parent_from_child: Se2) -> FrameTransform {
    FrameTransform {
        timestamp: timestamp(t_ns),
        parent_frame_id: parent.into(),
        child_frame_id: child.into(),
        translation: Some(Vector3 { x: parent_from_child.x_m, y: parent_from_child.y_m, z: 0.0 }),
        rotation: Some(yaw_quaternion(parent_from_child.yaw_rad)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_of_a_quarter_turn() {
        let q = yaw_quaternion(std::f64::consts::FRAC_PI_2);
        // 1e-15: one ulp of sqrt(1/2).
        assert!((q.z - 0.5f64.sqrt()).abs() < 1e-15 && (q.w - 0.5f64.sqrt()).abs() < 1e-15);
        let t = frame_transform(1_500_000_000, "world", "base_link", Se2::new(1.0, 2.0, 0.0));
        assert_eq!(t.timestamp, Some(Timestamp::new(1, 500_000_000)));
        assert_eq!((t.parent_frame_id.as_str(), t.child_frame_id.as_str()), ("world", "base_link"));
        assert_eq!(timestamp(-1), None);
    }
}
