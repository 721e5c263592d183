//! Linear Kalman prediction and update, the two single-target roles the
//! trackers are assembled from.
//!
//! Prediction: `m' = F m`, `P' = F P F^T + Q`.
//!
//! Update with measurement `z` under `z = H x + w`, `w ~ N(0, R)`:
//!
//! ```text
//! eta = H m            (predicted measurement)
//! S   = H P H^T + R    (innovation covariance)
//! K   = P H^T S^-1     (gain)
//! m+  = m + K (z - eta)
//! P+  = (I - K H) P (I - K H)^T + K R K^T     (Joseph form, the default)
//!     = (I - K H) P                           (standard form)
//! ```
//!
//! `eta`, `S`, `K` and `P+` do not depend on `z`; [`PreparedUpdate`] computes
//! them once per prior so that a GM-PHD update against many measurements costs
//! one factorisation per component.
//!
//! # References
//! B.-N. Vo and W.-K. Ma, IEEE TSP 54(11), 2006, Table I, steps 2 and 4 (the
//! same quantities, there per mixture component); R. S. Bucy and P. D. Joseph,
//! *Filtering for Stochastic Processes with Applications to Guidance*, 1968 (the
//! Joseph form).

use faer::{Col, ColRef, Mat};

use crate::error::{FilterError, ensure_finite_vector, ensure_len, ensure_shape};
use crate::gaussian::{Gaussian, checked_spd, log_normal_pdf_with};
use crate::linalg::{Cholesky, mul, mul_add, mul_col, symmetrise};
use crate::models::{LinearMeasurement, TransitionModel};

/// How the posterior covariance is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CovarianceUpdate {
    /// `P+ = (I - K H) P (I - K H)^T + K R K^T`.
    ///
    /// Stays symmetric positive definite: it is a congruence of the SPD `P`
    /// plus the positive semi-definite `K R K^T`, so `x^T P+ x > 0` for every
    /// `x != 0` (if `(I - K H)^T x = 0` then `x = H^T K^T x`, so `K^T x != 0`
    /// and the second term is positive). This holds for *any* gain `K`, so the
    /// round-off in `K` cannot make `P+` indefinite, and the formula is
    /// symmetric by construction (we still symmetrise to remove the last ulp).
    #[default]
    Joseph,
    /// `P+ = (I - K H) P`, symmetrised. Cheaper, exact only for the optimal
    /// gain; with a badly conditioned `S` the subtraction can lose definiteness,
    /// which is then reported as [`FilterError::NotPositiveDefinite`].
    Standard,
}

/// The prediction role: pushes a Gaussian through a [`TransitionModel`].
#[derive(Debug, Clone, PartialEq)]
pub struct KalmanPredictor<T> {
    /// The motion model.
    pub model: T,
}

impl<T: TransitionModel> KalmanPredictor<T> {
    /// Wraps a motion model.
    pub fn new(model: T) -> Self {
        Self { model }
    }

    /// `N(F m, F P F^T + Q)` for a step of `dt_s` seconds.
    ///
    /// # Errors
    /// [`FilterError::DimensionMismatch`] when the prior does not have the
    /// model's state dimension (or the model hands out `F`, `Q` of another);
    /// the model's own errors for a bad `dt_s`;
    /// [`FilterError::NotPositiveDefinite`] / [`FilterError::NotFinite`] if the
    /// result is not a valid covariance (e.g. overflow).
    pub fn predict(&self, prior: &Gaussian, dt_s: f64) -> Result<Gaussian, FilterError> {
        let n = self.model.state_dim();
        ensure_len("prior mean", prior.mean(), n)?;
        let (f, q) = self.checked_matrices(dt_s)?;
        predict_with(prior, &f, &q)
    }

    /// [`KalmanPredictor::predict`] of every prior over the same step of
    /// `dt_s` seconds, with `(F, Q)` built once (and not at all for no
    /// priors); the first error ends it.
    ///
    /// # Errors
    /// As [`KalmanPredictor::predict`].
    pub fn predict_each<'a>(
        &self,
        priors: impl IntoIterator<Item = &'a Gaussian>,
        dt_s: f64,
    ) -> Result<Vec<Gaussian>, FilterError> {
        let n = self.model.state_dim();
        let priors = priors.into_iter();
        let mut out = Vec::with_capacity(priors.size_hint().0);
        let mut matrices = None;
        for prior in priors {
            ensure_len("prior mean", prior.mean(), n)?;
            let (f, q) = match &matrices {
                Some(fq) => fq,
                None => matrices.insert(self.checked_matrices(dt_s)?),
            };
            out.push(predict_with(prior, f, q)?);
        }
        Ok(out)
    }

    /// The model's `(F, Q)`, checked to be `n x n`.
    fn checked_matrices(&self, dt_s: f64) -> Result<(Mat<f64>, Mat<f64>), FilterError> {
        let n = self.model.state_dim();
        let (f, q) = self.model.matrices(dt_s)?;
        ensure_shape("transition matrix F", &f, n, n)?;
        ensure_shape("process covariance Q", &q, n, n)?;
        Ok((f, q))
    }
}

