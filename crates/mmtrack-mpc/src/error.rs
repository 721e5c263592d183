use thiserror::Error;

use crate::GmPhdError;

/// What can go wrong when configuring or running MPC detection and tracking.
#[derive(Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum MpcError {
    /// A configuration value is outside its meaningful range.
    #[error("mpc config: {field} = {value} is invalid: expected {expected}")]
    BadConfig {
        /// The field, as written in the config file.
        field: &'static str,
        /// Its value, as text.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A snapshot cannot be processed (wrong length, NaN taps, bad spacing).
    #[error("snapshot {snapshot} (set {set_index}, t_ns {t_ns}): {detail}")]
    BadSnapshot {
        /// Position of the snapshot in the input, 0-based.
        snapshot: usize,
        /// Its set.
        set_index: u64,
        /// Its time stamp.
        t_ns: i64,
        /// What is wrong.
        detail: String,
    },
    /// The sounder pulse is unusable (empty, all zero, NaN).
    #[error("sounder pulse: {detail}")]
    BadPulse {
        /// What is wrong.
        detail: String,
    },
    /// Snapshots must arrive in time order.
    #[error("snapshot {snapshot} (t_ns {t_ns}) is not after the previous one (t_ns {previous_t_ns})")]
    NonMonotonicTime {
        /// Position of the offending snapshot, 0-based.
        snapshot: usize,
        /// The previous time stamp.
        previous_t_ns: i64,
        /// The offending time stamp.
        t_ns: i64,
    },
    /// A set without snapshots was given.
    #[error("empty set after {snapshots_before} snapshots: a set needs at least one snapshot")]
    EmptySet {
        /// Snapshots pushed before it.
        snapshots_before: usize,
    },
    /// The GM-PHD baseline refused its config (`gmphd.<field>`) or input; the
    /// baseline's error is the source (not repeated in this message).
    #[error("GM-PHD baseline")]
    GmPhd {
        /// The baseline's error.
        source: GmPhdError,
    },
}
