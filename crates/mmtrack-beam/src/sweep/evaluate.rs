//! Beam-training accounting: runs a tracker over full sweeps, where the
//! best beam of every sweep is known, and scores each sweep.

use mmtrack_core::BeamSweep;

use super::error::SweepError;
use super::search::BeamProbe;
use super::{SweepTracker, dt_s};

/// One pass of full sweeps (every beam measured, so each sweep's best beam
/// is known), in time order, with the GNSS beam prediction of each sweep
/// when there is one.
#[derive(Debug, Clone, Copy)]
pub struct SweepPass<'a> {
    /// The sweeps, strictly increasing in time.
    pub sweeps: &'a [BeamSweep],
    /// One GNSS-predicted beam (continuous index, see
    /// [`super::BeamMap::predict_pass`]) per sweep, for GNSS-driven trackers.
    pub gnss_beam: Option<&'a [f64]>,
}

/// The accounting of one sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepRecord {
    /// Pass index in the evaluation's input.
    pub pass: usize,
    /// Sweep index within the pass (0 for the pass's first sweep).
    pub sweep: usize,
    /// Sweep time, nanoseconds.
    pub t_ns: i64,
    /// The beam the tracker chose.
    pub chosen_beam: usize,
    /// The strongest beam of the full sweep.
    pub best_beam: usize,
    /// Distinct beams the tracker measured in this sweep (a full sweep
    /// counts all of them, a re-acquisition its beams plus those measured
    /// before the loss was noticed).
    pub beams_measured: usize,
    /// Whether the tracker (re-)acquired the beam in this sweep.
    pub reinitialised: bool,
    /// Received-power loss of the chosen beam against the best, dB (`>= 0`):
    /// `10 log10(P_best / P_chosen)`.
    pub loss_db: f64,
}

/// Runs `tracker` over `passes` (calling [`SweepTracker::start_pass`] before
/// each) and scores every sweep against its full sweep's best beam.
///
/// # Errors
/// - [`SweepError::BeamNotMeasured`] for a sweep that is not a full sweep;
/// - [`SweepError::BeamCountMismatch`] for sweeps of different beam counts;
/// - [`SweepError::BadInput`] for a GNSS prediction of another length than
///   its pass;
/// - [`SweepError::NonIncreasingTime`] for sweep times that do not increase
///   within a pass;
/// - the tracker's errors.
pub fn evaluate(tracker: &mut dyn SweepTracker, passes: &[SweepPass<'_>]) -> Result<Vec<SweepRecord>, SweepError> {
    check_passes(passes)?;
    let mut records = Vec::with_capacity(passes.iter().map(|p| p.sweeps.len()).sum());
    for (pass_index, pass) in passes.iter().enumerate() {
        tracker.start_pass();
        for (sweep_index, sweep) in pass.sweeps.iter().enumerate() {
            let gnss_beam = pass.gnss_beam.map(|beams| beams[sweep_index]);
            let mut probe = BeamProbe::new(sweep);
            let decision = tracker.step(&mut probe, gnss_beam)?;
            let best_beam = sweep.best_measured_beam();
            let power = |beam: usize| sweep.power(beam).ok_or(SweepError::BeamNotMeasured { t_ns: sweep.t_ns(), beam });
            let (best_power, chosen_power) = (power(best_beam)?, power(decision.chosen_beam)?);
            let loss_db = if chosen_power == best_power { 0.0 } else { 10.0 * (best_power / chosen_power).log10() };
            records.push(SweepRecord {
                pass: pass_index,
                sweep: sweep_index,
                t_ns: sweep.t_ns(),
                chosen_beam: decision.chosen_beam,
                best_beam,
                beams_measured: probe.measured_count(),
                reinitialised: decision.reinitialised,
                loss_db,
            });
        }
    }
    Ok(records)
}

/// Every sweep full and of one beam count, GNSS predictions one per sweep,
/// times increasing within each pass.
fn check_passes(passes: &[SweepPass<'_>]) -> Result<(), SweepError> {
    let beam_count = passes.iter().find_map(|p| p.sweeps.first()).map(BeamSweep::beam_count);
    for pass in passes {
        if let Some(gnss) = pass.gnss_beam
            && gnss.len() != pass.sweeps.len()
        {
            return Err(SweepError::BadInput {
                what: format!("{} GNSS beam predictions for a pass of {} sweeps", gnss.len(), pass.sweeps.len()),
            });
        }
        for (index, sweep) in pass.sweeps.iter().enumerate() {
            if Some(sweep.beam_count()) != beam_count {
                return Err(SweepError::BeamCountMismatch {
                    sweep: index,
                    expected: beam_count.unwrap_or(0),
                    found: sweep.beam_count(),
                });
            }
            if let Some(beam) = (0..sweep.beam_count()).find(|&b| !sweep.is_measured(b)) {
                return Err(SweepError::BeamNotMeasured { t_ns: sweep.t_ns(), beam });
            }
            if index > 0 {
                dt_s(pass.sweeps[index - 1].t_ns(), sweep.t_ns())?;
            }
        }
    }
    Ok(())
}

/// Pooled scores of a set of sweep records.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepSummary {
    /// Sweeps scored.
    pub sweeps: usize,
    /// Mean received-power loss against the best beam, dB.
    pub mean_loss_db: f64,
    /// Median received-power loss, dB (the mean of the two middle values
    /// for an even count).
    pub median_loss_db: f64,
    /// Share of sweeps whose chosen beam is the best beam.
    pub top1: f64,
    /// Share of sweeps whose chosen beam is within one beam of the best.
    pub within_one: f64,
    /// Mean beams measured per sweep.
    pub mean_beams_per_sweep: f64,
    /// Sweeps with a (re-)acquisition.
    pub reinitialisations: usize,
}

impl SweepSummary {
    /// Summarises `records`; `None` for none.
    pub fn from_records<'a>(records: impl IntoIterator<Item = &'a SweepRecord>) -> Option<Self> {
        let records: Vec<&SweepRecord> = records.into_iter().collect();
        if records.is_empty() {
            return None;
        }
        let n = records.len() as f64;
        let mut losses: Vec<f64> = records.iter().map(|r| r.loss_db).collect();
        losses.sort_by(f64::total_cmp);
        let middle = losses.len() / 2;
        let median_loss_db =
            if losses.len() % 2 == 1 { losses[middle] } else { 0.5 * (losses[middle - 1] + losses[middle]) };
        let share = |ok: &dyn Fn(&SweepRecord) -> bool| records.iter().filter(|r| ok(r)).count() as f64 / n;
        Some(Self {
            sweeps: records.len(),
            mean_loss_db: losses.iter().sum::<f64>() / n,
            median_loss_db,
            top1: share(&|r| r.chosen_beam == r.best_beam),
            within_one: share(&|r| r.chosen_beam.abs_diff(r.best_beam) <= 1),
            mean_beams_per_sweep: records.iter().map(|r| r.beams_measured as f64).sum::<f64>() / n,
            reinitialisations: records.iter().filter(|r| r.reinitialised).count(),
        })
    }
}
