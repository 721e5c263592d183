//! The trackers and baselines on synthetic sweeps of a 16-element array
//! with a 64-beam, 90-degree codebook.

use mmtrack_core::BeamSweep;
use mmtrack_core::array::{Codebook, UniformLinearArray, u_from_broadside_angle};

use super::*;

const SWEEP_NS: i64 = 100_000_000;

/// Full sweeps of a car seen at `angle_rad(k)` from broadside at sweep `k`:
/// beam powers are the array's beamforming gain plus a -30 dB floor (so
/// sidelobe nulls stay finite in dB).
fn sweeps(count: usize, angle_rad: impl Fn(usize) -> f64) -> Vec<BeamSweep> {
    let array = UniformLinearArray::half_wavelength(16).unwrap();
    let codebook = Codebook::uniform_in_angle(64, 90_f64.to_radians()).unwrap();
    (0..count)
        .map(|k| {
            let u = u_from_broadside_angle(angle_rad(k));
            let power = codebook.steer_u().iter().map(|&s| array.gain(s, u) + 1e-3).collect();
            BeamSweep::full(k as i64 * SWEEP_NS, power).unwrap()
        })
        .collect()
}

/// Beam index (continuous) of angle `angle_rad` from broadside in the
/// 64-beam, 90-degree codebook.
fn beam_of(angle_rad: f64) -> f64 {
    angle_rad.to_degrees() / (90.0 / 64.0) + 31.5
}

fn run(tracker: &mut dyn SweepTracker, sweeps: &[BeamSweep], gnss: Option<&[f64]>) -> Vec<SweepRecord> {
    evaluate(tracker, &[SweepPass { sweeps, gnss_beam: gnss }]).unwrap()
}

/// Steady motion: 20 deg/s, 1.4 beams per sweep, from -40 deg.
fn steady(k: usize) -> f64 {
    (-40.0 + 2.0 * k as f64).to_radians()
}

#[test]
fn window_tracker_follows_a_steadily_moving_beam_with_few_beams() {
    let sweeps = sweeps(40, steady);
    let records = run(&mut WindowTracker::new(WindowTrackerConfig::default()).unwrap(), &sweeps, None);
    let summary = SweepSummary::from_records(&records).unwrap();
    // The gain is exact and noise-free: every sweep's chosen beam is the best.
    assert_eq!(summary.top1, 1.0, "{summary:?}");
    assert_eq!(summary.mean_loss_db, 0.0);
    assert_eq!(summary.reinitialisations, 1, "only the pass start");
    assert!(records[0].reinitialised && records[0].beams_measured < 64, "coarse acquisition");
    // After the start: the 3-beam window plus at most a step of climb.
    let tracked = SweepSummary::from_records(&records[1..]).unwrap();
    assert!(tracked.mean_beams_per_sweep <= 4.0, "{tracked:?}");
    // The full-sweep policy one sweep late loses power at 1.4 beams/sweep.
    let late = SweepSummary::from_records(&run(&mut LastFullSweep::new(), &sweeps, None)).unwrap();
    assert_eq!(late.mean_beams_per_sweep, 64.0);
    assert!(late.mean_loss_db > 0.3 && late.top1 < 0.5, "{late:?}");
}

#[test]
fn window_tracker_notices_a_jump_and_reacquires() {
    // The car is at -20 deg, then the best direction jumps to +25 deg at
    // sweep 15 (a blocked line of sight and a reflection, say).
    let sweeps = sweeps(30, |k| if k < 15 { -20_f64.to_radians() } else { 25_f64.to_radians() });
    for config in [
        WindowTrackerConfig::default(),
        WindowTrackerConfig {
            search: SearchConfig { reacquisition: Reacquisition::FullSweep, ..SearchConfig::default() },
            ..WindowTrackerConfig::default()
        },
    ] {
        let records = run(&mut WindowTracker::new(config).unwrap(), &sweeps, None);
        let reinit: Vec<usize> = records.iter().filter(|r| r.reinitialised).map(|r| r.sweep).collect();
        assert_eq!(reinit, [0, 15], "{config:?}");
        assert!(records.iter().all(|r| r.chosen_beam == r.best_beam), "{records:?}");
        if config.search.reacquisition == Reacquisition::FullSweep {
            assert_eq!(records[0].beams_measured, 64);
            assert!(records[15].beams_measured == 64, "a full sweep covers the window too");
        }
        // The jump's sweep pays the window, the climb and the re-acquisition.
        assert!(records[15].beams_measured > records[14].beams_measured);
    }
}

