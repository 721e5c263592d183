use num_complex::Complex64;

/// One multipath component (MPC) detected in one CIR snapshot.
#[derive(Debug, Clone, PartialEq)]
pub struct MpcDetection {
    /// Time of the snapshot, nanoseconds.
    pub t_ns: i64,
    /// Set of the snapshot.
    pub set_index: u64,
    /// Snapshot within its set.
    pub snapshot_index: u32,
    /// Estimated propagation delay, seconds (sub-tap resolution).
    pub delay_s: f64,
    /// Estimated complex amplitude (linear, the sounder's scale).
    pub amplitude: Complex64,
}

impl MpcDetection {
    /// Power of the component, dB: `20 log10 |amplitude|`.
    #[must_use]
    pub fn power_db(&self) -> f64 {
        20.0 * self.amplitude.norm().log10()
    }
}

/// A tracked multipath component: the detections associated to it over time.
#[derive(Debug, Clone, PartialEq)]
pub struct MpcTrack {
    /// Identifier, unique within one tracker run.
    pub track_id: u64,
    /// Doppler shift from a linear fit of delay over time, hertz
    /// (`nu = -slope * f_c`, Mahler et al. 2017 Sec. III-B); `None` before the
    /// track has enough points.
    pub doppler_hz: Option<f64>,
    /// Associated detections in time order.
    pub detections: Vec<MpcDetection>,
}

/// A true multipath component in one snapshot, as a simulator knows it.
///
/// `path_id` names the propagation path (the same reflector keeps its id while
/// it is visible), so tracks can be scored for purity and births/deaths
/// counted from the truth.
#[derive(Debug, Clone, PartialEq)]
pub struct MpcTruth {
    /// Time of the snapshot, nanoseconds.
    pub t_ns: i64,
    /// Set of the snapshot.
    pub set_index: u64,
    /// Snapshot within its set.
    pub snapshot_index: u32,
    /// Identifier of the propagation path (stable while the path exists).
    pub path_id: u64,
    /// True propagation delay, seconds (on the recording's delay axis).
    pub delay_s: f64,
    /// True complex amplitude (linear, the sounder's scale).
    pub amplitude: Complex64,
    /// True Doppler shift, hertz (`-f_c d(tau)/dt`).
    pub doppler_hz: f64,
}

impl MpcTruth {
    /// Power of the component, dB: `20 log10 |amplitude|`.
    #[must_use]
    pub fn power_db(&self) -> f64 {
        20.0 * self.amplitude.norm().log10()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_is_20_log10_magnitude() {
        let d = MpcDetection {
            t_ns: 0,
            set_index: 0,
            snapshot_index: 0,
            delay_s: 1e-9,
            amplitude: Complex64::new(0.0, 0.1),
        };
        assert!((d.power_db() + 20.0).abs() < 1e-12);
    }
}
