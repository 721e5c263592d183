//! Short-term tracking (Mahler et al. 2017, Sec. III-B) on hand-made
//! detections, so that each rule of the method is exercised alone.

use mmtrack_core::{Complex64, MpcDetection};
use mmtrack_mpc::short_term::{doppler_hz, is_full_lifetime};
use mmtrack_mpc::{ShortTermConfig, short_term_tracks};

use crate::common::CARRIER_HZ;

/// The paper's snapshot period, 0.717 ms.
const SNAPSHOT_NS: i64 = 717_000;

fn det(snapshot: u32, delay_s: f64, power_db: f64) -> MpcDetection {
    MpcDetection {
        t_ns: i64::from(snapshot) * SNAPSHOT_NS,
        set_index: 0,
        snapshot_index: snapshot,
        delay_s,
        amplitude: Complex64::from_polar(10f64.powf(power_db / 20.0), 0.3 * f64::from(snapshot)),
    }
}

/// A path with a linear delay `tau0 + rate t`, `rate` in s/s.
fn linear(snapshot: u32, tau0_s: f64, rate: f64, power_db: f64) -> MpcDetection {
    let t_s = f64::from(snapshot) * SNAPSHOT_NS as f64 * 1e-9;
    det(snapshot, tau0_s + rate * t_s, power_db)
}

fn delays_ns(track: &mmtrack_core::MpcTrack) -> Vec<f64> {
    track.detections.iter().map(|d| d.delay_s * 1e9).collect()
}

#[test]
fn two_drifting_mpcs_give_two_full_lifetime_tracks_with_their_doppler() {
    // Rates of 1e-7 and -2e-7 s/s (30 and 60 m/s of path length change):
    // nu = -rate f_c = -570 Hz and +1140 Hz.
    let (rate_a, rate_b) = (1e-7, -2e-7);
    let set: Vec<Vec<MpcDetection>> = (0..6)
        .map(|n| {
            let mut snapshot = vec![linear(n, 60e-9, rate_b, -120.0), linear(n, 50e-9, rate_a, -116.0)];
            if n == 2 {
                // A lone clutter peak: one point makes no track.
                snapshot.push(det(n, 80e-9, -125.0));
            }
            snapshot
        })
        .collect();
    let tracks = short_term_tracks(&set, CARRIER_HZ, &ShortTermConfig::default(), 7);
    assert_eq!(tracks.len(), 2, "{tracks:#?}");
    // Strongest first, ids consecutive from 7.
    assert_eq!((tracks[0].track_id, tracks[1].track_id), (7, 8));
    for (track, tau0_s, rate) in [(&tracks[0], 50e-9, rate_a), (&tracks[1], 60e-9, rate_b)] {
        assert!(is_full_lifetime(track, set.len()));
        for (n, d) in track.detections.iter().enumerate() {
            assert_eq!(d.snapshot_index as usize, n);
            // Exactly the generated detection (no mixing of the two paths).
            assert_eq!(d.delay_s, linear(n as u32, tau0_s, rate, 0.0).delay_s);
        }
        let truth_hz = -rate * CARRIER_HZ;
        let nu = track.doppler_hz.expect("six points");
        // 1 %: the requirement; noiseless detections give ~1e-6 relative
        // (round-off of delays near 5e-8 s over a 3.6 ms span).
        assert!((nu - truth_hz).abs() < 0.01 * truth_hz.abs(), "{nu} vs {truth_hz}");
        assert!((nu - truth_hz).abs() < 1e-4 * truth_hz.abs(), "{nu} vs {truth_hz}");
    }
}

#[test]
fn doppler_fit_is_least_squares_over_time() {
    // Delays 0, +d, 0 at times 0, T, 2T: slope 0 by least squares (not the
    // last difference).
    let d = [det(0, 10e-9, -100.0), det(1, 10.1e-9, -100.0), det(2, 10e-9, -100.0)];
    let nu = doppler_hz(&d, CARRIER_HZ).expect("three times");
    // A zero slope up to round-off of 1e-8 s delays (~1e-24 s over 1.4 ms): < 1e-5 Hz.
    assert!(nu.abs() < 1e-5, "{nu}");
    assert_eq!(doppler_hz(&d[..1], CARRIER_HZ), None);
    assert_eq!(doppler_hz(&[], CARRIER_HZ), None);
}

