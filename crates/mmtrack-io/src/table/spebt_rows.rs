//! Result tables of the SPEBT beam-tracking experiment (Liu et al. 2024,
//! Sec. IV, Table III and Fig. 5), written by `mmtrack reproduce spebt`
//! (partitions named by experiment) and by `mmtrack process beam --tracker
//! spebt` (partitions named by the recording's sequence).

use super::TableFrame;

crate::define_table! {
    /// `spebt_summary`: one row per experiment (or recording).
    pub const SPEBT_SUMMARY = "spebt_summary",
        "Beam-tracking accuracy of the SPEBT EKF over the Monte Carlo runs of one experiment (Liu et al. 2024, \
Table III): RMSE over every tracked slot (1..slots-1) of every run of the estimate after the slot's update (after a re-initialisation \
where one happened) against the true channel, the re-initialisations per run (Algorithm 1 steps 14-15) and the \
paper's numbers beside them. Written by `reproduce spebt` (one partition per experiment) and `process beam --tracker \
spebt` (one per recording).",
        frame: TableFrame::NotApplicable;
    /// One row of [`SPEBT_SUMMARY`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct SpebtSummaryRow {
        experiment: String, "",
            "pose-error-model (ground truth plus the paper's pose-error model) or radar-odometry (our radar odometry: \
on scans simulated along the trajectory in reproduce spebt, the --odometry table in process beam)";
        trajectory: String, "",
            "trajectory file the vehicle drives along (reproduce spebt radar-odometry: the simulator's poses along it; \
process beam: the recording, whose ground truth it is)";
        slots: u64, "", "slots per run (one per pose); slot 0 is the initial access";
        runs: u64, "", "Monte Carlo runs";
        seed: u64, "", "seed of the runs";
        rmse_gain_pct: f64, "%", "RMS of the relative error of abs(alpha): (estimate - truth) / truth";
        rmse_aod_rad: f64, "rad", "RMS of the wrapped AoD error";
        rmse_aoa_rad: f64, "rad", "RMS of the wrapped AoA error";
        rmse_gain_before_reset_pct: f64, "%",
            "rmse_gain_pct of the estimate after each slot's update, before any re-initialisation (the error that \
fired the deviation test counts, not the re-initialised estimate)";
        rmse_aod_before_reset_rad: f64, "rad", "rmse_aod_rad before any re-initialisation";
        rmse_aoa_before_reset_rad: f64, "rad", "rmse_aoa_rad before any re-initialisation";
        reinitialisations_mean: f64, "", "re-initialisations per run, mean over runs";
        reinitialisations_min: u64, "", "fewest re-initialisations of a run";
        reinitialisations_max: u64, "", "most re-initialisations of a run";
        reinitialisation_share_pct: f64, "%", "mean re-initialisations per run over the tracked slots (slots - 1)";
        reinit_gain_pct: f64, "%", "share of re-initialisations where the abs(alpha) test fired (tests may fire together)";
        reinit_aod_pct: f64, "%", "share of re-initialisations where the AoD test fired";
        reinit_aoa_pct: f64, "%", "share of re-initialisations where the AoA test fired";
        paper_rmse_gain_pct: f64, "%", "the paper's RMSE of abs(alpha) (Table III)";
        paper_rmse_aod_rad: f64, "rad", "the paper's AoD RMSE (Table III gives 0.22 deg)";
        paper_rmse_aoa_rad: f64, "rad", "the paper's AoA RMSE (Table III gives 4.6 deg)";
        paper_reinitialisation_share_pct: f64, "%",
            "the paper's re-initialisation share (fewer than 300 of 6388 slots, Sec. IV)";
    }
}

