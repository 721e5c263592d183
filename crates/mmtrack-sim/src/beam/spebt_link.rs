//! The SPEBT link of Liu et al. 2024 (Sec. II-A, IV, Table I): a base
//! station (BS) with an `N`-element ULA serving a vehicle with an
//! `M`-element ULA over its line-of-sight path, one pilot per slot, the
//! vehicle driving along any trajectory (one slot per pose).
//!
//! Per slot `k`, with `p_k` the vehicle's position, `theta_k` its yaw and
//! `r_k = p_k - b` the vector from the BS at `b` to the vehicle:
//!
//! ```text
//! alpha_k = |alpha_ref| (d0 / |r_k|)^(gamma/2) exp(j 2 pi / lambda (|r_k| - d0))     (22)
//! phi_k   = atan2(r_k.y, r_k.x)             AoD from the BS array axis (world x)
//! psi_k   = wrap(phi_k + pi - theta_k)      AoA from the vehicle's heading (Appendix A)
//! z_k     = g^H H_k f b_k + v_k = b alpha_k AF_r(g, cos psi_k) conj(AF_t(f, cos phi_k)) + v_k     (4)-(5)
//! v_k     ~ CN(0, sigma_v^2)
//! ```
//!
//! (`AF` the array factor of `mmtrack_core::array`; `g` and `f` the beams
//! the tracker chooses, given as steering direction cosines.) The BS array
//! axis lies along world x, the vehicle's along its heading, so that
//! `theta - phi + psi = pi` as in Appendix A.
//!
//! Positions are taken relative to the trajectory's first position (the
//! vehicle starts at (0, 0), Table I); headings are kept. The BS position is
//! given in that frame ((-30, -125) m in the paper).
//!
//! Power units: Table I gives the noise as -90 dBm and the pilot as
//! `E|b|^2 = 1`; read as watts, `sigma_v^2 = 1e-12 W` under a 1 W (30 dBm)
//! pilot (both configurable). At the start (129 m from the BS) that is an
//! SNR of 7.5 dB without array gain.
//!
//! The pose-error model of Appendix B, eq. (23): the pose estimates are the
//! true poses plus `N(0, sigma_r^2 I)` in position and `N(0, sigma_theta^2)`
//! in yaw, independent per slot. Slot 0's estimate is exact by default
//! (Algorithm 1 takes `r_0, theta_0` as input).
//!
//! A realisation ([`SpebtRun`]: pose estimates and receiver noise of every
//! slot) is drawn from `(seed, run)` alone, so a Monte Carlo run does not
//! depend on the thread that computes it.

use mmtrack_core::array::UniformLinearArray;
use mmtrack_core::random::{standard_normal, stream};
use mmtrack_core::{Complex64, Se2, StampedPose, wrap_angle_rad};
use serde::{Deserialize, Serialize};

use crate::SimError;
use crate::error::{ensure_finite, ensure_non_negative, ensure_positive, invalid};

/// Speed of light, m/s.
const SPEED_OF_LIGHT_MPS: f64 = 299_792_458.0;

/// The link's parameters; the defaults are the paper's (Table I).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SpebtScenario {
    /// Carrier frequency, Hz (50 GHz; lambda = 6 mm).
    pub carrier_hz: f64,
    /// Elements `N` of the BS ULA (4).
    pub bs_elements: usize,
    /// Elements `M` of the vehicle's ULA (4).
    pub vehicle_elements: usize,
    /// Element spacing `d`, wavelengths (1/2).
    pub spacing_wavelengths: f64,
    /// Path-loss exponent `gamma` (2.2).
    pub path_loss_exponent: f64,
    /// `|alpha_ref|`, the path-gain magnitude at the reference distance (5e-4).
    pub reference_gain_magnitude: f64,
    /// Reference distance `d0`, metres (1). The model (22) holds beyond it: a
    /// trajectory that comes closer to the BS is refused.
    pub reference_distance_m: f64,
    /// Receiver noise power `sigma_v^2`, dBm (-90).
    pub noise_dbm: f64,
    /// Pilot power `|b|^2`, dBm (30, i.e. 1 W: module docs).
    pub pilot_power_dbm: f64,
    /// BS x, metres, relative to the vehicle's first position (-30).
    pub bs_x_m: f64,
    /// BS y, metres, relative to the vehicle's first position (-125).
    pub bs_y_m: f64,
    /// Pose-error model: standard deviation `sigma_r` of each position
    /// coordinate, metres (1).
    pub position_sigma_m: f64,
    /// Pose-error model: standard deviation `sigma_theta` of the yaw,
    /// degrees (3).
    pub yaw_sigma_deg: f64,
    /// Slot 0's pose estimate is the true pose (Algorithm 1's input
    /// `r_0, theta_0`) rather than drawn from the error model (true).
    pub exact_first_pose: bool,
    /// A time step longer than this multiple of the median step is a gap in
    /// the pose sequence and refused (1.5: one missing scan of a regular
    /// sequence doubles the step).
    pub max_step_ratio: f64,
}

