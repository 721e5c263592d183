//! Long-term MPC tracking: relating the full-lifetime short-term tracks of
//! consecutive sets (Mahler et al. 2017, Sec. V, eqs. (33)-(43)).
//!
//! Each full-lifetime track `k` of set `i` is summarised ([`TrackSummary`],
//! eqs. (33)-(34)) by its mean delay `tau_k`, the power of its mean linear
//! power `a_k` (dB), its Doppler `nu_k` (eq. (31)) and its mean time `t_k`.
//! Then, for the tracks of set `i` **strongest first** (ties: smaller delay,
//! then input order):
//!
//! 1. **Candidates** (eqs. (35)-(36)): the tracks `c` of set `i + 1` not yet
//!    related with `|a_c - a_k| <= xi_a` and `|tau_c - tau_k| <= xi_tau`
//!    (componentwise, as in eq. (15); `xi_a` =
//!    [`LongTermConfig::magnitude_gate_db`], 5 dB; `xi_tau` =
//!    [`LongTermConfig::delay_gate_s`], 1 ns). That is the paper's gate
//!    ([`CandidateGate::RawDelay`], the default). Our variant
//!    [`CandidateGate::PredictedDelay`] centres the delay gate on the
//!    forward prediction of step 2 instead, `|tau_c - tau~_r| <= xi_tau`:
//!    the raw gate drops a path whose delay moves more than `xi_tau`
//!    between sets (an oncoming car moves about 1.75 ns per 10 ms) before
//!    its Doppler is ever consulted, although eqs. (37)-(42) would relate it.
//! 2. **Forward prediction** (eq. (37)):
//!    `tau~_r = tau_k + m_k T_r` with the delay rate `m_k = -nu_k / f_c` and
//!    `T_r = t_c - t_k` (the difference of the two tracks' mean times).
//!    The paper prints `tau~_r = tau_k - nu_k f_c T_r`, which is
//!    dimensionally wrong (Hz * Hz * s is not a delay); since eq. (31) defines
//!    `nu = -m f_c`, the delay rate is `-nu / f_c`, which is what is used.
//! 3. **Closest candidate** (eq. (38)): `eta = argmin_c |tau~_r - tau_c|`
//!    (ties: input order).
//! 4. **Backward prediction** (eq. (39)) from `eta` with its own Doppler:
//!    `tau~_k = tau_eta - m_eta T_r = tau_eta + nu_eta T_r / f_c` (the
//!    paper's `+ nu f_c T_r` has the same slip as eq. (37)).
//! 5. **Check** (eqs. (40)-(42)): with `d_r = |tau~_r - tau_eta|` and
//!    `d_k = |tau~_k - tau_k|`, the tracks are related if both are at most
//!    the largest confidence class `chi`
//!    ([`LongTermConfig::chi_classes_s`]); the link's class is the smallest
//!    `chi >= max(d_r, d_k)` (the classes of the paper's Figs. 10-11:
//!    0.1, 0.2, 0.5, 1 ns). Only `eta` is checked, as in the paper: when it
//!    fails, `k` has no successor.
//!
//! A track of set `i + 1` relates to at most one track of set `i` (the
//! strongest that chose it); the relation is one-to-one. [`LongTermTracker`]
//! chains the relations into long-term tracks: a track inherits the long-term
//! id of the track it is related to, otherwise it starts a new one
//! (eq. (43)).
//!
//! **Missed sets** ([`LongTermConfig::max_missed_sets`], ours; the paper's
//! is 0): a track of set `i` that relates to no track of set `i + 1` stays
//! open, and is tried (steps 1-5, `T_r` now the time from set `i`) against
//! the tracks of set `i + 2` that no track of set `i + 1` took, and so on
//! for up to `max_missed_sets` sets. Tracks that missed fewer sets choose
//! first (then strongest first, as above).
//!
//! # References
//! T. Mahler et al., "Tracking of wideband multipath components in a vehicular
//! communication scenario", IEEE TVT 66(1), 2017, Sec. V, eqs. (33)-(43).

use mmtrack_core::{MpcLongTermEntry, MpcTrack};

use crate::{CandidateGate, DelayRate, LongTermConfig, MpcError};

/// A full-lifetime track as long-term tracking sees it: `q_k` of eq. (34)
/// plus its identity and mean time.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackSummary {
    /// The short-term track's `track_id`.
    pub short_track_id: u64,
    /// Set of the track (of its first detection).
    pub set_index: u64,
    /// Mean time of the track's detections, nanoseconds (rounded).
    pub t_ns: i64,
    /// Mean delay, seconds (tau-bar of eq. (33)).
    pub mean_delay_s: f64,
    /// `10 log10` of the mean linear power `|alpha|^2`, dB (a-bar of eq. (33)).
    pub mean_power_db: f64,
    /// Doppler of the track, hertz (eq. (31)).
    pub doppler_hz: f64,
}

