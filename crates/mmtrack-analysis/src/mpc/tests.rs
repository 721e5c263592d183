use mmtrack_core::{Complex64, MpcDetection, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth, Se2, StampedPose};

use super::*;

const SET_NS: i64 = 10_000_000;

fn set(i: u64) -> MpcSetStats {
    MpcSetStats {
        set_index: i,
        t_ns: i as i64 * SET_NS,
        snapshots: 6,
        skipped_snapshots: 0,
        detections: 10,
        short_term_tracks: 3,
        full_lifetime_tracks: 2,
        noise_floor_db: Some(-140.0),
        channel_gain_db: Some(-80.0),
        detected_gain_db: Some(-82.0),
        tracked_gain_db: Some(-83.0),
        full_lifetime_gain_db: Some(-84.0),
        gmphd_tracked_gain_db: None,
    }
}

fn entry(track: u64, set: u64, chi_ns: Option<f64>) -> MpcLongTermEntry {
    MpcLongTermEntry {
        long_track_id: track,
        set_index: set,
        t_ns: set as i64 * SET_NS + 1_800_000,
        short_track_id: track * 100 + set,
        mean_delay_s: 1e-7 + track as f64 * 1e-8,
        mean_power_db: -90.0,
        doppler_hz: 0.0,
        link_error_s: chi_ns.map(|c| c * 0.5e-9),
        chi_class_s: chi_ns.map(|c| c * 1e-9),
    }
}

/// Long-term tracks A: sets 0-3, B: 1-2, C: 3, D: 0, E: 2 (linked entries
/// carry a chi class; A's links at 0.1 ns, B's at 0.5 ns).
fn long_term() -> Vec<MpcLongTermEntry> {
    vec![
        entry(0, 0, None),
        entry(3, 0, None),
        entry(0, 1, Some(0.1)),
        entry(1, 1, None),
        entry(0, 2, Some(0.1)),
        entry(1, 2, Some(0.5)),
        entry(4, 2, None),
        entry(0, 3, Some(0.1)),
        entry(2, 3, None),
    ]
}

/// Both cars drive along x at 100 m/s: 1 m each per 10 ms set period.
fn straight(offset_m: f64) -> Vec<StampedPose> {
    (0..=4)
        .map(|i| StampedPose { t_ns: i * SET_NS, parent_from_child: Se2::new(offset_m + i as f64, 0.0, 0.0) })
        .collect()
}

fn input(distance: DistanceSource) -> MpcInput {
    MpcInput {
        detections: Vec::new(),
        tracks: Vec::new(),
        long_term: long_term(),
        sets: (0..4).map(set).collect(),
        snapshots: None,
        truth: None,
        distance,
    }
}

#[test]
fn births_deaths_and_counts_follow_the_long_term_tracks() {
    let r = analyze_mpc(
        "s",
        input(DistanceSource::BothVehicles { tx: straight(50.0), rx: straight(0.0) }),
        &MpcOptions::default(),
    );
    let counts: Vec<u64> = r.per_set.iter().map(|s| s.long_term_mpcs).collect();
    assert_eq!(counts, vec![2, 2, 3, 2]);
    let births: Vec<Option<u64>> = r.per_set.iter().map(|s| s.births).collect();
    let deaths: Vec<Option<u64>> = r.per_set.iter().map(|s| s.deaths).collect();
    assert_eq!(births, vec![None, Some(1), Some(1), Some(1)]);
    assert_eq!(deaths, vec![None, Some(1), Some(0), Some(2)]);
    // 1 m per car per transition, both cars: 2 m (interpolation is exact on a line; 1e-12 covers rounding).
    assert!((r.per_set[3].distance_m.unwrap() - 2.0).abs() < 1e-12);
    assert!((r.per_set[3].death_rate_per_m.unwrap() - 1.0).abs() < 1e-12);
    assert!((r.per_set[3].death_rate_per_s.unwrap() - 200.0).abs() < 1e-9);
    let s = &r.summary;
    assert_eq!((s.births, s.deaths, s.long_term_tracks), (Some(3), Some(3), 5));
    assert!((s.distance_m.unwrap() - 6.0).abs() < 1e-12);
    assert!((s.birth_rate_per_m.unwrap() - 0.5).abs() < 1e-12);
    assert_eq!(s.distance_source, "ground_truth_tx+ground_truth_rx");
    assert!((s.mean_mpcs_per_set.unwrap() - 2.25).abs() < 1e-12);
    assert_eq!(s.median_mpcs_per_set, Some(2.0));
    assert_eq!(r.counts, vec![CountBin { mpcs: 2, sets: 3, cdf: 0.75 }, CountBin { mpcs: 3, sets: 1, cdf: 1.0 }]);
    assert!((s.mean_detection_loss_db.unwrap() - 2.0).abs() < 1e-12);
    assert!((s.mean_tracking_loss_db.unwrap() - 3.0).abs() < 1e-12);
}

