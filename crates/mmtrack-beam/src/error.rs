use mmtrack_filter::FilterError;
use thiserror::Error;

/// What can go wrong when configuring or running a beam tracker.
#[derive(Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum BeamError {
    /// A configuration value is outside its meaningful range.
    #[error("beam tracker config: {field} = {value} is invalid: expected {expected}")]
    BadConfig {
        /// The field, as written in the config.
        field: &'static str,
        /// Its value, as text.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A received pilot is NaN or infinite.
    #[error("pilot of block {block} is not finite ({value})")]
    BadPilot {
        /// Block index since the tracker started.
        block: usize,
        /// The pilot, as text.
        value: String,
    },
    /// A pose estimate that drives a tracker is unusable (not finite, on the
    /// base station).
    #[error("pose estimate of slot {slot}: {detail}")]
    BadPose {
        /// Slot index since the tracker started.
        slot: usize,
        /// What is wrong with it.
        detail: String,
    },
    /// `update` without a `predict` before it.
    #[error("update of block {block} without a prediction: call predict first")]
    UpdateWithoutPrediction {
        /// Block index since the tracker started.
        block: usize,
    },
    /// The filter failed (a covariance lost definiteness, a non-finite state).
    #[error("filter at block {block}: {source}")]
    Filter {
        /// Block index since the tracker started.
        block: usize,
        /// The filter's error.
        source: FilterError,
    },
}

/// Errors unless `value` is finite and satisfies `ok`.
pub(crate) fn check(field: &'static str, value: f64, ok: bool, expected: &'static str) -> Result<(), BeamError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(BeamError::BadConfig { field, value: value.to_string(), expected })
    }
}
