//! The measurement model of the appendix as the filter uses it: residuals
//! with wrapped angles, numerical Jacobians with respect to the UE and the
//! source, and the inversion of one path into hypothesised source positions
//! (the incidence point / SP and the VA of eq. (12)).

use faer::Mat;
use mmtrack_core::slam::{PathMeasurement, SourceType, UeState, norm3, predict_path, sub3, unit_vector};
use mmtrack_core::wrap_angle_rad;

/// UE components the measurements depend on, in the order of the Jacobians:
/// `[x, y, heading, clock bias]` (the height is known, Sec. V-A).
pub(crate) const UE_MEAS_DIM: usize = 4;

/// `eta(ue, source) - z`, angles wrapped to `(-pi, pi]`; `None` for a
/// degenerate geometry (the exact form [`FastPath::residual`] is checked
/// against).
#[cfg(test)]
pub(crate) fn residual(
    ue: &UeState,
    bs_m: [f64; 3],
    kind: SourceType,
    source_m: [f64; 3],
    z: &[f64; 5],
) -> Option<[f64; 5]> {
    let eta = predict_path(ue, bs_m, kind, source_m)?.to_array();
    Some([eta[0] - z[0], wrap_angle_rad(eta[1] - z[1]), eta[2] - z[2], wrap_angle_rad(eta[3] - z[3]), eta[4] - z[4]])
}

/// `eta` and its Jacobians with respect to the UE (`5 x 4`, [`UE_MEAS_DIM`])
/// and the source position (`5 x 3`) at `(ue, source)`, by central
/// differences (1 cm, 1 mrad steps: the model is smooth on that scale and
/// the noise is 10 cm / 10 mrad).
pub(crate) fn jacobians(
    ue: &UeState,
    bs_m: [f64; 3],
    kind: SourceType,
    source_m: [f64; 3],
) -> Option<([f64; 5], Mat<f64>, Mat<f64>)> {
    let eta = predict_path(ue, bs_m, kind, source_m)?.to_array();
    let diff = |a: [f64; 5], b: [f64; 5], h: f64| -> [f64; 5] {
        [
            (a[0] - b[0]) / h,
            wrap_angle_rad(a[1] - b[1]) / h,
            (a[2] - b[2]) / h,
            wrap_angle_rad(a[3] - b[3]) / h,
            (a[4] - b[4]) / h,
        ]
    };
    let mut h_ue = Mat::zeros(5, UE_MEAS_DIM);
    for j in 0..UE_MEAS_DIM {
        let step = if j == 2 { 1e-3 } else { 1e-2 };
        let shifted = |sign: f64| {
            let mut u = *ue;
            match j {
                0 => u.position_m[0] += sign * step,
                1 => u.position_m[1] += sign * step,
                2 => u.heading_rad += sign * step,
                _ => u.clock_bias_m += sign * step,
            }
            predict_path(&u, bs_m, kind, source_m).map(|p| p.to_array())
        };
        let d = diff(shifted(1.0)?, shifted(-1.0)?, 2.0 * step);
        for i in 0..5 {
            h_ue[(i, j)] = d[i];
        }
    }
    let mut h_src = Mat::zeros(5, 3);
    if kind != SourceType::BaseStation {
        for j in 0..3 {
            let step = 1e-2;
            let shifted = |sign: f64| {
                let mut s = source_m;
                s[j] += sign * step;
                predict_path(ue, bs_m, kind, s).map(|p| p.to_array())
            };
            let d = diff(shifted(1.0)?, shifted(-1.0)?, 2.0 * step);
            for i in 0..5 {
                h_src[(i, j)] = d[i];
            }
        }
    }
    Some((eta, h_ue, h_src))
}