#[test]
fn a_missing_detection_ends_the_track() {
    // One path over 8 snapshots, not detected in snapshot 3: the paper's
    // tracker cannot bridge the gap, so it yields two tracks, 0-2 and 4-7,
    // neither of full lifetime.
    let set: Vec<Vec<MpcDetection>> =
        (0..8).map(|n| if n == 3 { Vec::new() } else { vec![linear(n, 40e-9, 5e-8, -110.0)] }).collect();
    let tracks = short_term_tracks(&set, CARRIER_HZ, &ShortTermConfig::default(), 0);
    assert_eq!(tracks.len(), 2, "{tracks:#?}");
    let spans: Vec<Vec<u32>> = tracks.iter().map(|t| t.detections.iter().map(|d| d.snapshot_index).collect()).collect();
    assert_eq!(spans, vec![vec![0, 1, 2], vec![4, 5, 6, 7]]);
    assert!(tracks.iter().all(|t| !is_full_lifetime(t, set.len())));
}

#[test]
fn three_adjacent_detections_are_needed() {
    let config = ShortTermConfig::default();
    // Two points: no track.
    let two: Vec<Vec<MpcDetection>> = (0..2).map(|n| vec![linear(n, 30e-9, 0.0, -100.0)]).collect();
    assert!(short_term_tracks(&two, CARRIER_HZ, &config, 0).is_empty());
    // Two points, a gap, two points: still none.
    let gapped: Vec<Vec<MpcDetection>> =
        (0..5).map(|n| if n == 2 { Vec::new() } else { vec![linear(n, 30e-9, 0.0, -100.0)] }).collect();
    assert!(short_term_tracks(&gapped, CARRIER_HZ, &config, 0).is_empty());
    // Three points: one track.
    let three: Vec<Vec<MpcDetection>> = (0..3).map(|n| vec![linear(n, 30e-9, 0.0, -100.0)]).collect();
    let tracks = short_term_tracks(&three, CARRIER_HZ, &config, 0);
    assert_eq!(tracks.len(), 1);
    assert_eq!(tracks[0].detections.len(), 3);
    // A longer minimum drops the three-point track.
    let four = ShortTermConfig { min_track_length: 4, ..config };
    assert!(short_term_tracks(&three, CARRIER_HZ, &four, 0).is_empty());
}

#[test]
fn the_detection_nearest_the_predicted_delay_wins() {
    // 50.0 ns, 50.1 ns: predicted 50.2 ns and -100 dB in snapshot 2. Both
    // 50.25 ns (0.05 ns off, 8 dB off) and 50.55 ns (0.35 ns off, 0 dB off)
    // are in the search range; eq. (25) decides by delay alone.
    let set = vec![
        vec![det(0, 50.0e-9, -100.0)],
        vec![det(1, 50.1e-9, -100.0)],
        vec![det(2, 50.55e-9, -100.0), det(2, 50.25e-9, -108.0)],
    ];
    let tracks = short_term_tracks(&set, CARRIER_HZ, &ShortTermConfig::default(), 0);
    assert_eq!(tracks.len(), 1, "{tracks:#?}");
    let got = delays_ns(&tracks[0]);
    // 1e-9 ns: the values are copied, only the unit conversion rounds.
    assert!((got[2] - 50.25).abs() < 1e-9, "{got:?}");
}

#[test]
fn search_tolerances_bound_the_continuation() {
    let config = ShortTermConfig::default();
    // Predicted 50.2 ns / -100 dB. 50.75 ns is 0.55 ns off (> 0.5 ns);
    // 50.2 ns at -111 dB is 11 dB off (> 10 dB): neither continues the track.
    for third in [det(2, 50.75e-9, -100.0), det(2, 50.2e-9, -111.0)] {
        let set = vec![vec![det(0, 50.0e-9, -100.0)], vec![det(1, 50.1e-9, -100.0)], vec![third.clone()]];
        assert!(short_term_tracks(&set, CARRIER_HZ, &config, 0).is_empty(), "{third:?}");
    }
    // The prediction follows the magnitude trend: -100, -104 predicts -108,
    // so -111 dB (3 dB off) continues it.
    let set = vec![vec![det(0, 50.0e-9, -100.0)], vec![det(1, 50.1e-9, -104.0)], vec![det(2, 50.2e-9, -111.0)]];
    assert_eq!(short_term_tracks(&set, CARRIER_HZ, &config, 0).len(), 1);
}

