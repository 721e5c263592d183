//! Behaviour of the channel-sounder simulator: the shared signal model,
//! geometry (LOS delay, Doppler sign and value), noise floor, set timing,
//! birth and death of traffic paths, determinism and scenario checks.

use mmtrack_core::sounder::{SounderBand, cir_from_spectrum};
use mmtrack_core::{Complex64, MpcTruth};
use mmtrack_sim::SimError;
use mmtrack_sim::sounder::{
    ArtificialChannelConfig, ConvoyConfig, ConvoySimulator, DiffuseConfig, PathKind, PulseModel, RoadKind,
    SPEED_OF_LIGHT_MPS, SounderConfig, SounderScenario, SounderSet, TrafficCar, TrafficConfig, artificial_channel,
};

fn no_traffic() -> TrafficConfig {
    TrafficConfig { oncoming_per_km: 0.0, same_direction_per_km: 0.0, ..TrafficConfig::default() }
}

/// A short tunnel run with everything on (random traffic, diffuse, double bounces).
fn tunnel(sets: usize) -> ConvoyConfig {
    ConvoyConfig { sets, ..ConvoyConfig::default() }
}

/// The run on the global rayon pool.
fn run(config: &ConvoyConfig, seed: u64) -> Vec<SounderSet> {
    ConvoySimulator::new(config, seed).unwrap().collect()
}

/// The run on a rayon pool of `threads` threads.
fn run_on(config: &ConvoyConfig, seed: u64, threads: usize) -> Vec<SounderSet> {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| run(config, seed))
}

fn truth_of(set: &SounderSet, snapshot: u32, id: u64) -> Option<&MpcTruth> {
    set.truth.iter().find(|t| t.snapshot_index == snapshot && t.path_id == id)
}

#[test]
fn los_delay_is_the_distance_between_the_cars_over_c() {
    let sets = run(&tunnel(20), 3);
    for set in &sets {
        let (tx, rx) = (set.tx_pose.parent_from_child, set.rx_pose.parent_from_child);
        let distance_m = (tx.x_m - rx.x_m).hypot(tx.y_m - rx.y_m);
        assert!((75.0..111.0).contains(&distance_m), "convoy distance {distance_m} m");
        let los = truth_of(set, 0, 0).expect("LOS in every set of the default tunnel");
        // 1e-15 s: the truth is computed as L / c from the same positions (rounding ~1e-22 s).
        assert!((los.delay_s - distance_m / SPEED_OF_LIGHT_MPS).abs() < 1e-15, "set {}", set.set_index);
        assert_eq!(los.t_ns, set.rx_pose.t_ns);
    }
}

#[test]
fn tunnel_has_los_wall_bounces_in_delay_order_and_stable_ids() {
    let sets = run(&tunnel(10), 3);
    for set in &sets {
        for snapshot in 0..6 {
            let los = truth_of(set, snapshot, 0).unwrap();
            let left = truth_of(set, snapshot, 100).expect("left wall bounce");
            let right = truth_of(set, snapshot, 101).expect("right wall bounce");
            assert!(los.delay_s < left.delay_s && los.delay_s < right.delay_s);
            for double in [200, 201] {
                let d = truth_of(set, snapshot, double).expect("double bounce");
                assert!(d.delay_s > left.delay_s.min(right.delay_s));
            }
            // Power: LOS strongest (free space only), wall bounces lose 8 dB each plus length.
            assert!(los.power_db() > left.power_db() + 7.9 && los.power_db() > right.power_db() + 7.9);
            // Every listed path id has a known kind and appears once per snapshot.
            let ids: Vec<u64> = set.truth.iter().filter(|t| t.snapshot_index == snapshot).map(|t| t.path_id).collect();
            assert!(ids.windows(2).all(|w| w[0] < w[1]), "{ids:?}");
            assert!(ids.iter().all(|id| PathKind::of(*id).is_some()));
        }
    }
}

/// Doppler of every truth path against the slope of its own delays over the
/// set: `nu = -f_c d tau / dt`.
#[test]
fn doppler_matches_the_delay_slope_for_every_path() {
    let config = tunnel(30);
    let fc = config.sounder.carrier_hz;
    let mut checked = 0;
    for set in run(&config, 11) {
        for first in set.truth.iter().filter(|t| t.snapshot_index == 0) {
            let Some(last) = truth_of(&set, 5, first.path_id) else { continue };
            let dt_s = (last.t_ns - first.t_ns) as f64 * 1e-9;
            let slope_hz = -fc * (last.delay_s - first.delay_s) / dt_s;
            let mean_hz = 0.5 * (first.doppler_hz + last.doppler_hz);
            // The Doppler changes little over 3.6 ms (speed swings of seconds):
            // 0.5 Hz of up to ~100 Hz covers the curvature of tau(t).
            assert!(
                (slope_hz - mean_hz).abs() < 0.5,
                "path {}: slope {slope_hz} Hz, truth {mean_hz} Hz",
                first.path_id
            );
            checked += 1;
        }
    }
    assert!(checked >= 150, "only {checked} paths checked");
}

