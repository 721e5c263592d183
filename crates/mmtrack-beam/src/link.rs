//! What every pilot-driven beam tracker shares: the beam pair it points, the
//! predict / update roles, and the complex pilot written as a real
//! measurement.

use mmtrack_core::Complex64;
use mmtrack_filter::faer::{Col, Mat};

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
