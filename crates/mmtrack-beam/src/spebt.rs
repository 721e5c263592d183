//! The beam-tracking EKF of SPEBT (Liu et al. 2024, Sec. III-B/C): the
//! line-of-sight channel `s = [|alpha|, phi, psi]` of a base station (BS) to
//! a vehicle, whose evolution is driven by the vehicle's *estimated* poses
//! (from radar odometry, GNSS, or ground truth plus a pose-error model) and
//! corrected by the power of one pilot per slot.
//!
//! # Geometry (Fig. 1, Appendix A)
//! The BS sits at `b`; the vehicle's pose at slot `k` is `(p_k, theta_k)`
//! (position, yaw counter-clockwise from the world x axis). With
//! `r_k = p_k - b` the vector from the BS to the vehicle:
//!
//! ```text
//! |alpha_k| = |alpha_ref| (d0 / |r_k|)^(gamma/2)                           (22)
//! phi_k     = atan2(r_k.y, r_k.x)              AoD, from the BS array axis (along world x)
//! psi_k     = phi_k + pi - theta_k             AoA, from the vehicle's heading (Appendix A: theta - phi + psi = pi)
//! ```
//!
//! Both arrays are ULAs that see an angle only through its cosine
//! (`mmtrack_core::array`, `a(angle) = a(u = cos angle)`, eq. (2)-(3)).
//!
//! # Evolution (Proposition 2 without `arg alpha`, eq. (15)-(19))
//! With the estimated poses `(r^_{k-1}, theta^_{k-1})`, `(r^_k, theta^_k)`:
//!
//! ```text
//! s_k|k-1 = F_k s_k-1|k-1 + u_k,   F_k = diag(rho^_k, 1, 1),   rho^_k = (|r^_k-1| / |r^_k|)^(gamma/2)
//! u_k     = [0, u3, u3 - dtheta^_k],   u3 = wrap(bearing(r^_k) - bearing(r^_k-1)),
//!           dtheta^_k = wrap(theta^_k - theta^_k-1)
//! P_k|k-1 = F_k P_k-1|k-1 F_k^T + Q_k
//! Q_k     = [[(gamma/2 rho^_k |alpha_k-1|)^2 beta_k sigma_r^2, 0, 0],
//!            [0, beta_k sigma_r^2, beta_k sigma_r^2],
//!            [0, beta_k sigma_r^2, beta_k sigma_r^2 + 2 sigma_theta^2]]              (16)-(17)
//! beta_k  = 1 / |r^_k-1|^2 + 1 / |r^_k|^2
//! ```
//!
//! `Q_k` is (16)-(17) with the `arg alpha` row and column removed; the
//! `|alpha|`-`phi` and `|alpha|`-`psi` covariances are zero because the
//! position error enters `|alpha|` along `r^` and the bearing across it.
//! `|alpha_k-1|` is the previous estimate.
//!
//! Where the seed text is garbled: its `u3 = arctan(x_k / y_k) arctan(x_k-1 /
//! y_k-1)` is read as the change of the four-quadrant bearing of `r`,
//! `atan2(y, x)`, the only reading consistent with Appendix A's
//! `theta - phi + psi = pi` and with `u4 = u3 - dtheta` (eq. (14)).
//!
//! # Measurement (eq. (20)-(21), Appendix C)
//! Beams come from the previous estimate (Algorithm 1 step 8):
//! `f_k = a_t(phi_k-1|k-1)`, `g_k = a_r(psi_k-1|k-1)`. The filter uses the
//! pilot's power only:
//!
//! ```text
//! z~_k = |z_k|^2 - sigma_v^2 = h(s_k) + v_k,   h(s) = |b|^2 |alpha|^2 G_r(psi) G_t(phi)
//! G_t(phi) = |f^H a_t(phi)|^2 = |AF_t(cos phi)|^2,   G_r(psi) = |g^H a_r(psi)|^2
//! dh/d|alpha| = 2 |b|^2 |alpha| G_r G_t
//! dh/dphi     = |b|^2 |alpha|^2 G_r 2 Re(conj(AF_t) AF_t'(cos phi)) (-sin phi)     (26)
//! dh/dpsi     = |b|^2 |alpha|^2 G_t 2 Re(conj(AF_r) AF_r'(cos psi)) (-sin psi)
//! var v_k     = (sigma_v^2 + 2 h(s_k|k-1)) sigma_v^2                               (21)
//! ```
//!
//! The update is the ordinary EKF update `s_k|k = s_k|k-1 + K (z~ -
//! h(s_k|k-1))` (Algorithm 1 step 12 is garbled into a linear form in the
//! seed text), in Joseph form, with the noise variance evaluated at the
//! prediction.
//!
//! # Re-initialisation (Algorithm 1 steps 3, 14-15)
//! Initial access gives `s_I`; the filter starts at `s_0|0 = s_I`,
//! `P_0|0 = Q_0` (with `r^_-1 = r^_0`). After each update, when
//! `||alpha_k| - |alpha_I|| > alpha~` or `|phi_k - phi_I| > phi~` or
//! `|psi_k - psi_I| > psi~` (angles wrapped), [`SpebtEkf::update`] reports
//! [`Deviation::Exceeded`]: the caller runs initial access again and calls
//! [`SpebtEkf::reinitialise`] with the new `s_I`. *Initial* means the latest
//! initial access: each re-initialisation replaces the reference `s_I`
//! (against the first slot's channel alone every turn of the road would
//! trigger a new access at every later slot). The covariance is reset as at
//! the start, `P_k|k = Q_k` (the paper resets only the state).
//!
//! # References
//! C. Liu, G. Zhu, F. Liu, Y. Liu, "Successive pose estimation and beam
//! tracking for mmWave vehicular communication systems", 2024
//! (`../shared/seeds/liu2024-spebt-fast-cfear.md`): eq. (1)-(5), (12)-(22),
//! (26), Algorithm 1, Appendices A-C.

