//! Turning the labelled estimates of each snapshot into [`MpcTrack`]s, and the
//! per-track Doppler of Mahler et al. 2017, eqs. (30)-(31).

use std::collections::BTreeMap;

use mmtrack_core::{Complex64, MpcDetection, MpcTrack};
use mmtrack_filter::Label;

/// Detections collected per label while the filter runs.
#[derive(Debug, Default)]
pub(super) struct TrackBook {
    tracks: BTreeMap<Label, Vec<MpcDetection>>,
}

impl TrackBook {
    /// Appends one step of `label`. `amplitude = None` (an extracted component
    /// no detection produced) repeats the track's last amplitude, or zero for a
    /// track without one (its `power_db` is then `-inf`, visibly not measured).
    pub(super) fn push(&mut self, label: Label, mut detection: MpcDetection, amplitude: Option<Complex64>) {
        let track = self.tracks.entry(label).or_default();
        detection.amplitude =
            amplitude.or_else(|| track.last().map(|d| d.amplitude)).unwrap_or(Complex64::new(0.0, 0.0));
        track.push(detection);
    }

    /// Tracks with at least `min_detections` steps, ordered by `track_id`
    /// (the label), each with its Doppler estimate.
    pub(super) fn finish(self, min_detections: usize, carrier_hz: f64) -> Vec<MpcTrack> {
        self.tracks
            .into_iter()
            .filter(|(_, d)| d.len() >= min_detections)
            .map(|(label, detections)| MpcTrack {
                track_id: label.0,
                doppler_hz: doppler_hz(&detections, carrier_hz),
                detections,
            })
            .collect()
    }
}

/// The per-track Doppler, shared with the proposed tracker.
pub(super) use crate::short_term::doppler_hz;

#[cfg(test)]
mod tests {
    use super::*;

    fn det(t_ns: i64, delay_s: f64) -> MpcDetection {
        MpcDetection { t_ns, set_index: 0, snapshot_index: 0, delay_s, amplitude: Complex64::new(1.0, 0.0) }
    }

    #[test]
    fn doppler_of_a_linear_delay() {
        // tau = 50 ns - 1e-7 t: nu = -5.7e9 * (-1e-7) = 570 Hz.
        let d: Vec<_> = (0..5).map(|k| det(k * 1_000_000, 50e-9 - 1e-7 * k as f64 * 1e-3)).collect();
        let nu = doppler_hz(&d, 5.7e9).expect("five distinct times");
        // Delays near 5e-8 carry ~1e-23 s of round-off over a 4 ms span: ~1e-5 Hz.
        assert!((nu - 570.0).abs() < 1e-3, "{nu}");
        assert_eq!(doppler_hz(&d[..1], 5.7e9), None);
    }
}
