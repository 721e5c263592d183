//! Scores against the simulator's true MPCs (`mpc_truth`).
//!
//! - Matching: in each snapshot, a detection matches a true MPC within
//!   [`MATCH_TOLERANCE_S`] of delay, one to one, greedily: true MPCs in order
//!   of decreasing power each take the nearest unmatched detection. (Greedy by
//!   power rather than an optimal assignment: the strong paths the paper cares
//!   about are well separated at 1 ns taps, so both agree except in rare
//!   crossings, and this crate stays free of algorithm crates.)
//! - Precision: matched detections / detections; recall: matched true MPCs /
//!   true MPCs; "above floor": only true MPCs whose power is at least the
//!   set's noise floor + 6 dB (the paper's detection threshold, with the
//!   noise floor as `mpc_sets` reports it per tap; a path's peak tap carries
//!   about its power for a unit-peak pulse, so this is approximate).
//! - Track purity: per short-term track, the share of its detections matched
//!   to its most frequent `path_id` (unmatched detections count against it);
//!   reported as the mean over tracks weighted by their detections.
//! - True births and deaths across consecutive sets: `path_id`s present in
//!   the later set and not the earlier (births) and vice versa (deaths),
//!   counting a path as present in a set when its mean power over the set is
//!   above the floor + 6 dB.

use std::collections::{BTreeMap, BTreeSet};

use mmtrack_core::{MpcDetection, MpcSetStats, MpcTrack, MpcTruth};

/// Largest delay difference of a match, seconds (0.5 ns, half a tap at 1 GHz).
pub const MATCH_TOLERANCE_S: f64 = 0.5e-9;

/// Margin of the detection threshold over the noise floor, dB (paper, Sec. III-A).
pub const FLOOR_MARGIN_DB: f64 = 6.0;

/// Scores of one sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct TruthScores {
    /// True MPCs over all snapshots.
    pub truth_mpcs: u64,
    /// Matched detections / detections.
    pub precision: Option<f64>,
    /// Matched true MPCs / true MPCs.
    pub recall: Option<f64>,
    /// Recall over true MPCs above the floor + 6 dB.
    pub recall_above_floor: Option<f64>,
    /// Detection-weighted mean track purity.
    pub track_purity: Option<f64>,
    /// Later set -> (true births, true deaths) across the pair of sets.
    pub transitions: BTreeMap<u64, (u64, u64)>,
}

type SnapshotKey = (u64, u32);

/// `path_id` matched to each detection (same order as `detections`).
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

/// Every score of one sequence.
#[must_use]
pub fn score(
    truth: &[MpcTruth],
    detections: &[MpcDetection],
    tracks: &[MpcTrack],
    sets: &[MpcSetStats],
) -> TruthScores {
    let matched = match_detections(truth, detections);
    let matched_detections = matched.iter().filter(|m| m.is_some()).count() as u64;
    // Which true MPCs were found: (snapshot, path) pairs taken by a detection.
    let found: BTreeSet<(u64, u32, u64)> =
        detections.iter().zip(&matched).filter_map(|(d, m)| m.map(|p| (d.set_index, d.snapshot_index, p))).collect();
    let threshold_db: BTreeMap<u64, f64> =
        sets.iter().map(|s| (s.set_index, s.noise_floor_db + FLOOR_MARGIN_DB)).collect();
    let above =
        |t: &MpcTruth| threshold_db.get(&t.set_index).is_none_or(|&th| t.power_db() >= th || t.power_db().is_nan());
    let (mut strong, mut strong_found) = (0u64, 0u64);
    for t in truth.iter().filter(|t| above(t)) {
        strong += 1;
        strong_found += u64::from(found.contains(&(t.set_index, t.snapshot_index, t.path_id)));
    }

    // Purity: detections are matched by value (set, snapshot, delay bits).
    let key = |d: &MpcDetection| (d.set_index, d.snapshot_index, d.delay_s.to_bits());
    let path_of: BTreeMap<(u64, u32, u64), u64> =
        detections.iter().zip(&matched).filter_map(|(d, m)| m.map(|p| (key(d), p))).collect();
    let (mut pure, mut total) = (0u64, 0u64);
    for track in tracks {
        let mut votes: BTreeMap<u64, u64> = BTreeMap::new();
        for d in &track.detections {
            if let Some(&p) = path_of.get(&key(d)) {
                *votes.entry(p).or_default() += 1;
            }
        }
        pure += votes.values().copied().max().unwrap_or(0);
        total += track.detections.len() as u64;
    }

    TruthScores {
        truth_mpcs: truth.len() as u64,
        precision: share(matched_detections, detections.len() as u64),
        recall: share(found.len() as u64, truth.len() as u64),
        recall_above_floor: share(strong_found, strong),
        track_purity: share(pure, total),
        transitions: true_transitions(truth, sets, &threshold_db),
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
