//! The one error type of the crate and the cheap precondition checks that raise it.
//!
//! Checks run in release builds too: invalid input is an error, never a debug
//! assertion and never a panic.

use faer::{Col, Mat};
use thiserror::Error;

/// Errors of the estimation building blocks.
///
/// Every variant names the quantity at fault (`what`) in words a caller can put
/// in front of a user, e.g. "measurement 3" or "transition covariance Q". A
/// variant that wraps another error names only its own part; the wrapped error
/// is its [`source`](std::error::Error::source), so a report of the chain
/// (`anyhow`'s `{:#}`) says each part once.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum FilterError {
    /// A vector or matrix does not have the shape the model requires.
    #[error("{what}: expected a {expected_rows}x{expected_cols} array, found {found_rows}x{found_cols}")]
    DimensionMismatch {
        /// Which array.
        what: &'static str,
        /// Rows required.
        expected_rows: usize,
        /// Columns required.
        expected_cols: usize,
        /// Rows found.
        found_rows: usize,
        /// Columns found.
        found_cols: usize,
    },
    /// An array holds NaN or an infinity.
    #[error("{what}: element ({row}, {col}) is not finite ({value})")]
    NotFinite {
        /// Which array.
        what: &'static str,
        /// Row of the first offending element.
        row: usize,
        /// Column of the first offending element (0 for vectors).
        col: usize,
        /// The offending value.
        value: f64,
    },
    /// A matrix that must be symmetric positive definite is not (its Cholesky
    /// factorisation fails, or it is visibly asymmetric).
    #[error("{what} is not symmetric positive definite")]
    NotPositiveDefinite {
        /// Which matrix.
        what: &'static str,
    },
    /// A scalar parameter is outside its allowed range.
    #[error("{name} = {value} is out of range: {expected}")]
    InvalidParameter {
        /// Parameter name, with its unit.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What was expected, in words.
        expected: &'static str,
    },
    /// One measurement of a measurement set is bad; `source` says how.
    #[error("measurement {index}")]
    Measurement {
        /// Index of the measurement in its set.
        index: usize,
        /// What is wrong with it.
        source: Box<FilterError>,
    },
    /// One birth component supplied to a prediction is bad; `source` says how.
    #[error("birth component {index}")]
    Birth {
        /// Index of the birth component in the supplied list.
        index: usize,
        /// What is wrong with it.
        source: Box<FilterError>,
    },
    /// A point of a point set does not have the dimension of the others.
    #[error("{what}: point {index} has dimension {found}, expected {expected}")]
    PointDimension {
        /// Which point set.
        what: &'static str,
        /// Index of the offending point.
        index: usize,
        /// Dimension of the first point.
        expected: usize,
        /// Dimension of the offending point.
        found: usize,
    },
}

/// Fails with [`FilterError::DimensionMismatch`] unless `m` is `rows x cols`.
pub(crate) fn ensure_shape(what: &'static str, m: &Mat<f64>, rows: usize, cols: usize) -> Result<(), FilterError> {
    if m.nrows() == rows && m.ncols() == cols {
        Ok(())
    } else {
        Err(FilterError::DimensionMismatch {
            what,
            expected_rows: rows,
            expected_cols: cols,
            found_rows: m.nrows(),
            found_cols: m.ncols(),
        })
    }
}

/// Fails with [`FilterError::DimensionMismatch`] unless `v` has `len` rows.
pub(crate) fn ensure_len(what: &'static str, v: &Col<f64>, len: usize) -> Result<(), FilterError> {
    if v.nrows() == len {
        Ok(())
    } else {
        Err(FilterError::DimensionMismatch {
            what,
            expected_rows: len,
            expected_cols: 1,
            found_rows: v.nrows(),
            found_cols: 1,
        })
    }
}

/// Fails with [`FilterError::NotFinite`] at the first non-finite element
/// (column-major order, so `(row, col)` is exact).
pub(crate) fn ensure_finite_matrix(what: &'static str, m: &Mat<f64>) -> Result<(), FilterError> {
    for col in 0..m.ncols() {
        if let Some(row) = m.col(col).iter().position(|v| !v.is_finite()) {
            return Err(FilterError::NotFinite { what, row, col, value: m[(row, col)] });
        }
    }
    Ok(())
}

/// Fails with [`FilterError::NotFinite`] at the first non-finite element.
pub(crate) fn ensure_finite_vector(what: &'static str, v: &Col<f64>) -> Result<(), FilterError> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(FilterError::NotFinite { what, row: i, col: 0, value: v[i] }),
    }
}

/// Fails with [`FilterError::InvalidParameter`] unless `lo <= value <= hi`
/// (which also rejects NaN).
pub(crate) fn ensure_in_range(
    name: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    expected: &'static str,
) -> Result<(), FilterError> {
    if value >= lo && value <= hi { Ok(()) } else { Err(FilterError::InvalidParameter { name, value, expected }) }
}

/// Fails with [`FilterError::InvalidParameter`] unless `value` is finite and `> 0`.
pub(crate) fn ensure_positive(name: &'static str, value: f64) -> Result<(), FilterError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(FilterError::InvalidParameter { name, value, expected: "finite and > 0" })
    }
}
