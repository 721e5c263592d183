//! The position-velocity-gain EKF of Shaham et al. 2020 on the overpass link.
//!
//! State `x = [d, v, Re alpha, Im alpha]` (eq. (8)): the vehicle's horizontal
//! distance from the overpass (m), its speed (m/s) and the channel
//! coefficient. Motion is linear, `x[k+1] = A x[k] + u[k]` (eq. (13)); the
//! pilot received through beams pointed from the prediction is
//!
//! ```text
//! z = alpha AF_r(cos theta) conj(AF_t(cos phi)),  cos theta = -d / r,  cos phi = d / r,  r = sqrt(h^2 + d^2)
//! ```
//!
//! (eq. (16), (20)-(22); `AF` the array factor of `mmtrack_core::array`),
//! with the Jacobian
//!
//! ```text
//! dz/dd      = alpha [AF_r'(cos theta) (-h^2 / r^3) conj(AF_t) + AF_r conj(AF_t'(cos phi)) (h^2 / r^3)]   (31)
//! dz/dv      = 0            (the state's own v; see below)
//! dz/dRe a   = AF_r conj(AF_t),   dz/dIm a = j AF_r conj(AF_t)
//! ```
//!
//! written as stacked real and imaginary rows (Sec. III-C).
//!
//! Two readings of the paper, both implemented ([`ProcessModel`]):
//! - eq. (14)-(15) as printed: `alpha` rows of `A` equal to 1 and
//!   `Sigma_u = diag(dt sigma_w^2, sigma_w^2, 1 - rho^2, 1 - rho^2)`;
//! - the kinematic model that eq. (9)-(12) define and the simulator draws
//!   from: `alpha` rows `rho`, the speed noise entering `d` and `v` together
//!   (`sigma_w^2 [[dt^2, dt], [dt, 1]]`) and `(1 - rho^2) / 2` per part of
//!   `alpha` (the default).
//!
//! Eq. (32), `dz/dv = dt dz/dd`, is the derivative through the *previous*
//! block's speed (the paper writes `z[k]` in terms of `d[k-1] + v[k-1] dt`);
//! here the measurement is a function of the predicted state, whose `d`
//! already carries `v dt`, and the recursion's `A P A^T` propagates that
//! dependence, so `dz/dv = 0` for the current state.
//!
//! Start (Sec. III-C): `x[0|0] = x0` from the channel estimate and
//! `P[1|0] = Sigma_u` (for the kinematic model its diagonal: the full matrix
//! is singular).

use mmtrack_core::Complex64;
use mmtrack_core::array::UniformLinearArray;
use mmtrack_filter::faer::{Col, Mat};
use mmtrack_filter::{FilterError, Gaussian, NonlinearMeasurement};
use serde::{Deserialize, Serialize};

use crate::error::check;
use crate::link::{PilotEkf, set_complex_column, stacked, stacked_noise_cov};
use crate::{BeamError, BeamPair, PilotTracker};

/// Which process model the filter assumes (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ProcessModel {
    /// `A` and `Sigma_u` consistent with eq. (9)-(12).
    #[default]
    Kinematic,
    /// `A` and `Sigma_u` exactly as printed in eq. (14)-(15).
    PaperTable,
}

/// Parameters of [`PositionVelocityEkf`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PositionVelocityEkfConfig {
    /// Overpass height `h`, metres.
    pub height_m: f64,
    /// Elements of each half-wavelength ULA.
    pub elements: usize,
    /// Block duration `dt`, seconds.
    pub block_s: f64,
    /// Gauss-Markov correlation `rho` of `alpha`.
    pub rho: f64,
    /// Speed noise `sigma_w` per block, m/s.
    pub speed_sigma_mps: f64,
    /// Pilot noise variance `sigma_n^2` (unit-power channel: `10^(-SNR/10)`).
    pub noise_variance: f64,
    /// Process model.
    pub process_model: ProcessModel,
}

/// The tracker (module docs).
#[derive(Debug, Clone)]
pub struct PositionVelocityEkf {
    height_m: f64,
    array: UniformLinearArray,
    noise_cov: Mat<f64>,
    ekf: PilotEkf,
}