/// `N(F m, F P F^T + Q)`, shapes already checked.
fn predict_with(prior: &Gaussian, f: &Mat<f64>, q: &Mat<f64>) -> Result<Gaussian, FilterError> {
    let mean = mul_col(f.as_ref(), prior.mean().as_ref());
    let fp = mul(f.as_ref(), prior.cov().as_ref());
    // F P F^T + Q, written into a copy of Q.
    let mut cov = q.clone();
    mul_add(cov.as_mut(), 1.0, fp.as_ref(), f.transpose());
    Gaussian::new(mean, symmetrise(cov))
}

/// The update role: conditions a Gaussian on a linear measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct KalmanUpdater {
    /// The measurement model.
    pub model: LinearMeasurement,
    /// Posterior covariance formula.
    pub covariance_update: CovarianceUpdate,
}

impl KalmanUpdater {
    /// An updater with the default (Joseph) covariance update.
    #[must_use]
    pub fn new(model: LinearMeasurement) -> Self {
        Self { model, covariance_update: CovarianceUpdate::default() }
    }

    /// Computes the `z`-independent parts of the update for `prior`.
    ///
    /// # Errors
    /// [`FilterError::DimensionMismatch`] if the prior's dimension is not the
    /// model's; [`FilterError::NotPositiveDefinite`] if `S` or `P+` is not SPD.
    pub fn prepare(&self, prior: &Gaussian) -> Result<PreparedUpdate, FilterError> {
        ensure_len("prior mean", prior.mean(), self.model.state_dim())?;
        let h = self.model.h();
        prepare_linearised(prior, mul_col(h.as_ref(), prior.mean().as_ref()), h, self.model.r(), self.covariance_update)
    }

    /// One full update of `prior` with measurement `z`.
    ///
    /// # Errors
    /// As [`KalmanUpdater::prepare`], plus [`FilterError::DimensionMismatch`] /
    /// [`FilterError::NotFinite`] for a bad `z`.
    pub fn update(&self, prior: &Gaussian, z: &Col<f64>) -> Result<Gaussian, FilterError> {
        self.prepare(prior)?.posterior(z)
    }
}

/// The update quantities of the module docs for a measurement model
/// linearised at the prior mean: predicted measurement `eta` (`H m` for a
/// linear model, `h(m)` for an extended Kalman filter) and Jacobian `H`.
/// Shapes: `H` is `m x n` for an `n`-dimensional prior, `eta` has `m` rows,
/// `R` is `m x m`; checked here.
pub(crate) fn prepare_linearised(
    prior: &Gaussian,
    predicted_measurement: Col<f64>,
    h: &Mat<f64>,
    r: &Mat<f64>,
    covariance_update: CovarianceUpdate,
) -> Result<PreparedUpdate, FilterError> {
    let n = prior.dim();
    let m = predicted_measurement.nrows();
    ensure_shape("measurement Jacobian H", h, m, n)?;
    ensure_shape("measurement covariance R", r, m, m)?;
    ensure_finite_vector("predicted measurement", &predicted_measurement)?;
    let p = prior.cov();
    let hp = mul(h.as_ref(), p.as_ref());
    // S = H P H^T + R, written into a copy of R.
    let mut s = r.clone();
    mul_add(s.as_mut(), 1.0, hp.as_ref(), h.transpose());
    let s = symmetrise(s);
    let s_chol = Cholesky::new("innovation covariance S", &s)?;
    // K^T = S^-1 H P (S and P symmetric), so K = (S^-1 (H P))^T.
    let mut gain_t = hp;
    s_chol.solve_in_place(gain_t.as_mut());
    let gain = gain_t.transpose().to_owned();
    // I - K H, written into I.
    let mut i_kh = Mat::<f64>::identity(n, n);
    mul_add(i_kh.as_mut(), -1.0, gain.as_ref(), h.as_ref());
    let i_kh_p = mul(i_kh.as_ref(), p.as_ref());
    let post = match covariance_update {
        CovarianceUpdate::Joseph => {
            let mut post = mul(i_kh_p.as_ref(), i_kh.transpose());
            mul_add(post.as_mut(), 1.0, mul(gain.as_ref(), r.as_ref()).as_ref(), gain.transpose());
            post
        }
        CovarianceUpdate::Standard => i_kh_p,
    };
    // Validate once here (as `Gaussian::new` would) so that `posterior`
    // only has to check the mean.
    let posterior_cov = checked_spd("Gaussian covariance", symmetrise(post), n)?;
    Ok(PreparedUpdate {
        prior_mean: prior.mean().clone(),
        predicted_measurement,
        log_det_s: s_chol.log_det(),
        s,
        s_chol,
        gain,
        posterior_cov,
    })
}

