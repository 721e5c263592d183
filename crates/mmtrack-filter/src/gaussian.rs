//! Gaussian densities: a validated mean/covariance pair and the small
//! operations on it (density, squared Mahalanobis distance).

use faer::{Col, ColRef, Mat};

use crate::error::{FilterError, ensure_finite_matrix, ensure_finite_vector, ensure_len, ensure_shape};
use crate::linalg::{Cholesky, is_positive_definite, max_asymmetry, symmetrise};

/// Relative asymmetry `max |P - P^T| / max(1, max |P|)` above which a matrix is
/// rejected as not symmetric. `1e-9` is far above the round-off of the
/// recursions here (a few ulps of the largest element, ~1e-15 relative) and far
/// below any asymmetry a caller could mean.
pub const SYMMETRY_TOLERANCE: f64 = 1e-9;

/// A Gaussian density `N(x; m, P)` with `P` symmetric positive definite.
///
/// Constructed only through [`Gaussian::new`], which checks shapes, finiteness
/// and positive definiteness, so every `Gaussian` in the crate is valid.
#[derive(Debug, Clone, PartialEq)]
pub struct Gaussian {
    mean: Col<f64>,
    cov: Mat<f64>,
}

impl Gaussian {
    /// Checks and wraps a mean `m` (length `n`) and covariance `P` (`n x n`).
    ///
    /// `P` is symmetrised as `(P + P^T) / 2` after the symmetry check, so
    /// round-off asymmetry never accumulates.
    ///
    /// # Errors
    /// [`FilterError::DimensionMismatch`] for inconsistent shapes or an empty
    /// state, [`FilterError::NotFinite`] for NaN/infinite entries,
    /// [`FilterError::NotPositiveDefinite`] when `P` is not SPD.
    pub fn new(mean: Col<f64>, cov: Mat<f64>) -> Result<Self, FilterError> {
        check_mean(&mean)?;
        let cov = checked_spd("Gaussian covariance", cov, mean.nrows())?;
        Ok(Self { mean, cov })
    }

    /// As [`Gaussian::new`] for a covariance that has already passed
    /// [`checked_spd`] as "Gaussian covariance" (symmetric positive definite,
    /// symmetrised): only the mean is checked, and the shapes, so the
    /// factorisation is not repeated for every posterior of a prepared update.
    pub(crate) fn with_checked_cov(mean: Col<f64>, cov: Mat<f64>) -> Result<Self, FilterError> {
        check_mean(&mean)?;
        ensure_shape("Gaussian covariance", &cov, mean.nrows(), mean.nrows())?;
        Ok(Self { mean, cov })
    }

    /// State dimension `n`.
    #[must_use]
    pub fn dim(&self) -> usize {
        self.mean.nrows()
    }

    /// Mean `m`.
    #[must_use]
    pub fn mean(&self) -> &Col<f64> {
        &self.mean
    }

    /// Covariance `P` (symmetric positive definite).
    #[must_use]
    pub fn cov(&self) -> &Mat<f64> {
        &self.cov
    }

    /// Squared Mahalanobis distance `(x - m)^T P^-1 (x - m)`.
    ///
    /// # Errors
    /// [`FilterError::DimensionMismatch`] if `x` has the wrong length,
    /// [`FilterError::NotFinite`] if it holds NaN.
    pub fn mahalanobis_squared(&self, x: &Col<f64>) -> Result<f64, FilterError> {
        ensure_len("point", x, self.dim())?;
        ensure_finite_vector("point", x)?;
        let chol = Cholesky::new("Gaussian covariance", &self.cov)?;
        Ok(chol.mahalanobis_squared((x - &self.mean).as_ref(), &mut Col::zeros(x.nrows())))
    }
}

/// A mean must have at least one element and be finite.
fn check_mean(mean: &Col<f64>) -> Result<(), FilterError> {
    if mean.nrows() == 0 {
        return Err(FilterError::DimensionMismatch {
            what: "Gaussian mean",
            expected_rows: 1,
            expected_cols: 1,
            found_rows: 0,
            found_cols: 1,
        });
    }
    ensure_finite_vector("Gaussian mean", mean)
}

/// Checks that `m` is an `n x n` finite, symmetric, positive definite matrix and
/// returns its symmetrised copy.
pub(crate) fn checked_spd(what: &'static str, m: Mat<f64>, n: usize) -> Result<Mat<f64>, FilterError> {
    ensure_shape(what, &m, n, n)?;
    ensure_finite_matrix(what, &m)?;
    let scale = m.norm_max().max(1.0);
    if max_asymmetry(&m) > SYMMETRY_TOLERANCE * scale {
        return Err(FilterError::NotPositiveDefinite { what });
    }
    let sym = symmetrise(m);
    if !is_positive_definite(&sym) {
        return Err(FilterError::NotPositiveDefinite { what });
    }
    Ok(sym)
}

/// `ln N(v; 0, S)` from the Cholesky factor of `S`:
/// `-(k ln 2 pi + ln det S + v^T S^-1 v) / 2` with `ln det S = 2 sum ln L_ii`.
pub(crate) fn log_normal_pdf_with(chol: &Cholesky, v: ColRef<'_, f64>) -> f64 {
    let k = v.nrows() as f64;
    let d2 = chol.mahalanobis_squared(v, &mut Col::zeros(v.nrows()));
    -0.5 * (k * (2.0 * std::f64::consts::PI).ln() + chol.log_det() + d2)
}

#[cfg(test)]
mod tests {
    use faer::{col, mat};

    use super::*;

    #[test]
    fn rejects_asymmetric_and_indefinite() {
        let m = Col::zeros(2);
        let asym = mat![[1.0, 0.5], [0.0, 1.0]];
        assert!(matches!(Gaussian::new(m.clone(), asym), Err(FilterError::NotPositiveDefinite { .. })));
        let indef = mat![[1.0, 2.0], [2.0, 1.0]];
        assert!(matches!(Gaussian::new(m, indef), Err(FilterError::NotPositiveDefinite { .. })));
    }

    #[test]
    fn log_pdf_of_standard_normal_at_zero() {
        let chol = Cholesky::new("I", &Mat::identity(1, 1)).expect("identity is SPD");
        let v = col![0.0];
        // ln(1/sqrt(2 pi)) = -0.918938533204672...; only round-off separates them.
        assert!((log_normal_pdf_with(&chol, v.as_ref()) + 0.918_938_533_204_672_7).abs() < 1e-14);
    }

    #[test]
    fn mahalanobis_of_diagonal() {
        let g = Gaussian::new(col![1.0, 2.0], mat![[4.0, 0.0], [0.0, 9.0]]).expect("valid");
        // (3-1)^2/4 + (5-2)^2/9 = 1 + 1 = 2, exact in binary up to round-off.
        let d2 = g.mahalanobis_squared(&col![3.0, 5.0]).expect("same dimension");
        assert!((d2 - 2.0).abs() < 1e-14);
    }
}
