//! Tables of the multipath-component pipeline beyond detections and tracks
//! (those are in `rows.rs`): GM-PHD tracks, long-term tracks, per-set and
//! per-snapshot statistics, the simulator's true MPCs and both sounder vehicles' ground
//! truth (Mahler et al. 2017, Secs. III-VI).

use super::TableFrame;

use mmtrack_core::{Complex64, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth, StampedPose};

/// A track of the GM-PHD baseline: the columns of `mpc_tracks`, in its own
/// table so both trackers' results sit side by side.
#[derive(Debug, Clone, PartialEq)]
pub struct GmPhdTrack(pub MpcTrack);

crate::define_table! {
    /// `mpc_tracks_gmphd`: tracks of the GM-PHD baseline.
    pub const MPC_TRACKS_GMPHD = "mpc_tracks_gmphd",
        "One associated detection of a GM-PHD baseline track (Mahler et al. 2017, Table I) per row; the \
columns of mpc_tracks; rows of a track are consecutive and in time order.",
        frame: TableFrame::NotApplicable;
    GmPhdTrack(MpcTrack);
}

crate::define_table! {
    /// `mpc_long_term`: long-term tracks across sets.
    pub const MPC_LONG_TERM = "mpc_long_term",
        "One full-lifetime short-term track as an entry of a long-term track per row (Mahler et al. 2017, \
Sec. V), ordered by set then long-term track; a long-term track is the rows sharing long_track_id.",
        frame: TableFrame::NotApplicable;
    MpcLongTermEntry {
        long_track_id: u64, "", "long-term track identifier, unique within the run";
        set_index: u64, "", "sounder set of this entry";
        t_ns: i64, "ns", "mean time of the short-term track's detections";
        short_track_id: u64, "", "the full-lifetime short-term track (track_id in mpc_tracks)";
        mean_delay_s: f64, "s", "mean delay over the set (tau-bar, eq. 33)";
        mean_power_db: f64, "dB", "10 log10 of the mean linear power |a|^2 over the set (a-bar, eq. 33); dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        doppler_hz: f64, "Hz", "Doppler of the short-term track (nu, eq. 31)";
        link_error_s: Option<f64>, "s",
            "larger two-way delay prediction error of the link from the previous entry of its track (eqs. 41-42): the previous set, or an earlier one with long_term.max_missed_sets; null for the first entry";
        chi_class_s: Option<f64>, "s",
            "smallest confidence class chi holding the link (eq. 40); null for the first entry";
    }
}

crate::define_table! {
    /// `mpc_sets`: per-set statistics of detection and tracking.
    pub const MPC_SETS = "mpc_sets",
        "One sounder set per row, in set order: counts of detections and tracks and the channel gains \
(Mahler et al. 2017, Figs. 8-9); gains are means over the set's snapshots of sum |a|^2 in dB, null when nothing \
was captured.",
        frame: TableFrame::NotApplicable;
    MpcSetStats {
        set_index: u64, "", "the set";
        t_ns: i64, "ns", "time of its first snapshot";
        snapshots: u32, "", "snapshots in the set";
        skipped_snapshots: u32, "", "snapshots skipped (e.g. all-zero CIRs)";
        detections: u32, "", "detections over the set";
        short_term_tracks: u32, "", "short-term tracks of the set";
        full_lifetime_tracks: u32, "", "short-term tracks spanning the whole set";
        noise_floor_db: Option<f64>, "dB", "mean noise floor (mean tap power) of the set's snapshots; null when every snapshot was skipped; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        channel_gain_db: Option<f64>, "dB", "channel gain (sum of |h|^2 over the taps) after thresholding and windowing; null when every snapshot was skipped or nothing was above the threshold; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        detected_gain_db: Option<f64>, "dB", "gain captured by the detections (sum of |a|^2 times the pulse energy); null without detections; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        tracked_gain_db: Option<f64>, "dB", "gain captured by the short-term tracks; null without tracks (e.g. one snapshot per set); dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        full_lifetime_gain_db: Option<f64>, "dB", "gain captured by the full-lifetime tracks; null without them; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        gmphd_tracked_gain_db: Option<f64>, "dB",
            "gain captured by the GM-PHD baseline's tracks (same definition); null when it did not run or found no track; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
    }
}

