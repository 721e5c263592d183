//! 5G mmWave SLAM data: one path measurement (TOA, DOA and DOD azimuth and
//! elevation), the UE state of the constant turn-rate velocity model, and the
//! geometry of the appendix of Kim et al. 2018 that links them to the sources
//! of the paths (the base station, virtual anchors, scattering points).
//!
//! Shared by the simulator (which draws measurements from it) and the SLAM
//! filter (which inverts it). Conventions:
//!
//! - positions are world coordinates in metres, `[x, y, z]`;
//! - the TOA is carried as a distance, `toa_m = c * tau`, so that it shares a
//!   unit with the clock bias `B` (metres), as in the paper's sigma = 0.1 m;
//! - DOA azimuth is measured in the UE frame (world azimuth minus heading),
//!   elevations are in `[-pi/2, pi/2]`, azimuths are wrapped to `(-pi, pi]`.
//!
//! # References
//! H. Kim, H. Wymeersch, N. Garcia, G. Seco-Granados, S. Kim, "5G mmWave
//! Vehicular Tracking", Asilomar 2018: eq. (1) (motion), footnote 1 (virtual
//! anchor), eq. (11)-(12) (incidence point) and the appendix (channel
//! parameters of LOS, VA and SP paths).

use std::f64::consts::FRAC_PI_2;

use crate::error::CoreError;
use crate::pose::wrap_angle_rad;

/// Number of components of one path measurement (TOA, DOA az/el, DOD az/el).
pub const PATH_MEASUREMENT_DIM: usize = 5;

/// One estimated propagation path, eq. (2): `z = [tau, theta, phi]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathMeasurement {
    /// Time of arrival times the speed of light, clock bias included, metres.
    pub toa_m: f64,
    /// Direction of arrival, azimuth in the UE frame, radians.
    pub doa_az_rad: f64,
    /// Direction of arrival, elevation, radians in `[-pi/2, pi/2]`.
    pub doa_el_rad: f64,
    /// Direction of departure, azimuth in the world frame at the BS, radians.
    pub dod_az_rad: f64,
    /// Direction of departure, elevation, radians in `[-pi/2, pi/2]`.
    pub dod_el_rad: f64,
}

impl PathMeasurement {
    /// The components in the fixed order `[toa_m, doa_az, doa_el, dod_az, dod_el]`.
    #[must_use]
    pub fn to_array(&self) -> [f64; PATH_MEASUREMENT_DIM] {
        [self.toa_m, self.doa_az_rad, self.doa_el_rad, self.dod_az_rad, self.dod_el_rad]
    }

    /// A measurement from `[toa_m, doa_az, doa_el, dod_az, dod_el]`.
    #[must_use]
    pub fn from_array(z: [f64; PATH_MEASUREMENT_DIM]) -> Self {
        Self { toa_m: z[0], doa_az_rad: z[1], doa_el_rad: z[2], dod_az_rad: z[3], dod_el_rad: z[4] }
    }

    /// Checks that every component is finite and both elevations lie in
    /// `[-pi/2, pi/2]`.
    ///
    /// # Errors
    /// [`CoreError::NotFinite`] or [`CoreError::OutOfRange`] naming the field.
    pub fn validate(&self) -> Result<(), CoreError> {
        let fields = [
            ("toa_m", self.toa_m),
            ("doa_az_rad", self.doa_az_rad),
            ("doa_el_rad", self.doa_el_rad),
            ("dod_az_rad", self.dod_az_rad),
            ("dod_el_rad", self.dod_el_rad),
        ];
        for (field, value) in fields {
            crate::error::ensure_finite(field, value)?;
        }
        for (field, value) in [("doa_el_rad", self.doa_el_rad), ("dod_el_rad", self.dod_el_rad)] {
            if !(-FRAC_PI_2..=FRAC_PI_2).contains(&value) {
                return Err(CoreError::OutOfRange { field, value, expected: "an elevation in [-pi/2, pi/2] rad" });
            }
        }
        Ok(())
    }
}

/// The type of a signal source.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SourceType {
    /// The base station (line of sight).
    BaseStation,
    /// A virtual anchor: the BS mirrored in a reflecting wall.
    VirtualAnchor,
    /// A scattering point (a small object).
    ScatteringPoint,
}