use mmtrack_core::array::UniformLinearArray;
use mmtrack_core::{Complex64, Se2, wrap_angle_rad};
use mmtrack_filter::faer::{Col, Mat};
use mmtrack_filter::{ExtendedKalmanUpdater, FilterError, Gaussian, NonlinearMeasurement, predict_linearised};
use serde::{Deserialize, Serialize};

use crate::error::check;
use crate::link::check_pilot;
use crate::{BeamError, BeamPair};

/// Parameters of [`SpebtEkf`] (Liu et al. Table I for the paper's values).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpebtConfig {
    /// Elements `N` of the BS array.
    pub bs_elements: usize,
    /// Elements `M` of the vehicle's array.
    pub vehicle_elements: usize,
    /// Element spacing `d`, wavelengths (both arrays).
    pub spacing_wavelengths: f64,
    /// Path-loss exponent `gamma`.
    pub path_loss_exponent: f64,
    /// BS position `b`, world x, metres.
    pub bs_x_m: f64,
    /// BS position `b`, world y, metres.
    pub bs_y_m: f64,
    /// Pilot power `|b_k|^2`, watts.
    pub pilot_power_w: f64,
    /// Receiver noise variance `sigma_v^2`, watts.
    pub noise_variance_w: f64,
    /// Standard deviation `sigma_r` of each position coordinate of a pose
    /// estimate, metres.
    pub position_sigma_m: f64,
    /// Standard deviation `sigma_theta` of a yaw estimate, radians.
    pub yaw_sigma_rad: f64,
    /// Re-initialisation threshold `alpha~` on `|alpha|` (linear amplitude).
    pub gain_threshold: f64,
    /// Re-initialisation threshold `phi~` on the AoD, radians.
    pub aod_threshold_rad: f64,
    /// Re-initialisation threshold `psi~` on the AoA, radians.
    pub aoa_threshold_rad: f64,
}

