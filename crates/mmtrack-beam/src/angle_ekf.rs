//! The angle-state EKF of Va, Vikalo and Heath 2016, the baseline of Shaham
//! et al. 2020 (Sec. IV-D).
//!
//! State `x = [theta, phi, Re alpha, Im alpha]`: AoA and AoD (radians from
//! each array's axis) and the channel coefficient. The angles take additive
//! random-walk steps of variance `sigma_a^2` (the paper's `(0.5 pi / 180)^2`)
//! and `alpha` is Gauss-Markov:
//!
//! ```text
//! x[k+1] = diag(1, 1, rho, rho) x[k] + u[k],   u ~ N(0, diag(sigma_a^2, sigma_a^2, (1 - rho^2)/2, (1 - rho^2)/2))
//! z      = alpha AF_r(cos theta) conj(AF_t(cos phi)) + n
//! dz/dtheta = alpha AF_r'(cos theta) (-sin theta) conj(AF_t),   dz/dphi = alpha AF_r conj(AF_t'(cos phi)) (-sin phi)
//! dz/dRe a  = AF_r conj(AF_t),   dz/dIm a = j AF_r conj(AF_t)
//! ```
//!
//! Beams point at the predicted angles; the start is the channel estimate
//! with `P[1|0]` the process covariance.

use mmtrack_core::Complex64;
use mmtrack_core::array::UniformLinearArray;
use mmtrack_filter::faer::{Col, Mat};
use mmtrack_filter::{FilterError, Gaussian, NonlinearMeasurement};
use serde::{Deserialize, Serialize};

use crate::error::check;
use crate::link::{PilotEkf, set_complex_column, stacked, stacked_noise_cov};
use crate::{BeamError, BeamPair, PilotTracker};

/// Parameters of [`AngleEkf`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AngleEkfConfig {
    /// Elements of each half-wavelength ULA.
    pub elements: usize,
    /// Gauss-Markov correlation `rho` of `alpha`.
    pub rho: f64,
    /// Standard deviation `sigma_a` of each angle's step per block, radians.
    pub angle_sigma_rad: f64,
    /// Pilot noise variance `sigma_n^2`.
    pub noise_variance: f64,
}

/// The tracker (module docs).
#[derive(Debug, Clone)]
pub struct AngleEkf {
    array: UniformLinearArray,
    noise_cov: Mat<f64>,
    ekf: PilotEkf,
}

impl AngleEkf {
    /// Starts from the channel estimate: AoA `aoa_rad`, AoD `aod_rad` (from
    /// the array axes) and `alpha`.
    ///
    /// # Errors
    /// [`BeamError::BadConfig`] naming a bad parameter or start value.
    pub fn new(config: &AngleEkfConfig, aoa_rad: f64, aod_rad: f64, alpha: Complex64) -> Result<Self, BeamError> {
        let c = config;
        check("rho", c.rho, (0.0..1.0).contains(&c.rho), "a correlation in [0, 1)")?;
        check("angle_sigma_rad", c.angle_sigma_rad, c.angle_sigma_rad > 0.0, "a positive standard deviation")?;
        check("noise_variance", c.noise_variance, c.noise_variance > 0.0, "a positive variance")?;
        check("aoa_rad", aoa_rad, true, "a finite angle")?;
        check("aod_rad", aod_rad, true, "a finite angle")?;
        check("alpha", alpha.norm(), true, "a finite channel coefficient")?;
        let array = UniformLinearArray::half_wavelength(c.elements).map_err(|_| BeamError::BadConfig {
            field: "elements",
            value: c.elements.to_string(),
            expected: "at least one element",
        })?;
        let (angle_var, alpha_var) = (c.angle_sigma_rad * c.angle_sigma_rad, 0.5 * (1.0 - c.rho * c.rho));
        let process_cov = diagonal(&[angle_var, angle_var, alpha_var, alpha_var]);
        let start = Col::from_fn(4, |i| [aoa_rad, aod_rad, alpha.re, alpha.im][i]);
        let transition = diagonal(&[1.0, 1.0, c.rho, c.rho]);
        // P[1|0] = Q: the start covariance is the process noise.
        let ekf = PilotEkf::new(start, transition, process_cov.clone(), process_cov)?;
        Ok(Self { array, noise_cov: stacked_noise_cov(c.noise_variance), ekf })
    }

    /// The current estimate (after the last predict or update).
    #[must_use]
    pub fn state(&self) -> &Gaussian {
        self.ekf.state()
    }
}

impl PilotTracker for AngleEkf {
    fn predict(&mut self) -> Result<BeamPair, BeamError> {
        self.ekf.predict(|x| BeamPair { rx_steer_u: x[0].cos(), tx_steer_u: x[1].cos() })
    }

    fn update(&mut self, pilot: Complex64) -> Result<(), BeamError> {
        let array = self.array;
        self.ekf.update(pilot, |beams| AnglePilot { array, beams, noise_cov: &self.noise_cov })
    }
}

/// The pilot as a function of the angle state, for given beams.
pub(crate) struct AnglePilot<'a> {
    pub(crate) array: UniformLinearArray,
    pub(crate) beams: BeamPair,
    pub(crate) noise_cov: &'a Mat<f64>,
}

impl NonlinearMeasurement for AnglePilot<'_> {
    fn state_dim(&self) -> usize {
        4
    }

    fn evaluate(&self, x: &Col<f64>) -> Result<(Col<f64>, Mat<f64>), FilterError> {
        let (theta, phi) = (x[0], x[1]);
        let alpha = Complex64::new(x[2], x[3]);
        let (af_r, daf_r) = self.array.array_factor_with_derivative(self.beams.rx_steer_u, theta.cos());
        let (af_t, daf_t) = self.array.array_factor_with_derivative(self.beams.tx_steer_u, phi.cos());
        let gain = af_r * af_t.conj();
        let mut jacobian = Mat::zeros(2, 4);
        set_complex_column(&mut jacobian, 0, alpha * daf_r * (-theta.sin()) * af_t.conj());
        set_complex_column(&mut jacobian, 1, alpha * af_r * daf_t.conj() * (-phi.sin()));
        set_complex_column(&mut jacobian, 2, gain);
        set_complex_column(&mut jacobian, 3, Complex64::i() * gain);
        Ok((stacked(alpha * gain), jacobian))
    }

    fn noise_cov(&self) -> &Mat<f64> {
        self.noise_cov
    }
}

fn diagonal(values: &[f64; 4]) -> Mat<f64> {
    Mat::from_fn(4, 4, |i, j| if i == j { values[i] } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use mmtrack_filter::numerical_jacobian;

    use super::*;

    #[test]
    fn jacobian_matches_finite_differences() {
        let noise_cov = stacked_noise_cov(1.0);
        let array = UniformLinearArray::half_wavelength(16).unwrap();
        for (theta, phi, steer) in [(-0.78, 2.36, (0.70, -0.71)), (1.2, 1.9, (0.3, -0.3))] {
            let model = AnglePilot {
                array,
                beams: BeamPair { rx_steer_u: steer.0, tx_steer_u: steer.1 },
                noise_cov: &noise_cov,
            };
            let x = Col::from_fn(4, |i| [theta, phi, -0.3, 0.9][i]);
            let (_, analytic) = model.evaluate(&x).unwrap();
            let numeric = numerical_jacobian(|x| model.evaluate(x).unwrap().0, &x, &[1e-6; 4]);
            assert!((&analytic - &numeric).norm_max() < 1e-7, "{analytic:?} vs {numeric:?}");
        }
    }
}
