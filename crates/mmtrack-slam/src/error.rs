//! The error type of the SLAM filter.

use mmtrack_core::CoreError;

/// What went wrong in the SLAM filter.
#[derive(Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SlamError {
    /// A configuration parameter is outside its domain.
    #[error("slam configuration: {field} = {value} is invalid, expected {expected}")]
    InvalidConfig {
        /// The field, with its unit.
        field: &'static str,
        /// The value found, as text.
        value: String,
        /// What the field must be.
        expected: &'static str,
    },
    /// An epoch's time does not come after the previous epoch's.
    #[error("epoch {epoch}: time {t_ns} ns does not follow the previous epoch ({previous_t_ns} ns)")]
    TimeNotIncreasing {
        /// Index of the epoch (0-based, in the order given to the filter).
        epoch: usize,
        /// Its time.
        t_ns: i64,
        /// The previous epoch's time.
        previous_t_ns: i64,
    },
    /// A path measurement is unusable (NaN, elevation out of range) and the
    /// filter was told to refuse such input instead of skipping it.
    #[error("epoch {epoch}, path {path}: {source}")]
    BadPath {
        /// Index of the epoch.
        epoch: usize,
        /// Index of the path in the epoch.
        path: usize,
        /// What is wrong with it.
        source: CoreError,
    },
    /// Every particle weight vanished (the measurements contradict the
    /// belief everywhere the particles are).
    #[error("epoch {epoch}: every particle weight is zero or not finite")]
    WeightsDegenerate {
        /// Index of the epoch.
        epoch: usize,
    },
    /// A numerical step failed (a covariance that is not positive definite).
    #[error("epoch {epoch}: {what} is not positive definite")]
    NotPositiveDefinite {
        /// Index of the epoch.
        epoch: usize,
        /// Which matrix.
        what: &'static str,
    },
    /// The assignment solver refused its cost matrix.
    #[error("epoch {epoch}: data association failed: {source}")]
    Association {
        /// Index of the epoch.
        epoch: usize,
        /// The solver's error.
        source: mmtrack_filter::FilterError,
    },
}

/// Shorthand for [`SlamError::InvalidConfig`].
pub(crate) fn invalid(field: &'static str, value: impl ToString, expected: &'static str) -> SlamError {
    SlamError::InvalidConfig { field, value: value.to_string(), expected }
}

/// Errors unless `value` is finite and `> 0`.
pub(crate) fn ensure_positive(field: &'static str, value: f64) -> Result<(), SlamError> {
    if value.is_finite() && value > 0.0 { Ok(()) } else { Err(invalid(field, value, "a positive finite number")) }
}

/// Errors unless `value` is finite and `>= 0`.
pub(crate) fn ensure_non_negative(field: &'static str, value: f64) -> Result<(), SlamError> {
    if value.is_finite() && value >= 0.0 { Ok(()) } else { Err(invalid(field, value, "a finite number >= 0")) }
}