/// Before: a run that tracked nothing reported 0.0 MPCs per set, 0 births
/// and a birth rate of 0 (while its tracking loss was null and its note
/// said births and deaths are empty). Now they are null, and "n/a" in the
/// printed line.
#[test]
fn counts_are_null_when_nothing_was_tracked() {
    let detection =
        MpcDetection { t_ns: 0, set_index: 0, snapshot_index: 0, delay_s: 1e-7, amplitude: Complex64::new(1e-4, 0.0) };
    let untracked = MpcInput { detections: vec![detection], long_term: Vec::new(), ..input(DistanceSource::None) };
    let r = analyze_mpc("s", untracked, &MpcOptions::default());
    let s = &r.summary;
    assert_eq!((s.births, s.deaths, s.mean_mpcs_per_set, s.median_mpcs_per_set), (None, None, None, None));
    assert_eq!((s.birth_rate_per_s, s.death_rate_per_s, s.birth_rate_per_m), (None, None, None));
    assert!(r.notes.iter().any(|n| n.contains("births, deaths")), "{:?}", r.notes);
    let line = crate::mpc_report::one_line(&r);
    assert!(line.contains("n/a MPCs per set, births n/a / deaths n/a"), "{line}");
    // Nor is there a distribution of counts or a plot of zeros beside the "n/a".
    assert!(r.counts.is_empty());
    for file in ["mpc_count.svg", "mpc_birth_death.svg"] {
        assert!(crate::mpc_plots::empty_because(&r, file).is_some(), "{file}");
    }
}

/// Before: a single-snapshot source (the real BUT 60 GHz sample: one set
/// per link, nothing tracked) got five plot files, four of them axes
/// without a curve. Now only plots with data are named in the report, and
/// the others say why in their place.
#[test]
fn plots_without_data_are_not_drawn_and_the_report_says_why() {
    let detection =
        MpcDetection { t_ns: 0, set_index: 0, snapshot_index: 0, delay_s: 1e-7, amplitude: Complex64::new(1e-4, 0.0) };
    let one_set = MpcInput {
        detections: vec![detection],
        long_term: Vec::new(),
        sets: vec![set(0)],
        ..input(DistanceSource::None)
    };
    let r = analyze_mpc("one", one_set, &MpcOptions::default());
    let empty: Vec<&str> = crate::mpc_report::PLOTS
        .iter()
        .map(|(file, _)| *file)
        .filter(|file| crate::mpc_plots::empty_because(&r, file).is_some())
        .collect();
    assert_eq!(empty, ["mpc_count.svg", "mpc_birth_death.svg", "mpc_power_loss.svg", "mpc_power_std.svg"]);
    let mut report = String::new();
    crate::mpc_report::section(&mut report, std::slice::from_ref(&r));
    assert!(report.contains("](plots/one/mpc_delay_tracks.svg)"), "{report}");
    assert!(!report.contains("](plots/one/mpc_birth_death.svg)"), "{report}");
    assert!(
        report.contains(
            "*No plot (birth and death rates (Fig. 13)): birth and death rates are taken between consecutive sets; \
             this sequence has 1 set.*"
        ),
        "{report}"
    );

    // Four sets with long-term tracks: every plot but the track power spread (no short-term tracks here).
    let r = analyze_mpc("four", input(DistanceSource::None), &MpcOptions::default());
    let empty: Vec<&str> = crate::mpc_report::PLOTS
        .iter()
        .map(|(file, _)| *file)
        .filter(|file| crate::mpc_plots::empty_because(&r, file).is_some())
        .collect();
    assert_eq!(empty, ["mpc_delay_tracks.svg", "mpc_power_std.svg"]);
}

#[test]
fn chi_shares_and_unrelated_power() {
    let r = analyze_mpc("s", input(DistanceSource::None), &MpcOptions::default());
    // Equal powers: three links at 0.1 ns and one at 0.5 ns; C, D, E (3 of 9 entries) are unrelated.
    assert_eq!(r.chi.len(), 3);
    assert!((r.chi[0].chi_class_s.unwrap() - 0.1e-9).abs() < 1e-24);
    assert!((r.chi[0].power_share - 0.75).abs() < 1e-12);
    assert_eq!(r.chi[2].chi_class_s, None);
    assert_eq!(r.chi[2].entries, 3);
    assert!((r.chi[2].power_share - 1.0 / 3.0).abs() < 1e-12);
    assert!((r.summary.chi_0_1ns_power_share.unwrap() - 0.75).abs() < 1e-12);
    // Without a trajectory only the per-second rates exist.
    assert_eq!(r.summary.distance_source, "none");
    assert_eq!(r.summary.birth_rate_per_m, None);
    assert!((r.summary.birth_rate_per_s.unwrap() - 100.0).abs() < 1e-9);
}

