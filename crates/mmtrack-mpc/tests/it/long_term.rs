//! Long-term tracking (Mahler et al. 2017, Sec. V) on hand-made
//! full-lifetime tracks.

use mmtrack_core::{Complex64, MpcDetection, MpcTrack};
use mmtrack_mpc::long_term::{TrackSummary, relate_sets};
use mmtrack_mpc::short_term::doppler_hz;
use mmtrack_mpc::{CandidateGate, DelayRate, LongTermConfig, LongTermTracker, MpcError};

use crate::common::CARRIER_HZ;

/// The paper's timing: 6 snapshots 0.717 ms apart, a set every 10 ms.
const SNAPSHOT_NS: i64 = 717_000;
const SET_NS: i64 = 10_000_000;

/// A full-lifetime track of set `set` for a path with delay
/// `tau0 + rate t` (t from 0 at set 0), power `power_db` and an extra delay
/// offset `offset_s` (to mimic a wrong association).
fn track(id: u64, set: u64, tau0_s: f64, rate: f64, power_db: f64, offset_s: f64) -> MpcTrack {
    track_of(id, set, power_db, |t_ns| tau0_s + rate * t_ns as f64 * 1e-9 + offset_s)
}

/// A full-lifetime track of set `set` (6 snapshots at the paper's timing)
/// with power `power_db` and the delay `delay_s(t_ns)` at each snapshot.
fn track_of(id: u64, set: u64, power_db: f64, delay_s: impl Fn(i64) -> f64) -> MpcTrack {
    let detections: Vec<MpcDetection> = (0..6u32)
        .map(|n| {
            let t_ns = set as i64 * SET_NS + i64::from(n) * SNAPSHOT_NS;
            MpcDetection {
                t_ns,
                set_index: set,
                snapshot_index: n,
                delay_s: delay_s(t_ns),
                amplitude: Complex64::from_polar(10f64.powf(power_db / 20.0), 0.0),
            }
        })
        .collect();
    MpcTrack { track_id: id, doppler_hz: doppler_hz(&detections, CARRIER_HZ), detections }
}

fn tracker() -> LongTermTracker {
    LongTermTracker::new(LongTermConfig::default(), CARRIER_HZ, 1000).unwrap()
}

#[test]
fn summary_is_mean_delay_power_of_mean_power_and_doppler() {
    let mut t = track(3, 2, 40e-9, 5e-8, -100.0, 0.0);
    for (n, d) in t.detections.iter_mut().enumerate() {
        if n % 2 == 1 {
            d.amplitude = Complex64::from_polar(10f64.powf(-110.0 / 20.0), 1.0);
        }
    }
    let s = TrackSummary::of(&t).unwrap();
    assert_eq!((s.short_track_id, s.set_index), (3, 2));
    // Mean time: set start + 2.5 snapshots.
    assert_eq!(s.t_ns, 2 * SET_NS + 5 * SNAPSHOT_NS / 2);
    // 10 log10((1e-10 + 1e-11) / 2) = -102.596 dB, not the mean of the dB
    // values (-105); 1e-9 dB: round-off.
    let expected_db = 10.0 * ((1e-10 + 1e-11) / 2.0f64).log10();
    assert!((s.mean_power_db - expected_db).abs() < 1e-9, "{}", s.mean_power_db);
    // The mean delay of a linear delay is the delay at the mean time.
    let expected_s = 40e-9 + 5e-8 * s.t_ns as f64 * 1e-9;
    assert!((s.mean_delay_s - expected_s).abs() < 1e-18, "{}", s.mean_delay_s);
    // nu = -rate f_c = -285 Hz; 1e-3 Hz: round-off of the fit.
    assert!((s.doppler_hz + 285.0).abs() < 1e-3, "{}", s.doppler_hz);
    assert_eq!(TrackSummary::of(&MpcTrack { track_id: 0, doppler_hz: None, detections: vec![] }), None);
}

