//! Scores against the simulator's true MPCs (`mpc_truth`).
//!
//! - **Resolvable truth** ([`resolvable_truth`]): the simulator lists
//!   propagation paths, but a sounder sees their sum, so true MPCs of one
//!   snapshot closer in delay than [`MATCH_TOLERANCE_S`] count as one: the
//!   complex sum of their amplitudes (what the CIR holds there), at their
//!   power-weighted mean delay and Doppler, named by the smallest `path_id`
//!   of the group (a stable identity across snapshots). Two such paths could
//!   not both be matched anyway, and their sum can be far weaker than either:
//!   in a straight tunnel the two orders of a wall-to-wall double bounce are
//!   equally long, and with opposite phases they cancel. Every score below
//!   uses the resolvable truth.
//! - Matching: in each snapshot, a detection matches a true MPC within
//!   [`MATCH_TOLERANCE_S`] of delay, one to one, greedily: true MPCs in order
//!   of decreasing power each take the nearest unmatched detection. (Greedy by
//!   power rather than an optimal assignment: the strong paths the paper cares
//!   about are well separated at 1 ns taps, so both agree except in rare
//!   crossings, and this crate stays free of algorithm crates.)
//! - Precision: matched detections / detections; recall: matched true MPCs /
//!   true MPCs; "above floor": only true MPCs whose power is at least the
//!   set's noise floor + 6 dB, the detectable truth: the detector stops at
//!   estimated amplitudes `|alpha|^2` below floor + 6 dB (the paper's
//!   threshold, with the noise floor as `mpc_sets` reports it per tap), so
//!   weaker paths are beyond any run of it.
//! - Track purity: over the short-term tracks with at least one detection
//!   matched to a true MPC, the share of their detections matched to their
//!   most frequent `path_id` (unmatched detections count against it),
//!   weighted by detections. Tracks with no matched detection are false
//!   tracks, counted apart (their share of all tracks), so purity measures
//!   identity mix-ups and precision the noise.
//! - Long-term tracks: a long-term track follows the most frequent
//!   `path_id` among the matched detections of its short-term tracks, or is
//!   false without any. Births and deaths of long-term tracks that follow a
//!   true path, and long-term tracks per followed path (1 when no true path
//!   is ever split across long-term tracks), tell broken chains from false
//!   tracks.
//! - True births and deaths across consecutive sets: `path_id`s present in
//!   the later set and not the earlier (births) and vice versa (deaths),
//!   counting a path as present in a set when its mean power over the set is
//!   above the floor + 6 dB.

use std::collections::{BTreeMap, BTreeSet};

use mmtrack_core::{Complex64, MpcDetection, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth};

/// Largest delay difference of a match, seconds (0.5 ns, half a tap at 1 GHz);
/// also the separation below which true MPCs are one resolvable MPC.
pub const MATCH_TOLERANCE_S: f64 = 0.5e-9;

/// Margin of the detection threshold over the noise floor, dB (paper, Sec. III-A).
pub const FLOOR_MARGIN_DB: f64 = 6.0;

/// Scores of one sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct TruthScores {
    /// Resolvable true MPCs over all snapshots.
    pub truth_mpcs: u64,
    /// Matched detections / detections.
    pub precision: Option<f64>,
    /// Matched true MPCs / true MPCs.
    pub recall: Option<f64>,
    /// Recall over true MPCs above the floor + 6 dB.
    pub recall_above_floor: Option<f64>,
    /// Detection-weighted mean purity of the short-term tracks on a true path.
    pub track_purity: Option<f64>,
    /// Share of short-term tracks without any matched detection.
    pub false_track_share: Option<f64>,
    /// Share of long-term tracks that follow no true path.
    pub false_long_term_share: Option<f64>,
    /// Births of long-term tracks that follow a true path (not in the first set).
    pub births_on_true_paths: u64,
    /// Deaths of long-term tracks that follow a true path (not in the last set).
    pub deaths_on_true_paths: u64,
    /// Long-term tracks that follow a true path / true paths followed.
    pub long_term_tracks_per_path: Option<f64>,
    /// `path_id` -> births of the long-term tracks that follow it (not in
    /// the first set): which paths the births on true paths are on.
    pub births_by_path: BTreeMap<u64, u64>,
    /// Later set -> (true births, true deaths) across the pair of sets.
    pub transitions: BTreeMap<u64, (u64, u64)>,
}

