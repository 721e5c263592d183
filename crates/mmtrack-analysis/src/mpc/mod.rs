//! Multipath-component statistics (Mahler et al. 2017, Secs. IV-VI): pure
//! functions on the tables `mmtrack process mpc` writes, already in memory.
//!
//! - number of MPCs per set: the long-term (full-lifetime) tracks present in
//!   each set, its distribution and CDF (Fig. 12);
//! - birth and death rates per metre travelled (Fig. 13): across each pair of
//!   consecutive sets, births are long-term tracks whose first entry is the
//!   later set, deaths those whose last entry is the earlier set; divided by
//!   the distance both vehicles drove between the two sets' times (or by the
//!   time between them when no trajectory is available);
//! - power loss: channel gain minus the gain captured by detection, by the
//!   short-term tracks, by the full-lifetime tracks and (when present) by the
//!   GM-PHD tracks, per set and its mean in dB (Figs. 8-9);
//! - per-track power standard deviation over the set (Fig. 7);
//! - share of the long-term link power per confidence class chi (Sec. VI-A:
//!   72 % at chi <= 0.1 ns in the paper) and the share of full-lifetime power
//!   related to no adjacent set (5 % in the paper);
//! - against the simulator's truth ([`truth`], made resolvable first: true
//!   MPCs closer than the match tolerance count as one): detection precision
//!   and recall (also over the detectable truth, above the floor + 6 dB),
//!   track purity and false tracks, long-term tracks that follow true paths
//!   (their births and deaths, tracks per path), true birth and death rates;
//! - the first path of each snapshot ([`first_path`]): the earliest detection
//!   within a dynamic range (20 dB) of the strongest, against the receiver's
//!   own first-path estimate when the recording carries one.

pub mod first_path;
pub mod truth;

use std::collections::BTreeMap;

use mmtrack_core::{MpcDetection, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth, StampedPose};
use mmtrack_io::table::{
    ChiClassShare, CountBin, FirstPathRow, MpcSnapshotStats, MpcSummary, SetMetrics, TrackPowerStd,
};

pub use first_path::{DEFAULT_FIRST_PATH_DYNAMIC_RANGE_DB, FirstPathSummary};
pub use truth::{TruthScores, match_detections, resolvable_truth};

/// Choices of the MPC statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct MpcOptions {
    /// Dynamic range below a snapshot's strongest detection within which the
    /// earliest detection is its first path, dB.
    pub first_path_dynamic_range_db: f64,
}

impl Default for MpcOptions {
    fn default() -> Self {
        Self { first_path_dynamic_range_db: DEFAULT_FIRST_PATH_DYNAMIC_RANGE_DB }
    }
}

/// Where the distance travelled comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum DistanceSource {
    /// Both sounder vehicles' ground truth (`ground_truth_tx`, `ground_truth_rx`):
    /// the paper's cumulative distance of both vehicles.
    BothVehicles {
        /// Transmitter car.
        tx: Vec<StampedPose>,
        /// Receiver car.
        rx: Vec<StampedPose>,
    },
    /// One trajectory (a `ground_truth` or `odometry` table), named.
    OneVehicle {
        /// Table it came from.
        table: String,
        /// The poses.
        poses: Vec<StampedPose>,
    },
    /// No trajectory: rates are per second only.
    None,
}

impl DistanceSource {
    /// Short label for tables and reports.
    #[must_use]
    pub fn label(&self) -> String {
        match self {
            Self::BothVehicles { .. } => "ground_truth_tx+ground_truth_rx".into(),
            Self::OneVehicle { table, .. } => table.clone(),
            Self::None => "none".into(),
        }
    }