#[test]
fn gnss_tracker_starts_from_a_biased_gnss_beam_and_skips_the_acquisition() {
    let sweeps = sweeps(40, steady);
    // The GNSS beam is 2.6 beams off the truth (a map or latency error).
    let gnss: Vec<f64> = (0..40).map(|k| beam_of(steady(k)) + 2.6).collect();
    let mut tracker = GnssWindowTracker::new(GnssTrackerConfig::default()).unwrap();
    let records = run(&mut tracker, &sweeps, Some(&gnss));
    let summary = SweepSummary::from_records(&records).unwrap();
    assert_eq!(summary.top1, 1.0, "{summary:?}");
    assert_eq!(summary.reinitialisations, 0, "the first window (+-6 beams) covers the offset");
    // First window 13 beams (fewer than the 16 of a coarse acquisition);
    // then 3 and a climb step now and then.
    assert_eq!(records[0].beams_measured, 13);
    assert!(SweepSummary::from_records(&records[1..]).unwrap().mean_beams_per_sweep <= 4.0);
    // The map alone is off by 2.6 beams: never the best beam.
    let alone = SweepSummary::from_records(&run(&mut GnssMapOnly, &sweeps, Some(&gnss))).unwrap();
    assert_eq!((alone.top1, alone.mean_beams_per_sweep), (0.0, 0.0));
    assert!(alone.mean_loss_db > 1.0, "{alone:?}");
    // A map too poor for its window to be cheaper than acquiring (sigma 8
    // beams: +-16) starts the pass with the coarse acquisition instead.
    let poor = GnssTrackerConfig { gnss_sigma_beams: 8.0, ..GnssTrackerConfig::default() };
    let records = run(&mut GnssWindowTracker::new(poor).unwrap(), &sweeps, Some(&gnss));
    assert!(records[0].reinitialised && records[0].beams_measured < 33, "{:?}", records[0]);
}

/// GNSS beams that jump from sweep to sweep (position noise of a few metres
/// at 10-30 m range: on the DeepSense passes the GNSS beam moves a median
/// 0.9-2 beams between sweeps against the best beam's own motion) must not
/// move the window with them: the peak, measured ten times finer, holds the
/// track. (A window centred on the GNSS beam reads 6.2 beams per sweep
/// here, measured by breaking the tracker so.)
#[test]
fn gnss_tracker_is_not_thrown_by_gnss_noise() {
    // 40 sweeps: -40 to +38 deg, inside the codebook's +-45 deg.
    let sweeps = sweeps(40, steady);
    // GNSS error alternating +3 / -3 beams (the map's residual, 3 beams).
    let gnss: Vec<f64> = (0..40).map(|k| beam_of(steady(k)) + if k % 2 == 0 { 3.0 } else { -3.0 }).collect();
    let config = GnssTrackerConfig { gnss_sigma_beams: 3.0, ..GnssTrackerConfig::default() };
    let records = run(&mut GnssWindowTracker::new(config).unwrap(), &sweeps, Some(&gnss));
    let summary = SweepSummary::from_records(&records).unwrap();
    assert_eq!(summary.top1, 1.0, "{summary:?}");
    assert_eq!(summary.reinitialisations, 0, "{summary:?}");
    assert!(SweepSummary::from_records(&records[1..]).unwrap().mean_beams_per_sweep <= 4.0, "{summary:?}");
}

