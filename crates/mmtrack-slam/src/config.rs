//! The filter's parameters. The defaults are the paper's (Sec. V-A) where it
//! gives them; the rest (new-source density, confirmation and merging
//! thresholds, forgetting) are ours, named and documented here.

use mmtrack_core::limits;
use serde::{Deserialize, Serialize};

use crate::error::{SlamError, ensure_non_negative, ensure_positive, invalid};

/// Parameters of [`crate::SlamFilter`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SlamConfig {
    /// Number of UE particles (2000).
    pub particles: usize,
    /// Message-passing iterations per epoch (10): the most likelihood
    /// tempering stages of the UE update and the most relinearisations of a
    /// source update (see the crate docs for what they replace).
    pub iterations: usize,
    /// Particles per parallel chunk (256). The chunking, not the thread
    /// count, fixes the random streams, so results do not depend on threads.
    pub chunk_size: usize,
    /// Base station position, metres ((0, 0, 40)).
    pub bs_m: [f64; 3],
    /// Prior standard deviation of the horizontal position, metres (14.2).
    pub prior_position_std_m: f64,
    /// Prior standard deviation of the heading, radians (1).
    pub prior_heading_std_rad: f64,
    /// Prior standard deviation of the speed, m/s (0.1).
    pub prior_speed_std_mps: f64,
    /// Prior standard deviation of the turn rate, rad/s (0.1).
    pub prior_turn_rate_std_radps: f64,
    /// Prior standard deviation of the clock bias, metres (10).
    pub prior_clock_bias_std_m: f64,
    /// Process noise `sigma_v` of eq. (1), m/s (0.1).
    pub speed_std_mps: f64,
    /// Process noise `sigma_omega` of eq. (1), rad/s (0.001).
    pub turn_rate_std_radps: f64,
    /// Process noise `sigma_B` of eq. (1), metres (0.1).
    pub clock_bias_std_m: f64,
    /// TOA standard deviation of `Sigma`, metres (0.1).
    pub toa_std_m: f64,
    /// DOA and DOD standard deviation of `Sigma`, radians (0.01).
    pub angle_std_rad: f64,
    /// `P_D` of eq. (3) as the filter assumes it (0.99; the paper simulates
    /// `P_D = 1`, where eq. (3)'s `P_D / (1 - P_D)` is infinite).
    pub detection_probability: f64,
    /// `P_N` of the "new source" columns of `S`, a density in the
    /// measurement space (m^-1 rad^-4) (1e-3; the paper says `P_N << 1`).
    pub new_source_density: f64,
    /// Squared Mahalanobis distance beyond which a (path, source) pair is
    /// not considered at all (100).
    pub association_gate: f64,
    /// The same gate for the line of sight that initialises the UE (20.5,
    /// the chi-square(5) 99.9 % quantile): under the broad prior a
    /// reflection can pass the general gate when the LOS path is missing.
    pub initialisation_gate: f64,
    /// Effective sample size, as a fraction of the particles, that each
    /// tempering stage keeps (0.5).
    pub ess_fraction: f64,
    /// Kernel bandwidth of the regularised resampling, as a fraction of the
    /// posterior standard deviations (0.2): position and heading have no
    /// process noise in (1), so resampled copies are spread by this kernel.
    pub jitter_bandwidth: f64,
    /// Keep a confirmed source's covariance at least as large as the error
    /// the UE's current uncertainty induces in it (true). Message passing
    /// treats the UE's error as independent from epoch to epoch, but it
    /// changes slowly, so without this floor a source's belief shrinks as
    /// if that error averaged out, and the overconfident map then holds
    /// the UE to its own past errors.
    pub ue_error_floor: bool,
    /// Sightings an unconfirmed source needs before it may be classified (3).
    pub confirm_min_sightings: usize,
    /// Footnote 3's test: a hypothesis is rejected when its drift statistic
    /// exceeds this many times the other's (10) ...
    pub confirm_ratio: f64,
    /// ... and exceeds this value (a chi-square(3) quantile, 16.3 = 99.9 %).
    pub confirm_min_drift: f64,
    /// Confirmed sources of one type closer than this are merged, metres (3).
    pub merge_distance_m: f64,
    /// An unconfirmed source not seen for this many epochs is forgotten (3).
    pub forget_unconfirmed_after_epochs: usize,
    /// Refuse an epoch holding an unusable path instead of skipping the
    /// path and counting it (false).
    pub strict: bool,
}