impl TrackSummary {
    /// The summary of `track`; `None` for a track without detections or
    /// without a Doppler estimate (fewer than two distinct times).
    #[must_use]
    pub fn of(track: &MpcTrack) -> Option<Self> {
        let first = track.detections.first()?;
        let doppler_hz = track.doppler_hz?;
        let n = track.detections.len();
        let t_sum: i128 = track.detections.iter().map(|d| i128::from(d.t_ns)).sum();
        let t_ns = i64::try_from(div_round(t_sum, n as i128)).ok()?;
        let mean_delay_s = track.detections.iter().map(|d| d.delay_s).sum::<f64>() / n as f64;
        let mean_power = track.detections.iter().map(|d| d.amplitude.norm_sqr()).sum::<f64>() / n as f64;
        Some(Self {
            short_track_id: track.track_id,
            set_index: first.set_index,
            t_ns,
            mean_delay_s,
            mean_power_db: 10.0 * mean_power.log10(),
            doppler_hz,
        })
    }
}

impl From<&MpcLongTermEntry> for TrackSummary {
    /// The summary a long-term entry was made from.
    fn from(e: &MpcLongTermEntry) -> Self {
        Self {
            short_track_id: e.short_track_id,
            set_index: e.set_index,
            t_ns: e.t_ns,
            mean_delay_s: e.mean_delay_s,
            mean_power_db: e.mean_power_db,
            doppler_hz: e.doppler_hz,
        }
    }
}

/// `a / b` rounded to the nearest integer (halves away from zero), `b > 0`.
fn div_round(a: i128, b: i128) -> i128 {
    let q = a.div_euclid(b);
    let r = a.rem_euclid(b);
    if 2 * r >= b { q + 1 } else { q }
}

/// A relation between track `current` of one set and track `next` of the
/// following set (indices into the slices given to [`relate_sets`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LongTermLink {
    /// Index of the track of the current set.
    pub current: usize,
    /// Index of the related track of the next set.
    pub next: usize,
    /// Forward prediction error `d_r`, seconds (eq. (41)).
    pub forward_error_s: f64,
    /// Backward prediction error `d_k`, seconds (eq. (42)).
    pub backward_error_s: f64,
    /// Smallest confidence class holding both errors, seconds (eq. (40)).
    pub chi_class_s: f64,
}

impl LongTermLink {
    /// The larger of the two prediction errors, seconds.
    #[must_use]
    pub fn error_s(&self) -> f64 {
        self.forward_error_s.max(self.backward_error_s)
    }
}

/// The first step of eqs. (35)-(42) a pair of tracks fails.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkRefusal {
    /// Their mean powers differ by more than `xi_a` (eq. (36)).
    MagnitudeGate,
    /// The candidate's delay is outside the gate of eq. (35).
    DelayGate,
    /// A two-way prediction error exceeds the largest class (eqs. (40)-(42)).
    TwoWayCheck,
}

/// A candidate of the next set as steps 1-2 see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// `T_r = t_c - t_k`, seconds.
    pub t_r_s: f64,
    /// Forward prediction error `d_r = |tau~_r - tau_c|`, seconds (eq. (41)).
    pub forward_error_s: f64,
}

/// Steps 1-2 for the open track `q_k`, predicted with the delay rate
/// `rate_k` (s/s; see [`forward_delay_rate`]), and the track `q_c` of a
/// later set: the gates of eqs. (35)-(36) and the forward prediction error
/// of eqs. (37) and (41).
///
/// # Errors
/// [`LinkRefusal::MagnitudeGate`] or [`LinkRefusal::DelayGate`].
pub fn candidate(
    q_k: &TrackSummary,
    rate_k: f64,
    q_c: &TrackSummary,
    config: &LongTermConfig,
) -> Result<Candidate, LinkRefusal> {
    if (q_c.mean_power_db - q_k.mean_power_db).abs() > config.magnitude_gate_db {
        return Err(LinkRefusal::MagnitudeGate);
    }
    let t_r_s = (i128::from(q_c.t_ns) - i128::from(q_k.t_ns)) as f64 * 1e-9;
    let predicted_s = q_k.mean_delay_s + rate_k * t_r_s;
    let gated_from_s = match config.candidate_gate {
        CandidateGate::RawDelay => q_k.mean_delay_s,
        CandidateGate::PredictedDelay => predicted_s,
    };
    if (q_c.mean_delay_s - gated_from_s).abs() > config.delay_gate_s {
        return Err(LinkRefusal::DelayGate);
    }
    Ok(Candidate { t_r_s, forward_error_s: (predicted_s - q_c.mean_delay_s).abs() })
}