/// The channel state `s = [|alpha|, phi, psi]` (eq. (18)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpebtState {
    /// Path-gain magnitude `|alpha|` (linear amplitude).
    pub gain_magnitude: f64,
    /// AoD `phi`, radians from the BS array axis.
    pub aod_rad: f64,
    /// AoA `psi`, radians from the vehicle's heading.
    pub aoa_rad: f64,
}

impl SpebtState {
    fn to_col(self) -> Col<f64> {
        Col::from_fn(3, |i| [self.gain_magnitude, self.aod_rad, self.aoa_rad][i])
    }

    fn is_finite(&self) -> bool {
        self.gain_magnitude.is_finite() && self.aod_rad.is_finite() && self.aoa_rad.is_finite()
    }
}

/// The outcome of the deviation check after an update (Algorithm 1 step 14).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[must_use]
pub enum Deviation {
    /// Every component within its threshold of `s_I`: keep tracking.
    Within,
    /// A component left its threshold: run initial access and call
    /// [`SpebtEkf::reinitialise`].
    Exceeded {
        /// `||alpha_k| - |alpha_I|| > alpha~`.
        gain: bool,
        /// `|phi_k - phi_I| > phi~`.
        aod: bool,
        /// `|psi_k - psi_I| > psi~`.
        aoa: bool,
    },
}

/// The tracker (module docs).
#[derive(Debug, Clone)]
pub struct SpebtEkf {
    config: SpebtConfig,
    bs_array: UniformLinearArray,
    vehicle_array: UniformLinearArray,
    /// `s_k|k` after an update, `s_k|k-1` between predict and update.
    state: Gaussian,
    /// `s_I`, the latest initial access.
    reference: SpebtState,
    /// The pose estimate of the last slot, `(r^_k-1, theta^_k-1)`.
    last_pose: Se2,
    /// The process covariance of the last prediction (the reset covariance
    /// of a re-initialisation).
    last_process_cov: Mat<f64>,
    slot: usize,
    beams: Option<BeamPair>,
}

