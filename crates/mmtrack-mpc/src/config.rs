//! Parameters of detection and tracking, with the paper's values as defaults.

use serde::{Deserialize, Serialize};

use crate::{GmPhdConfig, MpcError};

/// How the noise floor of a snapshot is estimated (detection step 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "kebab-case", deny_unknown_fields)]
pub enum NoiseFloor {
    /// Mean tap power of the quietest quarter of consecutive, non-overlapping
    /// windows of `window_taps` taps. The paper estimates the floor "in a part
    /// of the impulse response where no MPCs occur (usually at larger delays)";
    /// this finds such a part without knowing where the paths are. Windows are
    /// ranked on their even taps and averaged on their odd taps, so picking
    /// quiet windows does not bias the floor low.
    QuietestWindows {
        /// Taps per window.
        window_taps: usize,
    },
    /// Mean tap power between two delays on the recording's delay axis.
    DelayRange {
        /// First delay of the range, seconds.
        start_s: f64,
        /// Last delay of the range, seconds.
        end_s: f64,
    },
    /// A known floor, dB (`10 log10` of the mean tap power).
    Fixed {
        /// Floor, dB.
        power_db: f64,
    },
}

/// Detection per snapshot: search and subtract (Mahler et al. 2017, Sec. III-A).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DetectionConfig {
    /// How the noise floor is estimated.
    pub noise_floor: NoiseFloor,
    /// Margin added to the noise floor; taps below floor + margin are zeroed
    /// and peaks below it end the search, dB (paper: 6 dB).
    pub threshold_margin_db: f64,
    /// Zero the CIR taps below floor + margin before the search, as the
    /// paper's step 1 does. Switching it off keeps the weak skirts of each
    /// pulse (a -116 dB path over a -140 dB floor: mean delay error 0.029
    /// instead of 0.037 ns) at the price of more noise peaks to reject.
    pub zero_below_threshold: bool,
    /// Kaiser window shape `beta` (eq. (10) with `beta = pi a`) applied to the
    /// transfer function; `None` skips the window. Default 6: the paper says
    /// `a = 6`, but its pulse width of 2.47 ns at -10 dB is what `beta = 6`
    /// gives (2.50 ns for a flat 1 GHz band; `beta = 6 pi` gives 4.25 ns), see
    /// [`mmtrack_core::sounder::SounderBand::kaiser_window`].
    pub kaiser_beta: Option<f64>,
    /// Width of the delay range blocked around each detection, seconds;
    /// `None` takes the (windowed) pulse's width at 10 dB below its peak, as
    /// the paper does (2.47 ns for its sounder).
    pub blocked_width_s: Option<f64>,
    /// Most MPCs detected per snapshot (a guard; the search normally ends at
    /// the threshold).
    pub max_mpcs: usize,
    /// Ours, not the paper's: after each detection, re-estimate it and the
    /// detections within [`crate::detect::OVERLAP_TAPS`] of it, each with the
    /// others subtracted (a few coordinate sweeps), so two paths closer than
    /// a pulse width are fitted jointly instead of leaving the first one's
    /// misfit as a residue the search picks up. Detections whose
    /// re-estimated amplitude falls below the threshold are dropped.
    pub refine_overlapping: bool,
    /// Ours, not the paper's: after the search, re-estimate every
    /// detection's delay and amplitude on the CIR as measured (neither
    /// zeroed below the threshold nor windowed) with all other detections
    /// subtracted, by coordinate sweeps over the detections (SAGE-like). The
    /// search and its decisions (which paths, how many) stay the paper's; the
    /// estimates become the maximum-likelihood ones of eqs. (7)-(8) on the
    /// full band, whose delay noise the Kaiser window and the zeroing raise
    /// (one path at -116 dB over a -140 dB floor: 0.035 ns windowed and
    /// zeroed, 0.020 ns unwindowed and unzeroed, the Cramer-Rao level).
    pub refit_unwindowed: bool,
}

