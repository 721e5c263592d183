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

/// Where a true propagation path runs at one instant, as a simulator that
/// knows the geometry gives it: from the transmitter through each
/// interaction point (wall bounce, scattering car) to the receiver, in the
/// world frame, metres (horizontal plane).
#[derive(Debug, Clone, PartialEq)]
pub struct PathGeometry {
    /// Identifier of the propagation path, as in [`MpcTruth::path_id`].
    pub path_id: u64,
    /// Transmitter, interaction points in order, receiver; metres.
    pub points_m: Vec<[f64; 2]>,
}

impl MpcTruth {
    /// Power of the component, dB: `20 log10 |amplitude|`.
    #[must_use]
    pub fn power_db(&self) -> f64 {
        20.0 * self.amplitude.norm().log10()
    }
}

/// One short-term track's place in a long-term track (Mahler et al. 2017,
/// Sec. V): the full-lifetime track `short_track_id` of set `set_index`,
/// summarised by its mean delay and power and its Doppler, and how it was
/// related to the previous set.
#[derive(Debug, Clone, PartialEq)]
pub struct MpcLongTermEntry {
    /// Identifier of the long-term track, unique within one run.
    pub long_track_id: u64,
    /// Set of this entry.
    pub set_index: u64,
    /// Mean time of the short-term track's detections, nanoseconds.
    pub t_ns: i64,
    /// The short-term track (its `track_id`).
    pub short_track_id: u64,
    /// Mean delay over the set, seconds (tau-bar of eq. (33)).
    pub mean_delay_s: f64,
    /// Power of the mean linear power over the set, dB (a-bar of eq. (33)).
    pub mean_power_db: f64,
    /// Doppler of the short-term track, hertz (nu of eq. (31)).
    pub doppler_hz: f64,
    /// Larger of the two-way delay prediction errors of the link from the
    /// previous set, seconds (eqs. (41)-(42)); `None` for the first entry.
    pub link_error_s: Option<f64>,
    /// Smallest confidence class chi that holds the link, seconds (eq. (40));
    /// `None` for the first entry.
    pub chi_class_s: Option<f64>,
}

/// Per-set summary of detection and tracking: counts and channel gains
/// (Mahler et al. 2017, Figs. 8-9: the captured gains give the power losses).
#[derive(Debug, Clone, PartialEq)]
pub struct MpcSetStats {
    /// The set.
    pub set_index: u64,
    /// Time of its first snapshot, nanoseconds.
    pub t_ns: i64,
    /// Snapshots in the set.
    pub snapshots: u32,
    /// Snapshots skipped (e.g. all-zero CIRs).
    pub skipped_snapshots: u32,
    /// Detections over the set.
    pub detections: u32,
    /// Short-term tracks of the set.
    pub short_term_tracks: u32,
    /// Short-term tracks that span the whole set.
    pub full_lifetime_tracks: u32,
    /// Mean noise floor of the set's snapshots, dB; `None` when every
    /// snapshot was skipped.
    pub noise_floor_db: Option<f64>,
    /// Mean channel gain after thresholding and windowing, dB; `None` when
    /// every snapshot was skipped or nothing was left above the threshold.
    pub channel_gain_db: Option<f64>,
    /// Mean gain captured by the detections, dB; `None` without detections
    /// (or measured snapshots).
    pub detected_gain_db: Option<f64>,
    /// Mean gain captured by the short-term tracks, dB; `None` without
    /// tracks (e.g. a recording of one snapshot per set).
    pub tracked_gain_db: Option<f64>,
    /// Mean gain captured by the full-lifetime tracks, dB; `None` without
    /// them.
    pub full_lifetime_gain_db: Option<f64>,
    /// Mean gain captured by the GM-PHD baseline's tracks, dB (the same
    /// definition as `tracked_gain_db`); `None` when GM-PHD did not run or
    /// found no track.
    pub gmphd_tracked_gain_db: Option<f64>,
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