#[test]
fn evaluation_rejects_bad_passes() {
    let good = sweeps(3, steady);
    let mut tracker = LastFullSweep::new();
    let partial =
        vec![good[0].clone(), BeamSweep::new(SWEEP_NS, vec![1.0; 64], (0..64).map(|b| b != 5).collect()).unwrap()];
    assert_eq!(
        evaluate(&mut tracker, &[SweepPass { sweeps: &partial, gnss_beam: None }]),
        Err(SweepError::BeamNotMeasured { t_ns: SWEEP_NS, beam: 5 })
    );
    let short_gnss = [1.0, 2.0];
    assert!(matches!(
        evaluate(&mut tracker, &[SweepPass { sweeps: &good, gnss_beam: Some(&short_gnss) }]),
        Err(SweepError::BadInput { .. })
    ));
    let backwards = vec![good[1].clone(), good[0].clone()];
    assert!(matches!(
        evaluate(&mut tracker, &[SweepPass { sweeps: &backwards, gnss_beam: None }]),
        Err(SweepError::NonIncreasingTime { .. })
    ));
    let narrow = vec![BeamSweep::full(0, vec![1.0; 8]).unwrap()];
    assert!(matches!(
        evaluate(
            &mut tracker,
            &[SweepPass { sweeps: &good, gnss_beam: None }, SweepPass { sweeps: &narrow, gnss_beam: None }]
        ),
        Err(SweepError::BeamCountMismatch { expected: 64, found: 8, .. })
    ));
    // A GNSS tracker without GNSS is an error, not a guess.
    let mut gnss_tracker = GnssWindowTracker::new(GnssTrackerConfig::default()).unwrap();
    assert!(matches!(
        evaluate(&mut gnss_tracker, &[SweepPass { sweeps: &good, gnss_beam: None }]),
        Err(SweepError::BadInput { .. })
    ));
}

#[test]
fn bad_configs_are_errors() {
    let search = SearchConfig { reacquisition: Reacquisition::Coarse { stride: 1 }, ..SearchConfig::default() };
    assert!(matches!(
        WindowTracker::new(WindowTrackerConfig { search, ..WindowTrackerConfig::default() }),
        Err(SweepError::BadConfig { field: "reacquisition.stride", .. })
    ));
    let search = SearchConfig { drop_db: f64::NAN, ..SearchConfig::default() };
    let window = WindowTrackerConfig { search, ..WindowTrackerConfig::default() };
    assert!(GnssWindowTracker::new(GnssTrackerConfig { window, ..GnssTrackerConfig::default() }).is_err());
    for gnss_sigma_beams in [0.0, f64::NAN, f64::INFINITY] {
        let config = GnssTrackerConfig { gnss_sigma_beams, ..GnssTrackerConfig::default() };
        assert!(matches!(GnssWindowTracker::new(config), Err(SweepError::BadConfig { field: "gnss_sigma_beams", .. })));
    }
    assert!(
        WindowTracker::new(WindowTrackerConfig { measurement_sigma_beams: 0.0, ..WindowTrackerConfig::default() })
            .is_err()
    );
}

#[test]
fn summary_median_and_shares() {
    let record = |chosen_beam, loss_db, beams_measured| SweepRecord {
        pass: 0,
        sweep: 0,
        t_ns: 0,
        chosen_beam,
        best_beam: 10,
        beams_measured,
        reinitialised: false,
        loss_db,
    };
    let records = [record(10, 0.0, 3), record(11, 0.5, 5), record(13, 3.0, 4), record(10, 0.0, 64)];
    let s = SweepSummary::from_records(&records).unwrap();
    assert_eq!(s.median_loss_db, 0.25);
    assert_eq!(s.mean_loss_db, 0.875);
    assert_eq!((s.top1, s.within_one), (0.5, 0.75));
    assert_eq!(s.mean_beams_per_sweep, 19.0);
    assert!(SweepSummary::from_records(&[]).is_none());
}
