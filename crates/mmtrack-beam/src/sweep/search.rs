//! The measuring side every beam-sweep tracker shares: a probe that reads a
//! sweep beam by beam and counts what it read, the local window search with
//! its hill-climbing extension, the sub-beam peak estimate, the loss rule
//! and the re-acquisition sweeps.

use std::collections::VecDeque;

use mmtrack_core::{BeamSweep, NS_PER_S};

use super::error::{SweepError, check};

/// A measure-on-demand view of one sweep.
///
/// Trackers read beam powers only through a probe, so the number of beams a
/// tracker measured in a sweep is the number of distinct beams it asked
/// for ([`BeamProbe::measured_count`]), counted by the probe rather than
/// reported by the tracker. Powers come back in dB (`10 log10` of the
/// linear power; a zero power is `-inf` dB).
#[derive(Debug)]
pub struct BeamProbe<'a> {
    sweep: &'a BeamSweep,
    power_db: Vec<Option<f64>>,
    measured_count: usize,
}

impl<'a> BeamProbe<'a> {
    /// A probe over `sweep` that has measured nothing yet.
    #[must_use]
    pub fn new(sweep: &'a BeamSweep) -> Self {
        Self { sweep, power_db: vec![None; sweep.beam_count()], measured_count: 0 }
    }

    /// Beams in the codebook.
    #[must_use]
    pub fn beam_count(&self) -> usize {
        self.power_db.len()
    }

    /// Sweep time, nanoseconds.
    #[must_use]
    pub fn t_ns(&self) -> i64 {
        self.sweep.t_ns()
    }

    /// Measures `beam` (once; asking again costs nothing) and returns its
    /// power in dB.
    ///
    /// # Errors
    /// [`SweepError::BeamNotMeasured`] for a beam outside the codebook or
    /// one the underlying sweep does not hold.
    pub fn measure(&mut self, beam: usize) -> Result<f64, SweepError> {
        if let Some(Some(db)) = self.power_db.get(beam) {
            return Ok(*db);
        }
        let linear = self.sweep.power(beam).ok_or(SweepError::BeamNotMeasured { t_ns: self.t_ns(), beam })?;
        let db = 10.0 * linear.log10();
        self.power_db[beam] = Some(db);
        self.measured_count += 1;
        Ok(db)
    }

    /// Measures every beam (a full sweep).
    ///
    /// # Errors
    /// As [`BeamProbe::measure`].
    pub fn measure_all(&mut self) -> Result<(), SweepError> {
        for beam in 0..self.beam_count() {
            self.measure(beam)?;
        }
        Ok(())
    }

    /// Power in dB of `beam` if it has been measured through this probe.
    #[must_use]
    pub fn measured(&self, beam: usize) -> Option<f64> {
        self.power_db.get(beam).copied().flatten()
    }

    /// Number of distinct beams measured so far.
    #[must_use]
    pub fn measured_count(&self) -> usize {
        self.measured_count
    }

    /// The strongest beam measured so far and its power in dB (the lowest
    /// index among equal powers); `None` before any measurement.
    #[must_use]
    pub fn best_measured(&self) -> Option<(usize, f64)> {
        let mut best = None::<(usize, f64)>;
        for (beam, db) in self.power_db.iter().enumerate() {
            if let Some(db) = *db
                && best.is_none_or(|(_, best_db)| db > best_db)
            {
                best = Some((beam, db));
            }
        }
        best
    }
}

/// How a tracker re-acquires the beam at the start of a pass and after a
/// loss.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reacquisition {
    /// Measure every beam of the codebook.
    FullSweep,
    /// Measure every `stride`-th beam (starting at `stride / 2`), then climb
    /// from the strongest to a local maximum whose two neighbours are
    /// measured. With a codebook that oversamples the array's beamwidth (64
    /// beams across 90 degrees for a 16-element array: about 1.4 degrees per
    /// beam against a half-power beamwidth of about 6.4 degrees, 4.5 beams), a
    /// stride up to the half-power beamwidth in beams puts a coarse beam
    /// inside the main lobe's half-power region, so the climb reaches the
    /// main-lobe peak.
    Coarse {
        /// Beams between coarse measurements, at least 2.
        stride: usize,
    },
}

