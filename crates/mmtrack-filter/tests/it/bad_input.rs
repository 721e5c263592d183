//! Bad input gives errors naming what is wrong, never a panic.

use mmtrack_filter::gmphd::{Component, MixtureReducer, StateExtractor, WeightedGaussian};
use mmtrack_filter::metrics::{gospa, ospa};
use mmtrack_filter::{
    ConstantVelocity, FilterError, Gaussian, GmPhdFilter, GmPhdParams, KalmanPredictor, KalmanUpdater, Label,
    LinearMeasurement, NoGate,
};
use proptest::prelude::*;

use crate::support::{m, v};

fn filter() -> GmPhdFilter<ConstantVelocity> {
    GmPhdFilter::new(
        KalmanPredictor::new(ConstantVelocity::new(1, 0.3).expect("valid")),
        KalmanUpdater::new(LinearMeasurement::position(1, 0.1).expect("valid")),
        GmPhdParams { p_survival: 0.99, p_detection: 0.95, clutter_intensity: 1e-3 },
        MixtureReducer::new(1e-2, 0.1, 100).expect("valid"),
        StateExtractor::new(0.2).expect("valid"),
    )
    .expect("valid")
}

fn birth(x: f64) -> WeightedGaussian {
    WeightedGaussian {
        weight: 0.5,
        density: Gaussian::new(v(&[x, 0.0]), m(2, 2, &[1.0, 0.0, 0.0, 1.0])).expect("valid"),
    }
}

#[test]
fn gaussian_rejects_wrong_shapes_nan_and_indefinite() {
    let e = Gaussian::new(v(&[0.0, 0.0]), m(3, 3, &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0])).unwrap_err();
    assert!(matches!(e, FilterError::DimensionMismatch { expected_rows: 2, found_rows: 3, .. }), "{e}");
    let e = Gaussian::new(v(&[f64::NAN]), m(1, 1, &[1.0])).unwrap_err();
    assert!(matches!(e, FilterError::NotFinite { row: 0, .. }), "{e}");
    let e = Gaussian::new(v(&[0.0]), m(1, 1, &[-1.0])).unwrap_err();
    assert!(matches!(e, FilterError::NotPositiveDefinite { .. }), "{e}");
    let e = Gaussian::new(v(&[0.0, 0.0]), m(2, 2, &[1.0, f64::INFINITY, f64::INFINITY, 1.0])).unwrap_err();
    assert!(matches!(e, FilterError::NotFinite { row: 1, col: 0, .. }), "{e}");
    assert!(LinearMeasurement::new(m(1, 2, &[1.0, 0.0]), m(1, 1, &[0.0])).is_err(), "R = 0 is not PD");
}

#[test]
fn parameters_out_of_range_are_named() {
    let e = GmPhdParams { p_survival: 0.99, p_detection: 1.5, clutter_intensity: 0.0 }.validate().unwrap_err();
    assert!(matches!(e, FilterError::InvalidParameter { name: "p_detection", .. }), "{e}");
    let e = GmPhdParams { p_survival: f64::NAN, p_detection: 0.5, clutter_intensity: 0.0 }.validate().unwrap_err();
    assert!(matches!(e, FilterError::InvalidParameter { name: "p_survival", .. }), "{e}");
    assert!(MixtureReducer::new(-1.0, 0.1, 10).is_err());
    assert!(MixtureReducer::new(0.01, 0.1, 0).is_err());
    assert!(StateExtractor::new(f64::INFINITY).is_err());
    assert!(ConstantVelocity::new(0, 1.0).is_err());
    assert!(ospa(&[v(&[0.0])], &[v(&[0.0])], 0.0, 1.0).is_err());
    assert!(gospa(&[v(&[0.0])], &[v(&[0.0])], 1.0, 0.5).is_err());
}

