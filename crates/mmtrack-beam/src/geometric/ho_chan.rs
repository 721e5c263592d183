//! The baseline: the batch geometric-polar estimator of Ho and Chan (2008)
//! with a running reference, as Zoechmann et al. 2019 use it (Sec. III, the
//! black reference of Fig. 3, and Sec. VI).
//!
//! At every epoch `k` the reference is the current epoch: the state
//! `x^k = [r_k, v sin(alpha_k), v cos(alpha_k)]` is the least-squares
//! solution of (7) written with `b_k:j = phi^_j - phi^_k` and `t_k:j = t_j -
//! t_k` over all epochs `j <= k` so far ("an increasing system of equations,
//! anew, at any time"). The current azimuth `phi^_k` enters every row, the
//! correlation between observation and regressor that biases it (Sec. VI).
//!
//! Every row of that system is a fixed row in Cartesian coordinates (`p_0`,
//! the position at the first epoch, and `v`) times a 4x3 map `T_k` from the
//! polar state at `k` (with `u = (cos phi^_k, sin phi^_k)`, `u' = (-sin
//! phi^_k, cos phi^_k)`, `v = x2 u' + x3 u`, `p_0 = x1 u - t_k v`):
//!
//! ```text
//! bearing j:  [sin phi^_j, -cos phi^_j, t_j sin phi^_j, -t_j cos phi^_j] . [p_0; v] = 0
//! Doppler j:  [0, 0, cos phi^_j, sin phi^_j] / lambda . [p_0; v] = nu_j
//! ```
//!
//! (the bearing row is the cross product of the position `p_0 + t_j v` with
//! the direction `phi^_j`, which rotation leaves unchanged; the Doppler row is
//! `v` along `phi^_j`). So the normal equations `T_k^T G T_k x = T_k^T h`
//! come from the accumulated 4x4 `G = sum a a^T` and `h = sum a y`: the
//! same solution as re-solving the whole stack at every epoch (tested
//! against [`super::batch::running_reference`]), in constant time per
//! epoch. Times count from the first epoch. Rank deficiency (the range
//! unobserved while every azimuth so far is the same) gives the
//! minimum-norm solution, range 0.

// Index loops read like the formulas on these 3x3 arrays.
#![allow(clippy::needless_range_loop)]

use super::linalg::{Sym3, min_norm_solve};
use super::{DopplerBearing, GeometricError, PolarState, RangeEstimator, check_time, check_wavelength};

/// The running-reference batch estimator (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct HoChanBatch {
    wavelength_m: f64,
    t0_s: Option<f64>,
    g: [[f64; 4]; 4],
    h: [f64; 4],
    state: Option<PolarState>,
    epochs: usize,
}

impl HoChanBatch {
    /// An empty estimator.
    ///
    /// # Errors
    /// [`GeometricError::BadConfig`] for a wavelength that is not positive.
    pub fn new(wavelength_m: f64) -> Result<Self, GeometricError> {
        check_wavelength(wavelength_m)?;
        Ok(Self { wavelength_m, t0_s: None, g: [[0.0; 4]; 4], h: [0.0; 4], state: None, epochs: 0 })
    }
}

fn add_outer4(g: &mut [[f64; 4]; 4], h: &mut [f64; 4], a: &[f64; 4], y: f64) {
    for i in 0..4 {
        for j in 0..4 {
            g[i][j] += a[i] * a[j];
        }
        h[i] += a[i] * y;
    }
}

impl RangeEstimator for HoChanBatch {
    fn update(&mut self, observation: &DopplerBearing) -> Result<(), GeometricError> {
        let epoch = self.epochs;
        observation.check(epoch)?;
        check_time(epoch, observation.t_s, self.state.map(|s| s.t_ref_s))?;
        let t0 = self.t0_s.unwrap_or(observation.t_s);
        let t = observation.t_s - t0;
        let (s, c) = observation.azimuth_rad.sin_cos();
        let (mut g, mut h) = (self.g, self.h);
        add_outer4(&mut g, &mut h, &[s, -c, t * s, -t * c], 0.0);
        add_outer4(&mut g, &mut h, &[0.0, 0.0, c / self.wavelength_m, s / self.wavelength_m], observation.doppler_hz);
        // T_k: columns for r, x2 = v sin(alpha), x3 = v cos(alpha).
        let columns = [[c, s, 0.0, 0.0], [t * s, -t * c, -s, c], [-t * c, -t * s, c, s]];
        let mut m: Sym3 = [[0.0; 3]; 3];
        let mut z = [0.0; 3];
        for (a, col_a) in columns.iter().enumerate() {
            let mut g_col = [0.0; 4];
            for i in 0..4 {
                g_col[i] = (0..4).map(|j| g[i][j] * col_a[j]).sum();
            }
            for (b, col_b) in columns.iter().enumerate() {
                m[b][a] = (0..4).map(|i| col_b[i] * g_col[i]).sum();
            }
            z[a] = (0..4).map(|i| col_a[i] * h[i]).sum();
        }
        let x = min_norm_solve(&m, &z)
            .ok_or(GeometricError::Numerical { epoch, detail: "running-reference normal equations" })?;
        self.t0_s = Some(t0);
        self.g = g;
        self.h = h;
        self.state = Some(PolarState { t_ref_s: observation.t_s, azimuth_ref_rad: observation.azimuth_rad, x });
        self.epochs += 1;
        Ok(())
    }

    fn state(&self) -> Option<PolarState> {
        self.state
    }

    fn range_now_m(&self) -> Option<f64> {
        self.state.map(|s| s.range_m(s.t_ref_s))
    }
}
