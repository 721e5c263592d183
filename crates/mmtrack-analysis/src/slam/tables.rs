//! Result tables of the 5G mmWave SLAM experiment, with units.

mmtrack_io::define_table! {
    /// `slam_summary`: one row per experiment row (scenario variant).
    pub const SLAM_SUMMARY = "slam_summary",
        "5G mmWave SLAM over the Monte Carlo runs of one scenario variant (Kim et al. 2018, Sec. V): mean over \
runs of the time-averaged UE errors, of the time-averaged localisation errors of the confirmed VAs and SPs (each \
against the nearest true source of its type), and the epochs (1-based, as the paper's k) at which every VA and every \
SP seen along the drive was confirmed.";
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
        va_error_m: Option<f64>, "m", "mean localisation error of confirmed VAs; null when none was confirmed";
        sp_error_m: Option<f64>, "m", "mean localisation error of confirmed SPs; null when none was confirmed";
        all_va_epoch_mean: f64, "", "mean over runs of the epoch when all VAs were confirmed (epochs + 1 if never)";
        all_va_epoch_max: u64, "", "latest such epoch over the runs (epochs + 1 if never)";
        all_sp_epoch_mean: f64, "", "mean over runs of the epoch when all seen SPs were confirmed (epochs + 1 if never)";
        all_sp_epoch_max: u64, "", "latest such epoch over the runs (epochs + 1 if never)";
        false_sources: f64, "", "mean confirmed sources per run with no true source of their type within the match radius";
        skipped_paths: u64, "", "paths skipped as unusable over all runs";
    }
}

mmtrack_io::define_table! {
    /// `slam_per_epoch`: errors and map size per epoch, averaged over runs.
    pub const SLAM_PER_EPOCH = "slam_per_epoch",
        "5G mmWave SLAM per epoch, averaged over the Monte Carlo runs of one scenario variant (Kim et al. 2018, \
Figs. 4-6): UE errors, localisation errors of the confirmed sources and the number of confirmed VAs and SPs.";
    /// One row of [`SLAM_PER_EPOCH`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct SlamPerEpochRow {
        row: String, "", "scenario variant";
        epoch: u64, "", "epoch k (1-based)";
        ue_position_error_m: f64, "m", "mean UE position error";
        ue_heading_error_rad: f64, "rad", "mean absolute heading error";
        ue_clock_bias_error_m: f64, "m", "mean absolute clock-bias error";
        va_error_m: Option<f64>, "m", "mean error of the confirmed VAs; null when no run had one";
        sp_error_m: Option<f64>, "m", "mean error of the confirmed SPs; null when no run had one";
        confirmed_va: f64, "", "mean number of confirmed VAs";
        confirmed_sp: f64, "", "mean number of confirmed SPs";
    }
}