fn straight_convoy(rx_kmh: f64, tx_kmh: f64) -> ConvoyConfig {
    ConvoyConfig {
        sets: 3,
        road: mmtrack_sim::sounder::RoadConfig { kind: RoadKind::Highway, radius_m: 0.0, ..Default::default() },
        vehicles: mmtrack_sim::sounder::ConvoyVehicles {
            rx_speed_kmh: [rx_kmh, rx_kmh],
            tx_speed_kmh: [tx_kmh, tx_kmh],
            ..Default::default()
        },
        traffic: no_traffic(),
        diffuse: DiffuseConfig { scatterers_per_m: 0.0, ..Default::default() },
        ..ConvoyConfig::default()
    }
}

#[test]
fn approaching_cars_give_positive_doppler_and_falling_delay() {
    for (rx_kmh, tx_kmh, approaching) in [(60.0, 40.0, true), (40.0, 60.0, false)] {
        let config = straight_convoy(rx_kmh, tx_kmh);
        let sets = run(&config, 1);
        let los: Vec<&MpcTruth> = sets.iter().flat_map(|s| s.truth.iter().filter(|t| t.path_id == 0)).collect();
        assert_eq!(los.len(), 18);
        // Closing speed 20 km/h: |nu| = f_c * 5.556 / c = 105.6 Hz.
        let expected_hz = 5.7e9 * (20.0 / 3.6) / SPEED_OF_LIGHT_MPS;
        for pair in los.windows(2) {
            assert_eq!(pair[1].delay_s < pair[0].delay_s, approaching);
        }
        for t in &los {
            let signed = if approaching { expected_hz } else { -expected_hz };
            // 1e-9 Hz: a straight road and constant speeds make this exact up to rounding.
            assert!((t.doppler_hz - signed).abs() < 1e-9, "{} vs {signed}", t.doppler_hz);
        }
        // The phase turns at the Doppler: arg(a1 / a0) = 2 pi nu dt.
        let rotation = (los[1].amplitude / los[0].amplitude).arg();
        let dt_s = (los[1].t_ns - los[0].t_ns) as f64 * 1e-9;
        let expected = std::f64::consts::TAU * los[0].doppler_hz * dt_s;
        assert!((rotation - expected).abs() < 1e-6, "{rotation} vs {expected}");
    }
}

#[test]
fn noise_floor_power_matches_the_setting() {
    // Artificial channel: taps 150..256 are far from the MPCs at 90..110 ns.
    let config = ArtificialChannelConfig { snapshots: 400, ..ArtificialChannelConfig::default() };
    let (snapshots, _) = artificial_channel(&config, 5).unwrap();
    let power: Vec<f64> = snapshots.iter().flat_map(|s| s.taps[150..].iter().map(|t| t.norm_sqr())).collect();
    let mean_db = 10.0 * (power.iter().sum::<f64>() / power.len() as f64).log10();
    // 42 400 exponential samples: the mean's standard error is 0.5 %, 0.02 dB.
    assert!((mean_db + 140.0).abs() < 0.5, "{mean_db} dB");
    // The convoy's noise tail (last 64 taps), measured-like pulse.
    let mut convoy = tunnel(20);
    convoy.sounder.pulse = PulseModel::measured_like();
    convoy.sounder.noise_floor_db = -130.0;
    let sets = run(&convoy, 2);
    let tail: Vec<f64> =
        sets.iter().flat_map(|s| s.snapshots.iter()).flat_map(|c| c.taps[448..].iter().map(|t| t.norm_sqr())).collect();
    let mean_db = 10.0 * (tail.iter().sum::<f64>() / tail.len() as f64).log10();
    // 7680 samples: 0.05 dB standard error; the pulse sidelobes that reach the tail are far below -130 dB.
    assert!((mean_db + 130.0).abs() < 0.5, "{mean_db} dB");
}