#[test]
fn two_sets_link_by_their_doppler_at_the_smallest_class() {
    // Two paths drifting 0.5 ns and -0.3 ns per 10 ms (rates 5e-8, -3e-8 s/s:
    // nu = -285 Hz, +171 Hz). The eq. (37) as printed (`- nu f_c T_r`)
    // would predict kilometres of delay; with the delay rate -nu / f_c the
    // prediction is exact, so both links are in the 0.1 ns class. With the
    // sign of the rate flipped the error would be 1 ns and 0.6 ns instead.
    let mut lt = tracker();
    let set0 = [track(0, 0, 30e-9, 5e-8, -100.0, 0.0), track(1, 0, 45e-9, -3e-8, -104.0, 0.0)];
    let first = lt.push_set(&set0);
    assert_eq!(first.len(), 2);
    assert_eq!((first[0].long_track_id, first[1].long_track_id), (1000, 1001));
    assert!(first.iter().all(|e| e.link_error_s.is_none() && e.chi_class_s.is_none()));

    // The next set lists the tracks in the other order: relations go by
    // prediction, not position.
    let set1 = [track(10, 1, 45e-9, -3e-8, -103.0, 0.0), track(11, 1, 30e-9, 5e-8, -101.0, 0.0)];
    let second = lt.push_set(&set1);
    assert_eq!(second.len(), 2);
    assert_eq!((second[0].short_track_id, second[0].long_track_id), (10, 1001));
    assert_eq!((second[1].short_track_id, second[1].long_track_id), (11, 1000));
    for entry in &second {
        assert_eq!(entry.set_index, 1);
        assert_eq!(entry.chi_class_s, Some(0.1e-9));
        // Exact linear delays: the error is round-off of ~1e-8 s values, far
        // below 1e-3 ns.
        assert!(entry.link_error_s.unwrap() < 1e-12, "{entry:?}");
    }
    // Doppler is carried into the entry (-285 Hz for the 5e-8 s/s path).
    assert!((second[1].doppler_hz + 285.0).abs() < 1e-3);
}

#[test]
fn the_link_class_is_the_smallest_chi_holding_both_errors() {
    // The next set's track is off its prediction by `offset`: both the
    // forward and the backward error equal |offset| (same Doppler on both
    // sides), so the class is the first chi >= |offset|.
    for (offset_ns, class_ns) in [(0.05, Some(0.1)), (0.15, Some(0.2)), (-0.4, Some(0.5)), (0.8, Some(1.0))] {
        let mut lt = tracker();
        lt.push_set(&[track(0, 0, 30e-9, 1e-8, -100.0, 0.0)]);
        let next = lt.push_set(&[track(1, 1, 30e-9, 1e-8, -100.0, offset_ns * 1e-9)]);
        assert_eq!(next[0].chi_class_s.map(|c| c * 1e9), class_ns, "offset {offset_ns} ns");
        // 1e-6 ns: round-off of the two-way predictions.
        assert!((next[0].link_error_s.unwrap() * 1e9 - offset_ns.abs()).abs() < 1e-6, "{next:?}");
        assert_eq!(next[0].long_track_id, 1000);
    }
}

#[test]
fn the_backward_prediction_uses_the_candidates_own_doppler() {
    // Same mean delays as a consistent pair, but the next set's track has a
    // Doppler for a rate of 1.4e-7 s/s instead of 5e-8: forward error 0
    // (the current track predicts it), backward error (1.4e-7 - 5e-8) * 10 ms
    // = 0.9 ns: class 1 ns. With 2e-7 s/s the backward error is 1.5 ns: no
    // relation, and the next track starts a new long-term track.
    for (rate, class_ns) in [(1.4e-7, Some(1.0)), (2e-7, None)] {
        let mut lt = tracker();
        lt.push_set(&[track(0, 0, 30e-9, 5e-8, -100.0, 0.0)]);
        let mut next = track(1, 1, 30e-9, 5e-8, -100.0, 0.0);
        next.doppler_hz = Some(-rate * CARRIER_HZ);
        let entries = lt.push_set(&[next]);
        assert_eq!(entries[0].chi_class_s.map(|c| (c * 1e9 * 1e6).round() / 1e6), class_ns, "rate {rate}");
        let expected_long_id = if class_ns.is_some() { 1000 } else { 1001 };
        assert_eq!(entries[0].long_track_id, expected_long_id);
    }
}

