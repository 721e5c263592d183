//! Plausibility bounds: the one place that says which values read from a
//! file are believable, so that a wrong file is refused instead of turning
//! into a silently wrong result.
//!
//! Every reader (Oxford, Boreas, MulRan, TUM/KITTI/Oxford poses, NMEA, ROS 2
//! bags, DeepSense arrays) and `analyze` check what they read against these
//! bounds and wrap an [`Implausible`] with the file, the record and the field.
//! Each bound is far outside any real value of its kind (so nothing real is
//! refused) and far inside what breaks the arithmetic downstream (1e300
//! metres squares to infinity; a latitude of 200 deg projects to nonsense).
//! Issue 26 lists the inputs that motivated each.

use std::fmt;

/// A value outside its plausible range: what it is, and what was expected.
#[derive(Debug, Clone, PartialEq)]
pub struct Implausible {
    /// The value as read.
    pub value: f64,
    /// What a plausible value is, in words, with the bound.
    pub expected: &'static str,
}

impl fmt::Display for Implausible {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // 1e300 as written, not as 301 digits.
        if self.value.is_finite() && self.value.abs() >= 1e9 {
            write!(f, "{:e} is not {}", self.value, self.expected)
        } else {
            write!(f, "{} is not {}", self.value, self.expected)
        }
    }
}

impl std::error::Error for Implausible {}

/// A closed interval of plausible values of one kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// Smallest plausible value.
    pub min: f64,
    /// Largest plausible value.
    pub max: f64,
    /// What an error says was expected; it states `min` and `max`.
    pub expected: &'static str,
}

impl Bound {
    /// `value` if it is finite and within the bound.
    ///
    /// # Errors
    /// [`Implausible`] for NaN, infinities and values outside `[min, max]`.
    pub fn check(&self, value: f64) -> Result<f64, Implausible> {
        if value >= self.min && value <= self.max {
            Ok(value)
        } else {
            Err(Implausible { value, expected: self.expected })
        }
    }
}

/// Geodetic latitude, degrees.
pub const LATITUDE_DEG: Bound = Bound { min: -90.0, max: 90.0, expected: "a latitude within [-90, 90] deg" };

/// Geodetic longitude, degrees.
pub const LONGITUDE_DEG: Bound = Bound { min: -180.0, max: 180.0, expected: "a longitude within [-180, 180] deg" };

/// Altitude or ellipsoidal height of a ground vehicle's receiver, metres:
/// the Dead Sea shore is at -430 m, the highest road near 5 800 m; the bound
/// allows aircraft and geoid offsets with a wide margin. A GNSS altitude
/// becomes the origin of a recording's local frame, so a wrong one moves
/// every position.
pub const ALTITUDE_M: Bound = Bound { min: -1_000.0, max: 100_000.0, expected: "an altitude within [-1000, 100000] m" };

/// A position coordinate, metres: local frames, UTM eastings/northings
/// (below 1e7 m) and Earth-centred coordinates (below 6.4e6 m) all fit with
/// a wide margin; 1e300 does not (its square overflows in every distance).
pub const COORDINATE_M: Bound =
    Bound { min: -1.0e8, max: 1.0e8, expected: "a coordinate within +-1e8 m (any place on Earth, in any frame)" };

/// An angle read from a file, radians: headings are usually wrapped to one
/// turn; unwrapped headings of very long drives reach hundreds of turns.
pub const ANGLE_RAD: Bound = Bound { min: -1.0e6, max: 1.0e6, expected: "an angle within +-1e6 rad" };

/// How far a rotation matrix read from a file may be from orthonormal: the
/// largest entry of `R^T R - I`. Files print rotations to 6 or more
/// significant digits (KITTI: `%e`), about 1e-6 off; a matrix off by more
/// than 1e-3 is not a rotation written out (a scale, a shear, columns read
/// from the wrong place).
pub const ROTATION_ORTHONORMAL_TOLERANCE: f64 = 1e-3;