#[test]
fn an_on_grid_mpc_without_noise_is_recovered_exactly() {
    let config = ArtificialChannelConfig {
        sounder: SounderConfig { noise_floor_db: f64::NEG_INFINITY, ..SounderConfig::default() },
        snapshots: 11,
        start_separation_s: 20e-9,
        end_separation_s: 0.0,
        centre_delay_s: 100e-9,
        ..ArtificialChannelConfig::default()
    };
    let (snapshots, truth) = artificial_channel(&config, 9).unwrap();
    assert_eq!((snapshots.len(), truth.len()), (11, 22));
    let magnitude = 10f64.powf(-116.0 / 20.0);
    for (i, cir) in snapshots.iter().enumerate().take(10) {
        let (early, late) = (&truth[2 * i], &truth[2 * i + 1]);
        // Separation 20 - 2i ns: taps 90 + i and 110 - i.
        assert_eq!((early.delay_s * 1e9).round() as usize, 90 + i);
        for (k, tap) in cir.taps.iter().enumerate() {
            let expected = if k == 90 + i {
                early.amplitude
            } else if k == 110 - i {
                late.amplitude
            } else {
                Complex64::default()
            };
            // 1e-12 of the amplitude: a 256-point FFT rounds at ~1e-15 relative.
            assert!((tap - expected).norm() < 1e-12 * magnitude, "snapshot {i} tap {k}: {tap} vs {expected}");
        }
        assert!((early.power_db() + 116.0).abs() < 1e-9);
    }
    // The two MPCs approach: the earlier one's delay grows by 1 ns per 0.717 ms
    // (negative Doppler), the later one's falls (positive).
    let rate = 1e-9 / 0.717e-3;
    assert!((truth[0].doppler_hz + 5.7e9 * rate).abs() < 1e-6 && (truth[1].doppler_hz - 5.7e9 * rate).abs() < 1e-6);
}

#[test]
fn a_flat_pulse_model_leaves_a_residual_on_a_measured_like_pulse() {
    let band = SounderBand::new(256, 1e-9).unwrap();
    let measured = PulseModel::measured_like().spectrum(&band);
    // Normalised: (1/U) sum P = 1.
    let mean: Complex64 = measured.iter().sum::<Complex64>() / 256.0;
    assert!((mean - Complex64::new(1.0, 0.0)).norm() < 1e-14);
    let alpha = Complex64::new(1e-6, 0.5e-6);
    let mut spectrum = vec![Complex64::default(); 256];
    band.add_path(&mut spectrum, &measured, 40e-9, alpha);
    let cir = cir_from_spectrum(&spectrum);
    // The peak tap is alpha (normalisation), but the pulse spreads over neighbours.
    assert!((cir[40] - alpha).norm() < 1e-12 * alpha.norm());
    let subtract = |pulse: &[Complex64]| {
        let mut model = vec![Complex64::default(); 256];
        band.add_path(&mut model, pulse, 40e-9, alpha);
        let residual: f64 = cir.iter().zip(cir_from_spectrum(&model)).map(|(h, m)| (h - m).norm_sqr()).sum();
        10.0 * (residual / alpha.norm_sqr()).log10()
    };
    let exact_db = subtract(&measured);
    let flat_db = subtract(&PulseModel::Flat.spectrum(&band));
    assert!(exact_db < -250.0, "the exact pulse removes the path: {exact_db} dB");
    // The band-edge roll-off (10 % per edge) leaves well above the -24 dB an MPC at 24 dB SNR would hide in.
    assert!(flat_db > -20.0, "a flat model leaves {flat_db} dB of the path");
}

#[test]
fn sets_have_the_papers_timing() {
    let config = ConvoyConfig { start_t_ns: 1_000, ..tunnel(4) };
    let sets = run(&config, 1);
    for (m, set) in sets.iter().enumerate() {
        assert_eq!(set.set_index, m as u64);
        assert_eq!(set.snapshots.len(), 6);
        for (n, cir) in set.snapshots.iter().enumerate() {
            assert_eq!((cir.set_index, cir.snapshot_index), (m as u64, n as u32));
            assert_eq!(cir.t_ns, 1_000 + m as i64 * 10_000_000 + n as i64 * 717_000);
            assert_eq!((cir.carrier_hz, cir.tap_spacing_s, cir.delay_offset_s), (5.7e9, 1e-9, 200e-9));
            assert_eq!(cir.taps.len(), 512);
            cir.validate().unwrap();
        }
        assert_eq!((set.rx_pose.t_ns, set.tx_pose.t_ns), (set.snapshots[0].t_ns, set.snapshots[0].t_ns));
    }
}