impl Default for DetectionConfig {
    fn default() -> Self {
        Self {
            noise_floor: NoiseFloor::QuietestWindows { window_taps: 32 },
            threshold_margin_db: 6.0,
            zero_below_threshold: true,
            kaiser_beta: Some(6.0),
            blocked_width_s: None,
            max_mpcs: 200,
            refine_overlapping: false,
            refit_unwindowed: false,
        }
    }
}

/// Short-term tracking within a set of snapshots (Sec. III-B, eqs. (13)-(32)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ShortTermConfig {
    /// Largest delay change between the first two detections of a track,
    /// seconds (xi_tau of eq. (15)). The paper derives it from "the physical
    /// limits of the moving objects" without a value; 0.5 ns covers a
    /// 200 m/s change of path length over 0.717 ms (0.48 ns) and matches the
    /// search tolerance.
    pub initial_delay_gate_s: f64,
    /// Largest magnitude change between the first two detections, dB (xi_a);
    /// not given in the paper; 10 dB like the search tolerance.
    pub initial_magnitude_gate_db: f64,
    /// Delay search tolerance around the linear prediction, seconds
    /// (epsilon_tau of eq. (23); paper: 0.5 ns).
    pub delay_tolerance_s: f64,
    /// Magnitude search tolerance around the linear prediction, dB
    /// (epsilon_a; paper: 10 dB).
    pub magnitude_tolerance_db: f64,
    /// Fewest consecutive detections that make a track (paper: 3).
    pub min_track_length: usize,
    /// How the next point of a track is predicted before the search of
    /// eqs. (20)-(23) (default: the paper's eq. (17), from the last two
    /// points).
    pub prediction: ShortTermPrediction,
}

/// The linear prediction of the short-term search (eqs. (17)-(19)).
///
/// Both choices extrapolate a straight line in snapshot index `m` (the
/// snapshots of a set are equally spaced, as eq. (17) assumes), for the
/// magnitude and the delay alike. With delay noise `sigma` per detection,
/// independent between snapshots, the search's miss
/// `tau[m + 1] - tau~[m + 1]` of a path moving linearly has the variance
/// `sigma^2 (1 + 1/k + (k - mbar)^2 / S_mm)` for a line fitted to `k` points
/// (`mbar = (k - 1) / 2`, `S_mm = k (k^2 - 1) / 12`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShortTermPrediction {
    /// The paper's eq. (17): `s~[m + 1] = s[m] + (s[m] - s[m - 1])`, the
    /// line through the last two points. Its miss is the second difference
    /// `tau[m + 1] - 2 tau[m] + tau[m - 1]`: `sqrt(6) sigma` at every step.
    #[default]
    LastDifference,
    /// Ours: the least-squares line through all `k` points of the track so
    /// far, evaluated at the next snapshot. At `k = 2` it is eq. (17); from
    /// the third point on its miss shrinks to `sqrt(10/3) sigma` (`k = 3`),
    /// `sqrt(5/2) sigma` (4) and `sqrt(21/10) sigma` (5), where eq. (17)
    /// stays at `sqrt(6) sigma`. The tolerance `epsilon_tau` of eq. (23) is
    /// unchanged; there is no parameter to set.
    LeastSquares,
}

impl Default for ShortTermConfig {
    fn default() -> Self {
        Self {
            initial_delay_gate_s: 0.5e-9,
            initial_magnitude_gate_db: 10.0,
            delay_tolerance_s: 0.5e-9,
            magnitude_tolerance_db: 10.0,
            min_track_length: 3,
            prediction: ShortTermPrediction::LastDifference,
        }
    }
}

/// Where the delay gate of eq. (35) is centred.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CandidateGate {
    /// The paper's eq. (35) as printed: `|tau_c - tau_k| <= xi_tau`, the raw
    /// change of mean delay between the two sets.
    #[default]
    RawDelay,
    /// Ours: `|tau_c - tau~_r| <= xi_tau`, around the Doppler-predicted
    /// delay `tau~_r` of eq. (37) (the prediction the paper uses next, in
    /// eqs. (38) and (41)). A path whose delay moves more than `xi_tau`
    /// between sets (an oncoming car: about 1.75 ns per 10 ms) stays a
    /// candidate; the two-way check of eqs. (40)-(42) is unchanged.
    PredictedDelay,
}