/// The two source hypotheses one path gives for a UE at `position_m` with
/// heading and clock bias: the VA at distance `toa - B` along the DOA (eq.
/// (12)), and the point on the DOA ray whose bistatic path length from the
/// BS is `toa - B` (the SP, which for a reflection is the incidence point of
/// eq. (11)). The second is `None` when no such point exists (a path
/// shorter than the line of sight).
#[inline]
pub(crate) fn invert(
    position_m: [f64; 3],
    heading_rad: f64,
    clock_bias_m: f64,
    bs_m: [f64; 3],
    z: &PathMeasurement,
) -> ([f64; 3], Option<[f64; 3]>) {
    let d = z.toa_m - clock_bias_m;
    let u = unit_vector(z.doa_az_rad + heading_rad, z.doa_el_rad);
    let va = [position_m[0] + d * u[0], position_m[1] + d * u[1], position_m[2] + d * u[2]];
    // |p + r u| = d - r with p = x - x_BS: r = (d^2 - |p|^2) / (2 (p.u + d)).
    let p = sub3(position_m, bs_m);
    let pp = norm3(p);
    let den = 2.0 * (p[0] * u[0] + p[1] * u[1] + p[2] * u[2] + d);
    let sp = if d > pp && den > 0.0 {
        let r = (d * d - pp * pp) / den;
        Some([position_m[0] + r * u[0], position_m[1] + r * u[1], position_m[2] + r * u[2]])
    } else {
        None
    };
    (va, sp)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mmtrack_core::slam::incidence_point;
    use std::f64::consts::FRAC_PI_2;

    fn ue() -> UeState {
        UeState {
            position_m: [70.73, 10.0, 0.0],
            heading_rad: FRAC_PI_2,
            speed_mps: 22.0,
            turn_rate_radps: 0.3,
            clock_bias_m: 300.0,
        }
    }

    #[test]
    fn inversion_recovers_the_va_and_the_incidence_point() {
        let bs = [0.0, 0.0, 40.0];
        let va = [200.0, 0.0, 40.0];
        let z = predict_path(&ue(), bs, SourceType::VirtualAnchor, va).unwrap();
        let (va_hat, sp_hat) = invert(ue().position_m, ue().heading_rad, ue().clock_bias_m, bs, &z);
        assert!(norm3(sub3(va_hat, va)) < 1e-9, "{va_hat:?}");
        let xs = incidence_point(va, bs, ue().position_m).unwrap();
        assert!(norm3(sub3(sp_hat.unwrap(), xs)) < 1e-9, "{sp_hat:?} vs {xs:?}");
        let sp = [60.0, 40.0, 3.0];
        let z = predict_path(&ue(), bs, SourceType::ScatteringPoint, sp).unwrap();
        let (_, sp_hat) = invert(ue().position_m, ue().heading_rad, ue().clock_bias_m, bs, &z);
        assert!(norm3(sub3(sp_hat.unwrap(), sp)) < 1e-9);
    }

    #[test]
    fn jacobians_match_a_hand_derivative() {
        // dTOA/dB = 1, dDOA_az/dheading = -1, and a SP's DOD does not depend on the UE.
        let bs = [0.0, 0.0, 40.0];
        let (_, h_ue, h_src) = jacobians(&ue(), bs, SourceType::ScatteringPoint, [60.0, 40.0, 3.0]).unwrap();
        assert!((h_ue[(0, 3)] - 1.0).abs() < 1e-9);
        assert!((h_ue[(1, 2)] + 1.0).abs() < 1e-9);
        assert!(h_ue[(3, 0)].abs() < 1e-12 && h_ue[(4, 1)].abs() < 1e-12);
        // dTOA/dx_SP = unit(SP - BS) + unit(SP - x).
        let sp = [60.0, 40.0, 3.0];
        let a = sub3(sp, bs);
        let b = sub3(sp, ue().position_m);
        let expected = a[0] / norm3(a) + b[0] / norm3(b);
        assert!((h_src[(0, 0)] - expected).abs() < 1e-6);
        let r = residual(
            &ue(),
            bs,
            SourceType::BaseStation,
            bs,
            &predict_path(&ue(), bs, SourceType::BaseStation, bs).unwrap().to_array(),
        )
        .unwrap();
        assert!(r.iter().all(|v| v.abs() < 1e-12));
    }
}