#[test]
fn an_oncoming_car_is_born_and_dies_with_the_delay_window() {
    let mut config = straight_convoy(45.0, 45.0);
    config.sets = 120;
    config.snapshots_per_set = 1;
    config.set_interval_s = 0.1;
    config.traffic.cars = vec![TrafficCar { start_s_m: 200.0, lane_m: 3.5, speed_kmh: -50.0 }];
    // List the car however weak, so only the delay window decides.
    config.truth_min_power_db = -300.0;
    let sets = run(&config, 4);
    let present: Vec<bool> = sets.iter().map(|s| truth_of(s, 0, PathKind::TRAFFIC_BASE).is_some()).collect();
    let born = present.iter().position(|p| *p).expect("the car appears");
    let died = present.iter().rposition(|p| *p).unwrap() + 1;
    assert!(born > 0 && died < present.len(), "born {born}, died {died}");
    assert!(present[born..died].iter().all(|p| *p), "one contiguous life");
    // It enters at the far end of the window (194 m of path) and leaves there too.
    let window_end_m = (200e-9 + 448e-9) * SPEED_OF_LIGHT_MPS;
    for index in [born, died - 1] {
        let t = truth_of(&sets[index], 0, PathKind::TRAFFIC_BASE).unwrap();
        // One set is 0.1 s; the path length changes at about 53 m/s.
        assert!((t.delay_s * SPEED_OF_LIGHT_MPS - window_end_m).abs() < 6.0, "set {index}");
    }
    // Approaching while it comes (positive Doppler), receding after it passed the receiver.
    assert!(truth_of(&sets[born], 0, 1000).unwrap().doppler_hz > 0.0);
    assert!(truth_of(&sets[died - 1], 0, 1000).unwrap().doppler_hz < 0.0);
    // Expected times: 2 s_c - s_tx - s_rx falls from 320 m at 2 * 13.9 + 2 * 12.5 = 52.8 m/s:
    // it enters the 194 m window near 2.4 s and leaves near 9.7 s.
    assert!((born as f64 * 0.1 - 2.4).abs() < 0.3 && (died as f64 * 0.1 - 9.7).abs() < 0.3, "{born} {died}");
}

#[test]
fn a_wall_hides_a_car_behind_the_bend() {
    // A sharp left bend (R = 120 m): an oncoming car on the inner lane comes
    // round the bend. In the tunnel the inner wall hides it until later than
    // on an open road of the same shape, where only the delay window decides.
    let mut config = straight_convoy(40.0, 40.0);
    config.road.radius_m = 120.0;
    config.vehicles.start_distance_m = 40.0;
    // 40 m of LOS is 133 ns: start the window at 100 ns (31..164 m of path).
    config.delay_offset_s = 100e-9;
    config.sets = 80;
    config.snapshots_per_set = 1;
    config.set_interval_s = 0.1;
    config.truth_min_power_db = -300.0;
    config.traffic.cars = vec![TrafficCar { start_s_m: 110.0, lane_m: 5.25, speed_kmh: -40.0 }];
    let born = |kind: RoadKind| {
        let mut c = config.clone();
        c.road.kind = kind;
        c.road.double_bounces = false;
        let sets = run(&c, 4);
        // The LOS between the cars (40 m apart on the bend) stays clear.
        assert!(sets.iter().all(|s| truth_of(s, 0, 0).is_some()));
        sets.iter().position(|s| truth_of(s, 0, PathKind::TRAFFIC_BASE).is_some()).expect("the car appears")
    };
    let (open, tunnel) = (born(RoadKind::Highway), born(RoadKind::Tunnel));
    assert!(tunnel > open + 2, "tunnel birth at set {tunnel}, open road at {open}");
}

#[test]
fn same_seed_same_bytes_for_any_thread_count() {
    let config = tunnel(5);
    let one = run_on(&config, 21, 1);
    let three = run_on(&config, 21, 3);
    assert_eq!(one, three);
    let other = run_on(&config, 22, 1);
    assert_ne!(one[0].snapshots[0].taps, other[0].snapshots[0].taps);
    let simulator = ConvoySimulator::new(&config, 21).unwrap();
    assert_eq!(simulator.render_set(3).unwrap(), one[3]);
    assert!(simulator.render_set(5).is_none());
    let config = ArtificialChannelConfig::default();
    assert_eq!(artificial_channel(&config, 1).unwrap(), artificial_channel(&config, 1).unwrap());
}

fn expect_invalid(result: Result<(), SimError>, field: &str) {
    match result {
        Err(SimError::InvalidParameter { field: f, .. }) => assert_eq!(f, field),
        other => panic!("expected an error naming {field}, got {other:?}"),
    }
}