    /// Distance driven between `t0_ns` and `t1_ns` (both vehicles summed),
    /// from positions interpolated at both times; `None` without poses or
    /// outside their time span.
    #[must_use]
    pub fn distance_m(&self, t0_ns: i64, t1_ns: i64) -> Option<f64> {
        let one = |poses: &[StampedPose]| -> Option<f64> {
            let (a, b) = (position_at(poses, t0_ns)?, position_at(poses, t1_ns)?);
            Some((b.0 - a.0).hypot(b.1 - a.1))
        };
        match self {
            Self::BothVehicles { tx, rx } => Some(one(tx)? + one(rx)?),
            Self::OneVehicle { poses, .. } => one(poses),
            Self::None => None,
        }
    }
}

/// Position at `t_ns`, linearly interpolated; `None` outside the span.
fn position_at(poses: &[StampedPose], t_ns: i64) -> Option<(f64, f64)> {
    let i = poses.partition_point(|p| p.t_ns < t_ns);
    let at = |p: &StampedPose| (p.parent_from_child.x_m, p.parent_from_child.y_m);
    let after = poses.get(i)?;
    if after.t_ns == t_ns {
        return Some(at(after));
    }
    let before = poses.get(i.checked_sub(1)?)?;
    let w = (t_ns - before.t_ns) as f64 / (after.t_ns - before.t_ns) as f64;
    let (a, b) = (at(before), at(after));
    Some((a.0 + w * (b.0 - a.0), a.1 + w * (b.1 - a.1)))
}

/// The MPC tables of one sequence partition.
#[derive(Debug, Clone, PartialEq)]
pub struct MpcInput {
    /// `mpc_detections`.
    pub detections: Vec<MpcDetection>,
    /// `mpc_tracks` (short-term tracks).
    pub tracks: Vec<MpcTrack>,
    /// `mpc_long_term`.
    pub long_term: Vec<MpcLongTermEntry>,
    /// `mpc_sets`.
    pub sets: Vec<MpcSetStats>,
    /// `mpc_snapshots`, when present (tables of older versions lack it).
    pub snapshots: Option<Vec<MpcSnapshotStats>>,
    /// `mpc_truth`, when the recording had truth.
    pub truth: Option<Vec<MpcTruth>>,
    /// Trajectories for the distance travelled.
    pub distance: DistanceSource,
}

/// Everything computed for one sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct MpcResult {
    /// Sequence partition.
    pub sequence: String,
    /// Per set.
    pub per_set: Vec<SetMetrics>,
    /// Per short-term track.
    pub power_std: Vec<TrackPowerStd>,
    /// Per chi class, then the unrelated share (class `None`).
    pub chi: Vec<ChiClassShare>,
    /// Distribution of the number of MPCs per set.
    pub counts: Vec<CountBin>,
    /// Per snapshot: its first path.
    pub first_path: Vec<FirstPathRow>,
    /// Summary.
    pub summary: MpcSummary,
    /// Detections and short-term tracks for the delay-vs-time plot.
    pub detections: Vec<MpcDetection>,
    /// Short-term tracks (for the plot).
    pub tracks: Vec<MpcTrack>,
    /// Plain sentences on metrics left empty and why (for the report).
    pub notes: Vec<String>,
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let (sum, n) = values.filter(|v| v.is_finite()).fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    (n > 0).then(|| sum / n as f64)
}

/// The loss `channel - captured` in dB (Mahler et al. Figs. 8-9); `None`
/// when either gain is (nothing measured, or nothing captured).
fn loss_db(channel_gain_db: Option<f64>, captured_gain_db: Option<f64>) -> Option<f64> {
    Some(channel_gain_db? - captured_gain_db?)
}

/// Sample standard deviation with `n - 1` (0 for a single value).
fn std_dev(values: &[f64]) -> f64 {
    if values.len() < 2 {
        return 0.0;
    }
    let m = values.iter().sum::<f64>() / values.len() as f64;
    (values.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (values.len() - 1) as f64).sqrt()
}

fn ratio(a: u64, b: f64) -> Option<f64> {
    (b > 0.0).then(|| a as f64 / b)
}

