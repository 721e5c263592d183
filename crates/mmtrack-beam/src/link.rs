//! What every pilot-driven beam tracker shares: the beam pair it points, the
//! predict / update roles, and the complex pilot written as a real
//! measurement.

use mmtrack_core::Complex64;
use mmtrack_filter::faer::{Col, Mat};
use mmtrack_filter::{ExtendedKalmanUpdater, Gaussian, NonlinearMeasurement, predict_linearised};

use crate::BeamError;

/// The beams for one pilot: receive and transmit steering direction cosines
/// (`u = cos` of the angle from the array axis, see `mmtrack_core::array`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamPair {
    /// Receive combiner direction cosine.
    pub rx_steer_u: f64,
    /// Transmit beamformer direction cosine.
    pub tx_steer_u: f64,
}

impl BeamPair {
    /// Angle of the transmit beam from the array axis, radians in `[0, pi]`.
    #[must_use]
    pub fn tx_angle_rad(&self) -> f64 {
        self.tx_steer_u.clamp(-1.0, 1.0).acos()
    }

    /// Angle of the receive beam from the array axis, radians in `[0, pi]`.
    #[must_use]
    pub fn rx_angle_rad(&self) -> f64 {
        self.rx_steer_u.clamp(-1.0, 1.0).acos()
    }
}

/// The roles of a tracker driven by one pilot per block.
pub trait PilotTracker {
    /// Predicts the link to the next block and returns the beams to sound
    /// it with (pointed from the prediction).
    ///
    /// # Errors
    /// The filter's errors.
    fn predict(&mut self) -> Result<BeamPair, BeamError>;

    /// Updates with the pilot received through the beams of the last
    /// [`PilotTracker::predict`].
    ///
    /// # Errors
    /// [`BeamError::BadPilot`] for a non-finite pilot,
    /// [`BeamError::UpdateWithoutPrediction`], the filter's errors.
    fn update(&mut self, pilot: Complex64) -> Result<(), BeamError>;
}

/// A tracker's predictor run open loop: [`PilotTracker::predict`] as the
/// tracker's, every pilot discarded. From the channel estimate of block 0,
/// the position-velocity EKF's prediction (eq. (24), `x[k+1|k] = A x[k|k]`)
/// then extrapolates the start at constant speed, `d[k] = d[0] + v[0] k dt`:
/// the baseline that tells what the measurement updates add.
#[derive(Debug, Clone)]
pub struct OpenLoop<T>(pub T);

impl<T: PilotTracker> PilotTracker for OpenLoop<T> {
    fn predict(&mut self) -> Result<BeamPair, BeamError> {
        self.0.predict()
    }

    /// Discards the pilot (no measurement update).
    fn update(&mut self, _pilot: Complex64) -> Result<(), BeamError> {
        Ok(())
    }
}

/// A complex pilot as the real measurement `[Re z, Im z]` (Shaham et al.
/// Sec. III-C).
pub(crate) fn stacked(z: Complex64) -> Col<f64> {
    Col::from_fn(2, |i| if i == 0 { z.re } else { z.im })
}

/// Noise covariance of the stacked pilot: `n ~ CN(0, sigma_n^2)` puts
/// `sigma_n^2 / 2` on each of the real and imaginary parts.
pub(crate) fn stacked_noise_cov(noise_variance: f64) -> Mat<f64> {
    Mat::from_fn(2, 2, |i, j| if i == j { 0.5 * noise_variance } else { 0.0 })
}

/// Writes the derivative `dz/dx_j` of a complex measurement into column `j`
/// of the stacked Jacobian `[Re dz/dx; Im dz/dx]`.
pub(crate) fn set_complex_column(jacobian: &mut Mat<f64>, j: usize, dz: Complex64) {
    jacobian[(0, j)] = dz.re;
    jacobian[(1, j)] = dz.im;
}

/// Checks a received pilot.
pub(crate) fn check_pilot(block: usize, pilot: Complex64) -> Result<(), BeamError> {
    if pilot.re.is_finite() && pilot.im.is_finite() {
        Ok(())
    } else {
        Err(BeamError::BadPilot { block, value: pilot.to_string() })
    }
}

/// The recursion the pilot EKFs share: linear motion `x[k+1] = A x[k] + u`,
/// `u ~ N(0, Q)`, started at the channel estimate with `P[1|0]` given; an
/// EKF update per pilot through the beams pointed from the prediction. It
/// keeps the block count and the beams in flight, so a tracker only says
/// how a state points the beams and what pilot it predicts.
#[derive(Debug, Clone)]
pub(crate) struct PilotEkf {
    transition: Mat<f64>,
    process_cov: Mat<f64>,
    initial_cov: Mat<f64>,
    state: Gaussian,
    block: usize,
    beams: Option<BeamPair>,
}

impl PilotEkf {
    /// Starts at `start` (block 0); `initial_cov` is `P[1|0]`.
    pub(crate) fn new(
        start: Col<f64>,
        transition: Mat<f64>,
        process_cov: Mat<f64>,
        initial_cov: Mat<f64>,
    ) -> Result<Self, BeamError> {
        let state =
            Gaussian::new(start, initial_cov.clone()).map_err(|source| BeamError::Filter { block: 0, source })?;
        Ok(Self { transition, process_cov, initial_cov, state, block: 0, beams: None })
    }

    /// The current estimate (after the last predict or update).
    pub(crate) fn state(&self) -> &Gaussian {
        &self.state
    }

    /// Predicts the next block (`P[1|0]` for the first) and points the beams
    /// from the predicted mean with `point`.
    pub(crate) fn predict(&mut self, point: impl FnOnce(&Col<f64>) -> BeamPair) -> Result<BeamPair, BeamError> {
        let block = self.block + 1;
        let mean = &self.transition * self.state.mean();
        let predicted = if self.block == 0 {
            Gaussian::new(mean, self.initial_cov.clone())
        } else {
            predict_linearised(&self.state, mean, &self.transition, &self.process_cov)
        };
        self.state = predicted.map_err(|source| BeamError::Filter { block, source })?;
        self.block = block;
        let beams = point(self.state.mean());
        self.beams = Some(beams);
        Ok(beams)
    }

    /// Updates with the pilot received through the beams of the last
    /// prediction; `model` gives the measurement for those beams.
    pub(crate) fn update<M: NonlinearMeasurement>(
        &mut self,
        pilot: Complex64,
        model: impl FnOnce(BeamPair) -> M,
    ) -> Result<(), BeamError> {
        let block = self.block;
        let beams = self.beams.take().ok_or(BeamError::UpdateWithoutPrediction { block })?;
        check_pilot(block, pilot)?;
        let model = model(beams);
        self.state = ExtendedKalmanUpdater::default()
            .update(&self.state, &model, &stacked(pilot))
            .map_err(|source| BeamError::Filter { block, source })?;
        Ok(())
    }
}