impl Default for SpebtScenario {
    fn default() -> Self {
        Self {
            carrier_hz: 50e9,
            bs_elements: 4,
            vehicle_elements: 4,
            spacing_wavelengths: 0.5,
            path_loss_exponent: 2.2,
            reference_gain_magnitude: 5e-4,
            reference_distance_m: 1.0,
            noise_dbm: -90.0,
            pilot_power_dbm: 30.0,
            bs_x_m: -30.0,
            bs_y_m: -125.0,
            position_sigma_m: 1.0,
            yaw_sigma_deg: 3.0,
            exact_first_pose: true,
            max_step_ratio: 1.5,
        }
    }
}

impl SpebtScenario {
    /// Checks every parameter.
    ///
    /// # Errors
    /// [`SimError::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<(), SimError> {
        ensure_positive("carrier_hz", self.carrier_hz)?;
        ensure_positive("spacing_wavelengths", self.spacing_wavelengths)?;
        ensure_positive("path_loss_exponent", self.path_loss_exponent)?;
        ensure_positive("reference_gain_magnitude", self.reference_gain_magnitude)?;
        ensure_positive("reference_distance_m", self.reference_distance_m)?;
        ensure_finite("noise_dbm", self.noise_dbm)?;
        ensure_finite("pilot_power_dbm", self.pilot_power_dbm)?;
        ensure_finite("bs_x_m", self.bs_x_m)?;
        ensure_finite("bs_y_m", self.bs_y_m)?;
        ensure_non_negative("position_sigma_m", self.position_sigma_m)?;
        ensure_non_negative("yaw_sigma_deg", self.yaw_sigma_deg)?;
        // As the --sigma-r-m / --sigma-theta-deg flags: beyond these no pose
        // estimate is meant, and squared they overflow the filter (1e300).
        if self.position_sigma_m > 1000.0 {
            return Err(invalid("position_sigma_m", self.position_sigma_m, "at most 1000 m"));
        }
        if self.yaw_sigma_deg > 180.0 {
            return Err(invalid("yaw_sigma_deg", self.yaw_sigma_deg, "at most 180 deg"));
        }
        if !(self.max_step_ratio.is_finite() && self.max_step_ratio > 1.0) {
            return Err(invalid("max_step_ratio", self.max_step_ratio, "a finite ratio above 1"));
        }
        for (field, elements) in [("bs_elements", self.bs_elements), ("vehicle_elements", self.vehicle_elements)] {
            if elements == 0 {
                return Err(invalid(field, 0, "at least one antenna element"));
            }
        }
        Ok(())
    }

    /// Carrier wavelength `lambda`, metres.
    #[must_use]
    pub fn wavelength_m(&self) -> f64 {
        SPEED_OF_LIGHT_MPS / self.carrier_hz
    }

    /// Noise variance `sigma_v^2`, watts.
    #[must_use]
    pub fn noise_variance_w(&self) -> f64 {
        10f64.powf((self.noise_dbm - 30.0) / 10.0)
    }

    /// Pilot power `|b|^2`, watts.
    #[must_use]
    pub fn pilot_power_w(&self) -> f64 {
        10f64.powf((self.pilot_power_dbm - 30.0) / 10.0)
    }

    /// The true path gain at range `range_m` (eq. (22)).
    #[must_use]
    pub fn path_gain(&self, range_m: f64) -> Complex64 {
        let magnitude =
            self.reference_gain_magnitude * (self.reference_distance_m / range_m).powf(0.5 * self.path_loss_exponent);
        let phase = std::f64::consts::TAU / self.wavelength_m() * (range_m - self.reference_distance_m);
        Complex64::from_polar(magnitude, phase)
    }
}