impl PositionVelocityEkf {
    /// Starts from the channel estimate `x0 = [distance_m, speed_mps, alpha]`.
    ///
    /// # Errors
    /// [`BeamError::BadConfig`] naming a bad parameter or start value.
    pub fn new(
        config: &PositionVelocityEkfConfig,
        distance_m: f64,
        speed_mps: f64,
        alpha: Complex64,
    ) -> Result<Self, BeamError> {
        let c = config;
        check("height_m", c.height_m, c.height_m > 0.0, "a positive height")?;
        check("block_s", c.block_s, c.block_s > 0.0, "a positive duration")?;
        check("rho", c.rho, (0.0..1.0).contains(&c.rho), "a correlation in [0, 1)")?;
        check("speed_sigma_mps", c.speed_sigma_mps, c.speed_sigma_mps > 0.0, "a positive standard deviation")?;
        check("noise_variance", c.noise_variance, c.noise_variance > 0.0, "a positive variance")?;
        check("distance_m", distance_m, true, "a finite distance")?;
        check("speed_mps", speed_mps, true, "a finite speed")?;
        check("alpha", alpha.norm(), true, "a finite channel coefficient")?;
        let array = UniformLinearArray::half_wavelength(c.elements).map_err(|_| BeamError::BadConfig {
            field: "elements",
            value: c.elements.to_string(),
            expected: "at least one element",
        })?;
        let (dt, s2) = (c.block_s, c.speed_sigma_mps * c.speed_sigma_mps);
        let (transition, process_cov, initial_cov) = match c.process_model {
            ProcessModel::Kinematic => {
                let a = 0.5 * (1.0 - c.rho * c.rho);
                let q = matrix(&[
                    [s2 * dt * dt, s2 * dt, 0.0, 0.0],
                    [s2 * dt, s2, 0.0, 0.0],
                    [0.0, 0.0, a, 0.0],
                    [0.0, 0.0, 0.0, a],
                ]);
                let p0 = Mat::from_fn(4, 4, |i, j| if i == j { q[(i, i)] } else { 0.0 });
                (transition(dt, c.rho), q, p0)
            }
            ProcessModel::PaperTable => {
                let a = 1.0 - c.rho * c.rho;
                let q = diagonal(&[dt * s2, s2, a, a]);
                (transition(dt, 1.0), q.clone(), q)
            }
        };
        let start = Col::from_fn(4, |i| [distance_m, speed_mps, alpha.re, alpha.im][i]);
        let ekf = PilotEkf::new(start, transition, process_cov, initial_cov)?;
        Ok(Self { height_m: c.height_m, array, noise_cov: stacked_noise_cov(c.noise_variance), ekf })
    }

    /// The current estimate (after the last predict or update).
    #[must_use]
    pub fn state(&self) -> &Gaussian {
        self.ekf.state()
    }

    /// Estimated distance from the overpass, metres.
    #[must_use]
    pub fn distance_m(&self) -> f64 {
        self.ekf.state().mean()[0]
    }

    /// Estimated speed, m/s.
    #[must_use]
    pub fn speed_mps(&self) -> f64 {
        self.ekf.state().mean()[1]
    }
}

impl PilotTracker for PositionVelocityEkf {
    fn predict(&mut self) -> Result<BeamPair, BeamError> {
        let height_m = self.height_m;
        self.ekf.predict(|x| {
            let (rx_steer_u, tx_steer_u) = direction_cosines(height_m, x[0]);
            BeamPair { rx_steer_u, tx_steer_u }
        })
    }

    fn update(&mut self, pilot: Complex64) -> Result<(), BeamError> {
        let (height_m, array) = (self.height_m, self.array);
        self.ekf.update(pilot, |beams| OverpassPilot { height_m, array, beams, noise_cov: &self.noise_cov })
    }
}

/// The pilot as a function of the state (module docs), for given beams.
pub(crate) struct OverpassPilot<'a> {
    pub(crate) height_m: f64,
    pub(crate) array: UniformLinearArray,
    pub(crate) beams: BeamPair,
    pub(crate) noise_cov: &'a Mat<f64>,
}