impl SpebtEkf {
    /// Starts at slot 0 from initial access `initial_access` (`s_I`) and the
    /// pose estimate `pose` of that slot (Algorithm 1 step 3).
    ///
    /// # Errors
    /// [`BeamError::BadConfig`] naming a bad parameter or start value;
    /// [`BeamError::BadPose`] for a pose that is not finite or sits on the BS.
    pub fn new(config: &SpebtConfig, initial_access: SpebtState, pose: &Se2) -> Result<Self, BeamError> {
        let c = config;
        let array = |field: &'static str, elements: usize| {
            UniformLinearArray::new(elements, c.spacing_wavelengths).map_err(|_| BeamError::BadConfig {
                field,
                value: format!("{elements} elements, spacing {}", c.spacing_wavelengths),
                expected: "at least one element and a positive spacing",
            })
        };
        let (bs_array, vehicle_array) =
            (array("bs_elements", c.bs_elements)?, array("vehicle_elements", c.vehicle_elements)?);
        check("path_loss_exponent", c.path_loss_exponent, c.path_loss_exponent > 0.0, "a positive exponent")?;
        check("bs_x_m", c.bs_x_m, true, "a finite coordinate")?;
        check("bs_y_m", c.bs_y_m, true, "a finite coordinate")?;
        check("pilot_power_w", c.pilot_power_w, c.pilot_power_w > 0.0, "a positive power")?;
        check("noise_variance_w", c.noise_variance_w, c.noise_variance_w > 0.0, "a positive variance")?;
        check("position_sigma_m", c.position_sigma_m, c.position_sigma_m > 0.0, "a positive standard deviation")?;
        check("yaw_sigma_rad", c.yaw_sigma_rad, c.yaw_sigma_rad > 0.0, "a positive standard deviation")?;
        check("gain_threshold", c.gain_threshold, c.gain_threshold > 0.0, "a positive threshold")?;
        check("aod_threshold_rad", c.aod_threshold_rad, c.aod_threshold_rad > 0.0, "a positive threshold")?;
        check("aoa_threshold_rad", c.aoa_threshold_rad, c.aoa_threshold_rad > 0.0, "a positive threshold")?;
        check_initial_access(&initial_access)?;
        let range_m = range_to(c, pose, 0)?;
        let process_cov = process_cov(c, 1.0, range_m, range_m, initial_access.gain_magnitude);
        let state = Gaussian::new(initial_access.to_col(), process_cov.clone())
            .map_err(|source| BeamError::Filter { block: 0, source })?;
        Ok(Self {
            config: c.clone(),
            bs_array,
            vehicle_array,
            state,
            reference: initial_access,
            last_pose: *pose,
            last_process_cov: process_cov,
            slot: 0,
            beams: None,
        })
    }

    /// Algorithm 1 steps 8-10 for the next slot: the beams from the previous
    /// estimate, then the prediction driven by the pose estimate `pose` of
    /// the new slot. Returns the beams to receive this slot's pilot with.
    ///
    /// # Errors
    /// [`BeamError::BadPose`] for a pose that is not finite or sits on the
    /// BS; [`BeamError::Filter`] when the covariance loses definiteness.
    pub fn predict(&mut self, pose: &Se2) -> Result<BeamPair, BeamError> {
        let slot = self.slot + 1;
        let c = &self.config;
        let previous_range_m = range_to(c, &self.last_pose, slot - 1)?;
        let range_m = range_to(c, pose, slot)?;
        let x = self.state.mean();
        // Step 8: f_k = a_t(phi_k-1|k-1), g_k = a_r(psi_k-1|k-1).
        let beams = BeamPair { rx_steer_u: x[2].cos(), tx_steer_u: x[1].cos() };
        let rho = (previous_range_m / range_m).powf(0.5 * c.path_loss_exponent);
        let bearing_change = wrap_angle_rad(bearing_rad(c, pose) - bearing_rad(c, &self.last_pose));
        let yaw_change = wrap_angle_rad(pose.yaw_rad - self.last_pose.yaw_rad);
        let mean = Col::from_fn(3, |i| match i {
            0 => rho * x[0],
            1 => x[1] + bearing_change,
            _ => x[2] + bearing_change - yaw_change,
        });
        let transition = Mat::from_fn(3, 3, |i, j| match (i, j) {
            (0, 0) => rho,
            (i, j) if i == j => 1.0,
            _ => 0.0,
        });
        let q = process_cov(c, rho, previous_range_m, range_m, x[0].abs());
        self.state = predict_linearised(&self.state, mean, &transition, &q)
            .map_err(|source| BeamError::Filter { block: slot, source })?;
        self.last_process_cov = q;
        self.last_pose = *pose;
        self.slot = slot;
        self.beams = Some(beams);
        Ok(beams)
    }

    /// Algorithm 1 steps 11-14: the update with the pilot `z_k` received
    /// through the beams of the last [`SpebtEkf::predict`], then the
    /// deviation check against `s_I`.
    ///
    /// # Errors
    /// [`BeamError::BadPilot`] for a non-finite pilot,
    /// [`BeamError::UpdateWithoutPrediction`], [`BeamError::Filter`].
    pub fn update(&mut self, pilot: Complex64) -> Result<Deviation, BeamError> {
        let slot = self.slot;
        let beams = self.beams.take().ok_or(BeamError::UpdateWithoutPrediction { block: slot })?;
        check_pilot(slot, pilot)?;
        let sigma2 = self.config.noise_variance_w;
        let mut model = PowerPilot {
            bs_array: self.bs_array,
            vehicle_array: self.vehicle_array,
            beams,
            pilot_power_w: self.config.pilot_power_w,
            noise_cov: Mat::zeros(1, 1),
        };
        let predicted = model.power(self.state.mean());
        // (21): var = (sigma_v^2 + 2 h(s)) sigma_v^2 at the prediction.
        model.noise_cov[(0, 0)] = (sigma2 + 2.0 * predicted.max(0.0)) * sigma2;
        let z = Col::from_fn(1, |_| pilot.norm_sqr() - sigma2);
        self.state = ExtendedKalmanUpdater::default()
            .update(&self.state, &model, &z)
            .map_err(|source| BeamError::Filter { block: slot, source })?;
        Ok(self.deviation())
    }

    /// Algorithm 1 step 15: a new initial access `s_I` becomes the state and
    /// the reference of the deviation check; the covariance is reset to the
    /// last prediction's `Q_k` (module docs).
    ///
    /// # Errors
    /// [`BeamError::BadConfig`] for a non-finite or negative `initial_access`.
    pub fn reinitialise(&mut self, initial_access: SpebtState) -> Result<(), BeamError> {
        check_initial_access(&initial_access)?;
        self.state = Gaussian::new(initial_access.to_col(), self.last_process_cov.clone())
            .map_err(|source| BeamError::Filter { block: self.slot, source })?;
        self.reference = initial_access;
        self.beams = None;
        Ok(())
    }

    /// The current estimate, angles wrapped to `(-pi, pi]`.
    #[must_use]
    pub fn estimate(&self) -> SpebtState {
        let x = self.state.mean();
        SpebtState { gain_magnitude: x[0], aod_rad: wrap_angle_rad(x[1]), aoa_rad: wrap_angle_rad(x[2]) }
    }

    /// The current estimate and covariance (angles not wrapped).
    #[must_use]
    pub fn state(&self) -> &Gaussian {
        &self.state
    }

    /// The reference `s_I` of the deviation check.
    #[must_use]
    pub fn reference(&self) -> SpebtState {
        self.reference
    }

    /// Slots predicted since the start.
    #[must_use]
    pub fn slot(&self) -> usize {
        self.slot
    }

    fn deviation(&self) -> Deviation {
        let (x, r, c) = (self.state.mean(), &self.reference, &self.config);
        let gain = (x[0] - r.gain_magnitude).abs() > c.gain_threshold;
        let aod = wrap_angle_rad(x[1] - r.aod_rad).abs() > c.aod_threshold_rad;
        let aoa = wrap_angle_rad(x[2] - r.aoa_rad).abs() > c.aoa_threshold_rad;
        if gain || aod || aoa { Deviation::Exceeded { gain, aod, aoa } } else { Deviation::Within }
    }
}

