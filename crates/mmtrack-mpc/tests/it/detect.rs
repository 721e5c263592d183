//! Detection per snapshot against known channels.

use mmtrack_core::Complex64;
use mmtrack_mpc::{DetectionConfig, Detector, MpcError, NoiseFloor, SounderPulse};

use crate::common::{Path, TAP_S, band, rng, snapshot};

fn noiseless_config(kaiser_beta: Option<f64>) -> DetectionConfig {
    DetectionConfig { noise_floor: NoiseFloor::Fixed { power_db: -200.0 }, kaiser_beta, ..DetectionConfig::default() }
}

#[test]
fn noiseless_off_grid_paths_are_recovered() {
    let band = band(256);
    let pulse = SounderPulse::flat(&band);
    let paths = [
        Path { delay_s: 40.37e-9, power_db: -100.0, phase_rad: 0.3 },
        Path { delay_s: 71.81e-9, power_db: -106.0, phase_rad: -2.0 },
        Path { delay_s: 120.5e-9, power_db: -112.0, phase_rad: 1.1 },
    ];
    for kaiser_beta in [Some(6.0), None] {
        let detector = Detector::new(noiseless_config(kaiser_beta), TAP_S, &pulse).unwrap();
        // One path at fractional delays across a tap: the refinement's
        // truncated interpolation is calibrated on the kernel (detect.rs), so
        // what is left is its node spacing and the subtraction table, far
        // below the noise-limited 0.03 taps of the paper's operating point
        // (measured: 1.2e-7 taps with the Kaiser window, 2.6e-5 without).
        let (mut worst_delay_taps, mut worst_amplitude) = (0.0_f64, 0.0_f64);
        for step in 0..40 {
            let path = Path { delay_s: (40.0 + 0.0251 * f64::from(step)) * TAP_S, ..paths[0] };
            let single = detector.detect(&snapshot(&band, &pulse, &[path], None, &mut rng(1), 0), 0).unwrap();
            let found = &single.detections[0];
            worst_delay_taps = worst_delay_taps.max((found.delay_s - path.delay_s).abs() / TAP_S);
            worst_amplitude =
                worst_amplitude.max((found.amplitude - path.amplitude()).norm() / path.amplitude().norm());
        }
        println!(
            "{kaiser_beta:?}: lone noiseless path, worst delay error {worst_delay_taps:.1e} taps, amplitude {worst_amplitude:.1e}"
        );
        // Bounds a decade above the measured values, per window.
        let lone_bound = if kaiser_beta.is_some() { 1e-6 } else { 1e-4 };
        assert!(worst_delay_taps < lone_bound && worst_amplitude < lone_bound, "{kaiser_beta:?}");
        // Three paths: search and subtract estimates one path at a time, so the
        // others, not yet subtracted, bias each estimate a little: with the
        // Kaiser window, 5e-4 taps for the first path, whose 6 dB weaker
        // neighbour 31 taps away sits at the edge of the refinement's
        // interpolation window (+-32 taps; exact interpolation over all taps
        // gave 1e-4); without the window the flat band's sidelobes decay
        // only as 1/n (1.6e-3 taps measured).
        let bound_taps = if kaiser_beta.is_some() { 1e-3 } else { 1e-2 };
        let all = detector.detect(&snapshot(&band, &pulse, &paths, None, &mut rng(1), 0), 0).unwrap();
        assert!(all.detections.len() >= 3, "{kaiser_beta:?}: {:?}", all.detections);
        for (path, detection) in paths.iter().zip(&all.detections) {
            let error_taps = (detection.delay_s - path.delay_s).abs() / TAP_S;
            println!("{kaiser_beta:?}: path at {:.2} ns found {error_taps:.2e} taps off", path.delay_s * 1e9);
            assert!(error_taps < bound_taps, "{kaiser_beta:?}: {detection:?} vs {path:?}");
            let relative = (detection.amplitude - path.amplitude()).norm() / path.amplitude().norm();
            assert!(relative < 1e-2, "{kaiser_beta:?}: amplitude off by {relative}");
        }
    }
}

