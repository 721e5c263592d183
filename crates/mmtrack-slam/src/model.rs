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
/// degenerate geometry.
#[inline]
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