fn check_initial_access(s: &SpebtState) -> Result<(), BeamError> {
    if s.is_finite() && s.gain_magnitude >= 0.0 {
        Ok(())
    } else {
        Err(BeamError::BadConfig {
            field: "initial_access",
            value: format!("{s:?}"),
            expected: "a finite channel with |alpha| >= 0",
        })
    }
}

/// `|r| = |p - b|` of a pose estimate, metres; errors for a non-finite pose
/// or one on the BS (where (22) and the bearing are undefined).
fn range_to(c: &SpebtConfig, pose: &Se2, slot: usize) -> Result<f64, BeamError> {
    if !pose.is_finite() {
        return Err(BeamError::BadPose { slot, detail: format!("not finite: {pose:?}") });
    }
    let range_m = (pose.x_m - c.bs_x_m).hypot(pose.y_m - c.bs_y_m);
    if range_m > 0.0 {
        Ok(range_m)
    } else {
        Err(BeamError::BadPose { slot, detail: "on the base station (zero range)".into() })
    }
}

/// Bearing of `r = p - b`, radians counter-clockwise from world x.
fn bearing_rad(c: &SpebtConfig, pose: &Se2) -> f64 {
    (pose.y_m - c.bs_y_m).atan2(pose.x_m - c.bs_x_m)
}

/// `Q_k` of (16)-(17) without the `arg alpha` row and column (module docs).
fn process_cov(c: &SpebtConfig, rho: f64, previous_range_m: f64, range_m: f64, gain_magnitude: f64) -> Mat<f64> {
    let beta = 1.0 / (previous_range_m * previous_range_m) + 1.0 / (range_m * range_m);
    let position = beta * c.position_sigma_m * c.position_sigma_m;
    let gain_sd = 0.5 * c.path_loss_exponent * rho * gain_magnitude;
    let yaw = 2.0 * c.yaw_sigma_rad * c.yaw_sigma_rad;
    Mat::from_fn(3, 3, |i, j| match (i, j) {
        (0, 0) => gain_sd * gain_sd * position,
        (1, 1) | (1, 2) | (2, 1) => position,
        (2, 2) => position + yaw,
        _ => 0.0,
    })
}

