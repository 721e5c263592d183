//! `track_gmphd` runs its own two-state filter on stack arrays; this is the
//! same baseline assembled from `mmtrack-filter`'s generic roles
//! (`GmPhdFilter` with `ConstantVelocity`, `LinearMeasurement::position`, a
//! `Gate`, `MixtureReducer`, `StateExtractor`), as `track_gmphd` was written
//! up to session 17. Both must give the same tracks, number for number, on
//! drawn sparse and dense detections.

use std::collections::{BTreeMap, BTreeSet};

use mmtrack_core::{Complex64, MpcDetection, MpcTrack};
use mmtrack_filter::faer::{Col, ColRef, MatRef};
use mmtrack_filter::gmphd::{MixtureReducer, StateExtractor, WeightedGaussian};
use mmtrack_filter::{
    ConstantVelocity, FilterError, Gate, GateCandidate, Gaussian, GmPhdFilter, GmPhdParams, KalmanPredictor,
    KalmanUpdater, Label, LinearMeasurement,
};
use mmtrack_mpc::gmphd::{GmPhdConfig, GmPhdSnapshot, track_gmphd};
use mmtrack_mpc::short_term::doppler_hz;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;

const C_M_PER_S: f64 = mmtrack_mpc::SPEED_OF_LIGHT_M_PER_S;

/// The maximum delay / magnitude change gate.
struct ChangeGate<'a> {
    max_innovation_m: f64,
    max_magnitude_change_db: f64,
    last_power_db: &'a BTreeMap<Label, f64>,
    powers_db: &'a [f64],
}

impl Gate for ChangeGate<'_> {
    fn admits(&self, candidate: &GateCandidate<'_>) -> bool {
        let delay_ok = candidate.innovation.iter().all(|nu| nu.abs() <= self.max_innovation_m);
        let magnitude_ok =
            match (self.last_power_db.get(&candidate.label), self.powers_db.get(candidate.measurement_index)) {
                (Some(last), Some(now)) => (now - last).abs() <= self.max_magnitude_change_db,
                _ => true,
            };
        delay_ok && magnitude_ok
    }
}

/// What the generic reducer did over a run: components merged into others,
/// dropped by the `J_max` cap.
#[derive(Debug, Default, Clone, Copy)]
struct Reduced {
    merged: usize,
    capped: usize,
}

/// The baseline on the generic filter (input assumed valid).
fn track_generic(
    snapshots: &[GmPhdSnapshot],
    config: &GmPhdConfig,
    reduced: &mut Reduced,
) -> Result<Vec<MpcTrack>, FilterError> {
    let c = C_M_PER_S;
    let mut filter = GmPhdFilter::new(
        KalmanPredictor::new(ConstantVelocity::new(1, config.sigma_process_mps2)?),
        KalmanUpdater::new(LinearMeasurement::position(1, config.sigma_measurement_m)?),
        GmPhdParams {
            p_survival: config.p_survival,
            p_detection: config.p_detection,
            clutter_intensity: config.clutter_intensity_per_m,
        },
        MixtureReducer::new(config.truncation_threshold, config.merge_threshold, config.max_components)?,
        StateExtractor::new(config.extraction_threshold)?,
    )?;
    let birth_predictor = KalmanPredictor::new(ConstantVelocity::new(1, config.sigma_process_mps2)?);
    let (sd, sv) = (config.sigma_measurement_m, config.birth_sigma_rate_mps);
    let birth_cov = MatRef::from_row_major_slice(&[sd * sd, 0.0, 0.0, sv * sv], 2, 2).to_owned();

    let mut unexplained: Vec<(f64, f64)> = Vec::new();
    let mut last_power_db: BTreeMap<Label, f64> = BTreeMap::new();
    let mut tracks: BTreeMap<Label, Vec<MpcDetection>> = BTreeMap::new();
    let mut previous_t_ns: Option<i64> = None;
    for snap in snapshots {
        let dt_s = previous_t_ns.map_or(0.0, |p| (i128::from(snap.t_ns) - i128::from(p)) as f64 * 1e-9);
        previous_t_ns = Some(snap.t_ns);
        let at_detections = unexplained
            .iter()
            .map(|&(d, _)| Gaussian::new(ColRef::from_slice(&[d, 0.0]).to_owned(), birth_cov.clone()))
            .collect::<Result<Vec<_>, _>>()?;
        let births = birth_predictor
            .predict_each(&at_detections, dt_s)?
            .into_iter()
            .map(|density| WeightedGaussian { weight: config.birth_weight, density })
            .collect();
        let labels = filter.predict(dt_s, births)?;
        for (label, &(_, power_db)) in labels.iter().zip(&unexplained) {
            last_power_db.insert(*label, power_db);
        }
        let zs: Vec<Col<f64>> = snap.detections.iter().map(|d| Col::full(1, c * d.delay_s)).collect();
        let powers_db: Vec<f64> = snap.detections.iter().map(MpcDetection::power_db).collect();
        let gate = ChangeGate {
            max_innovation_m: c * config.max_delay_change_s,
            max_magnitude_change_db: config.max_magnitude_change_db,
            last_power_db: &last_power_db,
            powers_db: &powers_db,
        };
        let report = filter.update(&zs, &gate)?;
        let report = (report, filter.reduce()?);
        reduced.merged += report.1.merged;
        reduced.capped += report.1.capped;
        let report = report.0;
        for estimate in filter.extract() {
            let source = estimate.measurement.and_then(|j| snap.detections.get(j));
            if let Some(d) = source {
                last_power_db.insert(estimate.label, d.power_db());
            }
            let track = tracks.entry(estimate.label).or_default();
            let amplitude = source
                .map(|d| d.amplitude)
                .or_else(|| track.last().map(|d| d.amplitude))
                .unwrap_or(Complex64::new(0.0, 0.0));
            track.push(MpcDetection {
                t_ns: snap.t_ns,
                set_index: snap.set_index,
                snapshot_index: snap.snapshot_index,
                delay_s: estimate.density.mean()[0] / c,
                amplitude,
            });
        }
        unexplained = zs
            .iter()
            .zip(&powers_db)
            .zip(&report.measurement_weights)
            .filter(|(_, w)| **w < config.birth_association_threshold)
            .map(|((z, p), _)| (z[0], *p))
            .collect();
        let alive: BTreeSet<Label> = filter.mixture().iter().map(|comp| comp.label).collect();
        last_power_db.retain(|label, _| alive.contains(label));
    }
    Ok(tracks
        .into_iter()
        .filter(|(_, d)| d.len() >= config.min_track_detections)
        .map(|(label, detections)| MpcTrack {
            track_id: label.0,
            doppler_hz: doppler_hz(&detections, config.carrier_hz),
            detections,
        })
        .collect())
}

