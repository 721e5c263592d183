//! GM-PHD: a two-target scenario, pruning/merging and labelled extraction.

use std::collections::BTreeMap;

use mmtrack_filter::faer::Col;
use mmtrack_filter::gmphd::{Component, Estimate, MixtureReducer, StateExtractor, WeightedGaussian};
use mmtrack_filter::{
    ConstantVelocity, Gaussian, GmPhdFilter, GmPhdParams, KalmanPredictor, KalmanUpdater, Label, LinearMeasurement,
    NoGate, TransitionModel,
};

use crate::support::{Normal, m, v};

const SIGMA_Z: f64 = 1.0;
const P_D: f64 = 0.9;
/// One clutter point per step, uniform over [-50, 150]: kappa = 1 / 200.
const KAPPA: f64 = 1.0 / 200.0;

fn filter() -> GmPhdFilter<ConstantVelocity> {
    GmPhdFilter::new(
        KalmanPredictor::new(ConstantVelocity::new(1, 0.1).expect("valid")),
        KalmanUpdater::new(LinearMeasurement::position(1, SIGMA_Z).expect("valid")),
        GmPhdParams { p_survival: 0.99, p_detection: P_D, clutter_intensity: KAPPA },
        MixtureReducer::new(1e-3, 4.0, 50).expect("valid"),
        StateExtractor::new(0.5).expect("valid"),
    )
    .expect("consistent roles")
}

/// Births at the measurements no component explained at the previous step:
/// N([z, 0], diag(sigma_z^2, 2^2)) moved forward by `dt`.
fn births(prev: &[(Col<f64>, f64)], dt: f64) -> Vec<WeightedGaussian> {
    let model = ConstantVelocity::new(1, 0.1).expect("valid");
    let (f, q) = model.matrices(dt).expect("valid dt");
    prev.iter()
        .filter(|(_, w)| *w < 0.5)
        .map(|(z, _)| {
            let p0 = m(2, 2, &[SIGMA_Z * SIGMA_Z, 0.0, 0.0, 4.0]);
            let density = Gaussian::new(&f * v(&[z[0], 0.0]), &f * p0 * f.transpose() + &q).expect("SPD");
            WeightedGaussian { weight: 0.05, density }
        })
        .collect()
}

/// Two targets, x1 = 0 + t (from step 0) and x2 = 100 - 0.5 t (from step 3),
/// never closer than 45; one clutter point a step; scripted misses at steps 12
/// (target 1) and 20 (target 2). Over 40 steps the cardinality settles at 2
/// and each target keeps one label from its confirmation to the end.
#[test]
fn two_targets_cardinality_and_labels() {
    let mut f = filter();
    let mut noise = Normal::new(7);
    let mut prev: Vec<(Col<f64>, f64)> = Vec::new();
    // step -> estimates
    let mut history: Vec<Vec<Estimate>> = Vec::new();
    let mut cardinality = Vec::new();
    for k in 0..40_u32 {
        let t = f64::from(k);
        let mut zs = Vec::new();
        if k != 12 {
            zs.push(v(&[t + SIGMA_Z * noise.sample()]));
        }
        if k >= 3 && k != 20 {
            zs.push(v(&[100.0 - 0.5 * t + SIGMA_Z * noise.sample()]));
        }
        // Clutter in [-50, -11], away from both tracks, jumping by 13 or
        // 27 a step (> 5 sigma of a birth's innovation) so it never looks like
        // a target.
        zs.push(v(&[-50.0 + f64::from((k * 13) % 40)]));
        let dt = if k == 0 { 0.0 } else { 1.0 };
        let report = f.step(dt, births(&prev, dt), &zs, &NoGate).expect("valid step");
        prev = zs.into_iter().zip(report.update.measurement_weights.iter().copied()).collect();
        history.push(report.estimates);
        cardinality.push(f.expected_cardinality());
    }

    // Cardinality: each track contributes ~1 (1 - kappa / (kappa + p_D q) with
    // q ~ 0.2 is 0.97), each clutter birth at most 0.05 * (1 - p_D); 0.3 covers
    // both with margin. Miss steps (and the step after, while the weight
    // recovers) are excluded.
    for (k, n) in cardinality.iter().enumerate().skip(6) {
        if [12, 13, 20, 21].contains(&k) {
            continue;
        }
        assert!((n - 2.0).abs() < 0.3, "step {k}: expected cardinality {n}");
        assert_eq!(history[k].len(), 2, "step {k}: {:?}", history[k]);
    }

    // Labels: nearest estimate to each truth, within 4 sigma (4.0).
    let mut labels: [BTreeMap<Label, usize>; 2] = [BTreeMap::new(), BTreeMap::new()];
    for (k, est) in history.iter().enumerate().skip(6) {
        let t = k as f64;
        for (target, truth) in [t, 100.0 - 0.5 * t].into_iter().enumerate() {
            if let Some(e) = est.iter().find(|e| (e.density.mean()[0] - truth).abs() < 4.0) {
                *labels[target].entry(e.label).or_default() += 1;
            }
        }
    }
    assert_eq!(labels[0].len(), 1, "target 1 labels {:?}", labels[0]);
    assert_eq!(labels[1].len(), 1, "target 2 labels {:?}", labels[1]);
    assert_ne!(labels[0].keys().next(), labels[1].keys().next());
    // Present at every step from 6 on except its own miss step: 34 - 1.
    assert_eq!(labels[0].values().sum::<usize>(), 33);
    assert_eq!(labels[1].values().sum::<usize>(), 33);
}