/// The pilot power `h(s)` of (21) for given beams, with its gradient (26).
pub(crate) struct PowerPilot {
    pub(crate) bs_array: UniformLinearArray,
    pub(crate) vehicle_array: UniformLinearArray,
    pub(crate) beams: BeamPair,
    pub(crate) pilot_power_w: f64,
    pub(crate) noise_cov: Mat<f64>,
}

impl PowerPilot {
    /// `h(s) = |b|^2 |alpha|^2 G_r(psi) G_t(phi)`.
    fn power(&self, x: &Col<f64>) -> f64 {
        let g_t = self.bs_array.gain(self.beams.tx_steer_u, x[1].cos());
        let g_r = self.vehicle_array.gain(self.beams.rx_steer_u, x[2].cos());
        self.pilot_power_w * x[0] * x[0] * g_r * g_t
    }
}

/// `G(angle) = |AF(cos angle)|^2` and `dG/dangle = 2 Re(conj(AF) AF') (-sin angle)`.
fn gain_and_derivative(array: &UniformLinearArray, steer_u: f64, angle_rad: f64) -> (f64, f64) {
    let (af, daf) = array.array_factor_with_derivative(steer_u, angle_rad.cos());
    (af.norm_sqr(), 2.0 * (af.conj() * daf).re * (-angle_rad.sin()))
}

impl NonlinearMeasurement for PowerPilot {
    fn state_dim(&self) -> usize {
        3
    }

    fn evaluate(&self, x: &Col<f64>) -> Result<(Col<f64>, Mat<f64>), FilterError> {
        let (g_t, dg_t) = gain_and_derivative(&self.bs_array, self.beams.tx_steer_u, x[1]);
        let (g_r, dg_r) = gain_and_derivative(&self.vehicle_array, self.beams.rx_steer_u, x[2]);
        let (b2, a) = (self.pilot_power_w, x[0]);
        let jacobian =
            Mat::from_fn(1, 3, |_, j| [2.0 * b2 * a * g_r * g_t, b2 * a * a * g_r * dg_t, b2 * a * a * g_t * dg_r][j]);
        Ok((Col::from_fn(1, |_| b2 * a * a * g_r * g_t), jacobian))
    }

    fn noise_cov(&self) -> &Mat<f64> {
        &self.noise_cov
    }
}

#[cfg(test)]
mod tests {
    use mmtrack_filter::numerical_jacobian;

    use super::*;

    /// Table I of the paper: 50 GHz, 4x4 half-wavelength ULAs, gamma = 2.2,
    /// -90 dBm noise (1e-12 W) under a 1 W pilot, sigma_r = 1 m,
    /// sigma_theta = 3 deg, thresholds 5e-7 and 7.5 deg, BS at (-30, -125) m.
    pub(crate) fn paper_config() -> SpebtConfig {
        SpebtConfig {
            bs_elements: 4,
            vehicle_elements: 4,
            spacing_wavelengths: 0.5,
            path_loss_exponent: 2.2,
            bs_x_m: -30.0,
            bs_y_m: -125.0,
            pilot_power_w: 1.0,
            noise_variance_w: 1e-12,
            position_sigma_m: 1.0,
            yaw_sigma_rad: 3f64.to_radians(),
            gain_threshold: 5e-7,
            aod_threshold_rad: 7.5f64.to_radians(),
            aoa_threshold_rad: 7.5f64.to_radians(),
        }
    }

    /// The true channel of a pose (module docs), |alpha_ref| = 5e-4 at 1 m.
    fn channel(c: &SpebtConfig, pose: &Se2) -> SpebtState {
        let range = (pose.x_m - c.bs_x_m).hypot(pose.y_m - c.bs_y_m);
        let aod = bearing_rad(c, pose);
        SpebtState {
            gain_magnitude: 5e-4 * range.powf(-0.5 * c.path_loss_exponent),
            aod_rad: aod,
            aoa_rad: wrap_angle_rad(aod + std::f64::consts::PI - pose.yaw_rad),
        }
    }

