//! Result tables of the multipath-component statistics (`mmtrack analyze`
//! on the tables of `process mpc`, Mahler et al. 2017), with units: one
//! partition per sequence.

use super::TableFrame;

crate::define_table! {
    /// `mpc_set_metrics`: one row per set.
    pub const MPC_SET_METRICS = "mpc_set_metrics",
        "MPC statistics of one sounder set per row, in set order: long-term MPC count (Fig. 12), births and \
deaths across the pair (previous set, this set) and their rates (Fig. 13), channel gains and power losses (Figs. 8-9). \
Transition columns are null for the first set.",
        frame: TableFrame::NotApplicable;
    /// Per-set results: one row of [`MPC_SET_METRICS`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct SetMetrics {
        set_index: u64, "", "the set";
        t_ns: i64, "ns", "time of its first snapshot";
        long_term_mpcs: u64, "", "full-lifetime MPCs entered in long-term tracks in this set";
        detections: u64, "", "detections over the set";
        full_lifetime_tracks: u64, "", "short-term tracks spanning the set";
        births: Option<u64>, "", "long-term tracks whose first entry is this set";
        deaths: Option<u64>, "", "long-term tracks whose last entry is the previous set";
        distance_m: Option<f64>, "m", "distance driven since the previous set (both vehicles summed when known)";
        birth_rate_per_m: Option<f64>, "1/m", "births / distance_m";
        death_rate_per_m: Option<f64>, "1/m", "deaths / distance_m";
        birth_rate_per_s: Option<f64>, "1/s", "births / time since the previous set";
        death_rate_per_s: Option<f64>, "1/s", "deaths / time since the previous set";
        channel_gain_db: Option<f64>, "dB", "channel gain after thresholding and windowing (mpc_sets); null when nothing was measured; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        detected_gain_db: Option<f64>, "dB", "gain captured by the detections; null without detections; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        tracked_gain_db: Option<f64>, "dB", "gain captured by the short-term tracks; null without tracks (e.g. one snapshot per set); dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        full_lifetime_gain_db: Option<f64>, "dB", "gain captured by the full-lifetime tracks; null without them; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        gmphd_tracked_gain_db: Option<f64>, "dB", "gain captured by the GM-PHD tracks; null without them; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        detection_loss_db: Option<f64>, "dB", "channel_gain_db - detected_gain_db: dB re the channel gain; null when either is";
        tracking_loss_db: Option<f64>, "dB", "channel_gain_db - tracked_gain_db: dB re the channel gain; null when either is";
        gmphd_tracking_loss_db: Option<f64>, "dB", "channel_gain_db - gmphd_tracked_gain_db: dB re the channel gain; null when either is";
        true_births: Option<u64>, "", "true paths above the floor appearing since the previous set; null without truth";
        true_deaths: Option<u64>, "", "true paths above the floor gone since the previous set; null without truth";
    }
}

crate::define_table! {
    /// `mpc_track_power_std`: one row per short-term track.
    pub const MPC_TRACK_POWER_STD = "mpc_track_power_std",
        "Power standard deviation of each short-term track over its set (Mahler et al. 2017, Fig. 7), in \
the order of mpc_tracks: sample standard deviation (n - 1) of its detections' power_db, 0 for one detection.",
        frame: TableFrame::NotApplicable;
    /// Per-track power spread: one row of [`MPC_TRACK_POWER_STD`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct TrackPowerStd {
        track_id: u64, "", "track_id in mpc_tracks";
        set_index: u64, "", "set of the track";
        detections: u64, "", "detections of the track";
        full_lifetime: bool, "", "true when the track spans every processed snapshot of its set";
        power_std_db: f64, "dB", "standard deviation of power_db over the track (a spread of dB values, independent of their reference)";
    }
}

