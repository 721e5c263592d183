//! GM-PHD baseline on a synthetic two-MPC delay sequence with the paper's set
//! structure (6 snapshots 0.717 ms apart, a set every 10 ms).

use mmtrack_core::{Complex64, MpcDetection};
use mmtrack_mpc::gmphd::{GmPhdConfig, GmPhdError, GmPhdSnapshot, track_gmphd};

const F_C_HZ: f64 = 5.7e9;
const SETS: u64 = 12;
/// Delay noise of the detections, s: 0.01 ns, Table I's 3 mm over c.
const SIGMA_TAU_S: f64 = 1e-11;

/// True delay of MPC `k` at time `t_s`: 50 ns with +500 Hz Doppler, 60 ns with
/// -300 Hz (`tau = tau0 - nu t / f_c`).
fn truth_delay_s(k: usize, t_s: f64) -> f64 {
    let (tau0, nu) = [(50e-9, 500.0), (60e-9, -300.0)][k];
    tau0 - nu * t_s / F_C_HZ
}

/// Deterministic standard normals (LCG + Box-Muller).
struct Normal(u64);

impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn sample(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        mmtrack_core::random::box_muller(u1, u2).0
    }
}

fn det(t_ns: i64, set_index: u64, snapshot_index: u32, delay_s: f64, amp: f64) -> MpcDetection {
    MpcDetection { t_ns, set_index, snapshot_index, delay_s, amplitude: Complex64::new(amp, 0.0) }
}

/// 72 snapshots; snapshot 20 is empty, MPC 2 is missed at snapshot 40, and a
/// weak clutter detection appears every third snapshot at a delay that jumps
/// by 37 ns (never twice in a row near the same place).
fn scenario() -> Vec<GmPhdSnapshot> {
    let mut noise = Normal(11);
    let mut out = Vec::new();
    for set in 0..SETS {
        for snap in 0..6_u32 {
            let n = out.len();
            let t_ns = (set * 10_000_000 + u64::from(snap) * 717_000) as i64;
            let t_s = t_ns as f64 * 1e-9;
            let mut detections = Vec::new();
            if n != 20 {
                for (k, amp) in [1e-6, 0.7e-6].into_iter().enumerate() {
                    if !(k == 1 && n == 40) {
                        let tau = truth_delay_s(k, t_s) + SIGMA_TAU_S * noise.sample();
                        detections.push(det(t_ns, set, snap, tau, amp * (1.0 + 0.05 * noise.sample())));
                    }
                }
                if n % 3 == 0 {
                    let tau = 100e-9 + 1e-9 * ((n * 37) % 200) as f64;
                    detections.push(det(t_ns, set, snap, tau, 0.1e-6));
                }
            }
            out.push(GmPhdSnapshot { t_ns, set_index: set, snapshot_index: snap, detections });
        }
    }
    out
}

#[test]
fn two_mpcs_give_two_tracks_with_small_delay_error() {
    let tracks = track_gmphd(&scenario(), &GmPhdConfig::default()).expect("valid input");
    assert_eq!(tracks.len(), 2, "{:#?}", tracks.iter().map(|t| (t.track_id, t.detections.len())).collect::<Vec<_>>());
    assert!(tracks[0].track_id < tracks[1].track_id, "ordered by track_id");
    for track in &tracks {
        // Which MPC: the nearer truth at the first detection.
        let first = &track.detections[0];
        let k = usize::from(
            (first.delay_s - truth_delay_s(1, first.t_ns as f64 * 1e-9)).abs()
                < (first.delay_s - truth_delay_s(0, first.t_ns as f64 * 1e-9)).abs(),
        );
        // Present from the second snapshot (birth at the first) to the end,
        // minus the empty snapshot and (for MPC 2) its miss: 71 - 1 - k.
        assert_eq!(track.detections.len(), 70 - k, "MPC {k}");
        assert!(track.detections.windows(2).all(|w| w[0].t_ns < w[1].t_ns));
        let errors: Vec<f64> =
            track.detections.iter().map(|d| (d.delay_s - truth_delay_s(k, d.t_ns as f64 * 1e-9)).abs()).collect();
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        let max = errors.iter().copied().fold(0.0, f64::max);
        // The filter averages detections with 0.01 ns noise: its mean error
        // must be below that noise level, and no single step beyond 4 sigma.
        assert!(mean < SIGMA_TAU_S, "MPC {k}: mean delay error {mean:e} s");
        assert!(max < 4.0 * SIGMA_TAU_S, "MPC {k}: max delay error {max:e} s");
        // Doppler from the fitted slope over ~110 ms: the delay noise maps to
        // well under 1 Hz; 5 Hz leaves room for the filter's lag after births.
        let nu = track.doppler_hz.expect("many points");
        let want = [500.0, -300.0][k];
        assert!((nu - want).abs() < 5.0, "MPC {k}: Doppler {nu} Hz, want {want}");
        // Amplitudes come from this MPC's detections (nominal 1e-6 / 0.7e-6, +-5 %),
        // never from the 0.1e-6 clutter.
        let nominal = [1e-6, 0.7e-6][k];
        assert!(track.detections.iter().all(|d| (d.amplitude.re / nominal - 1.0).abs() < 0.25));
    }
}