#[test]
fn a_path_stronger_than_the_subtraction_table_reaches_is_removed_exactly() {
    // 2048 taps: the subtraction table holds +-256 taps, so a path 134 dB above
    // the threshold (-60 dB over a -200 dB floor) is subtracted over every tap
    // with one inverse FFT; the -100 dB path 20 taps from it and the -120 dB
    // path far away are then found as in a CIR of their own.
    let band = band(2048);
    let pulse = SounderPulse::flat(&band);
    let detector = Detector::new(noiseless_config(Some(6.0)), TAP_S, &pulse).unwrap();
    let paths = [
        Path { delay_s: 300.3e-9, power_db: -60.0, phase_rad: 0.4 },
        Path { delay_s: 320.6e-9, power_db: -100.0, phase_rad: 2.0 },
        Path { delay_s: 1500.7e-9, power_db: -120.0, phase_rad: -1.0 },
    ];
    let found = detector.detect(&snapshot(&band, &pulse, &paths, None, &mut rng(1), 0), 0).unwrap();
    for path in &paths {
        let nearest = found
            .detections
            .iter()
            .min_by(|a, b| (a.delay_s - path.delay_s).abs().total_cmp(&(b.delay_s - path.delay_s).abs()))
            .unwrap();
        let error_taps = (nearest.delay_s - path.delay_s).abs() / TAP_S;
        println!("{:.1} dB path: {error_taps:.1e} taps, {:.3} dB", path.power_db, nearest.power_db());
        assert!(error_taps < 1e-3 && (nearest.power_db() - path.power_db).abs() < 0.01, "{nearest:?}");
    }
    // Whatever else is found is residue of the three, far below the weakest.
    let others = found.detections.iter().filter(|d| paths.iter().all(|p| (d.delay_s - p.delay_s).abs() > 1e-9));
    let strongest_other = others.map(|d| d.power_db()).fold(f64::NEG_INFINITY, f64::max);
    println!("strongest other detection: {strongest_other:.1} dB ({} detections)", found.detections.len());
    assert!(strongest_other < -150.0, "{strongest_other}");
}

#[test]
fn blocked_width_of_the_kaiser_windowed_flat_pulse() {
    let band = band(1024);
    let detector = Detector::new(DetectionConfig::default(), TAP_S, &SounderPulse::flat(&band)).unwrap();
    let width_ns = detector.blocked_width_s() * 1e9;
    println!("Kaiser beta = 6, flat 1 GHz pulse: -10 dB width {width_ns:.3} ns (the paper's measured pulse: 2.47 ns)");
    // numpy's kaiser(1024, 6) on a flat band, 64x oversampled, gives 2.50 ns;
    // the paper's measured pulse 2.47 ns. 0.02 ns: the 1/100-tap search grid.
    assert!((width_ns - 2.50).abs() < 0.02, "{width_ns}");
}

/// Mean delay error over two equal-power MPCs at -116 dB, noise floor
/// -140 dB (Mahler et al. 2017, Sec. IV-A): "up to a delay distance of around
/// 2.5 ns, the mean delay estimation error is below 0.03 ns", i.e. averaged
/// over the approach from wide separations down to 2.5 ns. Here:
/// separations 20 ns down to 2.5 ns, 10 trials each, seed 7.
fn paper_operating_point_mean_delay_error_ns(config: DetectionConfig) -> f64 {
    let band = band(256);
    let pulse = SounderPulse::flat(&band);
    let detector = Detector::new(config, TAP_S, &pulse).unwrap();
    let mut rng = rng(7);
    let (mut total_error_s, mut total_count) = (0.0, 0);
    for step in 0..=35 {
        let separation_ns = 20.0 - 0.5 * f64::from(step);
        let (mut error_sum_s, mut count) = (0.0, 0);
        for trial in 0..10 {
            let first = 100.2e-9 + 0.037e-9 * f64::from(trial);
            let paths = [
                Path { delay_s: first, power_db: -116.0, phase_rad: 0.1 * f64::from(trial) },
                Path { delay_s: first + separation_ns * 1e-9, power_db: -116.0, phase_rad: -0.7 * f64::from(trial) },
            ];
            let cir = snapshot(&band, &pulse, &paths, Some(-140.0), &mut rng, i64::from(trial));
            let found = detector.detect(&cir, 0).unwrap();
            for path in &paths {
                let nearest =
                    found.detections.iter().map(|d| (d.delay_s - path.delay_s).abs()).fold(f64::INFINITY, f64::min);
                error_sum_s += nearest;
                count += 1;
            }
        }
        total_error_s += error_sum_s;
        total_count += count;
        if step % 5 == 0 || separation_ns <= 4.0 {
            println!(
                "separation {separation_ns:4.1} ns: mean delay error {:.4} ns",
                error_sum_s / f64::from(count) * 1e9
            );
        }
    }
    total_error_s / f64::from(total_count) * 1e9
}