/// The delay rate a long-term track is predicted with (eqs. (37), (41)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DelayRate {
    /// The paper's: the track's own Doppler of eq. (31), `m = -nu / f_c`,
    /// the slope of its delays within the set (3.6 ms of a 10 ms set).
    #[default]
    TrackDoppler,
    /// Ours: for a track that continues a long-term track, the slope of the
    /// mean delays (eq. (33)) of the chain's last two entries,
    /// `m = (tau_k - tau_p) / (t_k - t_p)`, over 10 ms or more; a track
    /// that starts a chain uses its Doppler as the paper does. Each mean
    /// averages the set's detections, so at the convoy cars' 0.19 ns rms
    /// delay noise the forward prediction over 10 ms errs by about 0.15 ns
    /// instead of about 0.6 ns with eq. (30)'s in-set slope. The backward
    /// prediction of eq. (39) keeps the candidate's own Doppler (a candidate
    /// has no chain yet), so the two-way check still tests it.
    ChainSlope,
}

/// Long-term tracking across sets (Sec. V, eqs. (33)-(43)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LongTermConfig {
    /// Largest change of mean delay between sets for a candidate, seconds
    /// (xi_tau of eq. (35); paper: 1 ns).
    pub delay_gate_s: f64,
    /// Where the delay gate is centred (default: the paper's raw delay).
    pub candidate_gate: CandidateGate,
    /// The delay rate of the forward prediction (default: the paper's
    /// Doppler of the track).
    pub delay_rate: DelayRate,
    /// Sets a long-term track may miss and still be continued (default 0,
    /// the paper: only adjacent sets are related). With 1, a track of set
    /// `i` without a successor in set `i + 1` is tried against the tracks
    /// of set `i + 2` that no track of set `i + 1` took, with `T_r` the
    /// 20 ms between them. The paper names this bridging as a possible fix
    /// and its risk: "bridging a track across multiple snapshots might
    /// result in less reliable tracking results" (Sec. IV-B).
    pub max_missed_sets: u32,
    /// Largest change of mean power between sets for a candidate, dB
    /// (xi_a; paper: 5 dB).
    pub magnitude_gate_db: f64,
    /// Confidence classes chi of eq. (40), ascending, seconds; a link is
    /// kept when both two-way prediction errors are below the last one
    /// (paper: 0.1, 0.2, 0.5, 1.0 ns).
    pub chi_classes_s: Vec<f64>,
}

impl Default for LongTermConfig {
    fn default() -> Self {
        Self {
            delay_gate_s: 1e-9,
            candidate_gate: CandidateGate::RawDelay,
            delay_rate: DelayRate::TrackDoppler,
            max_missed_sets: 0,
            magnitude_gate_db: 5.0,
            chi_classes_s: vec![0.1e-9, 0.2e-9, 0.5e-9, 1e-9],
        }
    }
}

/// Every parameter of `process mpc`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MpcConfig {
    /// Detection per snapshot.
    pub detection: DetectionConfig,
    /// Tracking within a set.
    pub short_term: ShortTermConfig,
    /// Tracking across sets.
    pub long_term: LongTermConfig,
    /// Also run the GM-PHD baseline on each set's detections
    /// ([`crate::MpcPipeline`]). Off by default: it is the comparison, not
    /// the method, and costs about ten times the proposed tracker.
    pub run_gmphd: bool,
    /// The GM-PHD baseline's parameters (Table I); its `carrier_hz` is
    /// replaced by the pipeline's carrier.
    pub gmphd: GmPhdConfig,
}

fn bad(field: &'static str, value: impl ToString, expected: &'static str) -> MpcError {
    MpcError::BadConfig { field, value: value.to_string(), expected }
}

fn positive(field: &'static str, value: f64) -> Result<(), MpcError> {
    if value.is_finite() && value > 0.0 { Ok(()) } else { Err(bad(field, value, "a finite positive number")) }
}