fn detection(snapshot: u32, delay_ns: f64, amplitude: f64) -> MpcDetection {
    MpcDetection {
        t_ns: i64::from(snapshot) * 717_000,
        set_index: 0,
        snapshot_index: snapshot,
        delay_s: delay_ns * 1e-9,
        amplitude: Complex64::new(amplitude, 0.0),
    }
}

fn truth_mpc(snapshot: u32, path_id: u64, delay_ns: f64, amplitude: f64) -> MpcTruth {
    MpcTruth {
        t_ns: i64::from(snapshot) * 717_000,
        set_index: 0,
        snapshot_index: snapshot,
        path_id,
        delay_s: delay_ns * 1e-9,
        amplitude: Complex64::new(amplitude, 0.0),
        doppler_hz: 0.0,
    }
}

#[test]
fn matching_is_one_to_one_strongest_first_within_half_a_nanosecond() {
    let truth = vec![truth_mpc(0, 1, 10.0, 1e-5), truth_mpc(0, 2, 10.4, 1e-4), truth_mpc(1, 1, 10.0, 1e-5)];
    let detections = vec![
        detection(0, 10.1, 1e-5),
        detection(0, 10.3, 1e-4),
        detection(0, 13.0, 1e-6),
        detection(1, 10.6, 1e-5), // 0.6 ns off: no match
    ];
    assert_eq!(truth::match_detections(&truth, &detections), vec![Some(1), Some(2), None, None]);
}

#[test]
fn purity_precision_and_recall() {
    // Path 1 at 10 ns in all six snapshots; a track follows it for four and
    // then jumps to path 2 at 10.9 ns for two.
    let mut truth = Vec::new();
    let mut detections = Vec::new();
    for k in 0..6 {
        truth.push(truth_mpc(k, 1, 10.0, 1e-4));
        truth.push(truth_mpc(k, 2, 10.9, 1e-4));
        detections.push(detection(k, if k < 4 { 10.05 } else { 10.85 }, 1e-4));
    }
    let track = MpcTrack { track_id: 0, doppler_hz: None, detections: detections.clone() };
    let mut sets = vec![set(0)];
    sets[0].noise_floor_db = Some(-200.0);
    let scores = truth::score(&truth, &detections, &[track], &[], &sets);
    assert_eq!(scores.precision, Some(1.0));
    assert_eq!(scores.recall, Some(0.5));
    assert!((scores.track_purity.unwrap() - 4.0 / 6.0).abs() < 1e-12);
}

fn detection_in(set: u64, snapshot: u32, delay_ns: f64, amplitude: f64) -> MpcDetection {
    MpcDetection {
        set_index: set,
        t_ns: set as i64 * SET_NS + i64::from(snapshot) * 717_000,
        ..detection(snapshot, delay_ns, amplitude)
    }
}

fn truth_in(set: u64, snapshot: u32, path_id: u64, delay_ns: f64, amplitude: f64) -> MpcTruth {
    MpcTruth {
        set_index: set,
        t_ns: set as i64 * SET_NS + i64::from(snapshot) * 717_000,
        ..truth_mpc(snapshot, path_id, delay_ns, amplitude)
    }
}

fn truth_input(sets: u64, detections: Vec<MpcDetection>, tracks: Vec<MpcTrack>, truth: Vec<MpcTruth>) -> MpcInput {
    MpcInput {
        detections,
        tracks,
        long_term: Vec::new(),
        sets: (0..sets).map(set).collect(), // floor -140 dB: detectable from -134 dB
        snapshots: None,
        truth: Some(truth),
        distance: DistanceSource::None,
    }
}