#[test]
fn paper_operating_point_delay_error_below_three_hundredths_of_a_nanosecond() {
    let mean_error_ns = paper_operating_point_mean_delay_error_ns(DetectionConfig::default());
    let verdict = if mean_error_ns < 0.03 { "met" } else { "missed" };
    println!("separations 20..2.5 ns: mean delay error {mean_error_ns:.4} ns (paper: below 0.03 ns): {verdict}");
    // Regression bound, not the paper's target: docs/results/multipath.md reports the
    // measured value (0.035 ns at this seed) against the paper's 0.03 ns and
    // why (zeroing below the threshold costs accuracy; see detect.rs docs).
    assert!(mean_error_ns < 0.04, "{mean_error_ns} ns");
}

/// `refit_unwindowed` (ours): the same detections re-estimated on the CIR
/// without the window and the zeroing reach the unwindowed maximum-likelihood
/// error (0.020 ns mean absolute here, module docs of `detect`), which the
/// paper's windowed, zeroed estimate misses by about 1.7x.
#[test]
fn refit_unwindowed_reaches_the_unwindowed_maximum_likelihood_error() {
    let paper = paper_operating_point_mean_delay_error_ns(DetectionConfig::default());
    let refit = paper_operating_point_mean_delay_error_ns(DetectionConfig {
        refit_unwindowed: true,
        ..DetectionConfig::default()
    });
    println!("mean delay error at -116 dB: paper's detection {paper:.4} ns, refit unwindowed {refit:.4} ns");
    assert!(refit < 0.022, "refit {refit} ns (unwindowed maximum likelihood: 0.020 ns)");
    assert!(paper > 0.03, "paper's detection {paper} ns: the comparison needs the windowed estimate's error");
}

#[test]
fn noise_floor_is_estimated_within_half_a_db() {
    let band = band(1024);
    let pulse = SounderPulse::flat(&band);
    let detector = Detector::new(DetectionConfig::default(), TAP_S, &pulse).unwrap();
    let paths = [Path { delay_s: 300.4e-9, power_db: -100.0, phase_rad: 0.0 }];
    let found = detector.detect(&snapshot(&band, &pulse, &paths, Some(-140.0), &mut rng(3), 0), 0).unwrap();
    // The floor averages 8 windows x 16 odd taps = 128 exponential samples:
    // a standard deviation of 1/sqrt(128) = 0.4 dB; 1 dB is 2.5 sigma.
    let floor_db = found.noise_floor_db.unwrap();
    assert!((floor_db + 140.0).abs() < 1.0, "{floor_db}");
    // The path first; noise peaks above floor + 6 dB may follow (tracking
    // removes them: they do not persist over three snapshots), but far weaker.
    let first = &found.detections[0];
    assert!((first.delay_s - 300.4e-9).abs() < 0.01e-9 && (first.power_db() + 100.0).abs() < 0.1, "{first:?}");
    assert!(found.detections[1..].iter().all(|d| d.power_db() < -125.0), "{:?}", found.detections);
    // Detection captures the path's gain: what it misses is noise, 40 dB down.
    assert!((found.channel_gain_db.unwrap() - found.detected_gain_db.unwrap()).abs() < 0.1);
}