#[test]
fn candidates_are_gated_in_power_and_delay() {
    let config = LongTermConfig::default();
    let current = [TrackSummary::of(&track(0, 0, 30e-9, 0.0, -100.0, 0.0)).unwrap()];
    // 6 dB weaker: outside xi_a = 5 dB. 4 dB: inside.
    for (power_db, related) in [(-106.0, false), (-104.0, true)] {
        let next = [TrackSummary::of(&track(1, 1, 30e-9, 0.0, power_db, 0.0)).unwrap()];
        assert_eq!(relate_sets(&current, &next, CARRIER_HZ, &config).len(), usize::from(related), "{power_db}");
    }
    // 1.2 ns away: outside xi_tau = 1 ns, even with a wide chi.
    let wide = LongTermConfig { chi_classes_s: vec![5e-9], ..config.clone() };
    let next = [TrackSummary::of(&track(1, 1, 31.2e-9, 0.0, -100.0, 0.0)).unwrap()];
    assert!(relate_sets(&current, &next, CARRIER_HZ, &wide).is_empty());
}

#[test]
fn relations_are_one_to_one_strongest_current_first() {
    // Two current tracks 0.3 ns apart, both with the same next track as
    // their only candidate: the stronger one takes it; the weaker one, though
    // nearer in delay, is left without a successor.
    let config = LongTermConfig::default();
    let current = [
        TrackSummary::of(&track(0, 0, 30.3e-9, 0.0, -103.0, 0.0)).unwrap(),
        TrackSummary::of(&track(1, 0, 30.0e-9, 0.0, -100.0, 0.0)).unwrap(),
    ];
    let next = [TrackSummary::of(&track(2, 1, 30.25e-9, 0.0, -102.0, 0.0)).unwrap()];
    let links = relate_sets(&current, &next, CARRIER_HZ, &config);
    assert_eq!(links.len(), 1, "{links:?}");
    assert_eq!((links[0].current, links[0].next), (1, 0));
    // 0.25 ns off: class 0.5 ns.
    assert_eq!(links[0].chi_class_s, 0.5e-9);

    // With a second next track near the weaker one, each gets its own.
    let next = [
        TrackSummary::of(&track(2, 1, 30.02e-9, 0.0, -100.0, 0.0)).unwrap(),
        TrackSummary::of(&track(3, 1, 30.31e-9, 0.0, -103.0, 0.0)).unwrap(),
    ];
    let mut pairs: Vec<(usize, usize)> =
        relate_sets(&current, &next, CARRIER_HZ, &config).iter().map(|l| (l.current, l.next)).collect();
    pairs.sort_unstable();
    assert_eq!(pairs, vec![(0, 1), (1, 0)]);
}

#[test]
fn an_empty_set_breaks_the_chains() {
    let mut lt = tracker();
    lt.push_set(&[track(0, 0, 30e-9, 0.0, -100.0, 0.0)]);
    assert!(lt.push_set(&[]).is_empty());
    let entries = lt.push_set(&[track(1, 2, 30e-9, 0.0, -100.0, 0.0)]);
    assert_eq!(entries[0].long_track_id, 1001);
    assert_eq!(entries[0].chi_class_s, None);
}

#[test]
fn bad_configs_are_refused_by_name() {
    let err = LongTermTracker::new(LongTermConfig::default(), 0.0, 0).unwrap_err();
    assert!(matches!(err, MpcError::BadConfig { field: "carrier_hz", .. }), "{err}");
    let config = LongTermConfig { chi_classes_s: vec![0.5e-9, 0.2e-9], ..LongTermConfig::default() };
    let err = LongTermTracker::new(config, CARRIER_HZ, 0).unwrap_err();
    assert!(matches!(err, MpcError::BadConfig { field: "long_term.chi_classes_s", .. }), "{err}");
}

