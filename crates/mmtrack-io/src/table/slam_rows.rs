//! Result tables of the 5G mmWave SLAM experiment, with units.

use super::TableFrame;

crate::define_table! {
    /// `slam_summary`: one row per experiment row (scenario variant).
    pub const SLAM_SUMMARY = "slam_summary",
        "5G mmWave SLAM over the Monte Carlo runs of one scenario variant (Kim et al. 2018, Sec. V): mean over \
runs of the time-averaged UE errors, of the time-averaged localisation errors of the confirmed VAs and SPs (each \
against the nearest true source of its type), and the epochs (1-based, as the paper's k) at which every VA and every \
SP seen along the drive was confirmed. Written by `reproduce kim` (one row per scenario variant) and by `mmtrack \
analyze` on the tables of `process slam` (one partition per sequence, row = the sequence, runs = 1).",
        frame: TableFrame::NotApplicable;
    /// One row of [`SLAM_SUMMARY`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct SlamSummaryRow {
        row: String, "", "scenario variant (paper, pd-0.9, clutter-1, ...)";
        runs: u64, "", "Monte Carlo runs";
        epochs: u64, "", "epochs per run";
        particles: u64, "", "UE particles";
        detection_probability: f64, "", "probability that a path is detected";
        clutter_per_epoch: u64, "", "clutter paths per epoch";
        ue_position_error_m: f64, "m", "mean UE position error";
        ue_error_over_spread: f64, "",
            "RMS UE position error over the RMS of the filter's position spread (root of the horizontal covariance \
trace), all epochs of all runs: 1 for a consistent filter, above 1 for an overconfident one";
        ue_heading_error_rad: f64, "rad", "mean absolute UE heading error";
        ue_clock_bias_error_m: f64, "m", "mean absolute clock-bias error";
        ue_speed_error_mps: f64, "m/s", "mean absolute speed error (1-step smoothed)";
        ue_turn_rate_error_radps: f64, "rad/s", "mean absolute turn-rate error (1-step smoothed)";
        va_error_m: Option<f64>, "m", "mean localisation error of every confirmed VA (its distance to the nearest true VA, no cut-off); null when none was confirmed";
        sp_error_m: Option<f64>, "m", "mean localisation error of every confirmed SP (its distance to the nearest true SP, no cut-off); null when none was confirmed";
        all_va_epoch_mean: f64, "", "mean over runs of the epoch when all VAs were confirmed (epochs + 1 if never)";
        all_va_epoch_max: u64, "", "latest such epoch over the runs (epochs + 1 if never)";
        all_sp_epoch_mean: f64, "", "mean over runs of the epoch when all seen SPs were confirmed (epochs + 1 if never)";
        all_sp_epoch_max: u64, "", "latest such epoch over the runs (epochs + 1 if never)";
        false_sources: f64, "", "mean confirmed sources per run, at the last epoch, that match no true source of their type (one confirmed source per true one, within the match radius)";
        skipped_paths: u64, "", "paths skipped as unusable over all runs";
    }
}

crate::define_table! {
    /// `slam_per_epoch`: errors and map size per epoch, averaged over runs.
    pub const SLAM_PER_EPOCH = "slam_per_epoch",
        "5G mmWave SLAM per epoch, averaged over the Monte Carlo runs of one scenario variant (Kim et al. 2018, \
Figs. 4-6): UE errors, localisation errors of the confirmed sources and the number of confirmed VAs and SPs. \
`mmtrack analyze` writes it per sequence of `process slam` (one run: the values of that run).",
        frame: TableFrame::NotApplicable;
    /// One row of [`SLAM_PER_EPOCH`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct SlamPerEpochRow {
        row: String, "", "scenario variant";
        epoch: u64, "", "epoch k (1-based)";
        ue_position_error_m: f64, "m", "mean UE position error";
        ue_heading_error_rad: f64, "rad", "mean absolute heading error";
        ue_clock_bias_error_m: f64, "m", "mean absolute clock-bias error";
        va_error_m: Option<f64>, "m", "mean error of every confirmed VA (no cut-off); null when no run had one";
        sp_error_m: Option<f64>, "m", "mean error of every confirmed SP (no cut-off); null when no run had one";
        confirmed_va: f64, "", "mean number of confirmed VAs";
        confirmed_sp: f64, "", "mean number of confirmed SPs";
    }
}