/// Steps 4-5 for `q_k` and its closest candidate `q_eta` (`found` by
/// [`candidate`]): the backward prediction of eq. (39) with `q_eta`'s own
/// Doppler and the check of eqs. (40)-(42). Returns `(d_k, chi)`.
///
/// # Errors
/// [`LinkRefusal::TwoWayCheck`].
pub fn two_way_check(
    q_k: &TrackSummary,
    q_eta: &TrackSummary,
    found: Candidate,
    carrier_hz: f64,
    config: &LongTermConfig,
) -> Result<(f64, f64), LinkRefusal> {
    let back_predicted_s = q_eta.mean_delay_s + q_eta.doppler_hz / carrier_hz * found.t_r_s;
    let backward_error_s = (back_predicted_s - q_k.mean_delay_s).abs();
    let worst = found.forward_error_s.max(backward_error_s);
    let chi_class_s = config.chi_classes_s.iter().find(|&&chi| worst <= chi).ok_or(LinkRefusal::TwoWayCheck)?;
    Ok((backward_error_s, *chi_class_s))
}

/// The delay rate (s/s) `q_k` is predicted forward with
/// ([`LongTermConfig::delay_rate`]): `-nu_k / f_c` (eq. (31)) for the
/// paper's [`DelayRate::TrackDoppler`] or a track without a predecessor,
/// else for [`DelayRate::ChainSlope`] the slope of the mean delays from its
/// long-term predecessor `q_p`.
#[must_use]
pub fn forward_delay_rate(
    q_k: &TrackSummary,
    predecessor: Option<&TrackSummary>,
    carrier_hz: f64,
    rate: DelayRate,
) -> f64 {
    match (rate, predecessor) {
        (DelayRate::ChainSlope, Some(q_p)) if q_k.t_ns != q_p.t_ns => {
            (q_k.mean_delay_s - q_p.mean_delay_s) / ((i128::from(q_k.t_ns) - i128::from(q_p.t_ns)) as f64 * 1e-9)
        }
        _ => -q_k.doppler_hz / carrier_hz,
    }
}

/// Relates the tracks of the current set to those of the next set (steps
/// 1-5 of the module docs), each current track predicted with its Doppler
/// (the paper's). Links come in the order they were made (strongest
/// current track first); each `next` index appears at most once.
#[must_use]
pub fn relate_sets(
    current: &[TrackSummary],
    next: &[TrackSummary],
    carrier_hz: f64,
    config: &LongTermConfig,
) -> Vec<LongTermLink> {
    let rates: Vec<f64> =
        current.iter().map(|q| forward_delay_rate(q, None, carrier_hz, DelayRate::TrackDoppler)).collect();
    relate_sets_at_rates(current, &rates, next, carrier_hz, config)
}

/// [`relate_sets`] with the forward delay rate (s/s) of each current track
/// given (`rates[k]` for `current[k]`, from [`forward_delay_rate`]).
#[must_use]
pub fn relate_sets_at_rates(
    current: &[TrackSummary],
    rates: &[f64],
    next: &[TrackSummary],
    carrier_hz: f64,
    config: &LongTermConfig,
) -> Vec<LongTermLink> {
    let mut order: Vec<usize> = (0..current.len()).collect();
    order.sort_by(|&i, &j| {
        let (p, q) = (&current[i], &current[j]);
        q.mean_power_db.total_cmp(&p.mean_power_db).then(p.mean_delay_s.total_cmp(&q.mean_delay_s)).then(i.cmp(&j))
    });
    let mut taken = vec![false; next.len()];
    let mut links = Vec::new();
    for k in order {
        let q_k = &current[k];
        let closest = next
            .iter()
            .enumerate()
            .filter(|&(c, _)| !taken[c])
            .filter_map(|(c, q_c)| candidate(q_k, rates[k], q_c, config).ok().map(|found| (c, found)))
            .min_by(|x, y| x.1.forward_error_s.total_cmp(&y.1.forward_error_s).then(x.0.cmp(&y.0)));
        let Some((eta, found)) = closest else { continue };
        let Ok((backward_error_s, chi_class_s)) = two_way_check(q_k, &next[eta], found, carrier_hz, config) else {
            continue;
        };
        taken[eta] = true;
        links.push(LongTermLink {
            current: k,
            next: eta,
            forward_error_s: found.forward_error_s,
            backward_error_s,
            chi_class_s,
        });
    }
    links
}

/// A long-term track waiting for its successor.
#[derive(Debug, Clone)]
struct OpenTrack {
    /// Its last entry.
    summary: TrackSummary,
    /// Its long-term id.
    long_track_id: u64,
    /// Sets missed since `summary` (0: the previous set's tracks).
    missed_sets: u32,
    /// Its forward delay rate, s/s ([`forward_delay_rate`]).
    rate: f64,
}