    #[test]
    fn gradient_26_matches_finite_differences() {
        let array = UniformLinearArray::half_wavelength(4).unwrap();
        for (x, beams) in
            [([2.4e-6, 1.33, -1.9], (0.2, 0.3)), ([7e-5, -0.4, 2.8], (-0.9, 0.85)), ([1e-7, 3.0, 0.05], (0.99, -0.97))]
        {
            let model = PowerPilot {
                bs_array: array,
                vehicle_array: array,
                beams: BeamPair { rx_steer_u: beams.0, tx_steer_u: beams.1 },
                pilot_power_w: 1.0,
                noise_cov: Mat::identity(1, 1),
            };
            let x = Col::from_fn(3, |i| x[i]);
            let (h, analytic) = model.evaluate(&x).unwrap();
            assert!((h[0] - model.power(&x)).abs() <= 1e-15 * h[0]);
            // Steps: 1e-4 relative on |alpha| (h is quadratic in it, so central
            // differences are exact up to round-off) and 1e-6 rad on the angles
            // (truncation ~ 1e-12 x |d3h/dangle3| ~ 1e-12 h).
            let numeric = numerical_jacobian(|x| model.evaluate(x).unwrap().0, &x, &[1e-4 * x[0], 1e-6, 1e-6]);
            for j in 0..3 {
                // Relative to the column's scale h / x_j (h / 1 rad for the angles):
                // 1e-6 covers the round-off of differences of h ~ 1e-16 h / step.
                let scale = h[0] / if j == 0 { x[0] } else { 1.0 };
                let diff = (analytic[(0, j)] - numeric[(0, j)]).abs();
                assert!(diff <= 1e-6 * scale, "column {j}: {analytic:?} vs {numeric:?}");
            }
        }
    }

    #[test]
    fn evolution_follows_the_geometry_without_noise_or_measurement() {
        // With exact poses the prediction (14) reproduces the true channel:
        // drive past the BS on a curve, compare the predicted mean each slot.
        let c = paper_config();
        let poses: Vec<Se2> = (0..200)
            .map(|k| {
                let t = k as f64 * 0.25;
                Se2::new(40.0 * (0.05 * t).sin() - 5.0 * t, 3.0 * t - 0.1 * t * t, 0.02 * t - 1.0)
            })
            .collect();
        let mut ekf = SpebtEkf::new(&c, channel(&c, &poses[0]), &poses[0]).unwrap();
        for pose in &poses[1..] {
            ekf.predict(pose).unwrap();
            let (x, truth) = (ekf.state().mean(), channel(&c, pose));
            // rho telescopes exactly; the angles accumulate wrapped steps:
            // round-off only (1e-12 relative / 1e-12 rad).
            assert!((x[0] - truth.gain_magnitude).abs() < 1e-12 * truth.gain_magnitude, "{x:?} vs {truth:?}");
            assert!(wrap_angle_rad(x[1] - truth.aod_rad).abs() < 1e-12);
            assert!(wrap_angle_rad(x[2] - truth.aoa_rad).abs() < 1e-12);
        }
    }

    #[test]
    fn process_noise_is_16_17_without_arg_alpha() {
        let c = paper_config();
        let q = process_cov(&c, 0.9, 100.0, 120.0, 2e-6);
        let beta = 1e-4 + 1.0 / 14_400.0;
        assert!((q[(1, 1)] - beta).abs() < 1e-18 && (q[(1, 2)] - beta).abs() < 1e-18);
        assert!((q[(2, 2)] - beta - 2.0 * 3f64.to_radians().powi(2)).abs() < 1e-15);
        assert!((q[(0, 0)] - (1.1 * 0.9 * 2e-6f64).powi(2) * beta).abs() < 1e-30);
        assert_eq!((q[(0, 1)], q[(0, 2)], q[(2, 0)]), (0.0, 0.0, 0.0));
    }