impl DetectionConfig {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), MpcError> {
        match &self.noise_floor {
            NoiseFloor::QuietestWindows { window_taps } if *window_taps == 0 => {
                return Err(bad("detection.noise_floor.window_taps", window_taps, "at least one tap"));
            }
            NoiseFloor::DelayRange { start_s, end_s } if !(start_s.is_finite() && end_s > start_s) => {
                return Err(bad("detection.noise_floor.end_s", end_s, "a finite delay after start_s"));
            }
            NoiseFloor::Fixed { power_db } if !power_db.is_finite() => {
                return Err(bad("detection.noise_floor.power_db", power_db, "a finite power"));
            }
            _ => {}
        }
        if !self.threshold_margin_db.is_finite() {
            return Err(bad("detection.threshold_margin_db", self.threshold_margin_db, "a finite margin in dB"));
        }
        if let Some(a) = self.kaiser_beta
            && !(a.is_finite() && a >= 0.0)
        {
            return Err(bad("detection.kaiser_beta", a, "a finite non-negative window parameter"));
        }
        if let Some(width) = self.blocked_width_s {
            positive("detection.blocked_width_s", width)?;
        }
        if self.max_mpcs == 0 {
            return Err(bad("detection.max_mpcs", self.max_mpcs, "at least 1"));
        }
        Ok(())
    }
}

impl ShortTermConfig {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), MpcError> {
        positive("short_term.initial_delay_gate_s", self.initial_delay_gate_s)?;
        positive("short_term.initial_magnitude_gate_db", self.initial_magnitude_gate_db)?;
        positive("short_term.delay_tolerance_s", self.delay_tolerance_s)?;
        positive("short_term.magnitude_tolerance_db", self.magnitude_tolerance_db)?;
        if self.min_track_length < 3 {
            return Err(bad(
                "short_term.min_track_length",
                self.min_track_length,
                "at least 3 (a linear prediction needs two points and a check)",
            ));
        }
        Ok(())
    }
}

/// Most sets a long-term track may miss ([`LongTermConfig::max_missed_sets`]).
const MAX_MISSED_SETS: u32 = 10;

impl LongTermConfig {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), MpcError> {
        positive("long_term.delay_gate_s", self.delay_gate_s)?;
        positive("long_term.magnitude_gate_db", self.magnitude_gate_db)?;
        if self.max_missed_sets > MAX_MISSED_SETS {
            return Err(bad("long_term.max_missed_sets", self.max_missed_sets, "at most 10 sets"));
        }
        if self.chi_classes_s.is_empty() {
            return Err(bad("long_term.chi_classes_s", "[]", "at least one class"));
        }
        for pair in self.chi_classes_s.windows(2) {
            if pair[1] <= pair[0] {
                return Err(bad(
                    "long_term.chi_classes_s",
                    format!("{:?}", self.chi_classes_s),
                    "strictly ascending classes",
                ));
            }
        }
        for &chi in &self.chi_classes_s {
            positive("long_term.chi_classes_s", chi)?;
        }
        Ok(())
    }
}

impl MpcConfig {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), MpcError> {
        self.detection.validate()?;
        self.short_term.validate()?;
        self.long_term.validate()?;
        self.gmphd.validate().map_err(|source| MpcError::GmPhd { source })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_partial_config_takes_the_other_fields_from_the_defaults() {
        let config: MpcConfig =
            toml::from_str("[long_term]\ndelay_gate_s = 2.5e-9\n[detection]\nkaiser_beta = 4.0\n").unwrap();
        assert_eq!(config.long_term.delay_gate_s, 2.5e-9);
        assert_eq!(config.long_term.chi_classes_s, LongTermConfig::default().chi_classes_s);
        assert_eq!(config.detection.kaiser_beta, Some(4.0));
        assert_eq!(config.detection.threshold_margin_db, 6.0);
        assert_eq!(config.short_term, ShortTermConfig::default());
        let unknown = toml::from_str::<MpcConfig>("[short_term]\ndelay_tolerance = 1e-9\n").unwrap_err().to_string();
        assert!(unknown.contains("delay_tolerance"), "{unknown}");
    }
}