type SnapshotKey = (u64, u32);

/// The true MPCs a sounder can tell apart (see the module docs): per
/// snapshot, true MPCs sorted by delay are grouped while consecutive delays
/// differ by at most [`MATCH_TOLERANCE_S`]; each group becomes one MPC with
/// the complex sum of its amplitudes, the power-weighted mean delay and
/// Doppler (plain means when all amplitudes are zero) and the group's
/// smallest `path_id`. Output in snapshot order, then delay order.
#[must_use]
pub fn resolvable_truth(truth: &[MpcTruth]) -> Vec<MpcTruth> {
    let mut by_snapshot: BTreeMap<SnapshotKey, Vec<&MpcTruth>> = BTreeMap::new();
    for t in truth {
        by_snapshot.entry((t.set_index, t.snapshot_index)).or_default().push(t);
    }
    let mut out = Vec::with_capacity(truth.len());
    for mut snapshot in by_snapshot.into_values() {
        snapshot.sort_by(|a, b| a.delay_s.total_cmp(&b.delay_s).then(a.path_id.cmp(&b.path_id)));
        let mut group: Vec<&MpcTruth> = Vec::new();
        for t in snapshot {
            if group.last().is_some_and(|last| t.delay_s - last.delay_s > MATCH_TOLERANCE_S) {
                out.push(merge(&group));
                group.clear();
            }
            group.push(t);
        }
        if !group.is_empty() {
            out.push(merge(&group));
        }
    }
    out
}

/// One resolvable MPC from a non-empty group of one snapshot's true MPCs.
fn merge(group: &[&MpcTruth]) -> MpcTruth {
    let first = group[0];
    if group.len() == 1 {
        return first.clone();
    }
    let power: f64 = group.iter().map(|t| t.amplitude.norm_sqr()).sum();
    let mean = |value: fn(&MpcTruth) -> f64| {
        if power > 0.0 {
            group.iter().map(|t| t.amplitude.norm_sqr() * value(t)).sum::<f64>() / power
        } else {
            group.iter().map(|t| value(t)).sum::<f64>() / group.len() as f64
        }
    };
    MpcTruth {
        t_ns: first.t_ns,
        set_index: first.set_index,
        snapshot_index: first.snapshot_index,
        path_id: group.iter().map(|t| t.path_id).min().unwrap_or(first.path_id),
        delay_s: mean(|t| t.delay_s),
        amplitude: group.iter().map(|t| t.amplitude).sum::<Complex64>(),
        doppler_hz: mean(|t| t.doppler_hz),
    }
}

/// `path_id` matched to each detection (same order as `detections`); `truth`
/// is taken as given (pass [`resolvable_truth`] for the scores' matching).
#[must_use]
pub fn match_detections(truth: &[MpcTruth], detections: &[MpcDetection]) -> Vec<Option<u64>> {
    let mut by_snapshot: BTreeMap<SnapshotKey, (Vec<usize>, Vec<usize>)> = BTreeMap::new();
    for (i, t) in truth.iter().enumerate() {
        by_snapshot.entry((t.set_index, t.snapshot_index)).or_default().0.push(i);
    }
    for (j, d) in detections.iter().enumerate() {
        by_snapshot.entry((d.set_index, d.snapshot_index)).or_default().1.push(j);
    }
    let mut matched = vec![None; detections.len()];
    for (mut true_ids, det_ids) in by_snapshot.into_values() {
        true_ids.sort_by(|&a, &b| truth[b].amplitude.norm_sqr().total_cmp(&truth[a].amplitude.norm_sqr()));
        for i in true_ids {
            let nearest = det_ids
                .iter()
                .copied()
                .filter(|&j| matched[j].is_none())
                .map(|j| (j, (detections[j].delay_s - truth[i].delay_s).abs()))
                .filter(|&(_, d)| d <= MATCH_TOLERANCE_S)
                .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((j, _)) = nearest {
                matched[j] = Some(truth[i].path_id);
            }
        }
    }
    matched
}