/// The measuring rules of a window tracker.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchConfig {
    /// Beams measured either side of the predicted beam: a window of `2 h +
    /// 1` beams.
    pub half_window_beams: usize,
    /// Beams the climb may add beyond the window when the strongest beam
    /// sits at the window's edge (measuring outward one beam at a time until
    /// the strongest is flanked by measured beams).
    pub max_extension_beams: usize,
    /// Loss rule, power part: the track is lost when the chosen beam's power
    /// is more than this many dB below the strongest chosen power of the
    /// last `hold_s` seconds.
    pub drop_db: f64,
    /// Length of that power hold, seconds.
    pub hold_s: f64,
    /// How the beam is found at a pass start and after a loss.
    pub reacquisition: Reacquisition,
}

impl Default for SearchConfig {
    /// A three-beam window, up to four beams of climb (about one half-power
    /// beamwidth of the 64-beam, 16-element codebook), loss at 6 dB below the
    /// best power of the last second (the sweep-to-sweep change of the best
    /// beam's power has a standard deviation of about 1.6 dB on the
    /// DeepSense scenario 1 passes, so 6 dB is about four of them), coarse
    /// re-acquisition every fourth beam.
    fn default() -> Self {
        Self {
            half_window_beams: 1,
            max_extension_beams: 4,
            drop_db: 6.0,
            hold_s: 1.0,
            reacquisition: Reacquisition::Coarse { stride: 4 },
        }
    }
}

impl SearchConfig {
    /// Checks the values.
    ///
    /// # Errors
    /// [`SweepError::BadConfig`] for a negative or non-finite `drop_db` or
    /// `hold_s`, or a coarse stride below 2.
    pub fn validate(&self) -> Result<(), SweepError> {
        check("drop_db", self.drop_db, self.drop_db >= 0.0, "a finite power drop >= 0 dB")?;
        check("hold_s", self.hold_s, self.hold_s >= 0.0, "a finite hold >= 0 s")?;
        if let Reacquisition::Coarse { stride } = self.reacquisition
            && stride < 2
        {
            return Err(SweepError::BadConfig {
                field: "reacquisition.stride",
                value: stride.to_string(),
                expected: "at least 2 (use FullSweep for every beam)",
            });
        }
        Ok(())
    }
}

/// A peak found by the search: the strongest measured beam, its power, and
/// whether it still has an unmeasured neighbour (the climb ran out).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Peak {
    pub beam: usize,
    pub power_db: f64,
    pub at_edge: bool,
}

/// Hill-climbs from the strongest measured beam: while it has an unmeasured
/// neighbour, measures that neighbour (at most `max_extra` new beams).
pub(crate) fn climb(probe: &mut BeamProbe<'_>, max_extra: usize) -> Result<Peak, SweepError> {
    let last = probe.beam_count() - 1;
    let mut extra = 0;
    loop {
        let (beam, power_db) =
            probe.best_measured().ok_or(SweepError::BadInput { what: "climb without a measured beam".to_string() })?;
        let left = (beam > 0 && probe.measured(beam - 1).is_none()).then(|| beam - 1);
        let right = (beam < last && probe.measured(beam + 1).is_none()).then_some(beam + 1);
        let Some(next) = left.or(right) else {
            return Ok(Peak { beam, power_db, at_edge: false });
        };
        if extra >= max_extra {
            return Ok(Peak { beam, power_db, at_edge: true });
        }
        probe.measure(next)?;
        extra += 1;
    }
}

/// Where a tracker looks in one sweep: the beams within `half` of the beam
/// nearest to `center`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Window {
    pub center: f64,
    pub half: usize,
}

/// Measures `window`: the `2 half + 1` beams around the beam nearest to its
/// center (shifted to stay inside the codebook; the whole codebook if it is
/// smaller). A center outside the codebook points at its nearest edge beam.
pub(crate) fn measure_window(probe: &mut BeamProbe<'_>, window: Window) -> Result<(), SweepError> {
    let count = probe.beam_count();
    let Window { center, half } = window;
    let width = (2 * half + 1).min(count);
    let nearest = if center.is_nan() { 0 } else { center.round().clamp(0.0, (count - 1) as f64) as usize };
    let start = nearest.saturating_sub(half).min(count - width);
    for beam in start..start + width {
        probe.measure(beam)?;
    }
    Ok(())
}

