//! Linear-Gaussian motion and measurement models.
//!
//! A motion model hands out its transition matrix `F` and process covariance `Q`
//! for a time step; a measurement model is a fixed pair `(H, R)`. The
//! constant-velocity model is the one of Vo & Ma 2006, Sec. VI (and of the GM-PHD
//! baseline of Mahler et al. 2017, Table I), for any number of spatial axes.

use faer::Mat;

use crate::error::{FilterError, ensure_finite_matrix, ensure_positive, ensure_shape};
use crate::gaussian::{SYMMETRY_TOLERANCE, checked_spd};
use crate::linalg::max_asymmetry;

/// A linear-Gaussian motion model `x_k = F(dt) x_{k-1} + v`, `v ~ N(0, Q(dt))`.
pub trait TransitionModel {
    /// State dimension `n`.
    fn state_dim(&self) -> usize;

    /// `(F, Q)` for a step of `dt_s` seconds; `F` is `n x n`, `Q` is `n x n`
    /// symmetric positive semi-definite.
    ///
    /// # Errors
    /// [`FilterError::InvalidParameter`] for a step the model cannot take (e.g.
    /// negative or non-finite `dt_s`).
    fn matrices(&self, dt_s: f64) -> Result<(Mat<f64>, Mat<f64>), FilterError>;
}

/// Constant velocity (nearly constant, driven by white acceleration) in `k`
/// spatial axes.
///
/// State order `[p_1 .. p_k, v_1 .. v_k]` (positions, then velocities). With
/// `T = dt` and `sigma_a` the acceleration standard deviation,
///
/// ```text
/// F = [ I  T I ]      Q = sigma_a^2 [ T^4/4 I  T^3/2 I ]
///     [ 0    I ]                    [ T^3/2 I    T^2 I ]
/// ```
///
/// i.e. `Q = sigma_a^2 G G^T` with `G = [T^2/2 I; T I]` (acceleration piecewise
/// constant over the step). `Q` has rank `k`: it is positive semi-definite, and
/// `F P F^T + Q` stays positive definite whenever `P` is.
///
/// # References
/// B.-N. Vo and W.-K. Ma, "The Gaussian mixture probability hypothesis density
/// filter", IEEE TSP 54(11), 2006, Sec. VI (the linear-Gaussian example, with
/// `sigma_v` the process-noise standard deviation in m/s^2).
#[derive(Debug, Clone, PartialEq)]
pub struct ConstantVelocity {
    spatial_dims: usize,
    sigma_accel: f64,
}

impl ConstantVelocity {
    /// A constant-velocity model in `spatial_dims >= 1` axes with acceleration
    /// noise standard deviation `sigma_accel >= 0` (units of position / s^2).
    ///
    /// # Errors
    /// [`FilterError::InvalidParameter`] for zero axes or a negative / non-finite
    /// noise level.
    pub fn new(spatial_dims: usize, sigma_accel: f64) -> Result<Self, FilterError> {
        if spatial_dims == 0 {
            return Err(FilterError::InvalidParameter {
                name: "spatial_dims",
                value: 0.0,
                expected: "at least one spatial axis",
            });
        }
        if !(sigma_accel.is_finite() && sigma_accel >= 0.0) {
            return Err(FilterError::InvalidParameter {
                name: "sigma_accel",
                value: sigma_accel,
                expected: "finite and >= 0",
            });
        }
        Ok(Self { spatial_dims, sigma_accel })
    }

    /// Number of spatial axes `k` (the state has `2k` elements).
    #[must_use]
    pub fn spatial_dims(&self) -> usize {
        self.spatial_dims
    }
}

impl TransitionModel for ConstantVelocity {
    fn state_dim(&self) -> usize {
        2 * self.spatial_dims
    }

    fn matrices(&self, dt_s: f64) -> Result<(Mat<f64>, Mat<f64>), FilterError> {
        if !(dt_s.is_finite() && dt_s >= 0.0) {
            return Err(FilterError::InvalidParameter { name: "dt_s", value: dt_s, expected: "finite and >= 0" });
        }
        let k = self.spatial_dims;
        let n = 2 * k;
        let s2 = self.sigma_accel * self.sigma_accel;
        let mut f = Mat::identity(n, n);
        let mut q = Mat::zeros(n, n);
        for i in 0..k {
            f[(i, k + i)] = dt_s;
            q[(i, i)] = s2 * dt_s.powi(4) / 4.0;
            q[(i, k + i)] = s2 * dt_s.powi(3) / 2.0;
            q[(k + i, i)] = s2 * dt_s.powi(3) / 2.0;
            q[(k + i, k + i)] = s2 * dt_s * dt_s;
        }
        Ok((f, q))
    }
}

/// A fixed transition `(F, Q)` that ignores the time step (for discrete-time
/// models and known-answer tests).
#[derive(Debug, Clone, PartialEq)]
pub struct FixedTransition {
    f: Mat<f64>,
    q: Mat<f64>,
}