impl SourceType {
    /// A short lowercase name for tables: `bs`, `va`, `sp`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::BaseStation => "bs",
            Self::VirtualAnchor => "va",
            Self::ScatteringPoint => "sp",
        }
    }
}

/// Where a simulated path came from (ground truth only).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathOrigin {
    /// The line of sight from the BS.
    LineOfSight,
    /// A reflection off the wall of virtual anchor `index` (in the world's list).
    VirtualAnchor(usize),
    /// A scattering point `index` (in the world's list).
    ScatteringPoint(usize),
    /// A clutter path with no physical source.
    Clutter,
}

/// The UE state `s = [x, alpha, v, omega, B]` of Sec. II-A.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UeState {
    /// Position, metres.
    pub position_m: [f64; 3],
    /// Heading (orientation in the horizontal plane), radians.
    pub heading_rad: f64,
    /// Longitudinal speed, m/s.
    pub speed_mps: f64,
    /// Turn rate, rad/s.
    pub turn_rate_radps: f64,
    /// Clock bias as a distance, metres.
    pub clock_bias_m: f64,
}

impl UeState {
    /// The noise-free constant turn-rate velocity step of eq. (1) over
    /// `dt_s`; the straight-line limit is used when `|omega dt| < 1e-9`.
    #[must_use]
    pub fn ctrv_step(&self, dt_s: f64) -> Self {
        let (dx, dy) = ctrv_displacement_m(self.heading_rad, self.speed_mps, self.turn_rate_radps, dt_s);
        Self {
            position_m: [self.position_m[0] + dx, self.position_m[1] + dy, self.position_m[2]],
            heading_rad: wrap_angle_rad(self.heading_rad + self.turn_rate_radps * dt_s),
            ..*self
        }
    }
}

/// The horizontal displacement of eq. (1): `v/omega (sin(a + omega dt) - sin a)`,
/// `v/omega (cos a - cos(a + omega dt))`, with the straight-line limit
/// `v dt (cos a, sin a)` when `|omega dt| < 1e-9`.
#[must_use]
pub fn ctrv_displacement_m(heading_rad: f64, speed_mps: f64, turn_rate_radps: f64, dt_s: f64) -> (f64, f64) {
    let turn = turn_rate_radps * dt_s;
    if turn.abs() < 1e-9 {
        return (speed_mps * dt_s * heading_rad.cos(), speed_mps * dt_s * heading_rad.sin());
    }
    let r = speed_mps / turn_rate_radps;
    let (s0, c0) = heading_rad.sin_cos();
    let (s1, c1) = (heading_rad + turn).sin_cos();
    (r * (s1 - s0), r * (c0 - c1))
}