/// Chains [`relate_sets`] over a stream of sets into long-term tracks.
///
/// Holds only the open tracks: the previous set's summaries and long-term
/// ids, and with [`LongTermConfig::max_missed_sets`] those of earlier sets
/// still waiting for a successor.
#[derive(Debug, Clone)]
pub struct LongTermTracker {
    config: LongTermConfig,
    carrier_hz: f64,
    next_long_id: u64,
    previous: Vec<OpenTrack>,
}

impl LongTermTracker {
    /// A tracker for a carrier of `carrier_hz`; long-term ids start at
    /// `first_long_id`.
    ///
    /// # Errors
    /// [`MpcError::BadConfig`] for an invalid config or carrier.
    pub fn new(config: LongTermConfig, carrier_hz: f64, first_long_id: u64) -> Result<Self, MpcError> {
        config.validate()?;
        if !(carrier_hz.is_finite() && carrier_hz > 0.0) {
            return Err(MpcError::BadConfig {
                field: "carrier_hz",
                value: carrier_hz.to_string(),
                expected: "a finite positive frequency",
            });
        }
        Ok(Self { config, carrier_hz, next_long_id: first_long_id, previous: Vec::new() })
    }

    /// Takes the full-lifetime tracks of the next set (the caller selects
    /// them, e.g. with [`crate::short_term::is_full_lifetime`]) and returns
    /// one entry per track, in input order. Tracks without a Doppler estimate
    /// are left out (they cannot be predicted). Fresh long-term ids are given
    /// in input order. A set without tracks breaks every chain (with
    /// [`LongTermConfig::max_missed_sets`] 0, the paper's).
    pub fn push_set(&mut self, full_lifetime_tracks: &[MpcTrack]) -> Vec<MpcLongTermEntry> {
        let summaries: Vec<TrackSummary> = full_lifetime_tracks.iter().filter_map(TrackSummary::of).collect();
        // Links with `current` an index into `self.previous`, `next` into
        // `summaries`: open tracks that missed fewer sets choose first.
        let mut link_of: Vec<Option<LongTermLink>> = vec![None; summaries.len()];
        let mut continued = vec![false; self.previous.len()];
        for missed in 0..=self.config.max_missed_sets {
            let open: Vec<usize> =
                (0..self.previous.len()).filter(|&k| self.previous[k].missed_sets == missed).collect();
            let free: Vec<usize> = (0..summaries.len()).filter(|&c| link_of[c].is_none()).collect();
            if open.is_empty() || free.is_empty() {
                continue;
            }
            let current: Vec<TrackSummary> = open.iter().map(|&k| self.previous[k].summary.clone()).collect();
            let rates: Vec<f64> = open.iter().map(|&k| self.previous[k].rate).collect();
            let next: Vec<TrackSummary> = free.iter().map(|&c| summaries[c].clone()).collect();
            for link in relate_sets_at_rates(&current, &rates, &next, self.carrier_hz, &self.config) {
                continued[open[link.current]] = true;
                link_of[free[link.next]] =
                    Some(LongTermLink { current: open[link.current], next: free[link.next], ..link });
            }
        }
        let mut entries = Vec::with_capacity(summaries.len());
        let mut previous = Vec::with_capacity(summaries.len());
        for (summary, link) in summaries.into_iter().zip(&link_of) {
            let predecessor = link.as_ref().map(|l| &self.previous[l.current]);
            let long_track_id = match predecessor {
                Some(open) => open.long_track_id,
                None => {
                    self.next_long_id += 1;
                    self.next_long_id - 1
                }
            };
            let rate = forward_delay_rate(
                &summary,
                predecessor.map(|open| &open.summary),
                self.carrier_hz,
                self.config.delay_rate,
            );
            entries.push(MpcLongTermEntry {
                long_track_id,
                set_index: summary.set_index,
                t_ns: summary.t_ns,
                short_track_id: summary.short_track_id,
                mean_delay_s: summary.mean_delay_s,
                mean_power_db: summary.mean_power_db,
                doppler_hz: summary.doppler_hz,
                link_error_s: link.as_ref().map(LongTermLink::error_s),
                chi_class_s: link.as_ref().map(|l| l.chi_class_s),
            });
            previous.push(OpenTrack { summary, long_track_id, missed_sets: 0, rate });
        }
        // Open tracks without a successor wait while they may miss more sets.
        for (open, continued) in self.previous.drain(..).zip(continued) {
            if !continued && open.missed_sets < self.config.max_missed_sets {
                previous.push(OpenTrack { missed_sets: open.missed_sets + 1, ..open });
            }
        }
        self.previous = previous;
        entries
    }
}
