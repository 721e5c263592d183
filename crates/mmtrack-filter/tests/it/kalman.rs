//! Known-answer Kalman step.

use mmtrack_filter::{CovarianceUpdate, FixedTransition, Gaussian, KalmanPredictor, KalmanUpdater, LinearMeasurement};

use crate::support::{m, v};

/// Prior N([0, 1], I), F = [[1, 1], [0, 1]], Q = 0, H = [1, 0], R = 1, z = 2.
/// By hand: predicted m = [1, 1], P = [[2, 1], [1, 1]]; S = 3, K = [2/3, 1/3];
/// posterior m = [5/3, 4/3], P = [[2/3, 1/3], [1/3, 2/3]].
#[test]
fn one_step_matches_hand_computation_in_both_covariance_forms() {
    let prior = Gaussian::new(v(&[0.0, 1.0]), m(2, 2, &[1.0, 0.0, 0.0, 1.0])).expect("valid prior");
    let predictor = KalmanPredictor::new(
        FixedTransition::new(m(2, 2, &[1.0, 1.0, 0.0, 1.0]), m(2, 2, &[0.0; 4])).expect("valid model"),
    );
    let predicted = predictor.predict(&prior, 1.0).expect("predicts");
    // Sums of small integers: exact in binary.
    assert_eq!(predicted.mean(), &v(&[1.0, 1.0]));
    assert_eq!(predicted.cov(), &m(2, 2, &[2.0, 1.0, 1.0, 1.0]));

    let model = LinearMeasurement::new(m(1, 2, &[1.0, 0.0]), m(1, 1, &[1.0])).expect("valid model");
    for form in [CovarianceUpdate::Joseph, CovarianceUpdate::Standard] {
        let updater = KalmanUpdater { model: model.clone(), covariance_update: form };
        let prep = updater.prepare(&predicted).expect("S is SPD");
        assert_eq!(prep.innovation_cov()[(0, 0)], 3.0);
        let post = prep.posterior(&v(&[2.0])).expect("finite z");
        // Thirds are inexact in binary; a few ulps of 1 separate the forms.
        let tol = 1e-14;
        assert!((post.mean()[0] - 5.0 / 3.0).abs() < tol, "{form:?}: {:?}", post.mean());
        assert!((post.mean()[1] - 4.0 / 3.0).abs() < tol);
        let want = m(2, 2, &[2.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 2.0 / 3.0]);
        for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            assert!((post.cov()[(i, j)] - want[(i, j)]).abs() < tol, "{form:?}: {:?}", post.cov());
        }
        // ln N(1; 0, 3) = -(ln(2 pi 3) + 1/3) / 2.
        let want = -0.5 * ((2.0 * std::f64::consts::PI * 3.0).ln() + 1.0 / 3.0);
        assert!((prep.log_likelihood(&v(&[2.0])).expect("finite z") - want).abs() < 1e-14);
        assert!((prep.mahalanobis_squared(&v(&[2.0])).expect("finite z") - 1.0 / 3.0).abs() < 1e-15);
    }
}

/// The Joseph form stays symmetric positive definite under a measurement far
/// more precise than the prior (R / P = 1e-12), where the standard form loses
/// precision: every posterior must still construct as a valid `Gaussian`, and
/// the Joseph variance must be within 1e-6 relative of the exact value.
#[test]
fn joseph_form_survives_a_very_precise_measurement() {
    let prior = Gaussian::new(v(&[0.0, 0.0]), m(2, 2, &[1e6, 1e3, 1e3, 1e2])).expect("valid prior");
    let model = LinearMeasurement::new(m(1, 2, &[1.0, 0.0]), m(1, 1, &[1e-6])).expect("valid model");
    let post = KalmanUpdater::new(model).update(&prior, &v(&[1.0])).expect("Joseph posterior is SPD");
    // Exact: P+_00 = P R / (P + R) = 1e6 * 1e-6 / (1e6 + 1e-6).
    let exact = 1.0 / (1e6 + 1e-6);
    assert!(((post.cov()[(0, 0)] - exact) / exact).abs() < 1e-6, "{:?}", post.cov());
}