/// `a - b`.
#[must_use]
pub fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a . b`.
#[must_use]
pub fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `|a|`.
#[must_use]
pub fn norm3(a: [f64; 3]) -> f64 {
    dot3(a, a).sqrt()
}

/// The virtual anchor of a wall (footnote 1): the BS mirrored in the plane
/// through `wall_point_m` with normal `wall_normal` (any length, not zero),
/// `x_VA = P x_BS + t`, `P = I - 2 u u^T`, `t = 2 (f^T u) u`.
///
/// # Errors
/// [`CoreError::OutOfRange`] when the normal is zero or not finite.
pub fn virtual_anchor(bs_m: [f64; 3], wall_point_m: [f64; 3], wall_normal: [f64; 3]) -> Result<[f64; 3], CoreError> {
    let n = norm3(wall_normal);
    if !(n.is_finite() && n > 0.0) {
        return Err(CoreError::OutOfRange { field: "wall_normal", value: n, expected: "a non-zero finite normal" });
    }
    let u = [wall_normal[0] / n, wall_normal[1] / n, wall_normal[2] / n];
    // P x_BS + t = x_BS - 2 (u^T x_BS) u + 2 (f^T u) u = x_BS + 2 ((f - x_BS)^T u) u.
    let d = dot3(sub3(wall_point_m, bs_m), u);
    Ok([bs_m[0] + 2.0 * d * u[0], bs_m[1] + 2.0 * d * u[1], bs_m[2] + 2.0 * d * u[2]])
}

/// The incidence point of eq. (11): where the line from the VA to the UE
/// crosses the wall, with `u = (x_BS - x_VA)/|x_BS - x_VA|` and
/// `f = (x_BS + x_VA)/2`. `None` when the VA coincides with the BS or the
/// line is parallel to the wall.
#[must_use]
pub fn incidence_point(va_m: [f64; 3], bs_m: [f64; 3], ue_m: [f64; 3]) -> Option<[f64; 3]> {
    let to_bs = sub3(bs_m, va_m);
    let len = norm3(to_bs);
    if len.is_nan() || len <= 0.0 {
        return None;
    }
    let u = [to_bs[0] / len, to_bs[1] / len, to_bs[2] / len];
    // (f - x_VA)^T u = |x_BS - x_VA| / 2.
    let num = 0.5 * len;
    let dir = sub3(ue_m, va_m);
    let den = dot3(dir, u);
    if den.abs() < 1e-12 {
        return None;
    }
    let s = num / den;
    Some([va_m[0] + s * dir[0], va_m[1] + s * dir[1], va_m[2] + s * dir[2]])
}

/// The virtual anchor from an incidence point, eq. (12):
/// `x_VA = x + (|x - x_s| + |x_BS - x_s|) (x_s - x)/|x_s - x|`. `None` when
/// the incidence point coincides with the UE.
#[must_use]
pub fn va_from_incidence(ue_m: [f64; 3], incidence_m: [f64; 3], bs_m: [f64; 3]) -> Option<[f64; 3]> {
    let dir = sub3(incidence_m, ue_m);
    let r = norm3(dir);
    if r.is_nan() || r <= 0.0 {
        return None;
    }
    let total = r + norm3(sub3(bs_m, incidence_m));
    Some([ue_m[0] + total * dir[0] / r, ue_m[1] + total * dir[1] / r, ue_m[2] + total * dir[2] / r])
}

/// Azimuth and elevation of the direction `d` (`atan2(dy, dx)`,
/// `asin(dz/|d|)`); `None` for a zero vector.
#[must_use]
pub fn azimuth_elevation_rad(d: [f64; 3]) -> Option<(f64, f64)> {
    let r = norm3(d);
    if r.is_nan() || r <= 0.0 {
        return None;
    }
    Some((d[1].atan2(d[0]), (d[2] / r).clamp(-1.0, 1.0).asin()))
}

/// The unit vector of azimuth `az` and elevation `el`.
#[must_use]
pub fn unit_vector(az_rad: f64, el_rad: f64) -> [f64; 3] {
    let (sa, ca) = az_rad.sin_cos();
    let (se, ce) = el_rad.sin_cos();
    [ca * ce, sa * ce, se]
}

/// The noise-free channel parameters of a path from a source of type `kind`
/// at `source_m` to a UE in state `ue` (appendix):
///
/// - LOS: `tau = |x_BS - x| + B`, DOD towards the UE, DOA towards the BS;
/// - VA: `tau = |x_VA - x| + B`, DOD towards the incidence point (11), DOA
///   towards the VA;
/// - SP: `tau = |x_SP - x_BS| + |x_SP - x| + B`, DOD towards the SP, DOA
///   towards the SP.
///
/// DOA azimuths are relative to the heading. For a BS source `source_m` is
/// ignored. `None` when the geometry is degenerate (source at the UE).
#[must_use]
pub fn predict_path(ue: &UeState, bs_m: [f64; 3], kind: SourceType, source_m: [f64; 3]) -> Option<PathMeasurement> {
    let x = ue.position_m;
    let (toa_m, towards_source, departure) = match kind {
        SourceType::BaseStation => (norm3(sub3(bs_m, x)), sub3(bs_m, x), sub3(x, bs_m)),
        SourceType::VirtualAnchor => {
            let xs = incidence_point(source_m, bs_m, x)?;
            (norm3(sub3(source_m, x)), sub3(source_m, x), sub3(xs, bs_m))
        }
        SourceType::ScatteringPoint => {
            (norm3(sub3(source_m, bs_m)) + norm3(sub3(source_m, x)), sub3(source_m, x), sub3(source_m, bs_m))
        }
    };
    let (doa_az, doa_el) = azimuth_elevation_rad(towards_source)?;
    let (dod_az, dod_el) = azimuth_elevation_rad(departure)?;
    Some(PathMeasurement {
        toa_m: toa_m + ue.clock_bias_m,
        doa_az_rad: wrap_angle_rad(doa_az - ue.heading_rad),
        doa_el_rad: doa_el,
        dod_az_rad: dod_az,
        dod_el_rad: dod_el,
    })
}

/// One epoch of path measurements (an unordered set, Sec. II-B).
#[derive(Debug, Clone, PartialEq)]
pub struct SlamEpoch {
    /// Time of the epoch, nanoseconds since scenario start.
    pub t_ns: i64,
    /// The estimated paths.
    pub paths: Vec<PathMeasurement>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
    }

    #[test]
    fn virtual_anchor_mirrors_the_bs_in_the_wall() {
        // Wall x = 100 (normal +x): BS (0, 0, 40) mirrors to (200, 0, 40), the paper's VA.
        let va = virtual_anchor([0.0, 0.0, 40.0], [100.0, 7.0, -3.0], [2.0, 0.0, 0.0]).unwrap();
        assert!(close(va, [200.0, 0.0, 40.0], 1e-12), "{va:?}");
        // A diagonal wall through (10, 0, 0) with normal (1, 1, 0): BS at the origin mirrors to (10, 10, 0).
        let va = virtual_anchor([0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [1.0, 1.0, 0.0]).unwrap();
        assert!(close(va, [10.0, 10.0, 0.0], 1e-12), "{va:?}");
        assert!(virtual_anchor([0.0; 3], [1.0, 0.0, 0.0], [0.0; 3]).is_err());
    }

    #[test]
    fn incidence_point_by_hand() {
        // BS (0,0,40), wall x = 100, VA (200,0,40), UE (50, 0, 0): the line VA->UE
        // (150 m long in x) crosses x = 100 after 100/150 = 2/3 of the way, z = 40 - 40 * 2/3.
        let xs = incidence_point([200.0, 0.0, 40.0], [0.0, 0.0, 40.0], [50.0, 0.0, 0.0]).unwrap();
        assert!(close(xs, [100.0, 0.0, 40.0 - 40.0 * 2.0 / 3.0], 1e-12), "{xs:?}");
        // UE (50, 30, 0): parameter s = 100/150, y = 30 * 2/3 = 20.
        let xs = incidence_point([200.0, 0.0, 40.0], [0.0, 0.0, 40.0], [50.0, 30.0, 0.0]).unwrap();
        assert!(close(xs, [100.0, 20.0, 40.0 - 40.0 * 2.0 / 3.0], 1e-12), "{xs:?}");
        // Equal path lengths: |BS - xs| + |xs - UE| = |VA - UE| (specular reflection).
        let bs = [0.0, 0.0, 40.0];
        let ue = [50.0, 30.0, 0.0];
        let va = [200.0, 0.0, 40.0];
        assert!((norm3(sub3(bs, xs)) + norm3(sub3(xs, ue)) - norm3(sub3(va, ue))).abs() < 1e-9);
        assert!(incidence_point(bs, bs, ue).is_none());
    }

    #[test]
    fn va_from_incidence_inverts_eq_11() {
        let bs = [0.0, 0.0, 40.0];
        let va = [200.0, 0.0, 40.0];
        let ue = [50.0, 30.0, 0.0];
        let xs = incidence_point(va, bs, ue).unwrap();
        let back = va_from_incidence(ue, xs, bs).unwrap();
        assert!(close(back, va, 1e-9), "{back:?}");
        // By hand: UE (0,0,0), incidence (3,4,0), BS (3,4,12): |x - xs| = 5,
        // |BS - xs| = 12, so the VA is 17 m along (0.6, 0.8, 0).
        let back = va_from_incidence([0.0; 3], [3.0, 4.0, 0.0], [3.0, 4.0, 12.0]).unwrap();
        assert!(close(back, [10.2, 13.6, 0.0], 1e-12), "{back:?}");
    }

    #[test]
    fn predicted_paths_match_the_appendix() {
        let bs = [0.0, 0.0, 40.0];
        let ue = UeState {
            position_m: [70.73, 0.0, 0.0],
            heading_rad: FRAC_PI_2,
            speed_mps: 22.22,
            turn_rate_radps: PI / 10.0,
            clock_bias_m: 300.0,
        };
        // LOS: tau = |BS - x| + B; DOA az = pi + atan2(y, x) - alpha = pi/2;
        // DOA el = asin(40/d); DOD az = atan2(y, x) = 0; DOD el = -asin(40/d).
        let d = (70.73f64 * 70.73 + 1600.0).sqrt();
        let los = predict_path(&ue, bs, SourceType::BaseStation, [0.0; 3]).unwrap();
        assert!((los.toa_m - (d + 300.0)).abs() < 1e-9);
        assert!((los.doa_az_rad - FRAC_PI_2).abs() < 1e-12);
        assert!((los.doa_el_rad - (40.0 / d).asin()).abs() < 1e-12);
        assert!(los.dod_az_rad.abs() < 1e-12);
        assert!((los.dod_el_rad + (40.0 / d).asin()).abs() < 1e-12);
        // VA (200, 0, 40): tau = |VA - x| + B, DOA az = 0 - pi/2, DOD az = 0
        // (incidence point on the x axis), DOD el = elevation of xs - BS.
        let va = predict_path(&ue, bs, SourceType::VirtualAnchor, [200.0, 0.0, 40.0]).unwrap();
        let dva = (129.27f64 * 129.27 + 1600.0).sqrt();
        assert!((va.toa_m - (dva + 300.0)).abs() < 1e-9);
        assert!((va.doa_az_rad + FRAC_PI_2).abs() < 1e-12);
        assert!((va.doa_el_rad - (40.0 / dva).asin()).abs() < 1e-12);
        assert!(va.dod_az_rad.abs() < 1e-12);
        // xs z = 40 - 40 * 100/129.27; the DOD points down from the BS by
        // atan(40*100/129.27 / 100) = atan(40/129.27).
        assert!((va.dod_el_rad + (40.0f64 / 129.27).atan()).abs() < 1e-12);
        // SP (70.73, 30, 0): tau = |SP - BS| + 30 + B, DOA az = pi/2 - pi/2 = 0.
        let sp = predict_path(&ue, bs, SourceType::ScatteringPoint, [70.73, 30.0, 0.0]).unwrap();
        let dsp = (70.73f64 * 70.73 + 900.0 + 1600.0).sqrt();
        assert!((sp.toa_m - (dsp + 30.0 + 300.0)).abs() < 1e-9);
        assert!(sp.doa_az_rad.abs() < 1e-12);
        assert!(sp.doa_el_rad.abs() < 1e-12);
        assert!((sp.dod_az_rad - (30.0f64).atan2(70.73)).abs() < 1e-12);
        assert!((sp.dod_el_rad + (40.0 / dsp).asin()).abs() < 1e-12);
    }

    #[test]
    fn ctrv_step_follows_the_circle() {
        // Radius v/omega = 70.73 m around the origin: after a quarter turn (5 s) the UE is at (0, 70.73).
        let omega = PI / 10.0;
        let mut ue = UeState {
            position_m: [22.22 / omega, 0.0, 0.0],
            heading_rad: FRAC_PI_2,
            speed_mps: 22.22,
            turn_rate_radps: omega,
            clock_bias_m: 0.0,
        };
        for _ in 0..25 {
            ue = ue.ctrv_step(0.2);
        }
        assert!(close(ue.position_m, [0.0, 22.22 / omega, 0.0], 1e-9), "{:?}", ue.position_m);
        assert!(wrap_angle_rad(ue.heading_rad - PI).abs() < 1e-9);
        let straight = UeState { turn_rate_radps: 0.0, heading_rad: 0.0, ..ue }.ctrv_step(1.0);
        assert!((straight.position_m[0] - ue.position_m[0] - 22.22).abs() < 1e-12);
    }

    #[test]
    fn validation_names_the_bad_field() {
        let good = PathMeasurement { toa_m: 1.0, doa_az_rad: 0.0, doa_el_rad: 0.1, dod_az_rad: 3.0, dod_el_rad: -0.2 };
        assert!(good.validate().is_ok());
        let nan = PathMeasurement { doa_az_rad: f64::NAN, ..good };
        assert!(matches!(nan.validate(), Err(CoreError::NotFinite { field: "doa_az_rad", .. })));
        let el = PathMeasurement { dod_el_rad: 2.0, ..good };
        assert!(matches!(el.validate(), Err(CoreError::OutOfRange { field: "dod_el_rad", .. })));
        assert_eq!(PathMeasurement::from_array(good.to_array()), good);
    }
}