/// A path prepared for [`fast_residual`]: the measured angles as sines and
/// cosines, and what does not depend on the particle.
#[derive(Debug, Clone)]
pub(crate) struct FastPath {
    kind: SourceType,
    source_m: [f64; 3],
    bs_m: [f64; 3],
    toa_m: f64,
    /// `(sin, cos)` of DOA az, DOA el, DOD az, DOD el.
    sc: [(f64, f64); 4],
    /// VA: unit normal of the wall towards the BS and half the VA-BS distance.
    wall: ([f64; 3], f64),
    /// SP: `|x_SP - x_BS|` and the (particle-independent) DOD residuals.
    sp: (f64, [f64; 2]),
}

/// The residual angle `a` from its sine and cosine, without a call to
/// `atan2`: `sin a` for `|a| <= pi/2`, continued monotonically to `+/-2` at
/// `+/-pi`. Equal to `a` to within `a^3 / 6` (1.7e-7 rad at 0.01 rad, the
/// measurement noise), and it keeps the sign and the order of larger
/// residuals, so a path pointing the wrong way is never mistaken for a good
/// one.
#[inline]
fn angle_residual(s: f64, c: f64) -> f64 {
    if c >= 0.0 {
        s
    } else if s >= 0.0 {
        2.0 - s
    } else {
        -2.0 - s
    }
}

/// `sin` and `cos` of `(direction's azimuth) - reference`, for a horizontal
/// direction `(dx, dy)` of length `rho`.
#[inline]
fn az_diff(dx: f64, dy: f64, rho: f64, (s_ref, c_ref): (f64, f64)) -> f64 {
    angle_residual((dy * c_ref - dx * s_ref) / rho, (dx * c_ref + dy * s_ref) / rho)
}

/// The same for elevations: `(dz, rho)` the vertical and horizontal parts,
/// `r` the length.
#[inline]
fn el_diff(dz: f64, rho: f64, r: f64, (s_ref, c_ref): (f64, f64)) -> f64 {
    angle_residual((dz * c_ref - rho * s_ref) / r, (rho * c_ref + dz * s_ref) / r)
}

impl FastPath {
    /// Prepares measurement `z` from a source of type `kind` at `source_m`.
    pub(crate) fn new(kind: SourceType, source_m: [f64; 3], bs_m: [f64; 3], z: &[f64; 5]) -> Self {
        let sc = [z[1].sin_cos(), z[2].sin_cos(), z[3].sin_cos(), z[4].sin_cos()];
        let mut wall = ([0.0; 3], 0.0);
        let mut sp = (0.0, [0.0; 2]);
        match kind {
            SourceType::VirtualAnchor => {
                let to_bs = sub3(bs_m, source_m);
                let len = norm3(to_bs);
                if len > 0.0 {
                    wall = ([to_bs[0] / len, to_bs[1] / len, to_bs[2] / len], 0.5 * len);
                }
            }
            SourceType::ScatteringPoint => {
                let q = sub3(source_m, bs_m);
                let rho = (q[0] * q[0] + q[1] * q[1]).sqrt();
                let r = norm3(q);
                if rho > 0.0 && r > 0.0 {
                    sp = (r, [az_diff(q[0], q[1], rho, sc[2]), el_diff(q[2], rho, r, sc[3])]);
                }
            }
            SourceType::BaseStation => {}
        }
        Self { kind, source_m, bs_m, toa_m: z[0], sc, wall, sp }
    }