/// The true link in one slot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpebtSlot {
    /// Time of the pose, nanoseconds (as in the trajectory).
    pub t_ns: i64,
    /// The vehicle's pose, positions relative to the first (module docs).
    pub pose: Se2,
    /// Distance `|r|` to the BS, metres.
    pub range_m: f64,
    /// Path gain `alpha` (eq. (22)).
    pub gain: Complex64,
    /// AoD `phi`, radians in `(-pi, pi]` from the BS array axis.
    pub aod_rad: f64,
    /// AoA `psi`, radians in `(-pi, pi]` from the vehicle's heading.
    pub aoa_rad: f64,
}

/// The link along one trajectory: the true channel of every slot.
#[derive(Debug, Clone, PartialEq)]
pub struct SpebtLink {
    scenario: SpebtScenario,
    bs_array: UniformLinearArray,
    vehicle_array: UniformLinearArray,
    slots: Vec<SpebtSlot>,
}

/// One realisation: the pose estimates and the receiver noise of every slot.
#[derive(Debug, Clone, PartialEq)]
pub struct SpebtRun {
    /// Pose estimates `(r^_k, theta^_k)` of the error model, one per slot.
    pub pose_estimates: Vec<Se2>,
    /// Receiver noise `v_k`, one per slot.
    pub noise: Vec<Complex64>,
}