#[test]
fn empty_input_and_empty_snapshots_give_no_tracks() {
    assert!(track_gmphd(&[], &GmPhdConfig::default()).expect("valid").is_empty());
    let empty: Vec<GmPhdSnapshot> = (0..10)
        .map(|i| GmPhdSnapshot { t_ns: i * 717_000, set_index: 0, snapshot_index: i as u32, detections: Vec::new() })
        .collect();
    assert!(track_gmphd(&empty, &GmPhdConfig::default()).expect("valid").is_empty());
}

#[test]
fn nan_delay_is_rejected_naming_the_snapshot() {
    let mut snaps = scenario();
    snaps[3].detections[1].delay_s = f64::NAN;
    let e = track_gmphd(&snaps, &GmPhdConfig::default()).unwrap_err();
    assert!(matches!(e, GmPhdError::BadDetection { snapshot: 3, detection: 1, field: "delay_s", .. }), "{e}");
    assert!(e.to_string().contains("snapshot 3"), "{e}");

    let mut snaps = scenario();
    snaps[5].detections[0].amplitude = Complex64::new(f64::INFINITY, 0.0);
    let e = track_gmphd(&snaps, &GmPhdConfig::default()).unwrap_err();
    assert!(matches!(e, GmPhdError::BadDetection { snapshot: 5, field: "amplitude", .. }), "{e}");
}

#[test]
fn time_order_and_detection_times_are_checked() {
    let mut snaps = scenario();
    let t6 = snaps[6].t_ns;
    snaps[7].t_ns = t6;
    for d in &mut snaps[7].detections {
        d.t_ns = t6;
    }
    let e = track_gmphd(&snaps, &GmPhdConfig::default()).unwrap_err();
    assert!(matches!(e, GmPhdError::TimeNotIncreasing { snapshot: 7, .. }), "{e}");

    let mut snaps = scenario();
    snaps[2].detections[0].t_ns += 1;
    let e = track_gmphd(&snaps, &GmPhdConfig::default()).unwrap_err();
    assert!(matches!(e, GmPhdError::DetectionTime { snapshot: 2, detection: 0, .. }), "{e}");
}

#[test]
fn config_defaults_are_table_one_and_bad_fields_are_named() {
    let c = GmPhdConfig::default();
    assert_eq!((c.sigma_process_mps2, c.sigma_measurement_m, c.p_survival, c.p_detection), (0.3, 3e-3, 0.99, 0.95));
    assert_eq!((c.truncation_threshold, c.merge_threshold, c.extraction_threshold), (1e-2, 0.1, 0.2));
    c.validate().expect("defaults are valid");
    for (mutate, field) in [
        (Box::new(|c: &mut GmPhdConfig| c.p_detection = 1.5) as Box<dyn Fn(&mut GmPhdConfig)>, "p_detection"),
        (Box::new(|c: &mut GmPhdConfig| c.sigma_measurement_m = 0.0), "sigma_measurement_m"),
        (Box::new(|c: &mut GmPhdConfig| c.clutter_intensity_per_m = f64::NAN), "clutter_intensity_per_m"),
        (Box::new(|c: &mut GmPhdConfig| c.max_components = 0), "max_components"),
        (Box::new(|c: &mut GmPhdConfig| c.carrier_hz = -1.0), "carrier_hz"),
    ] {
        let mut bad = GmPhdConfig::default();
        mutate(&mut bad);
        let e = bad.validate().unwrap_err();
        assert!(matches!(e, GmPhdError::BadConfig { field: f, .. } if f == field), "{e}");
        assert!(matches!(track_gmphd(&scenario(), &bad), Err(GmPhdError::BadConfig { .. })));
    }
}

/// The magnitude gate: a 20 dB drop of MPC 1 half-way (beyond the 10 dB
/// `max_magnitude_change_db`) cannot update the old track, so the old track
/// ends and a new one starts; with the gate widened to 30 dB it is one track.
#[test]
fn magnitude_jump_beyond_the_gate_splits_the_track() {
    let mut snaps = scenario();
    for snap in snaps.iter_mut().skip(36) {
        for d in &mut snap.detections {
            if (d.delay_s - truth_delay_s(0, d.t_ns as f64 * 1e-9)).abs() < 1e-10 {
                d.amplitude *= 0.1;
            }
        }
    }
    let near_mpc0 = |tracks: &[mmtrack_core::MpcTrack]| {
        tracks
            .iter()
            .filter(|t| (t.detections[0].delay_s - truth_delay_s(0, t.detections[0].t_ns as f64 * 1e-9)).abs() < 1e-10)
            .count()
    };
    let gated = track_gmphd(&snaps, &GmPhdConfig::default()).expect("valid input");
    assert_eq!(near_mpc0(&gated), 2, "split at the jump");
    let wide = GmPhdConfig { max_magnitude_change_db: 30.0, ..GmPhdConfig::default() };
    let joined = track_gmphd(&snaps, &wide).expect("valid input");
    assert_eq!(near_mpc0(&joined), 1, "one track with a wide gate");
}