#[test]
fn bad_snapshots_give_errors_naming_the_snapshot() {
    let band = band(64);
    let pulse = SounderPulse::flat(&band);
    let detector = Detector::new(DetectionConfig::default(), TAP_S, &pulse).unwrap();
    let good = snapshot(
        &band,
        &pulse,
        &[Path { delay_s: 10e-9, power_db: -90.0, phase_rad: 0.0 }],
        Some(-140.0),
        &mut rng(2),
        5,
    );

    let mut short = good.clone();
    short.taps.truncate(40);
    let error = detector.detect(&short, 17).unwrap_err();
    assert!(matches!(error, MpcError::BadSnapshot { snapshot: 17, t_ns: 5, .. }), "{error}");
    assert!(error.to_string().contains("40 taps"), "{error}");

    let mut nan = good.clone();
    nan.taps[9] = Complex64::new(f64::NAN, 0.0);
    let error = detector.detect(&nan, 3).unwrap_err();
    assert!(error.to_string().contains("tap 9 is not finite"), "{error}");

    let mut spacing = good.clone();
    spacing.tap_spacing_s = 2e-9;
    assert!(detector.detect(&spacing, 0).is_err());

    let mut zero = good.clone();
    zero.taps.iter_mut().for_each(|t| *t = Complex64::default());
    let skipped = detector.detect(&zero, 0).unwrap();
    assert!(skipped.detections.is_empty() && skipped.skipped.is_some());
    // Nothing measured: no levels (nulls in mpc_snapshots), not -inf.
    assert_eq!((skipped.noise_floor_db, skipped.channel_gain_db, skipped.detected_gain_db), (None, None, None));
}

#[test]
fn bad_configs_name_the_field() {
    let pulse = SounderPulse::flat(&band(64));
    let config = DetectionConfig { kaiser_beta: Some(-1.0), ..DetectionConfig::default() };
    let error = Detector::new(config, TAP_S, &pulse).unwrap_err();
    assert!(error.to_string().contains("detection.kaiser_beta"), "{error}");
    let config =
        DetectionConfig { noise_floor: NoiseFloor::QuietestWindows { window_taps: 0 }, ..DetectionConfig::default() };
    assert!(Detector::new(config, TAP_S, &pulse).unwrap_err().to_string().contains("window_taps"));
    assert!(Detector::new(DetectionConfig::default(), -1e-9, &pulse).is_err());
}

#[test]
fn refined_delays_stay_outside_earlier_detections_blocked_ranges() {
    // The blocked range exists so that one path is not detected twice
    // (Mahler et al. 2017, Sec. III-A, step 4); the sub-tap refinement of a
    // candidate found on an unblocked tap may still move it into a blocked
    // range. Channels that provoke it: a strong path with a 6 dB weaker one
    // 0.6..2.6 ns behind it (inside and just outside the 2.50 ns blocked
    // range), a third far away, a -140 dB floor.
    let band = band(256);
    let pulse = SounderPulse::flat(&band);
    let detector = Detector::new(DetectionConfig::default(), TAP_S, &pulse).unwrap();
    let half_width_s = detector.blocked_width_s() / 2.0;
    let mut rng = rng(13);
    let (mut closest_s, mut inside, mut pairs) = (f64::INFINITY, 0, 0);
    for trial in 0..200 {
        let fraction = f64::from(trial) / 200.0;
        let first_s = 60.0e-9 + 0.37e-9 * fraction;
        let paths = [
            Path { delay_s: first_s, power_db: -100.0, phase_rad: 6.0 * fraction },
            Path { delay_s: first_s + (0.6 + 2.0 * fraction) * 1e-9, power_db: -106.0, phase_rad: -11.0 * fraction },
            Path { delay_s: 150.3e-9, power_db: -110.0, phase_rad: 0.5 },
        ];
        let found = detector.detect(&snapshot(&band, &pulse, &paths, Some(-140.0), &mut rng, 0), 0).unwrap();
        let mut delays: Vec<f64> = found.detections.iter().map(|d| d.delay_s).collect();
        delays.sort_by(f64::total_cmp);
        for gap_s in delays.windows(2).map(|w| w[1] - w[0]) {
            pairs += 1;
            inside += usize::from(gap_s <= half_width_s);
            closest_s = closest_s.min(gap_s);
        }
    }
    println!(
        "{pairs} adjacent detection pairs over 200 channels: {inside} within half the blocked range ({:.3} ns), closest {:.4} ns",
        half_width_s * 1e9,
        closest_s * 1e9
    );
    // Exact: a kept detection lies outside every earlier one's blocked range.
    assert!(closest_s > half_width_s, "closest pair {closest_s} s, half blocked width {half_width_s} s");
}

