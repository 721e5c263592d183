//! Beam-sweep tracking for measured codebooks: choose each sweep's beam
//! while measuring only a few beams around a prediction, and account for
//! what that costs against a full sweep.
//!
//! A roadside array with a codebook of `N` beams (the DeepSense 6G 60 GHz
//! unit: 64 beams across about 90 degrees) can sweep every beam and use the
//! strongest; a tracker instead predicts where the best beam will be and
//! measures a small window around it. The pieces:
//!
//! - [`BeamProbe`]: the tracker's only access to a sweep, beam by beam; it
//!   counts the beams measured, so the accounting cannot be fooled;
//! - [`SearchConfig`] and [`Reacquisition`]: the window, its hill-climbing
//!   extension, the loss rule and how the beam is found again;
//! - [`WindowTracker`]: a constant-velocity Kalman filter on the beam index,
//!   from the measurements alone;
//! - [`GnssWindowTracker`]: the same filter with the beam the car's GNSS
//!   position predicts through the fitted [`BeamMap`] as a second, coarser
//!   measurement (the SPEBT idea of Liu et al. 2024 with GNSS in place of
//!   radar odometry);
//! - [`BeamMap`]: beam index against the car's bearing from the array, with
//!   the boresight, beam spacing and GNSS time offset fitted from data
//!   (leave-one-pass-out for evaluation);
//! - [`LastFullSweep`] and [`GnssMapOnly`]: the baselines, through the same
//!   [`SweepTracker`] interface;
//! - [`evaluate`] and [`SweepSummary`]: per-sweep chosen and best beam,
//!   beams measured, re-initialisations and received-power loss, and their
//!   summary.

mod baselines;
mod beam_map;
mod error;
mod evaluate;
mod gnss;
mod search;
mod window;

#[cfg(test)]
mod tests;

pub use baselines::{GnssMapOnly, LastFullSweep};
pub use beam_map::{BeamMap, BeamMapConfig, GnssPass, MapPass, bearing_rad};
pub use error::SweepError;
pub use evaluate::{SweepPass, SweepRecord, SweepSummary, evaluate};
pub use gnss::{GnssTrackerConfig, GnssWindowTracker};
pub use search::{BeamProbe, Reacquisition, SearchConfig};
pub use window::{WindowTracker, WindowTrackerConfig};

use mmtrack_core::ns_to_s;

/// What a tracker decided for one sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepDecision {
    /// The beam to use for this sweep's interval.
    pub chosen_beam: usize,
    /// Whether the beam was (re-)acquired in this sweep (pass start or
    /// loss).
    pub reinitialised: bool,
    /// The tracker's continuous beam estimate after the sweep, if it keeps
    /// one.
    pub track_beam: Option<f64>,
}

/// The role every beam-sweep tracker (and baseline) plays.
pub trait SweepTracker {
    /// Forgets the track: the next sweep starts a new pass.
    fn start_pass(&mut self);

    /// Chooses the beam for the sweep behind `probe`, measuring through the
    /// probe only the beams it needs. `gnss_beam` is the beam the car's GNSS
    /// position predicts for this sweep (continuous index, through a
    /// [`BeamMap`]), for the trackers that use it.
    ///
    /// # Errors
    /// [`SweepError::BeamNotMeasured`] when the sweep lacks a beam the
    /// tracker asks for; [`SweepError::NonIncreasingTime`]; a GNSS-driven
    /// tracker's [`SweepError::BadInput`] without a finite `gnss_beam`; the
    /// filter's errors.
    fn step(&mut self, probe: &mut BeamProbe<'_>, gnss_beam: Option<f64>) -> Result<SweepDecision, SweepError>;
}

/// Seconds from `previous_t_ns` to `t_ns`, which must be later.
pub(crate) fn dt_s(previous_t_ns: i64, t_ns: i64) -> Result<f64, SweepError> {
    if t_ns > previous_t_ns {
        Ok(ns_to_s(t_ns.saturating_sub(previous_t_ns)))
    } else {
        Err(SweepError::NonIncreasingTime { previous_t_ns, t_ns })
    }
}