fn share(a: u64, b: u64) -> Option<f64> {
    (b > 0).then(|| a as f64 / b as f64)
}

/// Most frequent key (ties: the smallest), `None` when empty.
fn majority(votes: &BTreeMap<u64, u64>) -> Option<(u64, u64)> {
    votes.iter().max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(a.0))).map(|(&k, &n)| (k, n))
}

/// Every score of one sequence; `truth` is the table as recorded (it is made
/// resolvable here).
#[must_use]
pub fn score(
    truth: &[MpcTruth],
    detections: &[MpcDetection],
    tracks: &[MpcTrack],
    long_term: &[MpcLongTermEntry],
    sets: &[MpcSetStats],
) -> TruthScores {
    let truth = resolvable_truth(truth);
    let matched = match_detections(&truth, detections);
    let matched_detections = matched.iter().filter(|m| m.is_some()).count() as u64;
    // Which true MPCs were found: (snapshot, path) pairs taken by a detection.
    let found: BTreeSet<(u64, u32, u64)> =
        detections.iter().zip(&matched).filter_map(|(d, m)| m.map(|p| (d.set_index, d.snapshot_index, p))).collect();
    // A set without a floor (every snapshot skipped) has no threshold: all
    // its true paths count as above it.
    let threshold_db: BTreeMap<u64, f64> =
        sets.iter().filter_map(|s| Some((s.set_index, s.noise_floor_db? + FLOOR_MARGIN_DB))).collect();
    let above =
        |t: &MpcTruth| threshold_db.get(&t.set_index).is_none_or(|&th| t.power_db() >= th || t.power_db().is_nan());
    let (mut strong, mut strong_found) = (0u64, 0u64);
    for t in truth.iter().filter(|t| above(t)) {
        strong += 1;
        strong_found += u64::from(found.contains(&(t.set_index, t.snapshot_index, t.path_id)));
    }

    // Detections are matched by value (set, snapshot, delay bits).
    let key = |d: &MpcDetection| (d.set_index, d.snapshot_index, d.delay_s.to_bits());
    let path_of: BTreeMap<(u64, u32, u64), u64> =
        detections.iter().zip(&matched).filter_map(|(d, m)| m.map(|p| (key(d), p))).collect();
    let votes_of = |track: &MpcTrack, votes: &mut BTreeMap<u64, u64>| {
        for p in track.detections.iter().filter_map(|d| path_of.get(&key(d))) {
            *votes.entry(*p).or_default() += 1;
        }
    };
    let (mut pure, mut on_paths, mut false_tracks) = (0u64, 0u64, 0u64);
    let mut short_votes: BTreeMap<u64, BTreeMap<u64, u64>> = BTreeMap::new();
    for track in tracks {
        let votes = short_votes.entry(track.track_id).or_default();
        votes_of(track, votes);
        match majority(votes) {
            Some((_, n)) => {
                pure += n;
                on_paths += track.detections.len() as u64;
            }
            None => false_tracks += 1,
        }
    }
    let set_span = (sets.iter().map(|s| s.set_index).min(), sets.iter().map(|s| s.set_index).max());
    let long = long_term_scores(long_term, &short_votes, set_span);

    TruthScores {
        truth_mpcs: truth.len() as u64,
        precision: share(matched_detections, detections.len() as u64),
        recall: share(found.len() as u64, truth.len() as u64),
        recall_above_floor: share(strong_found, strong),
        track_purity: share(pure, on_paths),
        false_track_share: share(false_tracks, tracks.len() as u64),
        false_long_term_share: long.false_share,
        births_on_true_paths: long.births,
        deaths_on_true_paths: long.deaths,
        long_term_tracks_per_path: long.per_path,
        births_by_path: long.births_by_path,
        transitions: true_transitions(&truth, sets, &threshold_db),
    }
}

