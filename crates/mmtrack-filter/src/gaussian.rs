//! Gaussian densities: a validated mean/covariance pair and the small
//! operations on it (density, squared Mahalanobis distance).

use nalgebra::{Cholesky, DMatrix, DVector, Dyn};

use crate::error::{FilterError, ensure_finite_matrix, ensure_finite_vector, ensure_len, ensure_shape};

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
    mean: DVector<f64>,
    cov: DMatrix<f64>,
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
    pub fn new(mean: DVector<f64>, cov: DMatrix<f64>) -> Result<Self, FilterError> {
        let n = mean.len();
        if n == 0 {
            return Err(FilterError::DimensionMismatch {
                what: "Gaussian mean",
                expected_rows: 1,
                expected_cols: 1,
                found_rows: 0,
                found_cols: 1,
            });
        }
        ensure_finite_vector("Gaussian mean", &mean)?;
        let cov = checked_spd("Gaussian covariance", cov, n)?;
        Ok(Self { mean, cov })
    }

    /// State dimension `n`.
    #[must_use]
    pub fn dim(&self) -> usize {
        self.mean.len()
    }

    /// Mean `m`.
    #[must_use]
    pub fn mean(&self) -> &DVector<f64> {
        &self.mean
    }

    /// Covariance `P` (symmetric positive definite).
    #[must_use]
    pub fn cov(&self) -> &DMatrix<f64> {
        &self.cov
    }

    /// Squared Mahalanobis distance `(x - m)^T P^-1 (x - m)`.
    ///
    /// # Errors
    /// [`FilterError::DimensionMismatch`] if `x` has the wrong length,
    /// [`FilterError::NotFinite`] if it holds NaN.
    pub fn mahalanobis_squared(&self, x: &DVector<f64>) -> Result<f64, FilterError> {
        ensure_len("point", x, self.dim())?;
        ensure_finite_vector("point", x)?;
        let chol = cholesky("Gaussian covariance", &self.cov)?;
        Ok(mahalanobis_squared_with(&chol, &(x - &self.mean)))
    }
}

/// Checks that `m` is an `n x n` finite, symmetric, positive definite matrix and
/// returns its symmetrised copy.
pub(crate) fn checked_spd(what: &'static str, m: DMatrix<f64>, n: usize) -> Result<DMatrix<f64>, FilterError> {
    ensure_shape(what, &m, n, n)?;
    ensure_finite_matrix(what, &m)?;
    let scale = m.amax().max(1.0);
    if (&m - m.transpose()).amax() > SYMMETRY_TOLERANCE * scale {
        return Err(FilterError::NotPositiveDefinite { what });
    }
    let sym = symmetrise(m);
    cholesky(what, &sym)?;
    Ok(sym)
}

/// `(P + P^T) / 2`.
pub(crate) fn symmetrise(m: DMatrix<f64>) -> DMatrix<f64> {
    let t = m.transpose();
    (m + t) * 0.5
}

/// Cholesky factor of an SPD matrix, or [`FilterError::NotPositiveDefinite`].
pub(crate) fn cholesky(what: &'static str, m: &DMatrix<f64>) -> Result<Cholesky<f64, Dyn>, FilterError> {
    m.clone().cholesky().ok_or(FilterError::NotPositiveDefinite { what })
}

/// `v^T S^-1 v` from the Cholesky factor `L` of `S` (`S = L L^T`): solve
/// `L y = v`, return `|y|^2`.
pub(crate) fn mahalanobis_squared_with(chol: &Cholesky<f64, Dyn>, v: &DVector<f64>) -> f64 {
    let y = chol.l_dirty().solve_lower_triangular(v).unwrap_or_else(|| DVector::from_element(v.len(), f64::INFINITY));
    y.norm_squared()
}

/// `ln N(v; 0, S)` from the Cholesky factor of `S`:
/// `-(k ln 2 pi + ln det S + v^T S^-1 v) / 2` with `ln det S = 2 sum ln L_ii`.
pub(crate) fn log_normal_pdf_with(chol: &Cholesky<f64, Dyn>, v: &DVector<f64>) -> f64 {
    let k = v.len() as f64;
    let log_det: f64 = 2.0 * chol.l_dirty().diagonal().iter().map(|d| d.ln()).sum::<f64>();
    -0.5 * (k * (2.0 * std::f64::consts::PI).ln() + log_det + mahalanobis_squared_with(chol, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_asymmetric_and_indefinite() {
        let m = DVector::from_vec(vec![0.0, 0.0]);
        let asym = DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.0, 1.0]);
        assert!(matches!(Gaussian::new(m.clone(), asym), Err(FilterError::NotPositiveDefinite { .. })));
        let indef = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(matches!(Gaussian::new(m, indef), Err(FilterError::NotPositiveDefinite { .. })));
    }

    #[test]
    fn log_pdf_of_standard_normal_at_zero() {
        let chol = cholesky("I", &DMatrix::identity(1, 1)).expect("identity is SPD");
        let v = DVector::from_vec(vec![0.0]);
        // ln(1/sqrt(2 pi)) = -0.918938533204672...; only round-off separates them.
        assert!((log_normal_pdf_with(&chol, &v) + 0.918_938_533_204_672_7).abs() < 1e-14);
    }

    #[test]
    fn mahalanobis_of_diagonal() {
        let g = Gaussian::new(
            DVector::from_vec(vec![1.0, 2.0]),
            DMatrix::from_diagonal(&DVector::from_vec(vec![4.0, 9.0])),
        )
        .expect("valid");
        // (3-1)^2/4 + (5-2)^2/9 = 1 + 1 = 2, exact in binary up to round-off.
        let d2 = g.mahalanobis_squared(&DVector::from_vec(vec![3.0, 5.0])).expect("same dimension");
        assert!((d2 - 2.0).abs() < 1e-14);
    }
}