/// Sets of 6 snapshots (0.717 ms apart, a set every 10 ms) of `paths` paths
/// spread over 2 us with linear delay drift (up to +-400 Hz at 5.7 GHz),
/// powers -125..-90 dB, each detected with probability 0.95 at 0.01 ns delay
/// error, and on average 0.5 false detections per snapshot (as `bench mpc`'s
/// drawn rows).
fn drawn(paths: usize, sets: u64, seed: u64) -> Vec<Vec<GmPhdSnapshot>> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let slot_s = 2016e-9 / paths as f64;
    let drawn: Vec<(f64, f64, f64)> = (0..paths)
        .map(|i| {
            let delay_s = 16e-9 + slot_s * (i as f64 + 0.25 + 0.5 * rng.random::<f64>());
            let rate = -400.0 * (2.0 * rng.random::<f64>() - 1.0) / 5.7e9;
            (delay_s, rate, 10f64.powf((-125.0 + 35.0 * rng.random::<f64>()) / 20.0))
        })
        .collect();
    (0..sets)
        .map(|set| {
            (0..6u32)
                .map(|k| {
                    let t_ns = set as i64 * 10_000_000 + i64::from(k) * 717_000;
                    let at = |delay_s: f64, magnitude: f64, phase: f64| MpcDetection {
                        t_ns,
                        set_index: set,
                        snapshot_index: k,
                        delay_s,
                        amplitude: Complex64::from_polar(magnitude, phase),
                    };
                    let mut detections = Vec::new();
                    for &(delay_s, rate, magnitude) in &drawn {
                        if rng.random::<f64>() < 0.95 {
                            let noise = mmtrack_core::random::standard_normal(&mut rng);
                            let d = delay_s + rate * t_ns as f64 * 1e-9 + 0.01e-9 * noise;
                            detections.push(at(d, magnitude, std::f64::consts::TAU * rng.random::<f64>()));
                        }
                    }
                    for _ in 0..2 {
                        if rng.random::<f64>() < 0.25 {
                            detections.push(at(16e-9 + 2016e-9 * rng.random::<f64>(), 10f64.powf(-6.4), 0.0));
                        }
                    }
                    GmPhdSnapshot { t_ns, set_index: set, snapshot_index: k, detections }
                })
                .collect()
        })
        .collect()
}

/// Compares the two on every set; returns the tracks and what the reducer did.
fn assert_same_tracks(sets: &[Vec<GmPhdSnapshot>], config: &GmPhdConfig) -> (usize, Reduced) {
    let (mut total, mut reduced) = (0, Reduced::default());
    for (s, set) in sets.iter().enumerate() {
        let fixed = track_gmphd(set, config).expect("valid input");
        let generic = track_generic(set, config, &mut reduced).expect("valid input");
        assert_eq!(fixed, generic, "set {s}");
        total += fixed.len();
    }
    (total, reduced)
}

#[test]
fn fixed_filter_equals_the_generic_one_on_sparse_and_dense_detections() {
    let config = GmPhdConfig::default();
    // 13 paths (about 13 detections per snapshot) and 147 (about 140).
    let (sparse, sparse_reduced) = assert_same_tracks(&drawn(13, 40, 1), &config);
    let (dense, dense_reduced) = assert_same_tracks(&drawn(147, 4, 2), &config);
    // Most paths become tracks in every set: the comparison is not over empty outputs.
    assert!(sparse >= 40 * 10, "{sparse} sparse tracks");
    assert!(dense >= 4 * 80, "{dense} dense tracks");
    // The default merge threshold merges each path's updated and missed copies.
    assert!(sparse_reduced.merged > 0 && dense_reduced.merged > 0, "{sparse_reduced:?} {dense_reduced:?}");
}

#[test]
fn fixed_filter_equals_the_generic_one_with_merging_capping_and_a_tight_gate() {
    // A wide merge threshold and a small component cap exercise the
    // moment-matched merge and the J_max cut; a 3 dB magnitude gate and
    // extraction at 0.1 the gate and the duplicate-label rule.
    let config = GmPhdConfig {
        merge_threshold: 4.0,
        max_components: 12,
        max_magnitude_change_db: 3.0,
        extraction_threshold: 0.1,
        ..GmPhdConfig::default()
    };
    let (tracks, reduced) = assert_same_tracks(&drawn(13, 30, 3), &config);
    assert!(tracks >= 30 * 5, "{tracks} tracks");
    assert!(reduced.merged > 0 && reduced.capped > 0, "{reduced:?}");
}