/// Long-term ids of a fast oncoming car's path (delay falling 1.75 ns per
/// 10 ms set, the convoy's oncoming cars) over sets 0..10 with set 5
/// missing, and of a slow wall bounce beside it, for one tracker config.
fn ids_of_a_fast_path_with_a_missing_set(config: LongTermConfig) -> (Vec<u64>, Vec<u64>) {
    let mut lt = LongTermTracker::new(config, CARRIER_HZ, 0).unwrap();
    let (mut fast, mut slow) = (Vec::new(), Vec::new());
    for set in 0..10u64 {
        let mut tracks = vec![track(2 * set, set, 150e-9, 0.0, -100.0, 0.0)];
        if set != 5 {
            tracks.push(track(2 * set + 1, set, 400e-9, -1.75e-7, -118.0, 0.0));
        }
        let entries = lt.push_set(&tracks);
        slow.push(entries[0].long_track_id);
        fast.extend(entries.get(1).map(|e| e.long_track_id));
    }
    (fast, slow)
}

fn distinct(ids: &[u64]) -> usize {
    ids.iter().collect::<std::collections::BTreeSet<_>>().len()
}

#[test]
fn the_doppler_gated_variant_with_a_one_set_gap_keeps_a_fast_path_whole_where_the_paper_gate_splits_it() {
    let variant = |candidate_gate, max_missed_sets| LongTermConfig {
        candidate_gate,
        max_missed_sets,
        ..LongTermConfig::default()
    };
    // The paper's eq. (35): 1.75 ns of raw delay change is outside the 1 ns
    // gate, so each of the 9 sets holding the path starts a new track.
    let (fast, slow) = ids_of_a_fast_path_with_a_missing_set(LongTermConfig::default());
    assert_eq!((fast.len(), distinct(&fast)), (9, 9), "{fast:?}");
    assert_eq!(distinct(&slow), 1, "the slow path links in every set: {slow:?}");
    // Gated around the Doppler-predicted delay: linked, but the missing
    // set ends the chain (the paper's adjacency).
    let (fast, _) = ids_of_a_fast_path_with_a_missing_set(variant(CandidateGate::PredictedDelay, 0));
    assert_eq!(distinct(&fast), 2, "{fast:?}");
    // A gap alone does not help the raw gate (3.5 ns over 20 ms).
    let (fast, _) = ids_of_a_fast_path_with_a_missing_set(variant(CandidateGate::RawDelay, 1));
    assert_eq!(distinct(&fast), 9, "{fast:?}");
    // Both: one long-term track across the gap; the slow path unchanged.
    let (fast, slow) = ids_of_a_fast_path_with_a_missing_set(variant(CandidateGate::PredictedDelay, 1));
    assert_eq!((fast.len(), distinct(&fast)), (9, 1), "{fast:?}");
    assert_eq!(distinct(&slow), 1, "{slow:?}");
}

/// A full-lifetime track of set `set` whose mean delay is
/// `tau0 + rate t_mid + offset_s` (`t_mid` its mean time) and whose delays
/// within the set run at `in_set_rate` (its Doppler is `-in_set_rate f_c`):
/// a noisy set as eq. (30) sees it.
fn noisy_track(id: u64, set: u64, tau0_s: f64, rate: f64, in_set_rate: f64, offset_s: f64) -> MpcTrack {
    let t_mid_ns = set as i64 * SET_NS + 5 * SNAPSHOT_NS / 2;
    track_of(id, set, -100.0, |t_ns| {
        tau0_s + rate * t_mid_ns as f64 * 1e-9 + in_set_rate * (t_ns - t_mid_ns) as f64 * 1e-9 + offset_s
    })
}

