//! Parameters of the GM-PHD baseline: Table I of Mahler et al. 2017 plus the
//! ones the paper uses but does not print, each with its reason.

use serde::{Deserialize, Serialize};

use super::GmPhdError;

/// Configuration of [`super::track_gmphd`].
///
/// `Default` is the paper's Table I for the seven values it gives; the others
/// are our choices, documented per field. Config files may give any subset of
/// fields; unknown fields are an error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GmPhdConfig {
    /// Standard deviation of the process noise (white acceleration of the path
    /// length), m/s^2. Table I: 0.3.
    pub sigma_process_mps2: f64,
    /// Standard deviation of the measurement noise of the path length
    /// `d = c tau`, m. Table I: 3e-3 (0.01 ns of delay).
    pub sigma_measurement_m: f64,
    /// Survival probability `p_S`. Table I: 0.99.
    pub p_survival: f64,
    /// Detection probability `p_D`. Table I: 0.95.
    pub p_detection: f64,
    /// Truncation threshold `T` of Vo & Ma Table II. Table I: 1e-2.
    pub truncation_threshold: f64,
    /// Merge threshold `U` (squared Mahalanobis distance) of Vo & Ma Table II.
    /// Table I: 0.1.
    pub merge_threshold: f64,
    /// Minimum weight for state extraction (Vo & Ma Table III). Table I: 0.2.
    pub extraction_threshold: f64,
    /// Most Gaussian components kept after merging (`J_max`). Not in the paper;
    /// 100 as in the linear example of Vo & Ma 2006, Sec. VI-A: far above the
    /// tens of MPCs a vehicular CIR holds, so it only guards against blow-up.
    pub max_components: usize,
    /// Weight `w_b` of each birth term (expected births per unexplained
    /// detection). Not printed in the paper ("three additional parameters for
    /// creating the birth processes": this, the two birth standard deviations).
    /// 0.01: one snapshot (0.717 ms) after its first detection a birth has a
    /// predicted spread of ~2.9 cm, so the next detection has a likelihood
    /// `q` ~ 10 /m and the birth's weight becomes
    /// `p_D w_b q / (kappa + p_D w_b q)` ~ 0.99: a new MPC is extracted at its
    /// second detection, while an unconfirmed birth is left with
    /// `(1 - p_D) w_b = 5e-4 < T` and disappears at once.
    pub birth_weight: f64,
    /// Standard deviation of the path-length rate of a birth, m/s (its mean is
    /// 0; its position standard deviation is `sigma_measurement_m`, the birth
    /// being centred on a detection). 40 m/s covers the path-length rates of
    /// vehicles at up to ~70 km/h each way (a Doppler of 760 Hz at 5.7 GHz) at
    /// one sigma, and keeps a birth's predicted spread after one 0.717 ms
    /// snapshot (2.9 cm) well inside the delay gate (15 cm).
    pub birth_sigma_rate_mps: f64,
    /// A detection spawns a birth at the next snapshot when the association
    /// weight `sum_i w_i(z)` that existing components gave it stays below this
    /// (it is "not explained"). 0.5: explained by more than half a target.
    pub birth_association_threshold: f64,
    /// Clutter intensity `kappa`, false detections per metre of path length per
    /// snapshot. Not in the paper. 1e-3 /m is 0.3 false detections per
    /// microsecond of delay window (about 0.6 per 2048-tap, 1 GHz CIR), in line
    /// with the few diffuse peaks per snapshot above floor + 6 dB. The filter
    /// is insensitive to it over decades because true detections have
    /// likelihoods of ~100 /m.
    pub clutter_intensity_per_m: f64,
    /// Largest delay change between a component's predicted delay and a
    /// detection it may be updated with, s (the paper's "maximum delay change"
    /// filter, cf. its eq. (15)). 0.5 ns, the paper's search tolerance
    /// epsilon_tau; also 200 m/s of path-length change over 0.717 ms.
    pub max_delay_change_s: f64,
    /// Largest magnitude change between a track's last associated detection and
    /// a detection it may be updated with, dB (the "maximum magnitude change"
    /// filter). 10 dB, the paper's search tolerance epsilon_a.
    pub max_magnitude_change_db: f64,
    /// Carrier frequency, Hz, for the Doppler of a track (`nu = -f_c dtau/dt`,
    /// eq. (31)). 5.7 GHz, the paper's sounder.
    pub carrier_hz: f64,
    /// Tracks with fewer extracted steps are dropped. 3, like the three-point
    /// initiation of the proposed tracker (Sec. III-B), so the two trackers'
    /// track counts compare.
    pub min_track_detections: usize,
}

impl Default for GmPhdConfig {
    fn default() -> Self {
        Self {
            sigma_process_mps2: 0.3,
            sigma_measurement_m: 3e-3,
            p_survival: 0.99,
            p_detection: 0.95,
            truncation_threshold: 1e-2,
            merge_threshold: 0.1,
            extraction_threshold: 0.2,
            max_components: 100,
            birth_weight: 0.01,
            birth_sigma_rate_mps: 40.0,
            birth_association_threshold: 0.5,
            clutter_intensity_per_m: 1e-3,
            max_delay_change_s: 0.5e-9,
            max_magnitude_change_db: 10.0,
            carrier_hz: 5.7e9,
            min_track_detections: 3,
        }
    }
}

fn bad(field: &'static str, value: f64, expected: &'static str) -> GmPhdError {
    GmPhdError::BadConfig { field, value, expected }
}

fn positive(field: &'static str, value: f64) -> Result<(), GmPhdError> {
    if value.is_finite() && value > 0.0 { Ok(()) } else { Err(bad(field, value, "finite and > 0")) }
}

fn non_negative(field: &'static str, value: f64) -> Result<(), GmPhdError> {
    if value.is_finite() && value >= 0.0 { Ok(()) } else { Err(bad(field, value, "finite and >= 0")) }
}

fn probability(field: &'static str, value: f64) -> Result<(), GmPhdError> {
    if (0.0..=1.0).contains(&value) { Ok(()) } else { Err(bad(field, value, "a probability in [0, 1]")) }
}

impl GmPhdConfig {
    /// Checks every field; the error names the first bad one.
    ///
    /// # Errors
    /// [`GmPhdError::BadConfig`].
    pub fn validate(&self) -> Result<(), GmPhdError> {
        non_negative("sigma_process_mps2", self.sigma_process_mps2)?;
        positive("sigma_measurement_m", self.sigma_measurement_m)?;
        probability("p_survival", self.p_survival)?;
        probability("p_detection", self.p_detection)?;
        non_negative("truncation_threshold", self.truncation_threshold)?;
        non_negative("merge_threshold", self.merge_threshold)?;
        non_negative("extraction_threshold", self.extraction_threshold)?;
        if self.max_components == 0 {
            return Err(bad("max_components", 0.0, "at least 1"));
        }
        non_negative("birth_weight", self.birth_weight)?;
        positive("birth_sigma_rate_mps", self.birth_sigma_rate_mps)?;
        probability("birth_association_threshold", self.birth_association_threshold)?;
        non_negative("clutter_intensity_per_m", self.clutter_intensity_per_m)?;
        positive("max_delay_change_s", self.max_delay_change_s)?;
        positive("max_magnitude_change_db", self.max_magnitude_change_db)?;
        positive("carrier_hz", self.carrier_hz)?;
        if self.min_track_detections == 0 {
            return Err(bad("min_track_detections", 0.0, "at least 1"));
        }
        Ok(())
    }
}