/// First and last set of every long-term track.
fn long_term_spans(entries: &[MpcLongTermEntry]) -> BTreeMap<u64, (u64, u64)> {
    let mut spans: BTreeMap<u64, (u64, u64)> = BTreeMap::new();
    for e in entries {
        let span = spans.entry(e.long_track_id).or_insert((e.set_index, e.set_index));
        span.0 = span.0.min(e.set_index);
        span.1 = span.1.max(e.set_index);
    }
    spans
}

/// All MPC statistics of one sequence.
#[must_use]
pub fn analyze_mpc(sequence: &str, input: MpcInput, options: &MpcOptions) -> MpcResult {
    let mut sets = input.sets.clone();
    sets.sort_by_key(|s| s.set_index);
    let mut per_set_count: BTreeMap<u64, u64> = sets.iter().map(|s| (s.set_index, 0)).collect();
    for e in &input.long_term {
        *per_set_count.entry(e.set_index).or_default() += 1;
    }
    let spans = long_term_spans(&input.long_term);
    let truth_scores =
        input.truth.as_deref().map(|t| truth::score(t, &input.detections, &input.tracks, &input.long_term, &sets));

    let mut per_set = Vec::with_capacity(sets.len());
    for (k, s) in sets.iter().enumerate() {
        let previous = k.checked_sub(1).and_then(|p| sets.get(p));
        let births = previous.map(|_| spans.values().filter(|span| span.0 == s.set_index).count() as u64);
        let deaths = previous.map(|p| spans.values().filter(|span| span.1 == p.set_index).count() as u64);
        let distance_m = previous.and_then(|p| input.distance.distance_m(p.t_ns, s.t_ns));
        let dt_s = previous.map(|p| (s.t_ns - p.t_ns) as f64 * 1e-9);
        let per = |n: Option<u64>, d: Option<f64>| n.zip(d).and_then(|(n, d)| ratio(n, d));
        // Tables written before the gains were nullable hold -inf for
        // "nothing captured": read as null, like the current ones.
        let [channel, detected, tracked, full_lifetime, gmphd] = [
            s.channel_gain_db,
            s.detected_gain_db,
            s.tracked_gain_db,
            s.full_lifetime_gain_db,
            s.gmphd_tracked_gain_db,
        ]
        .map(|db| db.filter(|db| db.is_finite()));
        let (true_births, true_deaths) = truth_scores
            .as_ref()
            .and_then(|t| t.transitions.get(&s.set_index))
            .map_or((None, None), |&(b, d)| (Some(b), Some(d)));
        per_set.push(SetMetrics {
            set_index: s.set_index,
            t_ns: s.t_ns,
            long_term_mpcs: per_set_count.get(&s.set_index).copied().unwrap_or(0),
            detections: u64::from(s.detections),
            full_lifetime_tracks: u64::from(s.full_lifetime_tracks),
            births,
            deaths,
            distance_m,
            birth_rate_per_m: per(births, distance_m),
            death_rate_per_m: per(deaths, distance_m),
            birth_rate_per_s: per(births, dt_s),
            death_rate_per_s: per(deaths, dt_s),
            channel_gain_db: channel,
            detected_gain_db: detected,
            tracked_gain_db: tracked,
            full_lifetime_gain_db: full_lifetime,
            gmphd_tracked_gain_db: gmphd,
            detection_loss_db: loss_db(channel, detected),
            tracking_loss_db: loss_db(channel, tracked),
            gmphd_tracking_loss_db: loss_db(channel, gmphd),
            true_births,
            true_deaths,
        });
    }

    let power_std = track_power_std(&input.tracks, &sets);
    let chi = chi_shares(&input.long_term);
    let range_db = options.first_path_dynamic_range_db;
    let first_path = first_path::first_paths(&input.detections, input.snapshots.as_deref(), range_db);
    let mut summary = summarise(&input, &per_set, &power_std, &chi, &spans, truth_scores.as_ref());
    // Null counts (nothing tracked) have no distribution either.
    let counts = match summary.mean_mpcs_per_set {
        Some(_) => count_distribution(per_set.iter().map(|s| s.long_term_mpcs)),
        None => Vec::new(),
    };
    let first = first_path::summarise_first_paths(&first_path);
    summary.first_path_dynamic_range_db = range_db;
    summary.first_path_snapshots = first.snapshots;
    summary.first_path_hint_snapshots = first.with_hint;
    summary.first_path_earlier_snapshots = first.with_earlier;
    summary.first_path_minus_hint_median_s = first.median_minus_hint_s;
    summary.first_path_hint_abs_median_s = first.median_abs_minus_hint_s;
    summary.first_path_hint_abs_p90_s = first.p90_abs_minus_hint_s;
    let notes = empty_metric_notes(&sets, &input.detections, &input.tracks);
    MpcResult {
        notes,
        sequence: sequence.to_string(),
        per_set,
        power_std,
        chi,
        counts,
        first_path,
        summary,
        detections: input.detections,
        tracks: input.tracks,
    }
}

