//! The genie bounds of Zoechmann et al. 2019, Sec. V. Both know the true
//! (unquantised) azimuths: the caller feeds them [`DopplerBearing`]s with the
//! true azimuth. Both use the fixed initial reference of the proposed tracker.
//!
//! - [`ErrorFreeRegressors`]: the least-squares solution of (7) with exact
//!   regressors, from the accumulated normal equations (minimum norm while
//!   rank deficient). No prior.
//! - [`NullspaceProjection`]: with exact azimuths the bearing equations (3)
//!   hold exactly, so the state lies in the null space of `A_B` (20); the
//!   Doppler equations fix the rest (21):
//!
//! ```text
//! x^NS = (I - A_B^+ A_B) m,   m = argmin || nu - A_D (I - A_B^+ A_B) m ||      (20)-(21)
//! ```
//!
//! `I - A_B^+ A_B` is the projector onto the null space of `A_B`, i.e. of
//! `G_B = A_B^T A_B`, accumulated per epoch; with an orthonormal null basis
//! `U`, `x^NS = U c` with `(U^T G_D U) c = U^T h_D` (`G_D = A_D^T A_D`,
//! `h_D = A_D^T nu`), the minimum-norm solution when that is singular.

// Index loops read like the formulas on these 3x3 arrays.
#![allow(clippy::needless_range_loop)]

use super::linalg::{Sym3, add_outer, dot, min_norm_solve, mul, null_basis};
use super::{
    DopplerBearing, GeometricError, PolarState, RangeEstimator, bearing_row, check_time, check_wavelength, doppler_row,
};

/// Fixed reference and accumulated normal equations shared by both genies.
#[derive(Debug, Clone, PartialEq)]
struct Accumulator {
    wavelength_m: f64,
    reference: Option<(f64, f64)>,
    g_b: Sym3,
    g_d: Sym3,
    h_d: [f64; 3],
    last_t_s: Option<f64>,
    epochs: usize,
}

impl Accumulator {
    fn new(wavelength_m: f64) -> Result<Self, GeometricError> {
        check_wavelength(wavelength_m)?;
        Ok(Self {
            wavelength_m,
            reference: None,
            g_b: [[0.0; 3]; 3],
            g_d: [[0.0; 3]; 3],
            h_d: [0.0; 3],
            last_t_s: None,
            epochs: 0,
        })
    }

    /// Checks and adds an observation; returns the epoch index.
    fn add(&mut self, observation: &DopplerBearing) -> Result<usize, GeometricError> {
        let epoch = self.epochs;
        observation.check(epoch)?;
        check_time(epoch, observation.t_s, self.last_t_s)?;
        let reference = *self.reference.get_or_insert((observation.t_s, observation.azimuth_rad));
        let b = mmtrack_core::wrap_angle_rad(observation.azimuth_rad - reference.1);
        let t = observation.t_s - reference.0;
        add_outer(&mut self.g_b, &bearing_row(b, t), 1.0);
        let a_d = doppler_row(b, self.wavelength_m);
        add_outer(&mut self.g_d, &a_d, 1.0);
        for i in 0..3 {
            self.h_d[i] += a_d[i] * observation.doppler_hz;
        }
        self.last_t_s = Some(observation.t_s);
        self.epochs += 1;
        Ok(epoch)
    }

    fn state(&self, x: [f64; 3]) -> Option<PolarState> {
        self.reference.map(|(t_ref_s, azimuth_ref_rad)| PolarState { t_ref_s, azimuth_ref_rad, x })
    }
}

/// The error-free-regressors genie (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorFreeRegressors {
    acc: Accumulator,
    x: [f64; 3],
}

impl ErrorFreeRegressors {
    /// An empty estimator.
    ///
    /// # Errors
    /// [`GeometricError::BadConfig`] for a wavelength that is not positive.
    pub fn new(wavelength_m: f64) -> Result<Self, GeometricError> {
        Ok(Self { acc: Accumulator::new(wavelength_m)?, x: [0.0; 3] })
    }
}

impl RangeEstimator for ErrorFreeRegressors {
    fn update(&mut self, observation: &DopplerBearing) -> Result<(), GeometricError> {
        let mut acc = self.acc.clone();
        let epoch = acc.add(observation)?;
        let mut n = acc.g_b;
        for i in 0..3 {
            for j in 0..3 {
                n[i][j] += acc.g_d[i][j];
            }
        }
        self.x = min_norm_solve(&n, &acc.h_d).ok_or(GeometricError::Numerical { epoch, detail: "normal equations" })?;
        self.acc = acc;
        Ok(())
    }

    fn state(&self) -> Option<PolarState> {
        self.acc.state(self.x)
    }

    fn range_now_m(&self) -> Option<f64> {
        Some(self.state()?.range_m(self.acc.last_t_s?))
    }
}

/// The nullspace-projection genie (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct NullspaceProjection {
    acc: Accumulator,
    x: [f64; 3],
}

impl NullspaceProjection {
    /// An empty estimator.
    ///
    /// # Errors
    /// [`GeometricError::BadConfig`] for a wavelength that is not positive.
    pub fn new(wavelength_m: f64) -> Result<Self, GeometricError> {
        Ok(Self { acc: Accumulator::new(wavelength_m)?, x: [0.0; 3] })
    }
}

impl RangeEstimator for NullspaceProjection {
    fn update(&mut self, observation: &DopplerBearing) -> Result<(), GeometricError> {
        let mut acc = self.acc.clone();
        let epoch = acc.add(observation)?;
        let numerical = |detail| GeometricError::Numerical { epoch, detail };
        let basis = null_basis(&acc.g_b).ok_or(numerical("null space of A_B"))?;
        let x = match basis.as_slice() {
            // A_B of full rank: the projector is zero (20).
            [] => [0.0; 3],
            [u] => {
                let denominator = dot(u, &mul(&acc.g_d, u));
                let c = if denominator > 0.0 { dot(u, &acc.h_d) / denominator } else { 0.0 };
                [c * u[0], c * u[1], c * u[2]]
            }
            many => {
                // Projector onto the null space; minimum-norm solve in it.
                let mut projector: Sym3 = [[0.0; 3]; 3];
                for u in many {
                    add_outer(&mut projector, u, 1.0);
                }
                let pg = product(&projector, &product(&acc.g_d, &projector));
                min_norm_solve(&pg, &mul(&projector, &acc.h_d)).ok_or(numerical("projected normal equations"))?
            }
        };
        if !x.iter().all(|v| v.is_finite()) {
            return Err(numerical("state not finite"));
        }
        self.x = x;
        self.acc = acc;
        Ok(())
    }

    fn state(&self) -> Option<PolarState> {
        self.acc.state(self.x)
    }

    fn range_now_m(&self) -> Option<f64> {
        Some(self.state()?.range_m(self.acc.last_t_s?))
    }
}

fn product(a: &Sym3, b: &Sym3) -> Sym3 {
    let mut out = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    out
}