impl NonlinearMeasurement for OverpassPilot<'_> {
    fn state_dim(&self) -> usize {
        4
    }

    fn evaluate(&self, x: &Col<f64>) -> Result<(Col<f64>, Mat<f64>), FilterError> {
        let (d, h) = (x[0], self.height_m);
        let alpha = Complex64::new(x[2], x[3]);
        let r = h.hypot(d);
        let (rx_u, tx_u) = direction_cosines(h, d);
        let (af_r, daf_r) = self.array.array_factor_with_derivative(self.beams.rx_steer_u, rx_u);
        let (af_t, daf_t) = self.array.array_factor_with_derivative(self.beams.tx_steer_u, tx_u);
        let gain = af_r * af_t.conj();
        // d cos(phi) / dd = h^2 / r^3 = -d cos(theta) / dd.
        let du_dd = h * h / (r * r * r);
        let dz_dd = alpha * (daf_r * (-du_dd) * af_t.conj() + af_r * daf_t.conj() * du_dd);
        let mut jacobian = Mat::zeros(2, 4);
        set_complex_column(&mut jacobian, 0, dz_dd);
        set_complex_column(&mut jacobian, 2, gain);
        set_complex_column(&mut jacobian, 3, Complex64::i() * gain);
        Ok((stacked(alpha * gain), jacobian))
    }

    fn noise_cov(&self) -> &Mat<f64> {
        self.noise_cov
    }
}

/// `(cos theta, cos phi) = (-d / r, d / r)` (eq. (20)-(21)).
fn direction_cosines(height_m: f64, distance_m: f64) -> (f64, f64) {
    let r = height_m.hypot(distance_m);
    (-distance_m / r, distance_m / r)
}

/// `A` of eq. (14) with `alpha` rows `rho_alpha`.
fn transition(dt: f64, rho_alpha: f64) -> Mat<f64> {
    matrix(&[[1.0, dt, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, rho_alpha, 0.0], [0.0, 0.0, 0.0, rho_alpha]])
}

fn matrix(rows: &[[f64; 4]; 4]) -> Mat<f64> {
    Mat::from_fn(4, 4, |i, j| rows[i][j])
}

fn diagonal(values: &[f64; 4]) -> Mat<f64> {
    Mat::from_fn(4, 4, |i, j| if i == j { values[i] } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use mmtrack_filter::numerical_jacobian;

    use super::*;

    #[test]
    fn jacobian_31_matches_finite_differences() {
        let noise_cov = stacked_noise_cov(1.0);
        let array = UniformLinearArray::half_wavelength(16).unwrap();
        for (d, steer) in [(-3.0, (0.70, -0.71)), (-0.4, (0.2, -0.1)), (2.0, (-0.5, 0.55))] {
            let model = OverpassPilot {
                height_m: 3.0,
                array,
                beams: BeamPair { rx_steer_u: steer.0, tx_steer_u: steer.1 },
                noise_cov: &noise_cov,
            };
            let x = Col::from_fn(4, |i| [d, 16.7, 0.6, -0.8][i]);
            let (_, analytic) = model.evaluate(&x).unwrap();
            let numeric = numerical_jacobian(|x| model.evaluate(x).unwrap().0, &x, &[1e-6; 4]);
            // Central differences, h = 1e-6 on a function with curvature ~ (2 pi N / r)^2:
            // truncation ~ 1e-12 * 1e3, round-off ~ 1e-16 / 1e-6.
            assert!((&analytic - &numeric).norm_max() < 1e-7, "d = {d}: {analytic:?} vs {numeric:?}");
        }
    }

    #[test]
    fn bad_config_and_misuse_are_errors() {
        let config = PositionVelocityEkfConfig {
            height_m: 3.0,
            elements: 16,
            block_s: 1e-3,
            rho: 0.995,
            speed_sigma_mps: 0.28,
            noise_variance: 1.0,
            process_model: ProcessModel::Kinematic,
        };
        let alpha = Complex64::new(1.0, 0.0);
        let bad = PositionVelocityEkfConfig { rho: 1.0, ..config.clone() };
        assert!(matches!(
            PositionVelocityEkf::new(&bad, -3.0, 16.7, alpha),
            Err(BeamError::BadConfig { field: "rho", .. })
        ));
        let bad = PositionVelocityEkfConfig { elements: 0, ..config.clone() };
        assert!(matches!(
            PositionVelocityEkf::new(&bad, -3.0, 16.7, alpha),
            Err(BeamError::BadConfig { field: "elements", .. })
        ));
        assert!(PositionVelocityEkf::new(&config, f64::NAN, 16.7, alpha).is_err());
        let mut ekf = PositionVelocityEkf::new(&config, -3.0, 16.7, alpha).unwrap();
        assert!(matches!(ekf.update(alpha), Err(BeamError::UpdateWithoutPrediction { .. })));
        ekf.predict().unwrap();
        assert!(matches!(ekf.update(Complex64::new(f64::NAN, 0.0)), Err(BeamError::BadPilot { block: 1, .. })));
    }
}