/// Sub-beam position of the peak at `beam`: the vertex of the parabola
/// through the dB powers of `beam - 1`, `beam`, `beam + 1`,
///
/// ```text
/// delta = (P[-1] - P[+1]) / (2 (P[-1] - 2 P[0] + P[+1])),
/// ```
///
/// which lies in `[-1/2, 1/2]` when the middle power is the largest. Falls
/// back to `beam` when a neighbour is unmeasured or the three powers do not
/// bend downwards.
///
/// # References
/// Quadratic interpolation of spectral peaks: J. O. Smith, *Spectral Audio
/// Signal Processing*, W3K 2011, "Quadratic Interpolation of Spectral Peaks"
/// (there on dB magnitudes of FFT bins; here on dB powers of adjacent beams).
pub(crate) fn subbeam_peak(probe: &BeamProbe<'_>, beam: usize) -> f64 {
    let (Some(left), Some(right)) = (beam.checked_sub(1).and_then(|b| probe.measured(b)), probe.measured(beam + 1))
    else {
        return beam as f64;
    };
    let Some(middle) = probe.measured(beam) else { return beam as f64 };
    let bend = left - 2.0 * middle + right;
    let delta = 0.5 * (left - right) / bend;
    if bend < 0.0 && delta.is_finite() && delta.abs() <= 0.5 { beam as f64 + delta } else { beam as f64 }
}

/// Finds the beam from scratch as `reacquisition` says.
pub(crate) fn acquire(probe: &mut BeamProbe<'_>, reacquisition: Reacquisition) -> Result<Peak, SweepError> {
    match reacquisition {
        Reacquisition::FullSweep => probe.measure_all()?,
        Reacquisition::Coarse { stride } => {
            let count = probe.beam_count();
            for beam in ((stride / 2).min(count - 1)..count).step_by(stride) {
                probe.measure(beam)?;
            }
        }
    }
    climb(probe, usize::MAX)
}

/// The strongest chosen power of the last `hold` seconds: the reference of
/// the loss rule's power part.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PowerHold {
    hold_ns: i64,
    history: VecDeque<(i64, f64)>,
}

impl PowerHold {
    pub fn new(hold_s: f64) -> Self {
        Self { hold_ns: (hold_s * NS_PER_S as f64).round() as i64, history: VecDeque::new() }
    }

    /// Forgets everything (a new pass).
    pub fn clear(&mut self) {
        self.history.clear();
    }

    /// Adds the chosen power of the sweep at `t_ns`, dropping entries older
    /// than the hold.
    pub fn push(&mut self, t_ns: i64, power_db: f64) {
        while self.history.front().is_some_and(|&(t, _)| t_ns.saturating_sub(t) > self.hold_ns) {
            self.history.pop_front();
        }
        self.history.push_back((t_ns, power_db));
    }

    /// The strongest held power at `t_ns` (`None` when nothing is held).
    pub fn level_db(&self, t_ns: i64) -> Option<f64> {
        self.history
            .iter()
            .filter(|&&(t, _)| t_ns.saturating_sub(t) <= self.hold_ns)
            .map(|&(_, db)| db)
            .reduce(f64::max)
    }
}

/// What one sweep's search found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SearchOutcome {
    /// The chosen beam and its power.
    pub peak: Peak,
    /// Sub-beam position of the chosen beam's peak.
    pub subbeam: f64,
    /// Whether the track was lost and the beam re-acquired.
    pub reacquired: bool,
}

