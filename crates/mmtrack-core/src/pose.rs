use std::f64::consts::PI;
use std::ops::Mul;

/// A rigid transform in the plane, SE(2): a rotation by `yaw_rad` followed by a
/// translation `(x_m, y_m)`.
///
/// Read a value named `a_from_b` as "maps coordinates in frame b to frame a":
/// `p_in_a = a_from_b.transform_point(p_in_b)`, and
/// `a_from_c = a_from_b * b_from_c`.
///
/// As a homogeneous matrix,
/// ```text
/// T = [ cos(yaw) -sin(yaw)  x ]
///     [ sin(yaw)  cos(yaw)  y ]
///     [ 0         0         1 ]
/// ```
/// so composition is matrix multiplication and yaw is counter-clockwise
/// positive (x forward, y left, z up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Se2 {
    /// Translation along x, metres.
    pub x_m: f64,
    /// Translation along y, metres.
    pub y_m: f64,
    /// Rotation angle, radians, counter-clockwise positive. Not normalised by
    /// the constructor; composition wraps it to (-pi, pi].
    pub yaw_rad: f64,
}

impl Se2 {
    /// The identity transform.
    pub const IDENTITY: Se2 = Se2 { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 };

    /// A transform from its translation and rotation.
    #[must_use]
    pub const fn new(x_m: f64, y_m: f64, yaw_rad: f64) -> Self {
        Self { x_m, y_m, yaw_rad }
    }

    /// The inverse transform: `b_from_a = a_from_b.inverse()`.
    ///
    /// `T^-1 = [R^T, -R^T t]`.
    #[must_use]
    pub fn inverse(&self) -> Se2 {
        let (s, c) = self.yaw_rad.sin_cos();
        Se2 {
            x_m: -(c * self.x_m + s * self.y_m),
            y_m: -(-s * self.x_m + c * self.y_m),
            yaw_rad: wrap_angle_rad(-self.yaw_rad),
        }
    }

    /// Applies the transform to a point: `R p + t`.
    #[must_use]
    pub fn transform_point(&self, p: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.yaw_rad.sin_cos();
        [c * p[0] - s * p[1] + self.x_m, s * p[0] + c * p[1] + self.y_m]
    }

    /// Length of the translation, metres.
    #[must_use]
    pub fn translation_norm_m(&self) -> f64 {
        self.x_m.hypot(self.y_m)
    }

    /// True when every component is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.x_m.is_finite() && self.y_m.is_finite() && self.yaw_rad.is_finite()
    }
}

impl Mul for Se2 {
    type Output = Se2;

    /// Composition `a_from_c = a_from_b * b_from_c`: `[R1 R2, R1 t2 + t1]`.
    // Group composition adds rotation angles; clippy's heuristic flags the `+`.
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn mul(self, rhs: Se2) -> Se2 {
        let [x_m, y_m] = self.transform_point([rhs.x_m, rhs.y_m]);
        Se2 { x_m, y_m, yaw_rad: wrap_angle_rad(self.yaw_rad + rhs.yaw_rad) }
    }
}

/// Wraps an angle to (-pi, pi]. Angles already in range are returned
/// unchanged (bit for bit), so composing small rotations adds no rounding.
#[must_use]
pub fn wrap_angle_rad(angle_rad: f64) -> f64 {
    if angle_rad > -PI && angle_rad <= PI {
        return angle_rad;
    }
    let wrapped = (angle_rad + PI).rem_euclid(2.0 * PI) - PI;
    if wrapped == -PI { PI } else { wrapped }
}

/// A pose at a time: `parent_from_child` observed at `t_ns`.
///
/// In a recording, ground truth and estimated trajectories are sequences of
/// these with `parent` = "world" and `child` = "vehicle" (or the sensor frame).
#[derive(Debug, Clone, PartialEq)]
pub struct StampedPose {
    /// Time of validity, nanoseconds.
    pub t_ns: i64,
    /// The transform, parent frame from child frame.
    pub parent_from_child: Se2,
}

/// The pose at `t_ns` between two stamped poses `a.t_ns <= t_ns <= b.t_ns`:
/// x and y linear in time, yaw along the shortest arc
/// (`yaw_a + alpha * wrap(yaw_b - yaw_a)`, `alpha = (t - t_a) / (t_b - t_a)`).
#[must_use]
pub fn interpolate_pose(a: &StampedPose, b: &StampedPose, t_ns: i64) -> Se2 {
    let span = (i128::from(b.t_ns) - i128::from(a.t_ns)) as f64;
    let alpha = if span > 0.0 { (i128::from(t_ns) - i128::from(a.t_ns)) as f64 / span } else { 0.0 };
    let (pa, pb) = (a.parent_from_child, b.parent_from_child);
    Se2::new(
        pa.x_m + alpha * (pb.x_m - pa.x_m),
        pa.y_m + alpha * (pb.y_m - pa.y_m),
        wrap_angle_rad(pa.yaw_rad + alpha * wrap_angle_rad(pb.yaw_rad - pa.yaw_rad)),
    )
}

/// Total length of the path through the translations of `poses`, metres.
#[must_use]
pub fn path_length_m(poses: &[StampedPose]) -> f64 {
    poses
        .windows(2)
        .map(|w| {
            let a = &w[0].parent_from_child;
            let b = &w[1].parent_from_child;
            (b.x_m - a.x_m).hypot(b.y_m - a.y_m)
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Se2, b: Se2) -> bool {
        // 1e-12: a few ulps of the O(10) magnitudes used below.
        (a.x_m - b.x_m).abs() < 1e-12
            && (a.y_m - b.y_m).abs() < 1e-12
            && wrap_angle_rad(a.yaw_rad - b.yaw_rad).abs() < 1e-12
    }

    #[test]
    fn inverse_composes_to_identity() {
        let t = Se2::new(3.0, -2.0, 0.7);
        assert!(close(t * t.inverse(), Se2::IDENTITY));
        assert!(close(t.inverse() * t, Se2::IDENTITY));
    }

    #[test]
    fn composition_matches_point_transforms() {
        let a_from_b = Se2::new(1.0, 2.0, 0.5);
        let b_from_c = Se2::new(-4.0, 0.5, -2.0);
        let p_in_c = [0.3, -7.0];
        let via_b = a_from_b.transform_point(b_from_c.transform_point(p_in_c));
        let direct = (a_from_b * b_from_c).transform_point(p_in_c);
        assert!((via_b[0] - direct[0]).abs() < 1e-12 && (via_b[1] - direct[1]).abs() < 1e-12);
    }

    #[test]
    fn yaw_is_counter_clockwise() {
        let quarter_turn = Se2::new(0.0, 0.0, std::f64::consts::FRAC_PI_2);
        let p = quarter_turn.transform_point([1.0, 0.0]);
        assert!(p[0].abs() < 1e-15 && (p[1] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn wrap_stays_in_half_open_interval() {
        assert_eq!(wrap_angle_rad(PI), PI);
        assert_eq!(wrap_angle_rad(-PI), PI);
        assert!((wrap_angle_rad(3.0 * PI + 0.1) - (-PI + 0.1)).abs() < 1e-12);
        assert_eq!(wrap_angle_rad(-0.1), -0.1);
    }
}