impl SpebtLink {
    /// The link along `trajectory`, one slot per pose.
    ///
    /// # Errors
    /// [`SimError::InvalidParameter`] for a bad scenario;
    /// [`SimError::TrajectoryTooShort`] for fewer than two poses;
    /// [`SimError::BadTrajectoryPose`] for a pose that is not finite, a time
    /// that does not increase, a gap (a step above `max_step_ratio` times the
    /// median step), or a path that comes closer to the BS than the
    /// reference distance.
    pub fn new(scenario: &SpebtScenario, trajectory: &[StampedPose]) -> Result<Self, SimError> {
        scenario.validate()?;
        let array = |field: &'static str, elements: usize| {
            UniformLinearArray::new(elements, scenario.spacing_wavelengths)
                .map_err(|_| invalid(field, elements, "at least one element"))
        };
        let bs_array = array("bs_elements", scenario.bs_elements)?;
        let vehicle_array = array("vehicle_elements", scenario.vehicle_elements)?;
        check_times(trajectory, scenario.max_step_ratio)?;
        let origin = trajectory[0].parent_from_child;
        let bs = [scenario.bs_x_m, scenario.bs_y_m];
        let mut slots: Vec<SpebtSlot> = Vec::with_capacity(trajectory.len());
        for (index, stamped) in trajectory.iter().enumerate() {
            let p = &stamped.parent_from_child;
            let pose = Se2::new(p.x_m - origin.x_m, p.y_m - origin.y_m, p.yaw_rad);
            let from = slots.last().map_or([pose.x_m, pose.y_m], |s| [s.pose.x_m, s.pose.y_m]);
            let closest_m = distance_to_segment(bs, from, [pose.x_m, pose.y_m]);
            if closest_m < scenario.reference_distance_m {
                return Err(SimError::BadTrajectoryPose {
                    index,
                    t_ns: stamped.t_ns,
                    detail: format!(
                        "the path passes {closest_m:.3} m from the base station at ({}, {}) m (relative to the first \
                         position); the path-loss model (22) needs at least the reference distance {} m",
                        bs[0], bs[1], scenario.reference_distance_m
                    ),
                });
            }
            let (rx, ry) = (pose.x_m - bs[0], pose.y_m - bs[1]);
            let range_m = rx.hypot(ry);
            let aod_rad = ry.atan2(rx);
            slots.push(SpebtSlot {
                t_ns: stamped.t_ns,
                pose,
                range_m,
                gain: scenario.path_gain(range_m),
                aod_rad,
                aoa_rad: wrap_angle_rad(aod_rad + std::f64::consts::PI - pose.yaw_rad),
            });
        }
        Ok(Self { scenario: scenario.clone(), bs_array, vehicle_array, slots })
    }

    /// The scenario.
    #[must_use]
    pub fn scenario(&self) -> &SpebtScenario {
        &self.scenario
    }

    /// The true link of every slot.
    #[must_use]
    pub fn slots(&self) -> &[SpebtSlot] {
        &self.slots
    }

    /// Number of slots.
    #[must_use]
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Always false: a link has at least two slots.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Realisation `run` under `seed`: the pose estimates of the error model
    /// (module docs) and the receiver noise of every slot.
    #[must_use]
    pub fn realise(&self, seed: u64, run: u64) -> SpebtRun {
        let s = &self.scenario;
        let mut rng = stream(seed, &[0x0073_7065_6274, run]);
        let (sigma_r, sigma_theta) = (s.position_sigma_m, s.yaw_sigma_deg.to_radians());
        let sigma_v = (0.5 * s.noise_variance_w()).sqrt();
        let mut pose_estimates = Vec::with_capacity(self.slots.len());
        let mut noise = Vec::with_capacity(self.slots.len());
        for (k, slot) in self.slots.iter().enumerate() {
            // Draw every slot's errors even when slot 0 is exact, so the
            // noise of later slots does not depend on that option.
            let error = [standard_normal(&mut rng), standard_normal(&mut rng), standard_normal(&mut rng)];
            let p = slot.pose;
            pose_estimates.push(if k == 0 && s.exact_first_pose {
                p
            } else {
                Se2::new(p.x_m + sigma_r * error[0], p.y_m + sigma_r * error[1], p.yaw_rad + sigma_theta * error[2])
            });
            noise.push(Complex64::new(sigma_v * standard_normal(&mut rng), sigma_v * standard_normal(&mut rng)));
        }
        SpebtRun { pose_estimates, noise }
    }

    /// The pilot of `slot` received through the combiner steered to
    /// direction cosine `rx_steer_u` and the precoder steered to
    /// `tx_steer_u` (eq. (5)), with the receiver noise `noise`.
    ///
    /// # Panics
    /// When `slot` is beyond the link (a caller's loop bound).
    #[must_use]
    pub fn pilot(&self, slot: usize, rx_steer_u: f64, tx_steer_u: f64, noise: Complex64) -> Complex64 {
        let s = &self.slots[slot];
        let rx = self.vehicle_array.array_factor(rx_steer_u, s.aoa_rad.cos());
        let tx = self.bs_array.array_factor(tx_steer_u, s.aod_rad.cos()).conj();
        self.scenario.pilot_power_w().sqrt() * s.gain * rx * tx + noise
    }
}

/// Times must be finite poses, strictly increasing, without gaps.
fn check_times(trajectory: &[StampedPose], max_step_ratio: f64) -> Result<(), SimError> {
    if trajectory.len() < 2 {
        return Err(SimError::TrajectoryTooShort { detail: format!("{} poses, need at least 2", trajectory.len()) });
    }
    for (index, pose) in trajectory.iter().enumerate() {
        if !pose.parent_from_child.is_finite() {
            return Err(SimError::BadTrajectoryPose { index, t_ns: pose.t_ns, detail: "not finite".into() });
        }
        if index > 0 && pose.t_ns <= trajectory[index - 1].t_ns {
            return Err(SimError::BadTrajectoryPose {
                index,
                t_ns: pose.t_ns,
                detail: format!("time does not increase (previous pose at {} ns)", trajectory[index - 1].t_ns),
            });
        }
    }
    let mut steps: Vec<i64> = trajectory.windows(2).map(|w| w[1].t_ns - w[0].t_ns).collect();
    steps.sort_unstable();
    let median_ns = steps[steps.len() / 2] as f64;
    for (index, pair) in trajectory.windows(2).enumerate() {
        let step_ns = (pair[1].t_ns - pair[0].t_ns) as f64;
        if step_ns > max_step_ratio * median_ns {
            return Err(SimError::BadTrajectoryPose {
                index: index + 1,
                t_ns: pair[1].t_ns,
                detail: format!(
                    "gap of {:.3} s after the previous pose, {:.1} times the median step of {:.3} s (more than \
                     max_step_ratio = {max_step_ratio}); the link has one slot per pose and cannot span a gap",
                    step_ns * 1e-9,
                    step_ns / median_ns,
                    median_ns * 1e-9
                ),
            });
        }
    }
    Ok(())
}