/// Why whole groups of metrics are empty: no detections at all, or no
/// short-term tracks (a track follows one path over at least
/// `short_term.min_track_length` >= 3 snapshots of one set, Mahler et al.
/// Sec. III-B, so sets of fewer snapshots cannot hold one).
fn empty_metric_notes(sets: &[MpcSetStats], detections: &[MpcDetection], tracks: &[MpcTrack]) -> Vec<String> {
    if detections.is_empty() {
        return vec![
            "no detections in any snapshot (no tap rose the threshold margin above the noise floor), so every MPC \
             metric is empty"
                .to_string(),
        ];
    }
    if !tracks.is_empty() {
        return Vec::new();
    }
    let most = sets.iter().map(|s| s.snapshots.saturating_sub(s.skipped_snapshots)).max().unwrap_or(0);
    let what = "tracking and full-lifetime losses, power standard deviations, long-term tracks, births, deaths and chi \
                shares are empty";
    if most < MIN_SHORT_TERM_TRACK_SNAPSHOTS {
        vec![format!(
            "no short-term tracks, so {what}: its sets hold at most {most} snapshot(s) each, and a short-term track \
             follows one path over at least {MIN_SHORT_TERM_TRACK_SNAPSHOTS} snapshots of one set \
             (`short_term.min_track_length`, Mahler et al. Sec. III-B). Sources that record one CIR per set (e.g. \
             DecaWave logs) give detections and first paths only"
        )]
    } else {
        vec![format!(
            "no short-term tracks, so {what}: its sets hold up to {most} snapshots, but no path stayed within the \
             short-term gates (`short_term.delay_tolerance_s`, `short_term.magnitude_tolerance_db`) for \
             `short_term.min_track_length` snapshots"
        )]
    }
}

/// The fewest snapshots a short-term track can span (the tracker refuses a
/// smaller `short_term.min_track_length`).
const MIN_SHORT_TERM_TRACK_SNAPSHOTS: u32 = 3;

fn track_power_std(tracks: &[MpcTrack], sets: &[MpcSetStats]) -> Vec<TrackPowerStd> {
    let lengths: BTreeMap<u64, u32> =
        sets.iter().map(|s| (s.set_index, s.snapshots.saturating_sub(s.skipped_snapshots))).collect();
    tracks
        .iter()
        .filter_map(|t| {
            let first = t.detections.first()?;
            let powers: Vec<f64> = t.detections.iter().map(MpcDetection::power_db).collect();
            let n = t.detections.len() as u64;
            Some(TrackPowerStd {
                track_id: t.track_id,
                set_index: first.set_index,
                detections: n,
                full_lifetime: lengths.get(&first.set_index).is_some_and(|&len| u64::from(len) == n),
                power_std_db: std_dev(&powers),
            })
        })
        .collect()
}

