use thiserror::Error;

/// Errors raised when a core type is constructed from inconsistent parts.
///
/// Constructors validate their input in release builds too: invalid data is an
/// error, never a debug assertion.
#[derive(Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum CoreError {
    /// A buffer does not have the length its declared shape implies.
    #[error("{what}: expected {expected} values, found {found}")]
    ShapeMismatch {
        /// Which buffer.
        what: &'static str,
        /// Length implied by the declared shape.
        expected: usize,
        /// Actual length.
        found: usize,
    },
    /// A value that must be finite is NaN or infinite.
    #[error("{field} is not finite ({value})")]
    NotFinite {
        /// Field name, with its unit.
        field: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A value is outside its allowed range.
    #[error("{field} = {value} is out of range: {expected}")]
    OutOfRange {
        /// Field name, with its unit.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// What was expected, in words.
        expected: &'static str,
    },
    /// Timestamps that must increase strictly do not.
    #[error("{what}: time goes backwards or repeats at index {index} ({previous_t_ns} ns then {t_ns} ns)")]
    NonMonotonicTime {
        /// Which sequence of timestamps.
        what: &'static str,
        /// Index of the first offending element.
        index: usize,
        /// The timestamp before it.
        previous_t_ns: i64,
        /// The offending timestamp.
        t_ns: i64,
    },
}

/// Fails with [`CoreError::NotFinite`] unless `value` is finite.
pub(crate) fn ensure_finite(field: &'static str, value: f64) -> Result<(), CoreError> {
    if value.is_finite() { Ok(()) } else { Err(CoreError::NotFinite { field, value }) }
}

/// Fails with [`CoreError::ShapeMismatch`] unless `found == expected`.
pub(crate) fn ensure_len(what: &'static str, expected: usize, found: usize) -> Result<(), CoreError> {
    if expected == found { Ok(()) } else { Err(CoreError::ShapeMismatch { what, expected, found }) }
}