/// Distance from `point` to the segment `[a, b]`.
fn distance_to_segment(point: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let length2 = dx * dx + dy * dy;
    let t =
        if length2 > 0.0 { (((point[0] - a[0]) * dx + (point[1] - a[1]) * dy) / length2).clamp(0.0, 1.0) } else { 0.0 };
    (a[0] + t * dx - point[0]).hypot(a[1] + t * dy - point[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stamped(t_s: f64, x_m: f64, y_m: f64, yaw_rad: f64) -> StampedPose {
        StampedPose { t_ns: (t_s * 1e9) as i64, parent_from_child: Se2::new(x_m, y_m, yaw_rad) }
    }

    /// A straight drive along x at 10 m/s, 4 Hz, from `(x0, y0)`.
    fn drive(slots: usize, x0: f64, y0: f64) -> Vec<StampedPose> {
        (0..slots).map(|k| stamped(100.0 + 0.25 * k as f64, x0 + 2.5 * k as f64, y0, 0.0)).collect()
    }

    #[test]
    fn geometry_path_loss_and_appendix_a() {
        let scenario = SpebtScenario::default();
        // Starts at (1000, 50) in the file: shifted to (0, 0).
        let link = SpebtLink::new(&scenario, &drive(40, 1000.0, 50.0)).unwrap();
        let first = link.slots()[0];
        assert_eq!((first.pose.x_m, first.pose.y_m), (0.0, 0.0));
        assert!((first.range_m - 30f64.hypot(125.0)).abs() < 1e-12);
        // |alpha| = 5e-4 * 128.55^-1.1 = 2.39e-6 (1e-18: a few ulps).
        assert!((first.gain.norm() - 2.393_272_755e-6).abs() < 1e-15, "{}", first.gain.norm());
        assert!((first.gain.norm() - 5e-4 * first.range_m.powf(-1.1)).abs() < 1e-18);
        assert!((first.aod_rad - 125f64.atan2(30.0)).abs() < 1e-12);
        for s in link.slots() {
            // theta - phi + psi = pi (mod 2 pi).
            assert!(wrap_angle_rad(s.pose.yaw_rad - s.aod_rad + s.aoa_rad - std::f64::consts::PI).abs() < 1e-12);
        }
        // Noise -90 dBm = 1e-12 W under a 1 W pilot.
        assert!((scenario.noise_variance_w() - 1e-12).abs() < 1e-24 && (scenario.pilot_power_w() - 1.0).abs() < 1e-15);
        assert!((scenario.wavelength_m() - 5.996e-3).abs() < 1e-6);
    }

    #[test]
    fn pilots_and_errors_have_the_stated_statistics() {
        let scenario = SpebtScenario::default();
        let link = SpebtLink::new(&scenario, &drive(400, 0.0, 0.0)).unwrap();
        let s = link.slots()[7];
        // On the true beams the pilot is sqrt(P) alpha + v.
        let z = link.pilot(7, s.aoa_rad.cos(), s.aod_rad.cos(), Complex64::new(0.0, 0.0));
        assert!((z - s.gain).norm() < 1e-15 * s.gain.norm());
        let (mut sum_xy, mut sum_yaw, mut sum_noise, mut n) = (0.0, 0.0, 0.0, 0.0);
        for run in 0..20 {
            let r = link.realise(5, run);
            assert_eq!(r.pose_estimates[0], link.slots()[0].pose, "slot 0 is exact");
            for (k, (e, slot)) in r.pose_estimates.iter().zip(link.slots()).enumerate().skip(1) {
                sum_xy += (e.x_m - slot.pose.x_m).powi(2) + (e.y_m - slot.pose.y_m).powi(2);
                sum_yaw += (e.yaw_rad - slot.pose.yaw_rad).powi(2);
                sum_noise += r.noise[k].norm_sqr();
                n += 1.0;
            }
        }
        // 7980 draws: the sample variances are within 5 % (about 3 standard errors).
        assert!((sum_xy / n / 2.0 - 1.0).abs() < 0.05, "{}", sum_xy / n);
        assert!((sum_yaw / n / 3f64.to_radians().powi(2) - 1.0).abs() < 0.05);
        assert!((sum_noise / n / 1e-12 - 1.0).abs() < 0.05);
        // Deterministic per (seed, run), different across runs.
        assert_eq!(link.realise(5, 3), link.realise(5, 3));
        assert_ne!(link.realise(5, 3).noise[1], link.realise(5, 4).noise[1]);
    }

    #[test]
    fn pose_error_sigmas_beyond_a_pose_estimate_are_named() {
        // 1e300 passed `validate` and overflowed the filter's covariance once squared.
        for (sigma_m, sigma_deg, field) in [(1e300, 1.0, "position_sigma_m"), (1.0, 1e300, "yaw_sigma_deg")] {
            let scenario = SpebtScenario { position_sigma_m: sigma_m, yaw_sigma_deg: sigma_deg, ..Default::default() };
            let err = scenario.validate().unwrap_err().to_string();
            assert!(err.contains(field) && err.contains("at most"), "{err}");
        }
    }

    #[test]
    fn bad_trajectories_are_named() {
        let scenario = SpebtScenario::default();
        // Through the BS: from (0, 0) to the line y = -125 (relative to the
        // start), then along it through the BS at x = -30 (pose 13).
        let through = |y_m: f64| -> Vec<StampedPose> {
            (0..40)
                .map(|k| {
                    let x = if k == 0 { 0.0 } else { -60.0 + 2.5 * (k - 1) as f64 };
                    stamped(0.25 * k as f64, x, if k == 0 { 0.0 } else { y_m }, 0.0)
                })
                .collect()
        };
        let err = SpebtLink::new(&scenario, &through(-125.0)).unwrap_err().to_string();
        assert!(err.contains("pose 13") && err.contains("passes 0.000 m from the base station"), "{err}");
        assert!(err.contains("reference distance 1 m"), "{err}");
        // Between two poses: 0.3 m off the BS at x = -30.
        let err = SpebtLink::new(&scenario, &through(-125.3)).unwrap_err().to_string();
        assert!(err.contains("passes 0.300 m from the base station"), "{err}");
        assert!(SpebtLink::new(&scenario, &through(-127.0)).is_ok(), "2 m away is fine");
        // NaN pose.
        let mut nan = drive(10, 0.0, 0.0);
        nan[4].parent_from_child.yaw_rad = f64::NAN;
        let err = SpebtLink::new(&scenario, &nan).unwrap_err().to_string();
        assert!(err.contains("pose 4") && err.contains("not finite"), "{err}");
        // A gap: pose 6 missing.
        let mut gap = drive(10, 0.0, 0.0);
        gap.remove(6);
        let err = SpebtLink::new(&scenario, &gap).unwrap_err().to_string();
        assert!(err.contains("pose 6") && err.contains("gap of 0.500 s") && err.contains("2.0 times"), "{err}");
        // Time going back, too short, bad parameters.
        let mut back = drive(10, 0.0, 0.0);
        back[3].t_ns = back[2].t_ns;
        assert!(SpebtLink::new(&scenario, &back).unwrap_err().to_string().contains("does not increase"));
        assert!(SpebtLink::new(&scenario, &drive(1, 0.0, 0.0)).unwrap_err().to_string().contains("need at least 2"));
        let bad = SpebtScenario { path_loss_exponent: 0.0, ..SpebtScenario::default() };
        assert!(SpebtLink::new(&bad, &drive(10, 0.0, 0.0)).unwrap_err().to_string().starts_with("path_loss_exponent"));
        let bad = SpebtScenario { vehicle_elements: 0, ..SpebtScenario::default() };
        assert!(SpebtLink::new(&bad, &drive(10, 0.0, 0.0)).unwrap_err().to_string().starts_with("vehicle_elements"));
    }
}