#[test]
fn the_chain_slope_links_a_set_whose_own_doppler_misses_the_next_set_by_more_than_the_class() {
    // A path closing at 1 ns per 10 ms set. Set 1's in-set slope says 1.7 ns
    // per 10 ms (eq. (30)'s noise), set 2's mean delay is 0.4 ns late: set
    // 1's Doppler predicts set 2 1.1 ns off (outside the 1 ns gate and
    // class); the slope of set 0 -> 1 predicts it 0.4 ns off, and set 2's
    // own Doppler back to set 1 is 0.4 ns off (the two-way check holds).
    let rate = -1e-7;
    let sets = || {
        vec![
            noisy_track(0, 0, 60e-9, rate, rate, 0.0),
            noisy_track(1, 1, 60e-9, rate, -1.7e-7, 0.0),
            noisy_track(2, 2, 60e-9, rate, rate, 0.4e-9),
            noisy_track(3, 3, 60e-9, rate, rate, 0.0),
            noisy_track(4, 4, 60e-9, rate, rate, 0.0),
        ]
    };
    let ids = |delay_rate| {
        let config = LongTermConfig { candidate_gate: CandidateGate::PredictedDelay, delay_rate, ..Default::default() };
        let mut lt = LongTermTracker::new(config, CARRIER_HZ, 0).unwrap();
        sets().iter().map(|t| lt.push_set(std::slice::from_ref(t))[0].clone()).collect::<Vec<_>>()
    };
    let paper = ids(DelayRate::TrackDoppler);
    assert_eq!(paper.iter().map(|e| e.long_track_id).collect::<Vec<_>>(), [0, 0, 1, 1, 1]);
    let chain = ids(DelayRate::ChainSlope);
    assert_eq!(chain.iter().map(|e| e.long_track_id).collect::<Vec<_>>(), [0, 0, 0, 0, 0]);
    // The larger of the two errors per link. Set 0 -> 1: set 1's Doppler
    // back to set 0 is 0.7 ns off (set 0 has no chain: its own Doppler
    // forward, exact). Set 1 -> 2 through the chain: 0.4 ns both ways. Set
    // 2 -> 3: the chain's slope carries set 2's 0.4 ns twice (0.8 ns).
    let errors: Vec<f64> = chain.iter().skip(1).map(|e| e.link_error_s.unwrap() * 1e9).collect();
    for (got, want) in errors.iter().zip([0.7, 0.4, 0.8, 0.4]) {
        assert!((got - want).abs() < 1e-6, "{errors:?}");
    }
}

#[test]
fn a_track_waits_at_most_max_missed_sets_and_the_bridge_carries_its_prediction_error() {
    let config = LongTermConfig { max_missed_sets: 1, ..LongTermConfig::default() };
    let mut lt = LongTermTracker::new(config, CARRIER_HZ, 0).unwrap();
    lt.push_set(&[track(0, 0, 30e-9, 4e-8, -100.0, 0.0)]);
    assert!(lt.push_set(&[]).is_empty());
    // Set 2: 20 ms later, 0.8 ns further (within the raw gate), linked to
    // set 0 with an exact prediction.
    let bridged = lt.push_set(&[track(1, 2, 30e-9, 4e-8, -100.0, 0.0)]);
    assert_eq!(bridged[0].long_track_id, 0);
    assert!(bridged[0].link_error_s.unwrap() < 1e-12, "{:?}", bridged[0].link_error_s);
    // Two sets missed: a new track.
    assert!(lt.push_set(&[]).is_empty());
    assert!(lt.push_set(&[]).is_empty());
    let fresh = lt.push_set(&[track(2, 5, 30e-9, 4e-8, -100.0, 0.0)]);
    assert_eq!((fresh[0].long_track_id, fresh[0].chi_class_s), (1, None));
    let err = LongTermTracker::new(LongTermConfig { max_missed_sets: 11, ..LongTermConfig::default() }, CARRIER_HZ, 0)
        .unwrap_err();
    assert!(matches!(err, MpcError::BadConfig { field: "long_term.max_missed_sets", .. }), "{err}");
}