crate::define_table! {
    /// `slam_ue`: the UE estimate of each epoch, with the truth when known.
    pub const SLAM_UE = "slam_ue",
        "The 5G mmWave SLAM filter's UE estimate per epoch of one recording (`mmtrack process slam`, Kim et al. \
2018): the posterior mean and spreads after the epoch's update, what the epoch held and used, and the true state when \
the recording carries it (/slam/ue_truth; null otherwise).",
        frame: TableFrame::Run;
    /// One row of [`SLAM_UE`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct SlamUeRow {
        epoch: u64, "", "epoch k (1-based, as the paper's k)";
        t_ns: i64, "ns", "epoch time";
        initialised: bool, "", "the UE has been initialised from a line-of-sight path (before that the estimate is the prior)";
        x_m: f64, "m", "estimated UE position x";
        y_m: f64, "m", "estimated UE position y";
        z_m: f64, "m", "UE height (not estimated: the prior's)";
        heading_rad: f64, "rad", "estimated heading";
        speed_mps: f64, "m/s", "estimated speed (1-step smoothed)";
        turn_rate_radps: f64, "rad/s", "estimated turn rate (1-step smoothed)";
        clock_bias_m: f64, "m", "estimated clock bias";
        position_std_m: f64, "m", "root of the trace of the horizontal position covariance";
        heading_std_rad: f64, "rad", "heading standard deviation";
        clock_bias_std_m: f64, "m", "clock-bias standard deviation";
        paths: u64, "", "paths in the epoch's measurement set";
        skipped_paths: u64, "", "paths skipped as unusable (NaN, elevation out of [-pi/2, pi/2])";
        paths_in_update: u64, "", "paths from the BS and confirmed sources used in the UE update";
        ess: f64, "", "effective sample size of the particles after the update";
        true_x_m: Option<f64>, "m", "true UE position x; null without ground truth";
        true_y_m: Option<f64>, "m", "true UE position y";
        true_z_m: Option<f64>, "m", "true UE height";
        true_heading_rad: Option<f64>, "rad", "true heading";
        true_speed_mps: Option<f64>, "m/s", "true speed";
        true_turn_rate_radps: Option<f64>, "rad/s", "true turn rate";
        true_clock_bias_m: Option<f64>, "m", "true clock bias";
    }
}

crate::define_table! {
    /// `slam_map`: every map source after every epoch.
    pub const SLAM_MAP = "slam_map",
        "The 5G mmWave SLAM map over time (`mmtrack process slam`): after each epoch, one row per source of the \
filter's map (the known base station, confirmed virtual anchors and scattering points, unconfirmed sources), with its \
type, spatial belief and history.",
        frame: TableFrame::Run;
    /// One row of [`SLAM_MAP`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct SlamMapRow {
        epoch: u64, "", "epoch k (1-based) after which the map is shown";
        t_ns: i64, "ns", "epoch time";
        source_id: u64, "", "source identifier, stable over epochs and never reused (0 = base station)";
        status: String, "", "bs, va (confirmed virtual anchor), sp (confirmed scattering point) or unconfirmed";
        confirmed: bool, "", "the source is the base station or a confirmed VA or SP";
        x_m: f64, "m", "mean of the spatial belief, x (unconfirmed: the latest SP hypothesis, else the VA one)";
        y_m: f64, "m", "mean of the spatial belief, y";
        z_m: f64, "m", "mean of the spatial belief, z";
        spread_m: f64, "m", "root of the trace of the belief's covariance";
        first_seen_epoch: u64, "", "epoch (1-based) of the first sighting";
        sightings: u64, "", "epochs with a path associated with the source";
        confirmed_epoch: Option<u64>, "", "epoch (1-based) at which it was confirmed; null while unconfirmed (the BS: 0)";
    }
}

crate::define_table! {
    /// `slam_associations`: the source each path of each epoch was given.
    pub const SLAM_ASSOCIATIONS = "slam_associations",
        "The 5G mmWave SLAM data association (`mmtrack process slam`, Kim et al. 2018, eq. (3)-(7), solved by \
Kuhn-Munkres): one row per usable path of each epoch, the decision and its score, beside the path's true source when \
the recording carries it.",
        frame: TableFrame::NotApplicable;
    /// One row of [`SLAM_ASSOCIATIONS`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct SlamAssociationRow {
        epoch: u64, "", "epoch k (1-based)";
        t_ns: i64, "ns", "epoch time";
        path: u64, "", "index of the path in the epoch's /slam/paths message";
        decision: String, "",
            "source (an existing map source), new_source (a new unconfirmed source), initialisation (the line of sight \
that initialised the UE) or waiting (dropped before the UE was initialised)";
        source_id: Option<u64>, "", "the map source (source and new_source); null otherwise";
        log_score: f64, "", "natural log of the chosen likelihood-matrix entry (log P_N for a new source)";
        true_source: Option<String>, "", "the path's true source type: bs, va, sp or clutter; null without ground truth";
        true_source_index: Option<u64>, "", "index of the true source among those of its type (slam_true_sources)";
    }
}

crate::define_table! {
    /// `slam_true_sources`: the sources of the paths in the recording.
    pub const SLAM_TRUE_SOURCES = "slam_true_sources",
        "The sources of the 5G mmWave paths as the recording gives them (/slam/sources): the base station and, \
from a simulation, the true virtual anchors and scattering points; with the number of epochs each was seen in \
(from the ground-truth path origins).",
        frame: TableFrame::Run;
    /// One row of [`SLAM_TRUE_SOURCES`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct SlamTrueSourceRow {
        kind: String, "", "bs, va or sp";
        index: u64, "", "index among the sources of its kind";
        x_m: f64, "m", "position x";
        y_m: f64, "m", "position y";
        z_m: f64, "m", "position z";
        detected_epochs: Option<u64>, "", "epochs with a measured path from this source; null without path origins";
    }
}