/// One sweep of a window tracker: measures `window`, climbs (up to
/// `max_extension_beams` new beams), applies the loss rule (the climb ran out at the window's edge,
/// or the power fell `drop_db` below the hold) and re-acquires when lost;
/// updates the power hold with the chosen beam's power (restarting it after
/// a re-acquisition, so a blocked link does not trigger one every sweep).
pub(crate) fn search_sweep(
    probe: &mut BeamProbe<'_>,
    window: Window,
    config: &SearchConfig,
    hold: &mut PowerHold,
) -> Result<SearchOutcome, SweepError> {
    measure_window(probe, window)?;
    let peak = climb(probe, config.max_extension_beams)?;
    let t_ns = probe.t_ns();
    let faded = hold.level_db(t_ns).is_some_and(|level| peak.power_db < level - config.drop_db);
    if peak.at_edge || faded {
        let peak = acquire(probe, config.reacquisition)?;
        hold.clear();
        hold.push(t_ns, peak.power_db);
        return Ok(SearchOutcome { peak, subbeam: subbeam_peak(probe, peak.beam), reacquired: true });
    }
    hold.push(t_ns, peak.power_db);
    Ok(SearchOutcome { peak, subbeam: subbeam_peak(probe, peak.beam), reacquired: false })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sweep whose dB power is a parabola peaking at `peak` (sub-beam),
    /// `-curvature_db (b - peak)^2`, floored at -30 dB.
    fn parabola_sweep(count: usize, peak: f64, curvature_db: f64) -> BeamSweep {
        let power =
            (0..count).map(|b| 10f64.powf((-curvature_db * (b as f64 - peak).powi(2)).max(-30.0) / 10.0)).collect();
        BeamSweep::full(0, power).unwrap()
    }

    #[test]
    fn window_climb_and_subbeam_find_an_offset_peak() {
        let sweep = parabola_sweep(64, 20.3, 0.5);
        let mut probe = BeamProbe::new(&sweep);
        measure_window(&mut probe, Window { center: 17.0, half: 1 }).unwrap();
        assert_eq!(probe.measured_count(), 3);
        let peak = climb(&mut probe, 4).unwrap();
        assert_eq!(peak.beam, 20);
        assert!(!peak.at_edge);
        // 16..=18 then 19, 20, 21: six beams.
        assert_eq!(probe.measured_count(), 6);
        // An exact parabola in dB: the vertex comes back exactly (to rounding).
        assert!((subbeam_peak(&probe, 20) - 20.3).abs() < 1e-9);
    }

    #[test]
    fn climb_stops_at_its_budget_and_reports_the_edge() {
        let sweep = parabola_sweep(64, 40.0, 0.1);
        let mut probe = BeamProbe::new(&sweep);
        measure_window(&mut probe, Window { center: 30.0, half: 1 }).unwrap();
        let peak = climb(&mut probe, 4).unwrap();
        assert_eq!((peak.beam, peak.at_edge), (35, true));
        assert_eq!(probe.measured_count(), 7);
    }

    #[test]
    fn window_stays_inside_the_codebook() {
        let sweep = parabola_sweep(8, 0.0, 0.5);
        let mut probe = BeamProbe::new(&sweep);
        measure_window(&mut probe, Window { center: -3.0, half: 2 }).unwrap();
        assert_eq!((0..5).map(|b| probe.measured(b).is_some()).filter(|&m| m).count(), 5);
        let mut probe = BeamProbe::new(&sweep);
        measure_window(&mut probe, Window { center: 1e9, half: 20 }).unwrap();
        assert_eq!(probe.measured_count(), 8, "a window wider than the codebook is the codebook");
    }

    #[test]
    fn coarse_acquisition_finds_the_main_lobe_with_fewer_beams() {
        let sweep = parabola_sweep(64, 45.6, 0.15);
        let mut probe = BeamProbe::new(&sweep);
        let peak = acquire(&mut probe, Reacquisition::Coarse { stride: 4 }).unwrap();
        assert_eq!(peak.beam, 46);
        assert!(!peak.at_edge);
        // 16 coarse beams (2, 6, ..., 62) plus the climb from 46: 45 and 47.
        assert_eq!(probe.measured_count(), 18);
        let mut probe = BeamProbe::new(&sweep);
        assert_eq!(acquire(&mut probe, Reacquisition::FullSweep).unwrap().beam, 46);
        assert_eq!(probe.measured_count(), 64);
    }

    #[test]
    fn power_hold_keeps_the_strongest_of_the_last_seconds() {
        let mut hold = PowerHold::new(1.0);
        hold.push(0, -5.0);
        hold.push(500_000_000, -9.0);
        assert_eq!(hold.level_db(900_000_000), Some(-5.0));
        assert_eq!(hold.level_db(1_200_000_000), Some(-9.0), "-5 dB is older than 1 s");
        hold.clear();
        assert_eq!(hold.level_db(0), None);
    }

    #[test]
    fn probe_refuses_unmeasured_and_outside_beams() {
        let sweep = BeamSweep::new(7, vec![1.0, 2.0], vec![true, false]).unwrap();
        let mut probe = BeamProbe::new(&sweep);
        assert_eq!(probe.measure(1), Err(SweepError::BeamNotMeasured { t_ns: 7, beam: 1 }));
        assert_eq!(probe.measure(2), Err(SweepError::BeamNotMeasured { t_ns: 7, beam: 2 }));
        assert_eq!(probe.measure(0), Ok(0.0));
        assert_eq!(probe.measure(0), Ok(0.0));
        assert_eq!(probe.measured_count(), 1, "a beam measured twice counts once");
    }
}