#[test]
fn initial_candidates_are_gated_and_tried_nearest_in_delay_first() {
    let config = ShortTermConfig::default();
    // Snapshot 1 has two candidates of the start at 50 ns: 50.1 ns and
    // 50.4 ns (both within xi_tau = 0.5 ns). The nearer, 50.1 ns, predicts
    // 50.2 ns, which is there: the track is 50.0, 50.1, 50.2.
    let set = vec![
        vec![det(0, 50.0e-9, -100.0)],
        vec![det(1, 50.4e-9, -100.0), det(1, 50.1e-9, -100.0)],
        vec![det(2, 50.2e-9, -100.0), det(2, 50.8e-9, -100.0)],
    ];
    let tracks = short_term_tracks(&set, CARRIER_HZ, &config, 0);
    assert_eq!(tracks.len(), 1);
    let got = delays_ns(&tracks[0]);
    assert!((got[1] - 50.1).abs() < 1e-9 && (got[2] - 50.2).abs() < 1e-9, "{got:?}");

    // When the nearer candidate finds no third point, the next one is tried:
    // 50.4 ns predicts 50.8 ns.
    let set = vec![
        vec![det(0, 50.0e-9, -100.0)],
        vec![det(1, 50.4e-9, -100.0), det(1, 50.1e-9, -100.0)],
        vec![det(2, 50.8e-9, -100.0)],
    ];
    let tracks = short_term_tracks(&set, CARRIER_HZ, &config, 0);
    assert_eq!(tracks.len(), 1);
    let got = delays_ns(&tracks[0]);
    assert!((got[1] - 50.4).abs() < 1e-9 && (got[2] - 50.8).abs() < 1e-9, "{got:?}");

    // Outside the initial gates (0.6 ns, or 11 dB), no candidate, no track.
    for second in [det(1, 50.6e-9, -100.0), det(1, 50.0e-9, -111.0)] {
        let set = vec![vec![det(0, 50.0e-9, -100.0)], vec![second.clone()], vec![det(2, 50.0e-9, -100.0)]];
        assert!(short_term_tracks(&set, CARRIER_HZ, &config, 0).is_empty(), "{second:?}");
    }
}

#[test]
fn tracks_start_in_later_snapshots_and_use_each_detection_once() {
    // Path A over snapshots 0-4; path B appears in snapshot 2 and lasts to 5.
    let set: Vec<Vec<MpcDetection>> = (0..6)
        .map(|n| {
            let mut snapshot = Vec::new();
            if n >= 2 {
                snapshot.push(linear(n, 70e-9, 0.0, -105.0));
            }
            if n <= 4 {
                snapshot.push(linear(n, 20e-9, 0.0, -100.0));
            }
            snapshot
        })
        .collect();
    let tracks = short_term_tracks(&set, CARRIER_HZ, &ShortTermConfig::default(), 100);
    assert_eq!(tracks.len(), 2);
    let starts: Vec<(u64, u32, usize)> =
        tracks.iter().map(|t| (t.track_id, t.detections[0].snapshot_index, t.detections.len())).collect();
    assert_eq!(starts, vec![(100, 0, 5), (101, 2, 4)]);
    let used: usize = tracks.iter().map(|t| t.detections.len()).sum();
    assert_eq!(used, set.iter().map(Vec::len).sum::<usize>());
}

#[test]
fn odd_input_gives_no_tracks_and_no_panic() {
    let config = ShortTermConfig::default();
    assert!(short_term_tracks(&[], CARRIER_HZ, &config, 0).is_empty());
    // Zero amplitude (-inf dB) and NaN delays never pass a gate.
    let mut zero = det(0, 10e-9, -100.0);
    zero.amplitude = Complex64::new(0.0, 0.0);
    let set = vec![
        vec![zero.clone(), det(0, f64::NAN, -100.0)],
        vec![zero.clone(), det(1, f64::NAN, -100.0)],
        vec![zero, det(2, f64::NAN, -100.0)],
    ];
    assert!(short_term_tracks(&set, CARRIER_HZ, &config, 0).is_empty());
}