    #[test]
    fn tracks_a_noiseless_pilot_and_reports_deviation() {
        let c = paper_config();
        let start = Se2::new(0.0, 0.0, 0.3);
        let truth0 = channel(&c, &start);
        let mut ekf = SpebtEkf::new(&c, truth0, &start).unwrap();
        // Drive 3 m per slot along the heading; exact poses, noiseless pilots
        // at the true channel power through the filter's beams.
        let mut pose = start;
        let mut exceeded_at = None;
        for k in 1..=60 {
            pose = Se2::new(pose.x_m + 3.0 * 0.3f64.cos(), pose.y_m + 3.0 * 0.3f64.sin(), 0.3);
            let beams = ekf.predict(&pose).unwrap();
            let truth = channel(&c, &pose);
            let array = UniformLinearArray::half_wavelength(4).unwrap();
            let power = truth.gain_magnitude.powi(2)
                * array.gain(beams.tx_steer_u, truth.aod_rad.cos())
                * array.gain(beams.rx_steer_u, truth.aoa_rad.cos());
            let deviation = ekf.update(Complex64::new((power + 1e-12).sqrt(), 0.0)).unwrap();
            let estimate = ekf.estimate();
            // Exact motion and a noiseless power: the estimate stays on the
            // truth to well inside the re-initialisation thresholds.
            assert!((estimate.gain_magnitude - truth.gain_magnitude).abs() < 0.02 * truth.gain_magnitude, "{k}");
            assert!(wrap_angle_rad(estimate.aod_rad - truth.aod_rad).abs() < 0.2f64.to_radians(), "{k}");
            assert!(wrap_angle_rad(estimate.aoa_rad - truth.aoa_rad).abs() < 0.2f64.to_radians(), "{k}");
            if deviation != Deviation::Within && exceeded_at.is_none() {
                exceeded_at = Some(k);
                ekf.reinitialise(truth).unwrap();
                assert_eq!(ekf.reference(), truth);
            }
        }
        // The vehicle drives away from (0, 0) and the bearing to the BS turns
        // by more than 7.5 deg (or |alpha| falls by 5e-7) within 60 slots.
        assert!(exceeded_at.is_some());
    }

    #[test]
    fn bad_input_is_an_error() {
        let c = paper_config();
        let start = Se2::new(0.0, 0.0, 0.0);
        let s = channel(&c, &start);
        assert!(matches!(
            SpebtEkf::new(&SpebtConfig { noise_variance_w: 0.0, ..c.clone() }, s, &start),
            Err(BeamError::BadConfig { field: "noise_variance_w", .. })
        ));
        assert!(matches!(
            SpebtEkf::new(&SpebtConfig { bs_elements: 0, ..c.clone() }, s, &start),
            Err(BeamError::BadConfig { field: "bs_elements", .. })
        ));
        let bs = Se2::new(-30.0, -125.0, 0.0);
        assert!(matches!(SpebtEkf::new(&c, s, &bs), Err(BeamError::BadPose { slot: 0, .. })));
        let mut ekf = SpebtEkf::new(&c, s, &start).unwrap();
        assert!(matches!(ekf.update(Complex64::new(1e-6, 0.0)), Err(BeamError::UpdateWithoutPrediction { .. })));
        let err = ekf.predict(&Se2::new(f64::NAN, 0.0, 0.0)).unwrap_err();
        assert!(matches!(err, BeamError::BadPose { slot: 1, .. }), "{err}");
        ekf.predict(&Se2::new(1.0, 0.0, 0.0)).unwrap();
        assert!(matches!(ekf.update(Complex64::new(f64::NAN, 0.0)), Err(BeamError::BadPilot { block: 1, .. })));
        let bad = SpebtState { gain_magnitude: f64::NAN, ..s };
        assert!(matches!(ekf.reinitialise(bad), Err(BeamError::BadConfig { field: "initial_access", .. })));
    }
}