/// Share of linked power per chi class (the power of the entry a link leads
/// to), then the share of all full-lifetime power in entries related to no
/// adjacent set (class `None`).
fn chi_shares(entries: &[MpcLongTermEntry]) -> Vec<ChiClassShare> {
    let power = |e: &MpcLongTermEntry| 10f64.powf(e.mean_power_db / 10.0);
    let mut classes: BTreeMap<u64, (u64, f64)> = BTreeMap::new();
    for e in entries {
        if let Some(chi) = e.chi_class_s {
            let slot = classes.entry(chi.to_bits()).or_default();
            slot.0 += 1;
            slot.1 += power(e);
        }
    }
    let linked: f64 = classes.values().map(|c| c.1).sum();
    let mut out: Vec<ChiClassShare> = classes
        .iter()
        .map(|(&bits, &(n, p))| ChiClassShare {
            chi_class_s: Some(f64::from_bits(bits)),
            entries: n,
            power_share: if linked > 0.0 { p / linked } else { 0.0 },
        })
        .collect();
    out.sort_by(|a, b| a.chi_class_s.partial_cmp(&b.chi_class_s).unwrap_or(std::cmp::Ordering::Equal));
    // An entry is related when it was linked from the previous set or the
    // next entry of its track links to it.
    let mut by_track: BTreeMap<u64, Vec<&MpcLongTermEntry>> = BTreeMap::new();
    for e in entries {
        by_track.entry(e.long_track_id).or_default().push(e);
    }
    let total: f64 = entries.iter().map(power).sum();
    let (mut unrelated, mut unrelated_n) = (0.0, 0u64);
    for track in by_track.values() {
        if track.len() == 1 && track[0].chi_class_s.is_none() {
            unrelated += power(track[0]);
            unrelated_n += 1;
        }
    }
    if !entries.is_empty() {
        out.push(ChiClassShare {
            chi_class_s: None,
            entries: unrelated_n,
            power_share: if total > 0.0 { unrelated / total } else { 0.0 },
        });
    }
    out
}

fn count_distribution(counts: impl Iterator<Item = u64>) -> Vec<CountBin> {
    let mut bins: BTreeMap<u64, u64> = BTreeMap::new();
    for c in counts {
        *bins.entry(c).or_default() += 1;
    }
    let total: u64 = bins.values().sum();
    let mut cumulative = 0;
    bins.into_iter()
        .map(|(mpcs, sets)| {
            cumulative += sets;
            CountBin { mpcs, sets, cdf: cumulative as f64 / total as f64 }
        })
        .collect()
}

/// The median of `values` (the mean of the middle two for an even count);
/// 0 when there are none.
fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    mmtrack_core::stats::median(&values).unwrap_or(0.0)
}

fn share_below(values: impl Iterator<Item = f64>, limit: f64) -> Option<f64> {
    let (below, n) = values.fold((0usize, 0usize), |(b, n), v| (b + usize::from(v < limit), n + 1));
    (n > 0).then(|| below as f64 / n as f64)
}

