//! The error type of the simulators.

/// What went wrong while checking a scenario or a trajectory.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    /// A scenario parameter is outside its valid domain.
    #[error("{field}: {value} is invalid, expected {expected}")]
    InvalidParameter {
        /// Dotted path of the field, e.g. `sensor.range_resolution_m`.
        field: String,
        /// The value found, as text.
        value: String,
        /// What the field must be.
        expected: &'static str,
    },
    /// A trajectory pose is unusable (not finite, time not increasing).
    #[error("trajectory pose {index} (t = {t_ns} ns): {detail}")]
    BadTrajectoryPose {
        /// Index of the pose in the caller's list.
        index: usize,
        /// Its time, nanoseconds.
        t_ns: i64,
        /// What is wrong with it.
        detail: String,
    },
    /// The trajectory cannot hold a single sweep.
    #[error("trajectory too short: {detail}")]
    TrajectoryTooShort {
        /// Span found and span needed.
        detail: String,
    },
}

/// Shorthand for a [`SimError::InvalidParameter`].
pub(crate) fn invalid(field: impl Into<String>, value: impl ToString, expected: &'static str) -> SimError {
    SimError::InvalidParameter { field: field.into(), value: value.to_string(), expected }
}

/// Errors unless `value` is finite and `> 0`.
pub(crate) fn ensure_positive(field: &str, value: f64) -> Result<(), SimError> {
    if value.is_finite() && value > 0.0 { Ok(()) } else { Err(invalid(field, value, "a positive finite number")) }
}

/// Errors unless `value` is finite and `>= 0`.
pub(crate) fn ensure_non_negative(field: &str, value: f64) -> Result<(), SimError> {
    if value.is_finite() && value >= 0.0 { Ok(()) } else { Err(invalid(field, value, "a finite number >= 0")) }
}

/// Errors unless `value` is finite and in `[lo, hi]`.
pub(crate) fn ensure_within(field: &str, value: f64, lo: f64, hi: f64, expected: &'static str) -> Result<(), SimError> {
    if value.is_finite() && (lo..=hi).contains(&value) { Ok(()) } else { Err(invalid(field, value, expected)) }
}

/// Errors unless `value` is finite.
pub(crate) fn ensure_finite(field: &str, value: f64) -> Result<(), SimError> {
    if value.is_finite() { Ok(()) } else { Err(invalid(field, value, "a finite number")) }
}