crate::define_table! {
    /// `mpc_chi_classes`: power share per long-term confidence class.
    pub const MPC_CHI_CLASSES = "mpc_chi_classes",
        "Long-term links per confidence class chi (Mahler et al. 2017, eq. 40, Sec. VI-A), in increasing \
chi: the share of the linked power (mean power of the entry each link leads to); a last row with a null chi gives \
the entries related to no adjacent set and their share of all full-lifetime power.",
        frame: TableFrame::NotApplicable;
    /// Power share of one confidence class: one row of [`MPC_CHI_CLASSES`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct ChiClassShare {
        chi_class_s: Option<f64>, "s", "confidence class; null for the unrelated entries";
        entries: u64, "", "links of this class (or unrelated entries)";
        power_share: f64, "", "share of linked power (or of all long-term power for the null row), 0..1";
    }
}

crate::define_table! {
    /// `mpc_count_distribution`: distribution of the number of MPCs per set.
    pub const MPC_COUNT_DISTRIBUTION = "mpc_count_distribution",
        "Distribution of the number of long-term (full-lifetime) MPCs per set (Mahler et al. 2017, \
Fig. 12), one row per count that occurs, in increasing count.",
        frame: TableFrame::NotApplicable;
    /// One value of the number-of-MPCs distribution: one row of [`MPC_COUNT_DISTRIBUTION`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct CountBin {
        mpcs: u64, "", "number of MPCs in a set";
        sets: u64, "", "sets with that many";
        cdf: f64, "", "share of sets with at most that many, 0..1";
    }
}

crate::define_table! {
    /// `mpc_summary`: one row per sequence.
    pub const MPC_SUMMARY = "mpc_summary",
        "Summary of the MPC statistics of one sequence partition (one row). Rates per metre use the \
distance named by distance_source (both sounder vehicles' ground truth summed, as the paper; or one trajectory); \
they are null without one, and the per-second rates always apply. Truth columns are null without mpc_truth.",
        frame: TableFrame::NotApplicable;
    /// Summary of one sequence: the row of [`MPC_SUMMARY`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct MpcSummary {
        sets: u64, "", "sets processed";
        detections: u64, "", "detections";
        short_term_tracks: u64, "", "short-term tracks";
        full_lifetime_tracks: u64, "", "short-term tracks spanning their set";
        long_term_tracks: u64, "", "long-term tracks";
        mean_mpcs_per_set: Option<f64>, "", "mean number of long-term MPCs per set (null when nothing was tracked)";
        median_mpcs_per_set: Option<f64>, "", "median number of long-term MPCs per set (null when nothing was tracked)";
        distance_source: String, "", "tables the distance comes from, or none";
        distance_m: Option<f64>, "m", "distance driven from the first to the last set";
        duration_s: f64, "s", "time from the first to the last set";
        births: Option<u64>, "", "long-term track births (not counting the first set; null when nothing was tracked)";
        deaths: Option<u64>, "", "long-term track deaths (not counting the last set; null when nothing was tracked)";
        birth_rate_per_m: Option<f64>, "1/m", "births / distance_m";
        death_rate_per_m: Option<f64>, "1/m", "deaths / distance_m";
        birth_rate_per_s: Option<f64>, "1/s", "births / duration_s";
        death_rate_per_s: Option<f64>, "1/s", "deaths / duration_s";
        mean_detection_loss_db: Option<f64>, "dB", "mean over sets of channel minus detected gain: dB re the channel gain";
        mean_tracking_loss_db: Option<f64>, "dB", "mean over sets of channel minus short-term tracked gain: dB re the channel gain";
        mean_full_lifetime_loss_db: Option<f64>, "dB", "mean over sets of channel minus full-lifetime gain: dB re the channel gain";
        mean_gmphd_tracking_loss_db: Option<f64>, "dB", "mean over sets of channel minus GM-PHD tracked gain: dB re the channel gain";
        full_lifetime_std_below_1db: Option<f64>, "", "share of full-lifetime tracks with power std < 1 dB";
        all_tracks_std_below_1_5db: Option<f64>, "", "share of all short-term tracks with power std < 1.5 dB";
        chi_0_1ns_power_share: Option<f64>, "", "share of linked power in classes chi <= 0.1 ns";
        unrelated_power_share: Option<f64>, "", "share of long-term power in entries related to no adjacent set";
        truth_mpcs: Option<u64>, "", "resolvable true MPCs over all snapshots (true MPCs within 0.5 ns merged)";
        precision: Option<f64>, "", "detections matching a true MPC within 0.5 ns / detections";
        recall: Option<f64>, "", "true MPCs matched / true MPCs";
        recall_above_floor: Option<f64>, "", "recall over true MPCs at least 6 dB above the noise floor";
        track_purity: Option<f64>, "",
            "over tracks with a matched detection: detection-weighted share on their majority path";
        false_track_share: Option<f64>, "", "share of short-term tracks without a matched detection";
        false_long_term_share: Option<f64>, "", "share of long-term tracks that follow no true path";
        births_on_true_paths: Option<u64>, "", "births of long-term tracks that follow a true path";
        deaths_on_true_paths: Option<u64>, "", "deaths of long-term tracks that follow a true path";
        long_term_tracks_per_path: Option<f64>, "", "long-term tracks following a true path / paths followed";
        true_births: Option<u64>, "", "true path births above the floor";
        true_deaths: Option<u64>, "", "true path deaths above the floor";
        true_birth_rate_per_m: Option<f64>, "1/m", "true_births / distance_m";
        true_death_rate_per_m: Option<f64>, "1/m", "true_deaths / distance_m";
        first_path_dynamic_range_db: f64, "dB",
            "a snapshot's first path is its earliest detection at most this far below its strongest (mpc_first_path): dB re the strongest detection's power";
        first_path_snapshots: u64, "", "snapshots with a first path (at least one detection)";
        first_path_hint_snapshots: u64, "", "of those, snapshots carrying the receiver's own first-path estimate";
        first_path_earlier_snapshots: u64, "",
            "of those, snapshots with detections before the first path (mpc_first_path.earlier_detections > 0)";
        first_path_minus_hint_median_s: Option<f64>, "s",
            "median of first path minus the receiver's estimate; null without estimates";
        first_path_hint_abs_median_s: Option<f64>, "s",
            "median of |first path - the receiver's estimate|; null without estimates";
        first_path_hint_abs_p90_s: Option<f64>, "s",
            "90th percentile of |first path - the receiver's estimate| (linear between order statistics)";
    }
}

