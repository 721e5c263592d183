//! Geometric Doppler-bearing tracking of a multipath component (Zoechmann et
//! al. 2019): the relative position and velocity of a non-accelerating
//! transmitter (or reflector) from quantised azimuths (the strongest beam of
//! a codebook scan) and noisy Doppler shifts, its batch baseline and two
//! genie bounds.
//!
//! # Model (Sec. III, Fig. 3)
//! The receiver array sits at the origin; the tracked component moves on a
//! straight line with constant relative velocity `v`. At the *initial
//! reference* epoch `i` it is at range `r_i` and azimuth `phi_i`; `alpha_i`
//! is the angle from the radial (outward) direction to `v`, so the velocity's
//! angle to the x axis is `alpha_i + phi_i`. With `b_i:k = phi_k - phi_i` and
//! `t_i:k = t_k - t_i`, the state
//!
//! ```text
//! x^i = [r_i, v sin(alpha_i), v cos(alpha_i)]
//! ```
//!
//! satisfies one bearing equation (2) and one Doppler equation (5) per epoch:
//!
//! ```text
//! a_B^T x^i = 0,     a_B = [sin b, -t cos b, t sin b]                       (2)
//! a_D^T x^i = nu_k,  a_D = [0, sin b / lambda, cos b / lambda]              (4)-(5)
//! ```
//!
//! `nu_k = v cos(alpha_k) / lambda` is the range rate over the wavelength
//! (positive when the range grows; the physical Doppler shift is its
//! negative, and a receiver flips the sign). The receiver replaces `b` by
//! `b^ = phi^_k - phi^_i` from its quantised azimuths ("errors in
//! variables"). The state gives position and velocity at any time by the
//! projection (10)-(11) ([`PolarState`]).
//!
//! # Estimators
//! - [`GeometricTracker`]: the proposed recursive tracker (Sec. IV): fixed
//!   initial reference, H-infinity (15)-(19) with `gamma = 2` and
//!   `x^_0 = 0` until three distinct azimuths were measured, then RLS in
//!   information form;
//! - [`HoChanBatch`]: the batch geometric-polar estimator of Ho and Chan
//!   (2008) with a running reference (the current epoch), the paper's
//!   baseline;
//! - [`ErrorFreeRegressors`]: the least-squares solution of (7) with the
//!   true (unquantised) azimuths, the first genie of Sec. V;
//! - [`NullspaceProjection`]: the nullspace-projected solution (20)-(21)
//!   with the true azimuths, the second genie;
//! - [`BeamSchedule`]: which beams a receiver measures (full scans for the
//!   first 10 epochs, then the 3 beams nearest the projected azimuth, Sec.
//!   VI), with [`BeamCount`] for the measurement accounting;
//! - [`batch`]: direct batch solves of the same equations on faer (stacked
//!   systems, QR and SVD), the references the recursions are tested against.
//!
//! All estimators take the same [`DopplerBearing`] observations (the genies
//! are simply fed the true azimuths) and implement [`RangeEstimator`].
//!
//! # Small matrices
//! The systems are 3x3 (4x4 for the batch baseline's accumulated normal
//! equations) and are solved once per epoch for every estimator of every
//! Monte Carlo run (10^8 solves in `mmtrack reproduce zoechmann`), so the
//! hot path uses closed-form 3x3 Cholesky solves and cross products on
//! stack arrays; faer is used where a factorisation must cope with rank
//! deficiency (the rare minimum-norm fallback) and in [`batch`].
//!
//! # References
//! E. Zoechmann, V. Va, M. Rupp, R. W. Heath Jr., "Geometric tracking of
//! vehicular mmWave channels to enable machine learning of onboard sensors",
//! 2019 (`../shared/seeds/zochmann2019-geometric-doppler-bearing-tracking.md`):
//! eq. (1)-(21), Sec. VI. K. C. Ho, Y. T. Chan, "Geometric-polar tracking from
//! bearings-only and Doppler-bearing measurements", IEEE TSP 56(11), 2008.

pub mod batch;
mod genie;
mod ho_chan;
mod linalg;
mod recursive;
mod selection;

pub use genie::{ErrorFreeRegressors, NullspaceProjection};
pub use ho_chan::HoChanBatch;
pub use recursive::{FilterMode, GeometricTracker, GeometricTrackerConfig};
pub use selection::{BeamCount, BeamSchedule, BeamSelection};

/// What can go wrong in this module. (Its own enum beside the crate's
/// [`crate::BeamError`], which covers the pilot-driven trackers.)
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GeometricError {
    /// A configuration value is outside its meaningful range.
    #[error("geometric tracker config: {field} = {value} is invalid: expected {expected}")]
    BadConfig {
        /// The field.
        field: &'static str,
        /// Its value, as text.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// An observation is not finite or not after the previous one.
    #[error("observation of epoch {epoch}: {field} = {value} is invalid")]
    BadObservation {
        /// Epoch index since the estimator started.
        epoch: usize,
        /// The field.
        field: &'static str,
        /// Its value, as text (with what was expected).
        value: String,
    },
    /// A matrix that must be positive definite is not (numerically), or an
    /// estimate came out non-finite.
    #[error("epoch {epoch}: {detail}")]
    Numerical {
        /// Epoch index since the estimator started.
        epoch: usize,
        /// What failed.
        detail: &'static str,
    },
}

/// One epoch's measurements: time, the azimuth of the strongest beam (or
/// the true azimuth for a genie) and the Doppler shift (range rate over the
/// wavelength, module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DopplerBearing {
    /// Time of the epoch, seconds (any origin; only differences matter).
    pub t_s: f64,
    /// Measured azimuth, radians (counter-clockwise from the array's x axis).
    pub azimuth_rad: f64,
    /// Doppler shift `nu = (dr/dt) / lambda`, Hz.
    pub doppler_hz: f64,
}