/// Long-term tracks against the truth (module docs).
struct LongTermScores {
    false_share: Option<f64>,
    births: u64,
    births_by_path: BTreeMap<u64, u64>,
    deaths: u64,
    per_path: Option<f64>,
}

/// `set_span`: the sequence's first and last set (births and deaths are not
/// counted there, as for all long-term tracks).
fn long_term_scores(
    entries: &[MpcLongTermEntry],
    short_votes: &BTreeMap<u64, BTreeMap<u64, u64>>,
    (first_set, last_set): (Option<u64>, Option<u64>),
) -> LongTermScores {
    // Per long-term track: (first set, last set, votes of its short-term tracks).
    let mut tracks: BTreeMap<u64, (u64, u64, BTreeMap<u64, u64>)> = BTreeMap::new();
    for e in entries {
        let slot = tracks.entry(e.long_track_id).or_insert((e.set_index, e.set_index, BTreeMap::new()));
        slot.0 = slot.0.min(e.set_index);
        slot.1 = slot.1.max(e.set_index);
        for (&path, &n) in short_votes.get(&e.short_track_id).into_iter().flatten() {
            *slot.2.entry(path).or_default() += n;
        }
    }
    let (mut births, mut deaths, mut false_tracks) = (0u64, 0u64, 0u64);
    let mut followed: BTreeMap<u64, u64> = BTreeMap::new();
    let mut births_by_path: BTreeMap<u64, u64> = BTreeMap::new();
    for (first, last, votes) in tracks.values() {
        let Some((path, _)) = majority(votes) else {
            false_tracks += 1;
            continue;
        };
        *followed.entry(path).or_default() += 1;
        if Some(*first) != first_set {
            births += 1;
            *births_by_path.entry(path).or_default() += 1;
        }
        deaths += u64::from(Some(*last) != last_set);
    }
    let on_paths: u64 = followed.values().sum();
    LongTermScores {
        false_share: share(false_tracks, tracks.len() as u64),
        births,
        births_by_path,
        deaths,
        per_path: share(on_paths, followed.len() as u64),
    }
}

fn true_transitions(
    truth: &[MpcTruth],
    sets: &[MpcSetStats],
    threshold_db: &BTreeMap<u64, f64>,
) -> BTreeMap<u64, (u64, u64)> {
    let mut power: BTreeMap<(u64, u64), (f64, u32)> = BTreeMap::new();
    for t in truth {
        let slot = power.entry((t.set_index, t.path_id)).or_default();
        slot.0 += t.amplitude.norm_sqr();
        slot.1 += 1;
    }
    let mut present: BTreeMap<u64, BTreeSet<u64>> = sets.iter().map(|s| (s.set_index, BTreeSet::new())).collect();
    for (&(set, path), &(p, n)) in &power {
        let mean_db = 10.0 * (p / f64::from(n)).log10();
        let threshold = threshold_db.get(&set).copied().unwrap_or(f64::NEG_INFINITY);
        if mean_db >= threshold
            && let Some(paths) = present.get_mut(&set)
        {
            paths.insert(path);
        }
    }
    let ordered: Vec<(&u64, &BTreeSet<u64>)> = present.iter().collect();
    ordered
        .windows(2)
        .map(|w| {
            let ((_, before), (&set, after)) = (w[0], w[1]);
            (set, (after.difference(before).count() as u64, before.difference(after).count() as u64))
        })
        .collect()
}