/// The measurement-independent part of a Kalman update (see the module docs).
#[derive(Debug, Clone)]
pub struct PreparedUpdate {
    prior_mean: Col<f64>,
    predicted_measurement: Col<f64>,
    /// `ln det S`, once per prior rather than once per measurement.
    log_det_s: f64,
    s: Mat<f64>,
    s_chol: Cholesky,
    gain: Mat<f64>,
    posterior_cov: Mat<f64>,
}

impl PreparedUpdate {
    /// Predicted measurement `eta = H m`.
    #[must_use]
    pub fn predicted_measurement(&self) -> &Col<f64> {
        &self.predicted_measurement
    }

    /// Innovation covariance `S = H P H^T + R`.
    #[must_use]
    pub fn innovation_cov(&self) -> &Mat<f64> {
        &self.s
    }

    /// Gain `K`.
    #[must_use]
    pub fn gain(&self) -> &Mat<f64> {
        &self.gain
    }

    /// Posterior covariance `P+` (the same for every `z`).
    #[must_use]
    pub fn posterior_cov(&self) -> &Mat<f64> {
        &self.posterior_cov
    }

    /// Innovation `z - eta`.
    ///
    /// # Errors
    /// [`FilterError::DimensionMismatch`] / [`FilterError::NotFinite`] for a bad `z`.
    pub fn innovation(&self, z: &Col<f64>) -> Result<Col<f64>, FilterError> {
        ensure_len("measurement", z, self.predicted_measurement.nrows())?;
        ensure_finite_vector("measurement", z)?;
        Ok(z - &self.predicted_measurement)
    }

    /// Squared Mahalanobis distance of `z` from the prediction, `nu^T S^-1 nu`.
    ///
    /// # Errors
    /// As [`PreparedUpdate::innovation`].
    pub fn mahalanobis_squared(&self, z: &Col<f64>) -> Result<f64, FilterError> {
        let nu = self.innovation(z)?;
        Ok(self.s_chol.mahalanobis_squared(nu.as_ref(), &mut Col::zeros(nu.nrows())))
    }

    /// `ln N(z; eta, S)`, the log measurement likelihood `ln q(z)` of Vo & Ma
    /// Table I, step 4.
    ///
    /// # Errors
    /// As [`PreparedUpdate::innovation`].
    pub fn log_likelihood(&self, z: &Col<f64>) -> Result<f64, FilterError> {
        Ok(log_normal_pdf_with(&self.s_chol, self.innovation(z)?.as_ref()))
    }

    /// `ln N(nu; 0, S)` from `d2 = nu^T S^-1 nu` already computed:
    /// `-(m ln 2 pi + ln det S + d2) / 2`, `ln det S = 2 sum ln L_ii`.
    pub(crate) fn log_likelihood_from_mahalanobis(&self, d2: f64) -> f64 {
        let m = self.predicted_measurement.nrows() as f64;
        -0.5 * (m * (2.0 * std::f64::consts::PI).ln() + self.log_det_s + d2)
    }

    /// `nu^T S^-1 nu` for an innovation already computed; `scratch` is
    /// working space (see [`Cholesky::mahalanobis_squared`]).
    pub(crate) fn mahalanobis_squared_of_innovation(&self, nu: &Col<f64>, scratch: &mut Col<f64>) -> f64 {
        self.s_chol.mahalanobis_squared(nu.as_ref(), scratch)
    }

    /// Posterior `N(m + K (z - eta), P+)`.
    ///
    /// # Errors
    /// As [`PreparedUpdate::innovation`].
    pub fn posterior(&self, z: &Col<f64>) -> Result<Gaussian, FilterError> {
        let nu = self.innovation(z)?;
        self.posterior_of_innovation(nu.as_ref())
    }

    /// Posterior for an innovation already computed.
    pub(crate) fn posterior_of_innovation(&self, nu: ColRef<'_, f64>) -> Result<Gaussian, FilterError> {
        // m + K nu, written into a copy of m.
        let mut mean = self.prior_mean.clone();
        mul_add(mean.as_mat_mut(), 1.0, self.gain.as_ref(), nu.as_mat());
        Gaussian::with_checked_cov(mean, self.posterior_cov.clone())
    }
}
