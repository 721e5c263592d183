//! WGS-84 geodetic coordinates to a local East-North-Up frame, exactly (via
//! Earth-centred Earth-fixed coordinates, no flat-earth approximation).

/// Origin of a local East-North-Up frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnuOrigin {
    /// Geodetic latitude, degrees.
    pub latitude_deg: f64,
    /// Geodetic longitude, degrees.
    pub longitude_deg: f64,
    /// Ellipsoidal height, metres.
    pub altitude_m: f64,
}

/// WGS-84 semi-major axis, metres.
const WGS84_A_M: f64 = 6_378_137.0;
/// WGS-84 flattening.
const WGS84_F: f64 = 1.0 / 298.257_223_563;

/// WGS-84 geodetic to Earth-centred Earth-fixed, metres:
/// `X = (N + h) cos(phi) cos(lambda)`, `Y = (N + h) cos(phi) sin(lambda)`,
/// `Z = (N (1 - e^2) + h) sin(phi)`, with `N = a / sqrt(1 - e^2 sin^2(phi))`
/// and `e^2 = f (2 - f)`.
fn ecef_m(latitude_deg: f64, longitude_deg: f64, altitude_m: f64) -> [f64; 3] {
    let e2 = WGS84_F * (2.0 - WGS84_F);
    let (sin_phi, cos_phi) = latitude_deg.to_radians().sin_cos();
    let (sin_lambda, cos_lambda) = longitude_deg.to_radians().sin_cos();
    let n = WGS84_A_M / (1.0 - e2 * sin_phi * sin_phi).sqrt();
    [
        (n + altitude_m) * cos_phi * cos_lambda,
        (n + altitude_m) * cos_phi * sin_lambda,
        (n * (1.0 - e2) + altitude_m) * sin_phi,
    ]
}

/// Geodetic position (WGS-84, ellipsoidal height) to local East-North-Up
/// metres about `origin`, exactly: both points go to ECEF
/// (`X = (N + h) cos(phi) cos(lambda)`, `Y = (N + h) cos(phi) sin(lambda)`,
/// `Z = (N (1 - e^2) + h) sin(phi)`, `N = a / sqrt(1 - e^2 sin^2(phi))`,
/// `a = 6378137 m`, `f = 1 / 298.257223563`, `e^2 = f (2 - f)`), and their
/// difference `d = p - p0` is rotated into the origin's tangent frame
/// (`p0`, `l0` the origin's latitude and longitude):
/// `e = -sin(l0) dx + cos(l0) dy`,
/// `n = -sin(p0) cos(l0) dx - sin(p0) sin(l0) dy + cos(p0) dz`,
/// `u = cos(p0) cos(l0) dx + cos(p0) sin(l0) dy + sin(p0) dz`.
/// Far points therefore get a negative `u` from the Earth's curvature.
#[must_use]
pub fn geodetic_to_enu_m(origin: &EnuOrigin, latitude_deg: f64, longitude_deg: f64, altitude_m: f64) -> [f64; 3] {
    let p0 = ecef_m(origin.latitude_deg, origin.longitude_deg, origin.altitude_m);
    let p = ecef_m(latitude_deg, longitude_deg, altitude_m);
    let d = [p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]];
    let (sp, cp) = origin.latitude_deg.to_radians().sin_cos();
    let (sl, cl) = origin.longitude_deg.to_radians().sin_cos();
    [-sl * d[0] + cl * d[1], -sp * cl * d[0] - sp * sl * d[1] + cp * d[2], cp * cl * d[0] + cp * sl * d[1] + sp * d[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    const E2: f64 = WGS84_F * (2.0 - WGS84_F);

    #[test]
    fn origin_maps_to_zero_and_height_to_up() {
        let origin = EnuOrigin { latitude_deg: 0.0, longitude_deg: 0.0, altitude_m: 0.0 };
        assert_eq!(geodetic_to_enu_m(&origin, 0.0, 0.0, 0.0), [0.0, 0.0, 0.0]);
        let [e, n, u] = geodetic_to_enu_m(&origin, 0.0, 0.0, 100.0);
        assert!(e.abs() < 1e-9 && n.abs() < 1e-9 && (u - 100.0).abs() < 1e-9, "{e} {n} {u}");
        // Away from the equator and the prime meridian too.
        let mtv = EnuOrigin { latitude_deg: 37.42, longitude_deg: -122.08, altitude_m: -25.0 };
        let [e, n, u] = geodetic_to_enu_m(&mtv, mtv.latitude_deg, mtv.longitude_deg, mtv.altitude_m);
        assert!(e.abs() < 1e-6 && n.abs() < 1e-6 && u.abs() < 1e-6, "{e} {n} {u}");
        let [e, n, u] = geodetic_to_enu_m(&mtv, mtv.latitude_deg, mtv.longitude_deg, mtv.altitude_m + 100.0);
        assert!(e.abs() < 1e-6 && n.abs() < 1e-6 && (u - 100.0).abs() < 1e-6, "{e} {n} {u}");
    }

    #[test]
    fn small_steps_match_the_meridian_arc_and_parallel_radius() {
        // At the equator the meridian radius of curvature is
        // M = a (1 - e^2) = 6335439.327 m per radian, so 0.001 deg north is
        // M * 1.745329e-5 = 110.5743 m (the published 110.574 km per degree).
        // The ENU north of that point is the chord, which differs from the arc
        // by about d^3 / (24 M^2) ~ 1e-9 m; 1 mm also covers the rounding of
        // the literal. The point also drops below the tangent plane by
        // n^2 / (2 R) with R ~ N = a at the equator: 0.96 mm.
        let origin = EnuOrigin { latitude_deg: 0.0, longitude_deg: 0.0, altitude_m: 0.0 };
        let [e, n, u] = geodetic_to_enu_m(&origin, 0.001, 0.0, 0.0);
        assert!(e.abs() < 1e-9, "{e}");
        assert!((n - 110.574).abs() < 1e-3, "{n}");
        assert!((n - WGS84_A_M * (1.0 - E2) * 0.001f64.to_radians()).abs() < 1e-6, "{n}");
        assert!((u + n * n / (2.0 * WGS84_A_M)).abs() < 1e-5, "{u}");
        // 0.001 deg east at 37.42 N: the radius of the parallel is N cos(phi),
        // N = a / sqrt(1 - e^2 sin^2 phi); again chord and arc agree to < 1 um.
        let mtv = EnuOrigin { latitude_deg: 37.42, longitude_deg: -122.08, altitude_m: 0.0 };
        let [e, n, _] = geodetic_to_enu_m(&mtv, 37.42, -122.079, 0.0);
        let phi = 37.42f64.to_radians();
        let parallel_radius_m = WGS84_A_M / (1.0 - E2 * phi.sin().powi(2)).sqrt() * phi.cos();
        assert!((e - parallel_radius_m * 0.001f64.to_radians()).abs() < 1e-6, "{e}");
        assert!((e - 88.520).abs() < 1e-3, "{e}");
        // Along a parallel the chord tilts towards the pole: n ~ e^2 tan(phi) / (2 N) ~ 0.5 mm.
        assert!(n > 0.0 && n < 1e-3, "{n}");
    }
}