impl DopplerBearing {
    /// Errors unless every field is finite.
    pub(crate) fn check(&self, epoch: usize) -> Result<(), GeometricError> {
        for (field, value) in [("t_s", self.t_s), ("azimuth_rad", self.azimuth_rad), ("doppler_hz", self.doppler_hz)] {
            if !value.is_finite() {
                return Err(GeometricError::BadObservation { epoch, field, value: value.to_string() });
            }
        }
        Ok(())
    }
}

/// A polar state `x^i = [r_i, v sin(alpha_i), v cos(alpha_i)]` at a reference
/// epoch (time `t_ref_s`, azimuth `azimuth_ref_rad`), with the projection
/// (10)-(11) to any time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolarState {
    /// Time of the reference epoch, seconds.
    pub t_ref_s: f64,
    /// Azimuth `phi_i` of the reference epoch, radians.
    pub azimuth_ref_rad: f64,
    /// `[r_i, v sin(alpha_i), v cos(alpha_i)]`: metres, m/s, m/s.
    pub x: [f64; 3],
}

impl PolarState {
    /// Position relative to the reference direction at `t_s`:
    /// `(x1 + t x3, t x2)` with `t = t_s - t_ref_s`.
    fn along_across(&self, t_s: f64) -> (f64, f64) {
        let t = t_s - self.t_ref_s;
        (self.x[0] + t * self.x[2], t * self.x[1])
    }

    /// Range at `t_s`, metres (10): `sqrt(x1^2 + t^2 (x2^2 + x3^2) + 2 t x1
    /// x3)`, evaluated as the norm of `(x1 + t x3, t x2)` (the same number,
    /// never the root of a negative rounding error).
    #[must_use]
    pub fn range_m(&self, t_s: f64) -> f64 {
        let (along, across) = self.along_across(t_s);
        along.hypot(across)
    }

    /// Azimuth at `t_s`, radians (11): `phi_i + atan2(t x2, x1 + t x3)`,
    /// wrapped to `(-pi, pi]`.
    #[must_use]
    pub fn azimuth_rad(&self, t_s: f64) -> f64 {
        let (along, across) = self.along_across(t_s);
        mmtrack_core::wrap_angle_rad(self.azimuth_ref_rad + across.atan2(along))
    }

    /// Position `(x, y)` at `t_s` in the receiver's frame, metres.
    #[must_use]
    pub fn position_m(&self, t_s: f64) -> [f64; 2] {
        let (along, across) = self.along_across(t_s);
        let (s, c) = self.azimuth_ref_rad.sin_cos();
        [c * along - s * across, s * along + c * across]
    }

    /// Relative velocity `(vx, vy)`, m/s: `x3` along and `x2` across the
    /// reference direction.
    #[must_use]
    pub fn velocity_mps(&self) -> [f64; 2] {
        let (s, c) = self.azimuth_ref_rad.sin_cos();
        [c * self.x[2] - s * self.x[1], s * self.x[2] + c * self.x[1]]
    }

    /// Speed `v = sqrt(x2^2 + x3^2)`, m/s (Sec. III-B).
    #[must_use]
    pub fn speed_mps(&self) -> f64 {
        self.x[1].hypot(self.x[2])
    }
}

/// What every estimator of this module does: take one epoch's observation,
/// and give its current estimate.
pub trait RangeEstimator {
    /// Takes the observation of the next epoch (times must increase).
    ///
    /// # Errors
    /// [`GeometricError::BadObservation`] for a non-finite field or a time
    /// not after the previous one (the estimator is left unchanged);
    /// [`GeometricError::Numerical`] when a solve fails.
    fn update(&mut self, observation: &DopplerBearing) -> Result<(), GeometricError>;

    /// The current estimate as a polar state (projectable to any time);
    /// `None` before the first observation.
    fn state(&self) -> Option<PolarState>;

    /// Range at the last observation's time, metres; `None` before the first.
    fn range_now_m(&self) -> Option<f64>;
}

/// The bearing row `a_B` (2) for angle `b` and time `t` from the reference.
#[must_use]
pub fn bearing_row(b_rad: f64, t_s: f64) -> [f64; 3] {
    let (s, c) = b_rad.sin_cos();
    [s, -t_s * c, t_s * s]
}

/// The Doppler row `a_D` (5) for angle `b` and wavelength `lambda`.
#[must_use]
pub fn doppler_row(b_rad: f64, wavelength_m: f64) -> [f64; 3] {
    let (s, c) = b_rad.sin_cos();
    [0.0, s / wavelength_m, c / wavelength_m]
}

/// Checks a wavelength.
fn check_wavelength(wavelength_m: f64) -> Result<(), GeometricError> {
    check_config("wavelength_m", wavelength_m, wavelength_m > 0.0, "a positive wavelength in metres")
}

/// Errors unless `value` is finite and `ok`.
fn check_config(field: &'static str, value: f64, ok: bool, expected: &'static str) -> Result<(), GeometricError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(GeometricError::BadConfig { field, value: value.to_string(), expected })
    }
}

/// Checks that `t_s` is after `last`.
fn check_time(epoch: usize, t_s: f64, last: Option<f64>) -> Result<(), GeometricError> {
    match last {
        Some(last) if t_s <= last => Err(GeometricError::BadObservation {
            epoch,
            field: "t_s",
            value: format!("{t_s} (not after the previous epoch's {last})"),
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests;