crate::define_table! {
    /// `mpc_snapshots`: per-snapshot detection statistics.
    pub const MPC_SNAPSHOTS = "mpc_snapshots",
        "One CIR snapshot per row, in recording order: what detection found in it (Mahler et al. 2017, \
Sec. III-A) and the receiver's own first-path estimate carried in the recording, for comparing first paths.",
        frame: TableFrame::NotApplicable;
    /// One row of [`MPC_SNAPSHOTS`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct MpcSnapshotStats {
        t_ns: i64, "ns", "time of the snapshot";
        set_index: u64, "", "sounder set";
        snapshot_index: u32, "", "snapshot within the set";
        detections: u32, "", "detected MPCs (rows of mpc_detections of this snapshot)";
        skipped: bool, "", "true when detection skipped the snapshot (all taps zero)";
        noise_floor_db: Option<f64>, "dB", "estimated noise floor (mean tap power); null when skipped; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        channel_gain_db: Option<f64>, "dB", "channel gain (sum of |h|^2 over the taps) after thresholding and windowing; null when skipped or nothing was above the threshold; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        detected_gain_db: Option<f64>, "dB", "gain captured by the detections; null without detections; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        first_path_hint_s: Option<f64>, "s",
            "the receiver's own first-path estimate on the delay axis (e.g. DW1000 HLP); null when not given";
    }
}

crate::define_table! {
    /// `mpc_truth`: the true MPCs of a simulated recording.
    pub const MPC_TRUTH = "mpc_truth",
        "One true multipath component of one snapshot per row, as the simulator knows it, in recording \
order; path_id is stable while the propagation path exists.",
        frame: TableFrame::NotApplicable;
    MpcTruth {
        t_ns: i64, "ns", "time of the snapshot";
        set_index: u64, "", "sounder set";
        snapshot_index: u32, "", "snapshot within the set";
        path_id: u64, "", "propagation path identifier";
        delay_s: f64, "s", "true delay on the recording's delay axis";
        amplitude_re: f64, "", "real part of the true complex amplitude", |r| r.amplitude.re;
        amplitude_im: f64, "", "imaginary part of the true complex amplitude", |r| r.amplitude.im;
        power_db: f64, "dB", "20 log10 |amplitude| (derived, for convenience); dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm) (the simulated CIR's)", MpcTruth::power_db;
        doppler_hz: f64, "Hz", "true Doppler shift, -f_c d(tau)/dt";
    } => {
        let amplitude = Complex64::new(amplitude_re, amplitude_im);
        MpcTruth { t_ns, set_index, snapshot_index, path_id, delay_s, amplitude, doppler_hz }
    }
}

/// Ground truth of a channel sounder's transmitter vehicle.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundTruthTxPose(pub StampedPose);

/// Ground truth of a channel sounder's receiver vehicle.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundTruthRxPose(pub StampedPose);

crate::define_table! {
    /// `ground_truth_tx`: the transmitter car's trajectory.
    pub const GROUND_TRUTH_TX = "ground_truth_tx",
        "One ground-truth pose world_from_vehicle of a channel sounder's transmitter car per row, in time \
order (recording topic /ground_truth/tx); the columns of poses.",
        frame: TableFrame::Run;
    GroundTruthTxPose(StampedPose);
}

crate::define_table! {
    /// `ground_truth_rx`: the receiver car's trajectory.
    pub const GROUND_TRUTH_RX = "ground_truth_rx",
        "One ground-truth pose world_from_vehicle of a channel sounder's receiver car per row, in time \
order (recording topic /ground_truth/rx); the columns of poses.",
        frame: TableFrame::Run;
    GroundTruthRxPose(StampedPose);
}
