//! Result tables of the beam trackers, with units.

use super::TableFrame;

crate::define_table! {
    /// `beam_rms_per_block`: RMS pointing error per block.
    pub const BEAM_RMS_PER_BLOCK = "beam_rms_per_block",
        "RMS transmit-beam pointing error over the Monte Carlo runs of one scenario point, per block and tracker \
(Shaham et al. 2020, Figs. 2-4): sqrt(E[(phi[k] - phi_bar[k])^2]), phi the true AoD and phi_bar the beam the tracker \
pointed from its prediction; block 0 is the channel estimate the trackers start from.",
        frame: TableFrame::NotApplicable;
    /// One row of [`BEAM_RMS_PER_BLOCK`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct BeamRmsRow {
        tracker: String, "", "tracker name (pv-ekf, pv-ekf-paper-table, angle-ekf, open-loop)";
        snr_db: f64, "dB", "received SNR of the scenario point: signal power over noise power, dB re the noise power";
        speed_kmh: f64, "km/h", "initial speed of the scenario point";
        block: u64, "", "block index (1 ms each)";
        rms_aod_rad: f64, "rad", "RMS AoD pointing error over the runs";
    }
}

crate::define_table! {
    /// `beam_valid_tracking`: blocks of valid tracking per scenario point.
    pub const BEAM_VALID_TRACKING = "beam_valid_tracking",
        "Valid-tracking duration per scenario point and tracker (Shaham et al. 2020, Sec. IV): the first block \
whose RMS AoD error exceeds half the beamwidth, null when no simulated block does; beside the paper's number \
where it gives one.",
        frame: TableFrame::NotApplicable;
    /// One row of [`BEAM_VALID_TRACKING`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct BeamValidTrackingRow {
        tracker: String, "", "tracker name";
        snr_db: f64, "dB", "received SNR: signal power over noise power, dB re the noise power";
        speed_kmh: f64, "km/h", "initial speed";
        runs: u64, "", "Monte Carlo runs";
        blocks_simulated: u64, "", "blocks per run";
        threshold_rad: f64, "rad", "half the half-power beamwidth at the initial AoD";
        valid_blocks: Option<u64>, "", "first block with RMS AoD error above the threshold; null if none";
        paper_blocks: Option<u64>, "", "the paper's number for this point and tracker; null where it gives none";
    }
}

crate::define_table! {
    /// `beam_sweep_summary`: per sequence, one row per beam-sweep tracker.
    pub const BEAM_SWEEP_SUMMARY = "beam_sweep_summary",
        "Beam-training accounting of one sequence (a vehicle pass) per tracker, from table beam_sweeps_tracked: \
received-power loss of the chosen beam against each full sweep's best beam, how often the chosen beam is the best or \
its neighbour, beams measured per sweep (a full sweep counts all beams) and re-initialisations.",
        frame: TableFrame::NotApplicable;
    /// One row of [`BEAM_SWEEP_SUMMARY`] (and of [`BEAM_SWEEP_POOLED`]).
    #[derive(Debug, Clone, PartialEq)]
    pub struct BeamSweepSummaryRow {
        tracker: String, "", "policy (beam_sweeps_tracked.tracker)";
        site: String, "", "array and place (beam_sweeps_tracked.site)";
        passes: u64, "", "sequences summarised (1 per sequence; the site's passes when pooled)";
        sweeps: u64, "", "sweeps summarised";
        beam_count: u32, "", "beams of the codebook (what a full sweep measures)";
        mean_loss_db: f64, "dB", "mean received-power loss against the best beam, 10 log10(P_best / P_chosen): dB re the best beam's received power";
        median_loss_db: f64, "dB", "median loss (mean of the two middle values for an even count); dB re the best beam's received power";
        p90_loss_db: f64, "dB", "90th percentile of the loss (nearest rank); dB re the best beam's received power";
        top1: f64, "", "share of sweeps whose chosen beam is the best beam";
        within_one: f64, "", "share of sweeps whose chosen beam is the best beam or its neighbour";
        mean_beams_per_sweep: f64, "", "mean beams measured per sweep, re-acquisitions included";
        reinitialisations: u64, "", "sweeps with a (re-)acquisition, pass starts included";
    }
}

/// A pooled summary: the columns of [`BEAM_SWEEP_SUMMARY`], in its own table.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamSweepPooledRow(pub BeamSweepSummaryRow);

crate::define_table! {
    /// `beam_sweep_pooled`: per site and tracker, every sequence pooled.
    pub const BEAM_SWEEP_POOLED = "beam_sweep_pooled",
        "Beam-training accounting pooled over every sequence of a site, one row per site and tracker (partition \
sequence=all): the columns of beam_sweep_summary, each sweep weighted once.",
        frame: TableFrame::NotApplicable;
    BeamSweepPooledRow(BeamSweepSummaryRow);
}