    /// The residual `eta - z` of a UE at `x` with heading `(sin, cos)` and
    /// clock bias, angles as [`angle_residual`]; `None` for a degenerate
    /// geometry.
    #[inline]
    pub(crate) fn residual(&self, x: [f64; 3], heading_sc: (f64, f64), bias_m: f64) -> Option<[f64; 5]> {
        let src = if self.kind == SourceType::BaseStation { self.bs_m } else { self.source_m };
        let d = sub3(src, x);
        let rho = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let r = (rho * rho + d[2] * d[2]).sqrt();
        if rho <= 0.0 || r <= 0.0 {
            return None;
        }
        // DOA azimuth in the UE frame: reference = heading + measured azimuth.
        let (s_m, c_m) = self.sc[0];
        let (s_h, c_h) = heading_sc;
        let reference = (s_h * c_m + c_h * s_m, c_h * c_m - s_h * s_m);
        let doa_az = az_diff(d[0], d[1], rho, reference);
        let doa_el = el_diff(d[2], rho, r, self.sc[1]);
        let (toa, dod) = match self.kind {
            SourceType::BaseStation => {
                (r, [az_diff(-d[0], -d[1], rho, self.sc[2]), el_diff(-d[2], rho, r, self.sc[3])])
            }
            SourceType::ScatteringPoint => (self.sp.0 + r, self.sp.1),
            SourceType::VirtualAnchor => {
                // Incidence point (11): x_s = x_VA + s (x - x_VA), s = (|BS - VA|/2) / ((x - x_VA).u).
                let (u, half) = self.wall;
                let den = -(d[0] * u[0] + d[1] * u[1] + d[2] * u[2]);
                if den.abs() < 1e-12 {
                    return None;
                }
                let s = half / den;
                let q = [
                    self.source_m[0] - s * d[0] - self.bs_m[0],
                    self.source_m[1] - s * d[1] - self.bs_m[1],
                    self.source_m[2] - s * d[2] - self.bs_m[2],
                ];
                let rho_q = (q[0] * q[0] + q[1] * q[1]).sqrt();
                let r_q = (rho_q * rho_q + q[2] * q[2]).sqrt();
                if rho_q <= 0.0 || r_q <= 0.0 {
                    return None;
                }
                (r, [az_diff(q[0], q[1], rho_q, self.sc[2]), el_diff(q[2], rho_q, r_q, self.sc[3])])
            }
        };
        Some([toa + bias_m - self.toa_m, doa_az, doa_el, dod[0], dod[1]])
    }
}

#[cfg(test)]
mod fast_tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn the_fast_residual_matches_the_exact_one() {
        let bs = [0.0, 0.0, 40.0];
        let truth = UeState {
            position_m: [70.0, 12.0, 0.0],
            heading_rad: FRAC_PI_2 + 0.1,
            speed_mps: 22.0,
            turn_rate_radps: 0.3,
            clock_bias_m: 300.0,
        };
        let cases = [
            (SourceType::BaseStation, bs),
            (SourceType::VirtualAnchor, [200.0, 0.0, 40.0]),
            (SourceType::VirtualAnchor, [0.0, -200.0, 40.0]),
            (SourceType::ScatteringPoint, [60.0, 40.0, 3.0]),
        ];
        for (kind, src) in cases {
            let z = predict_path(&truth, bs, kind, src).unwrap().to_array();
            // Small errors (a few sigma): equal to within the cubic term.
            let z_noisy = [z[0] + 0.2, z[1] + 0.02, z[2] - 0.015, z[3] + 0.01, z[4] - 0.02];
            for (dx, dh) in [(0.0, 0.0), (0.3, 0.01), (-0.5, -0.02)] {
                let ue =
                    UeState { position_m: [70.0 + dx, 12.0 - dx, 0.0], heading_rad: truth.heading_rad + dh, ..truth };
                let exact = residual(&ue, bs, kind, src, &z_noisy).unwrap();
                let fast = FastPath::new(kind, src, bs, &z_noisy)
                    .residual(ue.position_m, ue.heading_rad.sin_cos(), ue.clock_bias_m)
                    .unwrap();
                for i in 0..5 {
                    let tol = 1e-9 + exact[i].abs().powi(3) / 6.0 * 1.01;
                    assert!(
                        (fast[i] - exact[i]).abs() <= tol,
                        "{kind:?} component {i}: fast {} exact {}",
                        fast[i],
                        exact[i]
                    );
                }
            }
            // A heading off by pi gives a DOA residual of magnitude near 2, never near 0.
            let flipped = FastPath::new(kind, src, bs, &z)
                .residual(truth.position_m, (truth.heading_rad + 3.1).sin_cos(), truth.clock_bias_m)
                .unwrap();
            assert!(flipped[1].abs() > 1.9, "{flipped:?}");
        }
    }
}