/// Two paths closer than a pulse width (the convoy's LOS and the wall
/// bounce 1.1 ns behind it, 8 dB weaker), over a -140 dB floor, with the
/// bounce's phase and both sub-tap offsets varied. The paper's search and
/// subtract fits one pulse at a time: the LOS estimate is pulled towards
/// the bounce and the misfit leaves a residue the search picks up as a
/// third path. `refine_overlapping` re-estimates the pair jointly: the LOS
/// delay error falls to the noise's and the pair leaves no more stray
/// detections near it than the LOS alone does (noise peaks over floor +
/// 6 dB; the same noise draws).
#[test]
fn refining_overlapping_paths_removes_the_residue_of_a_pair_closer_than_a_pulse_width() {
    let band = band(256);
    let pulse = SounderPulse::flat(&band);
    let paper = Detector::new(DetectionConfig::default(), TAP_S, &pulse).unwrap();
    let refined =
        Detector::new(DetectionConfig { refine_overlapping: true, ..DetectionConfig::default() }, TAP_S, &pulse)
            .unwrap();
    let trials: u32 = 200;
    // Stray detections within 4 ns of the LOS and more than 0.5 ns from
    // both paths (noise taps elsewhere do not count), the sum of the LOS
    // delay errors and the times the LOS was found: the paper's search on
    // the pair, the refined search on the pair, the paper's on the LOS alone.
    let mut scores = [(0usize, 0.0_f64, 0usize); 3];
    let (mut noise_pair, mut noise_alone) = (rng(17), rng(17));
    for trial in 0..trials {
        let fraction = f64::from(trial) / f64::from(trials);
        let los_s = 60.0e-9 + 0.97e-9 * fraction;
        let paths = [
            Path { delay_s: los_s, power_db: -101.0, phase_rad: 0.0 },
            Path { delay_s: los_s + 1.12e-9, power_db: -109.0, phase_rad: 2.0 * std::f64::consts::PI * fraction * 7.0 },
        ];
        let pair = snapshot(&band, &pulse, &paths, Some(-140.0), &mut noise_pair, 0);
        let alone = snapshot(&band, &pulse, &paths[..1], Some(-140.0), &mut noise_alone, 0);
        for (score, (detector, cir)) in scores.iter_mut().zip([(&paper, &pair), (&refined, &pair), (&paper, &alone)]) {
            let found = detector.detect(cir, 0).unwrap();
            for d in &found.detections {
                let nearest = paths.iter().map(|p| (d.delay_s - p.delay_s).abs()).fold(f64::INFINITY, f64::min);
                score.0 += usize::from(nearest > 0.5e-9 && (d.delay_s - los_s).abs() < 4e-9);
            }
            if let Some(los) = found.detections.iter().find(|d| (d.delay_s - los_s).abs() <= 0.5e-9) {
                score.1 += (los.delay_s - los_s).abs();
                score.2 += 1;
            }
        }
    }
    let [on_pair, refined_pair, lone] = scores;
    let mean_ns = |s: (usize, f64, usize)| s.1 / s.2 as f64 * 1e9;
    for (name, s) in
        [("paper's search, pair", on_pair), ("refined, pair", refined_pair), ("paper's search, LOS alone", lone)]
    {
        println!(
            "{name}: {} stray detections in {trials} snapshots; LOS found {} times, mean delay error {:.4} ns",
            s.0,
            s.2,
            mean_ns(s)
        );
    }
    assert_eq!((on_pair.2, refined_pair.2, lone.2), (200, 200, 200), "the LOS is found every time");
    // The mechanism: one pulse at a time leaves strays and a biased LOS.
    assert!(on_pair.0 >= 2 * lone.0 + 20, "paper's strays {on_pair:?} vs the lone LOS's {lone:?}");
    assert!(mean_ns(on_pair) > 5.0 * mean_ns(lone), "{on_pair:?} vs {lone:?}");
    // Refined: what the lone LOS leaves (counts of a few dozen: +- 50 %).
    assert!(2 * refined_pair.0 <= 3 * lone.0 + 4, "refined strays {refined_pair:?} vs the lone LOS's {lone:?}");
    assert!(mean_ns(refined_pair) < 2.0 * mean_ns(lone), "{refined_pair:?} vs {lone:?}");
}
