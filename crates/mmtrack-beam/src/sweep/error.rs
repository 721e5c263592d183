//! What can go wrong when configuring or running a beam-sweep tracker, or
//! fitting its beam map.

use mmtrack_filter::FilterError;
use thiserror::Error;

/// Errors of the beam-sweep trackers, their evaluation and the beam-map fit.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SweepError {
    /// A configuration value is outside its meaningful range.
    #[error("beam-sweep config: {field} = {value} is invalid: expected {expected}")]
    BadConfig {
        /// The field, as written in the config.
        field: &'static str,
        /// Its value, as text.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A sweep has another number of beams than the tracker or the first
    /// sweep.
    #[error("sweep {sweep}: {found} beams, expected {expected}")]
    BeamCountMismatch {
        /// Sweep index (within its pass when known).
        sweep: usize,
        /// Beams expected.
        expected: usize,
        /// Beams found.
        found: usize,
    },
    /// A tracker asked for a beam the sweep did not measure, or an
    /// evaluation was given a sweep that is not a full sweep (its best beam
    /// would be unknown).
    #[error("sweep at {t_ns} ns: beam {beam} was not measured")]
    BeamNotMeasured {
        /// Sweep time, nanoseconds.
        t_ns: i64,
        /// The beam.
        beam: usize,
    },
    /// Sweep times within a pass do not increase strictly.
    #[error("sweep time {t_ns} ns does not follow {previous_t_ns} ns")]
    NonIncreasingTime {
        /// The previous sweep's time.
        previous_t_ns: i64,
        /// This sweep's time.
        t_ns: i64,
    },
    /// A GNSS-driven tracker or baseline got no GNSS beam prediction, or a
    /// per-sweep input has the wrong length or a non-finite value.
    #[error("{what}")]
    BadInput {
        /// What is wrong, in words.
        what: String,
    },
    /// The beam-map fit has too little data (fewer than two distinct
    /// bearings) to fit a line.
    #[error("beam map fit: {what}")]
    DegenerateFit {
        /// What is missing.
        what: &'static str,
    },
    /// The track filter failed (a covariance lost definiteness).
    #[error("track filter at {t_ns} ns")]
    Filter {
        /// Sweep time, nanoseconds.
        t_ns: i64,
        /// The filter's error.
        #[source]
        source: FilterError,
    },
}

/// Errors unless `value` is finite and satisfies `ok`.
pub(crate) fn check(field: &'static str, value: f64, ok: bool, expected: &'static str) -> Result<(), SweepError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(SweepError::BadConfig { field, value: value.to_string(), expected })
    }
}