crate::define_table! {
    /// `spebt_per_slot`: truth, one run's estimate and the RMSE over runs per slot.
    pub const SPEBT_PER_SLOT = "spebt_per_slot",
        "Per slot of one SPEBT experiment: the true pose and channel, the estimate of run 0 (the realisation of \
Liu et al. 2024, Fig. 5) and the RMSE over all runs at that slot.",
        frame: TableFrame::Fixed {
            id: "first_pose",
            meaning: "x_m, y_m: the vehicle's true position minus its first position, along the world axes of the trajectory (reproduce spebt: the simulator's, process beam: the recording's ground truth); yaw_rad counter-clockwise from world x; AoD from the base-station array axis (world x); AoA from the vehicle's heading",
        };
    /// One row of [`SPEBT_PER_SLOT`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct SpebtSlotRow {
        slot: u64, "", "slot index (one pose each); 0 is the initial access";
        t_ns: i64, "ns", "time of the slot's pose (the trajectory's or recording's clock, see time_base)";
        x_m: f64, "m", "true vehicle x, relative to its first position";
        y_m: f64, "m", "true vehicle y, relative to its first position";
        yaw_rad: f64, "rad", "true vehicle yaw, counter-clockwise from world x, wrapped to (-pi, pi]";
        range_m: f64, "m", "distance to the base station";
        true_gain: f64, "", "true path-gain magnitude abs(alpha) (linear amplitude)";
        true_aod_rad: f64, "rad", "true AoD, from the base-station array axis (world x)";
        true_aoa_rad: f64, "rad", "true AoA, from the vehicle's heading";
        run0_gain: f64, "", "run 0: estimated abs(alpha) after the slot's update (or re-initialisation)";
        run0_aod_rad: f64, "rad", "run 0: estimated AoD, wrapped to (-pi, pi]";
        run0_aoa_rad: f64, "rad", "run 0: estimated AoA, wrapped to (-pi, pi]";
        run0_reinitialised: bool, "", "run 0: the slot ended in a re-initialisation";
        rmse_gain_pct: f64, "%", "RMS over runs of the relative abs(alpha) error at this slot";
        rmse_aod_rad: f64, "rad", "RMS over runs of the AoD error at this slot";
        rmse_aoa_rad: f64, "rad", "RMS over runs of the AoA error at this slot";
        reinitialisation_rate: f64, "", "fraction of runs re-initialised at this slot";
    }
}

crate::define_table! {
    /// `spebt_pooled`: per experiment kind, every sequence pooled.
    pub const SPEBT_POOLED = "spebt_pooled",
        "SPEBT accuracy pooled over every sequence analysed (partition sequence=all), one row per experiment kind: \
each sequence's RMSE weighted by its tracked estimates ((slots - 1) x runs), so the pooled RMSE is the RMS over every \
estimate of every sequence; the re-initialisation share is every re-initialisation over every tracked slot. Written \
by `mmtrack analyze` from spebt_summary.",
        frame: TableFrame::NotApplicable;
    /// One row of [`SPEBT_POOLED`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct SpebtPooledRow {
        experiment: String, "", "pose-error-model or radar-odometry (spebt_summary.experiment)";
        sequences: u64, "", "sequences pooled";
        tracked_estimates: u64, "", "sum over sequences of (slots - 1) x runs";
        rmse_gain_pct: f64, "%", "RMS relative abs(alpha) error over every pooled estimate";
        rmse_aod_rad: f64, "rad", "RMS AoD error over every pooled estimate";
        rmse_aoa_rad: f64, "rad", "RMS AoA error over every pooled estimate";
        reinitialisation_share_pct: f64, "%", "re-initialisations over every pooled tracked slot";
        paper_rmse_gain_pct: f64, "%", "the paper's RMSE of abs(alpha) (Table III)";
        paper_rmse_aod_rad: f64, "rad", "the paper's AoD RMSE (Table III gives 0.22 deg)";
        paper_rmse_aoa_rad: f64, "rad", "the paper's AoA RMSE (Table III gives 4.6 deg)";
        paper_reinitialisation_share_pct: f64, "%", "the paper's re-initialisation share";
    }
}
