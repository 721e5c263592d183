//! The extended Kalman filter: it reduces to the linear filter on a linear
//! model, its finite-difference check agrees with an analytic Jacobian, and
//! a range measurement pulls the estimate as the hand computation says.

use mmtrack_filter::faer::{Col, Mat};
use mmtrack_filter::{
    ExtendedKalmanUpdater, FilterError, Gaussian, KalmanUpdater, LinearMeasurement, NonlinearMeasurement,
    numerical_jacobian, predict_linearised,
};

use crate::support::{m, v};

/// Range from the origin of a 2D position, `h(x) = |x|`, `H = x^T / |x|`.
struct Range {
    r: Mat<f64>,
}

impl NonlinearMeasurement for Range {
    fn state_dim(&self) -> usize {
        2
    }
    fn evaluate(&self, x: &Col<f64>) -> Result<(Col<f64>, Mat<f64>), FilterError> {
        let range = x.norm_l2();
        Ok((v(&[range]), m(1, 2, &[x[0] / range, x[1] / range])))
    }
    fn noise_cov(&self) -> &Mat<f64> {
        &self.r
    }
}

/// A linear model seen through the EKF interface.
struct Linear(LinearMeasurement);

impl NonlinearMeasurement for Linear {
    fn state_dim(&self) -> usize {
        self.0.state_dim()
    }
    fn evaluate(&self, x: &Col<f64>) -> Result<(Col<f64>, Mat<f64>), FilterError> {
        Ok((self.0.h() * x, self.0.h().clone()))
    }
    fn noise_cov(&self) -> &Mat<f64> {
        self.0.r()
    }
}

#[test]
fn on_a_linear_model_the_ekf_is_the_kalman_filter() {
    let prior = Gaussian::new(v(&[1.0, -2.0, 0.5]), m(3, 3, &[2.0, 0.3, 0.0, 0.3, 1.0, 0.1, 0.0, 0.1, 0.5])).unwrap();
    let model =
        LinearMeasurement::new(m(2, 3, &[1.0, 0.0, 2.0, 0.0, 1.0, -1.0]), m(2, 2, &[0.5, 0.1, 0.1, 0.4])).unwrap();
    let z = v(&[2.0, -1.0]);
    let linear = KalmanUpdater::new(model.clone()).update(&prior, &z).unwrap();
    let extended = ExtendedKalmanUpdater::default().update(&prior, &Linear(model), &z).unwrap();
    // The same arithmetic in the same order: identical to the last bit.
    assert_eq!(linear, extended);
}

#[test]
fn range_update_by_hand() {
    // Prior N([3, 4], I): range 5, H = [0.6, 0.8], S = H H^T + R = 1 + 1 = 2,
    // K = H^T / 2 = [0.3, 0.4]; z = 6 moves the mean by K (6 - 5).
    let prior = Gaussian::new(v(&[3.0, 4.0]), m(2, 2, &[1.0, 0.0, 0.0, 1.0])).unwrap();
    let model = Range { r: m(1, 1, &[1.0]) };
    let post = ExtendedKalmanUpdater::default().update(&prior, &model, &v(&[6.0])).unwrap();
    assert!((post.mean()[0] - 3.3).abs() < 1e-14 && (post.mean()[1] - 4.4).abs() < 1e-14, "{:?}", post.mean());
    // P+ = I - K H (optimal gain): [[1 - 0.18, -0.24], [-0.24, 1 - 0.32]].
    let want = m(2, 2, &[0.82, -0.24, -0.24, 0.68]);
    for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
        assert!((post.cov()[(i, j)] - want[(i, j)]).abs() < 1e-14, "{:?}", post.cov());
    }
}

#[test]
fn numerical_jacobian_agrees_with_the_analytic_one() {
    let model = Range { r: m(1, 1, &[1.0]) };
    let x = v(&[-2.0, 7.0]);
    let (_, analytic) = model.evaluate(&x).unwrap();
    let numeric = numerical_jacobian(|x| model.evaluate(x).unwrap().0, &x, &[1e-5, 1e-5]);
    // Central differences on a smooth function of scale 7: error ~ h^2 / |x|.
    assert!((&analytic - &numeric).norm_max() < 1e-9, "{analytic:?} vs {numeric:?}");
}

#[test]
fn predict_linearised_takes_the_models_mean_and_propagates_the_covariance() {
    let prior = Gaussian::new(v(&[1.0, 2.0]), m(2, 2, &[1.0, 0.0, 0.0, 4.0])).unwrap();
    let f = m(2, 2, &[1.0, 0.5, 0.0, 1.0]);
    let q = m(2, 2, &[0.1, 0.0, 0.0, 0.1]);
    let predicted = predict_linearised(&prior, v(&[9.0, 9.0]), &f, &q).unwrap();
    assert_eq!(predicted.mean(), &v(&[9.0, 9.0]));
    // F P F^T + Q = [[1 + 1 + 0.1, 2], [2, 4.1]].
    assert_eq!(predicted.cov(), &m(2, 2, &[2.1, 2.0, 2.0, 4.1]));
    assert!(matches!(predict_linearised(&prior, v(&[1.0]), &f, &q), Err(FilterError::DimensionMismatch { .. })));
    assert!(predict_linearised(&prior, v(&[f64::NAN, 0.0]), &f, &q).is_err());
}