#[test]
fn bad_values_are_named() {
    let mut c = tunnel(1);
    c.sounder.bandwidth_hz = -1e9;
    expect_invalid(c.validate(), "convoy.sounder.bandwidth_hz");
    let mut c = tunnel(1);
    c.snapshots_per_set = 0;
    expect_invalid(c.validate(), "convoy.snapshots_per_set");
    let mut c = tunnel(1);
    c.set_interval_s = 3e-3;
    expect_invalid(c.validate(), "convoy.set_interval_s");
    let mut c = tunnel(1);
    c.vehicles.rx_speed_kmh = [50.0, 40.0];
    expect_invalid(c.validate(), "convoy.vehicles.rx_speed_kmh");
    let mut c = tunnel(1);
    c.sounder.pulse = PulseModel::MeasuredLike {
        rolloff_fraction: 0.7,
        ripple_db: 0.5,
        ripple_cycles: 3.0,
        phase_ripple_deg: 2.0,
        phase_ripple_cycles: 2.0,
    };
    expect_invalid(c.validate(), "convoy.sounder.pulse.rolloff_fraction");
    let a = ArtificialChannelConfig { snapshots: 1, ..ArtificialChannelConfig::default() };
    expect_invalid(a.validate(), "artificial.snapshots");
    let a = ArtificialChannelConfig { centre_delay_s: 5e-9, ..ArtificialChannelConfig::default() };
    expect_invalid(a.validate(), "artificial.centre_delay_s");
    assert!(ConvoySimulator::new(&ConvoyConfig { sets: 0, ..tunnel(1) }, 1).is_err());
    // Through TOML: unknown fields are named by serde, values by validate.
    let parse = |text: &str| toml::from_str::<SounderScenario>(text);
    let err = parse("seed = 1\n[convoy.sounder]\nbandwdth_hz = 1e9\n").unwrap_err().to_string();
    assert!(err.contains("unknown field `bandwdth_hz`"), "{err}");
    let scenario = parse("seed = 1\n[convoy.sounder]\nbandwidth_hz = -1e9\n").unwrap();
    expect_invalid(scenario.validate(), "convoy.sounder.bandwidth_hz");
    let scenario = parse("seed = 1\n[convoy]\nsnapshots_per_set = 0\n").unwrap();
    expect_invalid(scenario.validate(), "convoy.snapshots_per_set");
    let scenario = parse("seed = 1\n[artificial]\n[convoy]\n").unwrap();
    assert!(scenario.validate().is_err());
    let scenario = parse("seed = 1\n[artificial.sounder]\nnoise_floor_db = -inf\n").unwrap();
    scenario.validate().unwrap();
}

#[test]
fn the_committed_scenarios_parse_and_validate() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/sounder");
    for name in ["convoy-tunnel.toml", "artificial.toml"] {
        let text = std::fs::read_to_string(dir.join(name)).unwrap();
        let scenario: SounderScenario = toml::from_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        scenario.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

/// Wall reflections hop from one polyline segment to the next as the cars
/// drive; the delay must stay continuous across those hand-overs. Between
/// consecutive sets (10 ms) the delay change equals the trapezoid of the
/// Dopplers at both ends.
#[test]
fn wall_bounce_delays_are_continuous_across_segment_hand_overs() {
    let mut config = tunnel(300);
    config.diffuse.scatterers_per_m = 0.0;
    config.traffic = no_traffic();
    config.sounder.noise_floor_db = f64::NEG_INFINITY;
    let fc = config.sounder.carrier_hz;
    let sets = run(&config, 8);
    let mut worst = [0.0f64; 2];
    for pair in sets.windows(2) {
        for id in [0, 100, 101, 200, 201] {
            let (a, b) = (truth_of(&pair[0], 0, id).unwrap(), truth_of(&pair[1], 0, id).unwrap());
            let dt_s = (b.t_ns - a.t_ns) as f64 * 1e-9;
            let predicted = -0.5 * (a.doppler_hz + b.doppler_hz) / fc * dt_s;
            let slot = usize::from(id >= 200);
            worst[slot] = worst[slot].max((b.delay_s - a.delay_s - predicted).abs());
        }
    }
    // 2e-13 s (0.06 mm of path): the trapezoid's error over 10 ms with speed swings
    // of 0.6 m/s^2 is ~1e-14 s; a jump at a segment hand-over would be far larger.
    assert!(worst[0] < 2e-13, "LOS and single bounces: worst delay mismatch {:e} s", worst[0]);
    // Double bounces: when a reflection point sits on a polyline vertex, the
    // alternating minimisation stops within a fraction of a millimetre of the
    // stationary path (measured up to 1.1e-12 s, 0.3 mm; a tap is 300 mm).
    assert!(worst[1] < 3e-12, "double bounces: worst delay mismatch {:e} s", worst[1]);
}