fn summarise(
    input: &MpcInput,
    per_set: &[SetMetrics],
    power_std: &[TrackPowerStd],
    chi: &[ChiClassShare],
    spans: &BTreeMap<u64, (u64, u64)>,
    truth: Option<&TruthScores>,
) -> MpcSummary {
    // Without short-term tracks there are no long-term ones to count: the
    // counts and the rates built on them are null, not 0 (as the report's
    // note on empty metrics says), so a run that tracked nothing does not
    // read as one that tracked a steady channel.
    let tracked = !(input.tracks.is_empty() && input.long_term.is_empty());
    let births: Option<u64> = tracked.then(|| per_set.iter().filter_map(|s| s.births).sum());
    let deaths: Option<u64> = tracked.then(|| per_set.iter().filter_map(|s| s.deaths).sum());
    let transitions: Vec<&SetMetrics> = per_set.iter().skip(1).collect();
    let distance_m = if transitions.is_empty() || transitions.iter().any(|s| s.distance_m.is_none()) {
        None
    } else {
        Some(transitions.iter().filter_map(|s| s.distance_m).sum::<f64>())
    };
    let duration_s = match (per_set.first(), per_set.last()) {
        (Some(a), Some(b)) => (b.t_ns - a.t_ns) as f64 * 1e-9,
        _ => 0.0,
    };
    let per_m = |n: Option<u64>| n.zip(distance_m).and_then(|(n, d)| ratio(n, d));
    let counts: Vec<f64> = per_set.iter().map(|s| s.long_term_mpcs as f64).collect();
    let chi_01 = chi
        .iter()
        .filter(|c| c.chi_class_s.is_some_and(|x| x <= 0.1e-9 * (1.0 + 1e-9)))
        .map(|c| c.power_share)
        .reduce(|a, b| a + b)
        .or_else(|| chi.iter().any(|c| c.chi_class_s.is_some()).then_some(0.0));
    MpcSummary {
        sets: per_set.len() as u64,
        detections: input.detections.len() as u64,
        short_term_tracks: input.tracks.len() as u64,
        full_lifetime_tracks: power_std.iter().filter(|p| p.full_lifetime).count() as u64,
        long_term_tracks: spans.len() as u64,
        mean_mpcs_per_set: if tracked { mean(counts.iter().copied()) } else { None },
        median_mpcs_per_set: tracked.then(|| median(counts)),
        distance_source: input.distance.label(),
        distance_m,
        duration_s,
        births,
        deaths,
        birth_rate_per_m: per_m(births),
        death_rate_per_m: per_m(deaths),
        birth_rate_per_s: births.and_then(|n| ratio(n, duration_s)),
        death_rate_per_s: deaths.and_then(|n| ratio(n, duration_s)),
        mean_detection_loss_db: mean(per_set.iter().filter_map(|s| s.detection_loss_db)),
        mean_tracking_loss_db: mean(per_set.iter().filter_map(|s| s.tracking_loss_db)),
        mean_full_lifetime_loss_db: mean(
            per_set.iter().filter_map(|s| loss_db(s.channel_gain_db, s.full_lifetime_gain_db)),
        ),
        mean_gmphd_tracking_loss_db: mean(per_set.iter().filter_map(|s| s.gmphd_tracking_loss_db)),
        full_lifetime_std_below_1db: share_below(
            power_std.iter().filter(|p| p.full_lifetime).map(|p| p.power_std_db),
            1.0,
        ),
        all_tracks_std_below_1_5db: share_below(power_std.iter().map(|p| p.power_std_db), 1.5),
        chi_0_1ns_power_share: chi_01,
        unrelated_power_share: chi.iter().find(|c| c.chi_class_s.is_none()).map(|c| c.power_share),
        truth_mpcs: truth.map(|t| t.truth_mpcs),
        precision: truth.and_then(|t| t.precision),
        recall: truth.and_then(|t| t.recall),
        recall_above_floor: truth.and_then(|t| t.recall_above_floor),
        track_purity: truth.and_then(|t| t.track_purity),
        false_track_share: truth.and_then(|t| t.false_track_share),
        false_long_term_share: truth.and_then(|t| t.false_long_term_share),
        births_on_true_paths: truth.map(|t| t.births_on_true_paths),
        deaths_on_true_paths: truth.map(|t| t.deaths_on_true_paths),
        long_term_tracks_per_path: truth.and_then(|t| t.long_term_tracks_per_path),
        true_births: truth.map(|t| t.transitions.values().map(|v| v.0).sum()),
        true_deaths: truth.map(|t| t.transitions.values().map(|v| v.1).sum()),
        true_birth_rate_per_m: truth.and_then(|t| per_m(Some(t.transitions.values().map(|v| v.0).sum()))),
        true_death_rate_per_m: truth.and_then(|t| per_m(Some(t.transitions.values().map(|v| v.1).sum()))),
        // Filled by analyze_mpc from the first paths.
        first_path_dynamic_range_db: DEFAULT_FIRST_PATH_DYNAMIC_RANGE_DB,
        first_path_snapshots: 0,
        first_path_hint_snapshots: 0,
        first_path_earlier_snapshots: 0,
        first_path_minus_hint_median_s: None,
        first_path_hint_abs_median_s: None,
        first_path_hint_abs_p90_s: None,
    }
}

#[cfg(test)]
mod tests;