#[test]
fn true_mpcs_closer_than_the_tolerance_are_one_resolvable_mpc() {
    // Per snapshot: a -100 dB path at 100 ns; two -117 dB paths 0.2 ps apart
    // at 120 ns in opposite phase (the two orders of a wall-to-wall double
    // bounce: they cancel in the CIR); two -120 dB paths in phase at 140 ns
    // (their sum, -114 dB, is what a detector sees). The detector finds the
    // first and the sum.
    let mut truth = Vec::new();
    let mut detections = Vec::new();
    for k in 0..6 {
        truth.push(truth_mpc(k, 0, 100.0, 1e-5));
        truth.push(truth_mpc(k, 201, 120.0002, -1.4e-6));
        truth.push(truth_mpc(k, 200, 120.0, 1.4e-6));
        truth.push(truth_mpc(k, 300, 140.0, 1e-6));
        truth.push(truth_mpc(k, 301, 140.0001, 1e-6));
        detections.push(detection(k, 100.01, 1e-5));
        detections.push(detection(k, 140.02, 2e-6));
    }
    let merged = truth::resolvable_truth(&truth[..5]);
    assert_eq!(merged.iter().map(|t| t.path_id).collect::<Vec<_>>(), vec![0, 200, 300]);
    // Opposite phases cancel exactly; the in-phase pair adds to 2e-6 at the
    // power-weighted mean delay (equal powers: the midpoint).
    assert_eq!(merged[1].amplitude.norm(), 0.0);
    assert!((merged[2].amplitude.re - 2e-6).abs() < 1e-18);
    assert!((merged[2].delay_s - 140.00005e-9).abs() < 1e-18);
    let s = analyze_mpc("s", truth_input(1, detections, Vec::new(), truth), &MpcOptions::default()).summary;
    // 3 resolvable MPCs in each of 6 snapshots; the cancelled pair is below
    // the floor, so both detectable MPCs are found every time.
    assert_eq!(s.truth_mpcs, Some(18));
    assert_eq!(s.precision, Some(1.0));
    assert_eq!(s.recall_above_floor, Some(1.0));
    assert!((s.recall.unwrap() - 12.0 / 18.0).abs() < 1e-12);
}

#[test]
fn purity_counts_tracks_on_true_paths_and_false_tracks_apart() {
    // Path 1 at 10 ns, followed by track 0 in all six snapshots; track 1 is
    // three noise detections at 50 ns (no true MPC there).
    let truth: Vec<MpcTruth> = (0..6).map(|k| truth_mpc(k, 1, 10.0, 1e-4)).collect();
    let on_path: Vec<MpcDetection> = (0..6).map(|k| detection(k, 10.02, 1e-4)).collect();
    let noise: Vec<MpcDetection> = (0..3).map(|k| detection(k, 50.0, 1e-7)).collect();
    let tracks = vec![
        MpcTrack { track_id: 0, doppler_hz: None, detections: on_path.clone() },
        MpcTrack { track_id: 1, doppler_hz: None, detections: noise.clone() },
    ];
    let s = analyze_mpc("s", truth_input(1, [on_path, noise].concat(), tracks, truth), &MpcOptions::default()).summary;
    assert_eq!(s.track_purity, Some(1.0), "the one track on a true path never leaves it");
    assert_eq!(s.false_track_share, Some(0.5));
    assert!((s.precision.unwrap() - 6.0 / 9.0).abs() < 1e-12, "the noise shows in precision");
}

#[test]
fn long_term_tracks_are_scored_by_the_path_they_follow() {
    // Sets 0-3, one snapshot each. Path 1 at 10 ns is one long-term track
    // (0) throughout; path 2 at 30 ns is split into long-term tracks 1 (sets
    // 0-1) and 2 (sets 2-3); long-term track 3 (set 2) follows noise at 50 ns.
    let mut truth = Vec::new();
    let mut detections = Vec::new();
    let mut tracks = Vec::new();
    let mut long_term = Vec::new();
    let mut add = |long_id: u64, set: u64, delay_ns: f64| {
        let d = detection_in(set, 0, delay_ns, 1e-5);
        let short_id = tracks.len() as u64;
        tracks.push(MpcTrack { track_id: short_id, doppler_hz: Some(0.0), detections: vec![d.clone()] });
        detections.push(d);
        long_term.push(MpcLongTermEntry {
            long_track_id: long_id,
            short_track_id: short_id,
            ..entry(long_id, set, None)
        });
    };
    for set in 0..4 {
        add(0, set, 10.01);
        add(if set < 2 { 1 } else { 2 }, set, 30.01);
    }
    add(3, 2, 50.0);
    for set in 0..4 {
        truth.push(truth_in(set, 0, 1, 10.0, 1e-5));
        truth.push(truth_in(set, 0, 2, 30.0, 1e-5));
    }
    let mut input = truth_input(4, detections, tracks, truth);
    input.long_term = long_term;
    let s = analyze_mpc("s", input, &MpcOptions::default()).summary;
    assert_eq!(
        (s.births, s.deaths),
        (Some(2), Some(2)),
        "tracks 2 and 3 are born in set 2; 1 and 3 die before the end"
    );
    assert_eq!((s.births_on_true_paths, s.deaths_on_true_paths), (Some(1), Some(1)), "the split of path 2");
    assert_eq!((s.true_births, s.true_deaths), (Some(0), Some(0)));
    assert_eq!(s.false_long_term_share, Some(0.25));
    assert_eq!(s.long_term_tracks_per_path, Some(1.5));
}