impl FixedTransition {
    /// Checks that `F` is square and finite and `Q` has its shape, is finite and
    /// symmetric (`Q` may be singular: only positive semi-definiteness is
    /// needed, and it is not checked beyond symmetry and a non-negative diagonal).
    ///
    /// # Errors
    /// [`FilterError::DimensionMismatch`], [`FilterError::NotFinite`] or
    /// [`FilterError::NotPositiveDefinite`] (asymmetric `Q` or a negative
    /// diagonal element).
    pub fn new(f: Mat<f64>, q: Mat<f64>) -> Result<Self, FilterError> {
        let n = f.nrows();
        ensure_shape("transition matrix F", &f, n, n)?;
        ensure_finite_matrix("transition matrix F", &f)?;
        ensure_shape("process covariance Q", &q, n, n)?;
        ensure_finite_matrix("process covariance Q", &q)?;
        let scale = q.norm_max().max(1.0);
        if max_asymmetry(&q) > SYMMETRY_TOLERANCE * scale || q.diagonal().column_vector().iter().any(|d| *d < 0.0) {
            return Err(FilterError::NotPositiveDefinite { what: "process covariance Q" });
        }
        Ok(Self { f, q })
    }
}

impl TransitionModel for FixedTransition {
    fn state_dim(&self) -> usize {
        self.f.nrows()
    }

    fn matrices(&self, _dt_s: f64) -> Result<(Mat<f64>, Mat<f64>), FilterError> {
        Ok((self.f.clone(), self.q.clone()))
    }
}

/// A linear-Gaussian measurement model `z = H x + w`, `w ~ N(0, R)`, `H` is
/// `m x n`, `R` is `m x m` symmetric positive definite.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearMeasurement {
    h: Mat<f64>,
    r: Mat<f64>,
}

impl LinearMeasurement {
    /// Checks shapes and finiteness, and that `R` is SPD.
    ///
    /// # Errors
    /// [`FilterError::DimensionMismatch`], [`FilterError::NotFinite`] or
    /// [`FilterError::NotPositiveDefinite`].
    pub fn new(h: Mat<f64>, r: Mat<f64>) -> Result<Self, FilterError> {
        let (m, n) = (h.nrows(), h.ncols());
        if m == 0 || n == 0 {
            return Err(FilterError::DimensionMismatch {
                what: "measurement matrix H",
                expected_rows: m.max(1),
                expected_cols: n.max(1),
                found_rows: m,
                found_cols: n,
            });
        }
        ensure_finite_matrix("measurement matrix H", &h)?;
        let r = checked_spd("measurement covariance R", r, m)?;
        Ok(Self { h, r })
    }

    /// Position measurement of a [`ConstantVelocity`] state in `spatial_dims`
    /// axes: `H = [I 0]`, `R = sigma^2 I`.
    ///
    /// # Errors
    /// [`FilterError::InvalidParameter`] for zero axes or a non-positive sigma.
    pub fn position(spatial_dims: usize, sigma: f64) -> Result<Self, FilterError> {
        if spatial_dims == 0 {
            return Err(FilterError::InvalidParameter {
                name: "spatial_dims",
                value: 0.0,
                expected: "at least one spatial axis",
            });
        }
        ensure_positive("measurement sigma", sigma)?;
        let k = spatial_dims;
        let h = Mat::from_fn(k, 2 * k, |i, j| if i == j { 1.0 } else { 0.0 });
        let variance = sigma * sigma;
        Self::new(h, Mat::from_fn(k, k, |i, j| if i == j { variance } else { 0.0 }))
    }

    /// Measurement dimension `m`.
    #[must_use]
    pub fn measurement_dim(&self) -> usize {
        self.h.nrows()
    }

    /// State dimension `n`.
    #[must_use]
    pub fn state_dim(&self) -> usize {
        self.h.ncols()
    }

    /// `H`.
    #[must_use]
    pub fn h(&self) -> &Mat<f64> {
        &self.h
    }

    /// `R`.
    #[must_use]
    pub fn r(&self) -> &Mat<f64> {
        &self.r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cv_matrices_in_two_axes() {
        let cv = ConstantVelocity::new(2, 2.0).expect("valid");
        let (f, q) = cv.matrices(0.5).expect("valid step");
        assert_eq!(f[(0, 2)], 0.5);
        assert_eq!(f[(1, 3)], 0.5);
        assert_eq!(f[(0, 1)], 0.0);
        // sigma^2 T^4 / 4 = 4 * 0.0625 / 4 = 0.0625; T^3/2 * 4 = 0.25; T^2 * 4 = 1 (exact in binary).
        assert_eq!(q[(1, 1)], 0.0625);
        assert_eq!(q[(1, 3)], 0.25);
        assert_eq!(q[(3, 3)], 1.0);
        assert_eq!(q[(0, 1)], 0.0);
        assert!(cv.matrices(f64::NAN).is_err());
        assert!(cv.matrices(-1.0).is_err());
    }
}
