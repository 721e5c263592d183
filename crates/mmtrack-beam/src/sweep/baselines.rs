//! The two reference policies the trackers are compared with, run through
//! the same [`SweepTracker`] interface and accounting.

use super::error::SweepError;
use super::search::BeamProbe;
use super::{SweepDecision, SweepTracker};

/// "Last full sweep's best beam": every sweep measures all beams, and the
/// beam used now is the best beam of the previous sweep (the sweep's
/// result arrives one sweep late).
///
/// The first sweep of a pass has no previous sweep: it is counted as a full
/// sweep that uses its own best beam (zero loss, a re-initialisation). An
/// evaluation can leave those sweeps out of its summary instead (the
/// records carry the sweep index within the pass).
#[derive(Debug, Clone, Default)]
pub struct LastFullSweep {
    previous_best: Option<usize>,
}

impl LastFullSweep {
    /// A baseline with no previous sweep.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }
}

impl SweepTracker for LastFullSweep {
    fn start_pass(&mut self) {
        self.previous_best = None;
    }

    fn step(&mut self, probe: &mut BeamProbe<'_>, _gnss_beam: Option<f64>) -> Result<SweepDecision, SweepError> {
        probe.measure_all()?;
        let (best, _) = probe.best_measured().ok_or(SweepError::BadInput { what: "empty sweep".to_string() })?;
        let chosen = self.previous_best.unwrap_or(best);
        let reinitialised = self.previous_best.is_none();
        self.previous_best = Some(best);
        Ok(SweepDecision { chosen_beam: chosen, reinitialised, track_beam: None })
    }
}

/// "GPS bearing through the fitted beam map": the beam nearest to the GNSS
/// beam prediction, with no beam measured.
#[derive(Debug, Clone, Copy, Default)]
pub struct GnssMapOnly;

impl SweepTracker for GnssMapOnly {
    fn start_pass(&mut self) {}

    fn step(&mut self, probe: &mut BeamProbe<'_>, gnss_beam: Option<f64>) -> Result<SweepDecision, SweepError> {
        let t_ns = probe.t_ns();
        let beam = match gnss_beam {
            Some(beam) if beam.is_finite() => beam,
            other => {
                return Err(SweepError::BadInput {
                    what: format!("sweep at {t_ns} ns: the GNSS map baseline needs a finite GNSS beam, got {other:?}"),
                });
            }
        };
        // The nearest codebook beam: a prediction beyond either end of the
        // field of view points at that end's beam.
        let last = (probe.beam_count() - 1) as f64;
        let chosen = beam.round().clamp(0.0, last) as usize;
        Ok(SweepDecision { chosen_beam: chosen, reinitialised: false, track_beam: Some(beam) })
    }
}