/// Checks that `r` (row-major) is a rotation: orthonormal within
/// [`ROTATION_ORTHONORMAL_TOLERANCE`] and with determinant +1 (not a
/// reflection).
///
/// # Errors
/// A sentence naming the largest deviation, or the determinant.
pub fn check_rotation(r: &[[f64; 3]; 3]) -> Result<(), String> {
    if r.iter().flatten().any(|v| !v.is_finite()) {
        return Err(format!("the rotation {r:?} has an entry that is not finite"));
    }
    let mut worst = 0.0_f64;
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
            let identity = if i == j { 1.0 } else { 0.0 };
            // NaN (entries so large that their products overflow) counts as the worst.
            let deviation = (dot - identity).abs();
            worst = if deviation.is_nan() { f64::INFINITY } else { worst.max(deviation) };
        }
    }
    if worst > ROTATION_ORTHONORMAL_TOLERANCE {
        return Err(format!(
            "the rotation is not orthonormal: R^T R differs from the identity by {worst:.3e} \
             (at most {ROTATION_ORTHONORMAL_TOLERANCE:e} for a rotation written out)"
        ));
    }
    let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    if det <= 0.0 {
        return Err(format!("the rotation has determinant {det:.3}: a reflection, not a rotation"));
    }
    Ok(())
}

/// How far the per-azimuth times in a Navtech scan's row headers may be
/// from the scan's own stamp (its file name), ns. A sweep lasts 0.25 s
/// (4 Hz); datasets stamp a scan at its first azimuth (Oxford: the first row
/// equals the file name to the microsecond) or near its middle. One second
/// is four sweeps; an hour's offset, a 1970 or a 2200 row time is refused.
pub const SCAN_ROW_TIME_TOLERANCE_NS: i64 = 1_000_000_000;

/// Whether `t_ns` lies within `tolerance_ns` of `reference_ns` (overflow
/// safe).
#[must_use]
pub fn time_near(t_ns: i64, reference_ns: i64, tolerance_ns: i64) -> bool {
    (i128::from(t_ns) - i128::from(reference_ns)).abs() <= i128::from(tolerance_ns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_refuse_nan_infinities_and_values_outside() {
        assert_eq!(LATITUDE_DEG.check(51.75), Ok(51.75));
        assert_eq!(LATITUDE_DEG.check(-90.0), Ok(-90.0));
        let err = LATITUDE_DEG.check(200.0).unwrap_err();
        assert_eq!(err.to_string(), "200 is not a latitude within [-90, 90] deg");
        let word = |v: f64| COORDINATE_M.check(v).unwrap_err().to_string().split(' ').next().map(str::to_string);
        assert_eq!((word(-2e8).as_deref(), word(1e300).as_deref()), (Some("-200000000"), Some("1e300")));
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300] {
            assert!(COORDINATE_M.check(bad).is_err(), "{bad}");
            assert!(ANGLE_RAD.check(bad).is_err(), "{bad}");
            assert!(ALTITUDE_M.check(bad).is_err(), "{bad}");
        }
        // Real values of each kind pass: Oxford INS northing, Dead Sea, Everest.
        assert!(COORDINATE_M.check(5_735_990.0).is_ok());
        assert!(ALTITUDE_M.check(-430.0).is_ok() && ALTITUDE_M.check(8_849.0).is_ok());
        assert!(LONGITUDE_DEG.check(-1.26).is_ok() && LONGITUDE_DEG.check(180.5).is_err());
    }

    #[test]
    fn rotations_pass_and_scaled_or_reflected_matrices_do_not() {
        let (s, c) = 0.3_f64.sin_cos();
        let yaw = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        assert!(check_rotation(&yaw).is_ok());
        // Printed to 6 digits, as KITTI files are.
        let printed = yaw.map(|row| row.map(|v| (v * 1e6).round() / 1e6));
        assert!(check_rotation(&printed).is_ok());
        let twice = [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]];
        let err = check_rotation(&twice).unwrap_err();
        assert!(err.contains("not orthonormal") && err.contains("3.000e0"), "{err}");
        let mirror = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(check_rotation(&mirror).unwrap_err().contains("reflection"));
        let nan = [[f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(check_rotation(&nan).is_err());
    }

    #[test]
    fn time_near_is_symmetric_and_does_not_overflow() {
        assert!(time_near(10, 0, 10) && time_near(-10, 0, 10) && !time_near(11, 0, 10));
        assert!(!time_near(i64::MAX, i64::MIN, SCAN_ROW_TIME_TOLERANCE_NS));
    }
}