fn comp(label: u64, weight: f64, mean: f64, var: f64) -> Component {
    Component {
        label: Label(label),
        weight,
        density: Gaussian::new(v(&[mean]), m(1, 1, &[var])).expect("valid"),
        measurement: Some(label as usize),
    }
}

/// Table II by hand: T = 0.01, U = 0.1.
/// - label 9 (w 0.005) is truncated;
/// - labels 1 (w 0.6, m 0) and 2 (w 0.3, m 0.1), both P = 1, are within
///   U of the heavier (d^2 = 0.01) and merge: w = 0.9,
///   m = 0.03 / 0.9 = 1/30, P = (0.6 (1 + (1/30)^2) + 0.3 (1 + (1/15)^2)) / 0.9 = 1 + 1/450,
///   label 1 (the heavier);
/// - label 3 (w 0.4, m 10) stays alone.
#[test]
fn pruning_and_merging_by_hand() {
    let mixture =
        vec![comp(2, 0.3, 0.1, 1.0), comp(9, 0.005, 0.0, 1.0), comp(3, 0.4, 10.0, 1.0), comp(1, 0.6, 0.0, 1.0)];
    let reducer = MixtureReducer::new(0.01, 0.1, 10).expect("valid");
    let (out, report) = reducer.reduce(&mixture).expect("valid mixture");
    assert_eq!((report.truncated, report.merged, report.capped), (1, 1, 0));
    assert_eq!(out.len(), 2);
    let merged = &out[0];
    assert_eq!(merged.label, Label(1));
    // A handful of roundings of numbers near 1: 1e-15 is generous.
    assert!((merged.weight - 0.9).abs() < 1e-15);
    assert!((merged.density.mean()[0] - 1.0 / 30.0).abs() < 1e-15);
    assert!((merged.density.cov()[(0, 0)] - (1.0 + 1.0 / 450.0)).abs() < 1e-15);
    assert_eq!(merged.measurement, Some(1), "provenance of the heaviest member");
    assert_eq!(out[1].label, Label(3));

    // J_max = 1 keeps the heaviest.
    let (capped, report) = MixtureReducer::new(0.01, 0.1, 1).expect("valid").reduce(&mixture).expect("valid");
    assert_eq!(report.capped, 1);
    assert_eq!(capped.len(), 1);
    assert_eq!(capped[0].label, Label(1));

    // Same means with U = 0: only identical means merge.
    let (apart, _) = MixtureReducer::new(0.01, 0.0, 10).expect("valid").reduce(&mixture).expect("valid");
    assert_eq!(apart.len(), 3);
}

/// Table III with labels: two extracted components sharing label 4 (w 0.9 and
/// 0.7): the heavier keeps 4, the other gets a fresh label written back into
/// the mixture; a component of weight 2.2 yields two estimates; weight 0.3 is
/// below the threshold.
#[test]
fn extraction_relabels_duplicates_and_repeats_heavy_components() {
    let mut mixture =
        vec![comp(4, 0.7, 1.0, 1.0), comp(4, 0.9, 5.0, 1.0), comp(6, 2.2, 9.0, 1.0), comp(7, 0.3, 0.0, 1.0)];
    let mut next = 100;
    let est = StateExtractor::new(0.5).expect("valid").extract(&mut mixture, &mut || {
        next += 1;
        Label(next)
    });
    let got: Vec<(u64, f64)> = est.iter().map(|e| (e.label.0, e.density.mean()[0])).collect();
    assert_eq!(got, vec![(4, 5.0), (6, 9.0), (101, 1.0), (102, 9.0)]);
    assert_eq!(mixture[0].label, Label(101), "relabel written back");
    assert_eq!(mixture[2].label, Label(6), "extra copies do not relabel the component");
}

/// With no measurements at all, the mixture decays by p_S (1 - p_D) per step
/// and is truncated; nothing panics and the cardinality goes to 0.
#[test]
fn empty_measurement_sets_decay_the_mixture() {
    let mut f = filter();
    let birth = WeightedGaussian {
        weight: 1.0,
        density: Gaussian::new(v(&[0.0, 0.0]), m(2, 2, &[1.0, 0.0, 0.0, 1.0])).expect("valid"),
    };
    f.step(0.0, vec![birth], &[], &NoGate).expect("valid");
    // 1.0 * (1 - 0.9) = 0.1 after the first update.
    assert!((f.expected_cardinality() - 0.1).abs() < 1e-15);
    for _ in 0..3 {
        f.step(1.0, Vec::new(), &[], &NoGate).expect("valid");
    }
    // 0.1 * 0.099 = 0.0099 > 1e-3 survives one more step, then 9.8e-4 is truncated.
    assert!(f.mixture().is_empty(), "{:?}", f.mixture());
    assert_eq!(f.expected_cardinality(), 0.0);
}
