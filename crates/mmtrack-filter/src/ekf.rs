//! The extended Kalman filter: the Kalman roles of [`crate::kalman`] for
//! nonlinear models, linearised at the current mean.
//!
//! ```text
//! predict:  m' = f(m),            P' = F P F^T + Q,     F = df/dx at m
//! update:   eta = h(m),           H = dh/dx at m
//!           S = H P H^T + R,      K = P H^T S^-1,       m+ = m + K (z - eta)
//!           P+ = (I - K H) P (I - K H)^T + K R K^T      (Joseph form, the default)
//! ```
//!
//! Models give their Jacobians analytically ([`NonlinearMeasurement`]);
//! [`numerical_jacobian`] is the finite-difference check their tests compare
//! against. A complex measurement is written as its stacked real and imaginary
//! parts (`z~ = [Re z; Im z]`, `H~ = [Re H; Im H]`, Shaham et al. 2020,
//! Sec. III-C), so the filter stays real.
//!
//! # References
//! T. Kailath, A. H. Sayed, B. Hassibi, *Linear Estimation*, 2000 (the
//! recursion, Shaham et al. eq. (24)-(30)); R. S. Bucy and P. D. Joseph, 1968
//! (the Joseph form).

use faer::linalg::matmul::matmul;
use faer::{Accum, Col, Mat, Par};

use crate::error::{FilterError, ensure_len, ensure_shape};
use crate::gaussian::Gaussian;
use crate::kalman::{CovarianceUpdate, PreparedUpdate, prepare_linearised};
use crate::linalg::symmetrise;

/// A measurement `z = h(x) + w`, `w ~ N(0, R)`, with an analytic Jacobian.
pub trait NonlinearMeasurement {
    /// State dimension `n`.
    fn state_dim(&self) -> usize;

    /// `h(x)` (length `m`) and the Jacobian `dh/dx` at `x` (`m x n`).
    ///
    /// # Errors
    /// The model's own errors (e.g. a state outside its domain).
    fn evaluate(&self, x: &Col<f64>) -> Result<(Col<f64>, Mat<f64>), FilterError>;

    /// Measurement noise covariance `R` (`m x m`).
    fn noise_cov(&self) -> &Mat<f64>;
}

/// The EKF update role.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ExtendedKalmanUpdater {
    /// Posterior covariance formula (Joseph by default).
    pub covariance_update: CovarianceUpdate,
}

impl ExtendedKalmanUpdater {
    /// The `z`-independent part of the update of `prior` under `model`,
    /// linearised at the prior mean.
    ///
    /// # Errors
    /// [`FilterError::DimensionMismatch`] when the model's shapes do not fit
    /// the prior; [`FilterError::NotFinite`] for a non-finite `h(m)`;
    /// [`FilterError::NotPositiveDefinite`] if `S` or `P+` is not SPD; the
    /// model's own errors.
    pub fn prepare(&self, prior: &Gaussian, model: &impl NonlinearMeasurement) -> Result<PreparedUpdate, FilterError> {
        ensure_len("prior mean", prior.mean(), model.state_dim())?;
        let (eta, h) = model.evaluate(prior.mean())?;
        prepare_linearised(prior, eta, &h, model.noise_cov(), self.covariance_update)
    }

    /// One full update of `prior` with measurement `z`.
    ///
    /// # Errors
    /// As [`ExtendedKalmanUpdater::prepare`], plus a bad `z`.
    pub fn update(
        &self,
        prior: &Gaussian,
        model: &impl NonlinearMeasurement,
        z: &Col<f64>,
    ) -> Result<Gaussian, FilterError> {
        self.prepare(prior, model)?.posterior(z)
    }
}

/// EKF prediction: `N(f(m), F P F^T + Q)` with `f(m)` (`predicted_mean`) and
/// the Jacobian `F` evaluated by the caller's motion model.
///
/// # Errors
/// [`FilterError::DimensionMismatch`] for shapes that do not fit the prior;
/// [`FilterError::NotFinite`] / [`FilterError::NotPositiveDefinite`] when the
/// result is not a valid Gaussian.
pub fn predict_linearised(
    prior: &Gaussian,
    predicted_mean: Col<f64>,
    f: &Mat<f64>,
    q: &Mat<f64>,
) -> Result<Gaussian, FilterError> {
    let n = prior.dim();
    ensure_len("predicted mean", &predicted_mean, n)?;
    ensure_shape("transition Jacobian F", f, n, n)?;
    ensure_shape("process covariance Q", q, n, n)?;
    // F P F^T + Q, written into a copy of Q.
    let mut cov = q.clone();
    matmul(cov.as_mut(), Accum::Add, f * prior.cov(), f.transpose(), 1.0, Par::Seq);
    Gaussian::new(predicted_mean, symmetrise(cov))
}

/// Central-difference Jacobian of `h` at `x`, column `j` with step
/// `step[j]`: `(h(x + e_j step_j) - h(x - e_j step_j)) / (2 step_j)`; the
/// error is `O(step^2)`. For checking analytic Jacobians in tests.
///
/// # Panics
/// When `step` does not have one entry per state or `h` changes its output
/// length (a test helper: its callers are tests).
#[must_use]
pub fn numerical_jacobian(h: impl Fn(&Col<f64>) -> Col<f64>, x: &Col<f64>, step: &[f64]) -> Mat<f64> {
    assert_eq!(step.len(), x.nrows(), "one finite-difference step per state");
    let m = h(x).nrows();
    let mut jacobian = Mat::zeros(m, x.nrows());
    for (j, &dx) in step.iter().enumerate() {
        let mut plus = x.clone();
        let mut minus = x.clone();
        plus[j] += dx;
        minus[j] -= dx;
        let (hp, hm) = (h(&plus), h(&minus));
        assert_eq!((hp.nrows(), hm.nrows()), (m, m), "h keeps its output length");
        for i in 0..m {
            jacobian[(i, j)] = (hp[i] - hm[i]) / (2.0 * dx);
        }
    }
    jacobian
}