#[test]
fn filter_rejects_bad_measurements_and_births_and_keeps_its_state() {
    let mut f = filter();
    f.step(0.0, vec![birth(0.0)], &[v(&[0.0])], &NoGate).expect("valid");
    let before = f.mixture().to_vec();
    let e = f.step(1.0, Vec::new(), &[v(&[0.0]), v(&[f64::NAN])], &NoGate).unwrap_err();
    assert!(matches!(e, FilterError::Measurement { index: 1, .. }), "{e}");
    let e = f.step(1.0, Vec::new(), &[v(&[0.0, 1.0])], &NoGate).unwrap_err();
    assert!(matches!(e, FilterError::Measurement { index: 0, .. }), "{e}");
    let bad_birth =
        WeightedGaussian { weight: 1.0, density: Gaussian::new(v(&[0.0]), m(1, 1, &[1.0])).expect("valid") };
    let e = f.step(1.0, vec![birth(1.0), bad_birth], &[], &NoGate).unwrap_err();
    assert!(matches!(e, FilterError::Birth { index: 1, .. }), "{e}");
    let e = f.step(f64::NAN, Vec::new(), &[], &NoGate).unwrap_err();
    assert!(matches!(e, FilterError::InvalidParameter { name: "dt_s", .. }), "{e}");
    assert_eq!(f.mixture(), &before[..], "failed steps leave the mixture unchanged");

    // Motion and measurement models of different state dimension.
    let e = GmPhdFilter::new(
        KalmanPredictor::new(ConstantVelocity::new(2, 0.3).expect("valid")),
        KalmanUpdater::new(LinearMeasurement::position(1, 0.1).expect("valid")),
        GmPhdParams { p_survival: 0.99, p_detection: 0.95, clutter_intensity: 1e-3 },
        MixtureReducer::new(1e-2, 0.1, 100).expect("valid"),
        StateExtractor::new(0.2).expect("valid"),
    )
    .unwrap_err();
    assert!(matches!(e, FilterError::DimensionMismatch { .. }), "{e}");
}

#[test]
fn reducer_rejects_components_of_mixed_dimension() {
    let component =
        |label: u64, density: Gaussian| Component { label: Label(label), weight: 0.5, density, measurement: None };
    let mixture = vec![
        component(0, Gaussian::new(v(&[0.0, 0.0]), m(2, 2, &[1.0, 0.0, 0.0, 1.0])).expect("valid")),
        component(1, Gaussian::new(v(&[0.0]), m(1, 1, &[1.0])).expect("valid")),
    ];
    let e = MixtureReducer::new(1e-2, 0.1, 10).expect("valid").reduce(&mixture).unwrap_err();
    assert!(matches!(e, FilterError::DimensionMismatch { expected_rows: 2, found_rows: 1, .. }), "{e}");
}

#[test]
fn metrics_reject_mixed_dimensions_and_nan() {
    let e = ospa(&[v(&[0.0, 0.0])], &[v(&[0.0])], 1.0, 1.0).unwrap_err();
    assert!(matches!(e, FilterError::PointDimension { index: 0, expected: 2, found: 1, .. }), "{e}");
    let e = gospa(&[v(&[0.0])], &[v(&[1.0]), v(&[f64::NAN])], 1.0, 1.0).unwrap_err();
    assert!(matches!(e, FilterError::NotFinite { row: 1, .. }), "{e}");
}

proptest! {
    /// Arbitrary measurement sets (any length, any dimension, NaN and
    /// infinities included) and time steps: the filter returns Ok or Err,
    /// never panics, and a successful step keeps every weight finite.
    #[test]
    fn arbitrary_input_never_panics(
        steps in proptest::collection::vec(
            (prop_oneof![Just(f64::NAN), Just(-1.0), 0.0..10.0_f64],
             proptest::collection::vec(
                 proptest::collection::vec(prop_oneof![Just(f64::NAN), Just(f64::INFINITY), -1e3..1e3_f64], 0..3),
                 0..6)),
            1..8)
    ) {
        let mut f = filter();
        for (dt, zs) in steps {
            let zs: Vec<_> = zs.into_iter().map(|z| v(&z)).collect();
            let births = zs.iter().filter(|z| z.nrows() == 1 && z[0].is_finite()).map(|z| birth(z[0])).collect();
            if f.step(dt, births, &zs, &NoGate).is_ok() {
                prop_assert!(f.mixture().iter().all(|c| c.weight.is_finite() && c.weight >= 0.0));
            }
        }
    }
}