crate::define_table! {
    /// `mpc_first_path`: one row per snapshot.
    pub const MPC_FIRST_PATH = "mpc_first_path",
        "The first path of each CIR snapshot, in the order of mpc_snapshots (or of set and snapshot \
without it): the earliest detection at most first_path_dynamic_range_db (mpc_summary) below the snapshot's \
strongest detection, and its distance from the receiver's own first-path estimate when the recording carries one \
(e.g. the DW1000's leading edge HLP). Delay columns are null for a snapshot without detections.",
        frame: TableFrame::NotApplicable;
    /// One snapshot's first path: one row of [`MPC_FIRST_PATH`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct FirstPathRow {
        t_ns: i64, "ns", "time of the snapshot";
        set_index: u64, "", "sounder set";
        snapshot_index: u32, "", "snapshot within the set";
        detections: u64, "", "detections of the snapshot";
        earlier_detections: u64, "",
            "detections before the first path, each more than the dynamic range below the strongest: noise peaks, or a weak first path the range leaves out (raise first_path_dynamic_range_db to reach it)";
        strongest_delay_s: Option<f64>, "s", "delay of the strongest detection";
        strongest_power_db: Option<f64>, "dB", "power of the strongest detection (mpc_detections.power_db); dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        first_path_delay_s: Option<f64>, "s", "delay of the first path";
        first_path_power_db: Option<f64>, "dB", "power of the first path (mpc_detections.power_db); dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)";
        first_path_hint_s: Option<f64>, "s", "the receiver's own first-path estimate (mpc_snapshots); null when not given";
        first_path_minus_hint_s: Option<f64>, "s", "first_path_delay_s - first_path_hint_s";
    }
}