impl Default for SlamConfig {
    fn default() -> Self {
        Self {
            particles: 2000,
            iterations: 10,
            chunk_size: 256,
            bs_m: [0.0, 0.0, 40.0],
            prior_position_std_m: 14.2,
            prior_heading_std_rad: 1.0,
            prior_speed_std_mps: 0.1,
            prior_turn_rate_std_radps: 0.1,
            prior_clock_bias_std_m: 10.0,
            speed_std_mps: 0.1,
            turn_rate_std_radps: 0.001,
            clock_bias_std_m: 0.1,
            toa_std_m: 0.1,
            angle_std_rad: 0.01,
            detection_probability: 0.99,
            new_source_density: 1e-3,
            association_gate: 100.0,
            initialisation_gate: 20.5,
            ess_fraction: 0.5,
            jitter_bandwidth: 0.2,
            ue_error_floor: true,
            confirm_min_sightings: 3,
            confirm_ratio: 10.0,
            confirm_min_drift: 16.3,
            merge_distance_m: 3.0,
            forget_unconfirmed_after_epochs: 3,
            strict: false,
        }
    }
}

impl SlamConfig {
    /// Checks every parameter.
    ///
    /// # Errors
    /// [`SlamError::InvalidConfig`] naming the field.
    pub fn validate(&self) -> Result<(), SlamError> {
        if self.particles < 2 || !limits::PARTICLES.allows_count(self.particles as u64) {
            return Err(invalid("particles", self.particles, limits::PARTICLES.expected));
        }
        if self.iterations == 0 || !limits::ITERATIONS.allows_count(self.iterations as u64) {
            return Err(invalid("iterations", self.iterations, limits::ITERATIONS.expected));
        }
        if self.chunk_size == 0 {
            return Err(invalid("chunk_size", self.chunk_size, "at least 1"));
        }
        for v in self.bs_m {
            if !v.is_finite() {
                return Err(invalid("bs_m", v, "finite coordinates"));
            }
        }
        ensure_positive("prior_position_std_m", self.prior_position_std_m)?;
        ensure_positive("prior_heading_std_rad", self.prior_heading_std_rad)?;
        ensure_non_negative("prior_speed_std_mps", self.prior_speed_std_mps)?;
        ensure_non_negative("prior_turn_rate_std_radps", self.prior_turn_rate_std_radps)?;
        ensure_positive("prior_clock_bias_std_m", self.prior_clock_bias_std_m)?;
        ensure_non_negative("speed_std_mps", self.speed_std_mps)?;
        ensure_non_negative("turn_rate_std_radps", self.turn_rate_std_radps)?;
        ensure_non_negative("clock_bias_std_m", self.clock_bias_std_m)?;
        ensure_positive("toa_std_m", self.toa_std_m)?;
        ensure_positive("angle_std_rad", self.angle_std_rad)?;
        let pd = self.detection_probability;
        if !(pd.is_finite() && pd > 0.0 && pd < 1.0) {
            return Err(invalid("detection_probability", pd, "a probability in (0, 1)"));
        }
        ensure_positive("new_source_density", self.new_source_density)?;
        ensure_positive("association_gate", self.association_gate)?;
        ensure_positive("initialisation_gate", self.initialisation_gate)?;
        let ess = self.ess_fraction;
        if !(ess.is_finite() && ess > 0.0 && ess < 1.0) {
            return Err(invalid("ess_fraction", ess, "a fraction in (0, 1)"));
        }
        ensure_non_negative("jitter_bandwidth", self.jitter_bandwidth)?;
        if self.confirm_min_sightings < 2 {
            return Err(invalid("confirm_min_sightings", self.confirm_min_sightings, "at least 2"));
        }
        ensure_positive("confirm_ratio", self.confirm_ratio)?;
        ensure_non_negative("confirm_min_drift", self.confirm_min_drift)?;
        ensure_non_negative("merge_distance_m", self.merge_distance_m)?;
        Ok(())
    }
}
