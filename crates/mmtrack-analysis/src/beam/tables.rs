//! Result tables of the beam trackers, with units.

mmtrack_io::define_table! {
    /// `beam_rms_per_block`: RMS pointing error per block.
    pub const BEAM_RMS_PER_BLOCK = "beam_rms_per_block",
        "RMS transmit-beam pointing error over the Monte Carlo runs of one scenario point, per block and tracker \
(Shaham et al. 2020, Figs. 2-4): sqrt(E[(phi[k] - phi_bar[k])^2]), phi the true AoD and phi_bar the beam the tracker \
pointed from its prediction; block 0 is the channel estimate the trackers start from.";
    /// One row of [`BEAM_RMS_PER_BLOCK`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct BeamRmsRow {
        tracker: String, "", "tracker name (pv-ekf, pv-ekf-paper-table, angle-ekf)";
        snr_db: f64, "dB", "received SNR of the scenario point";
        speed_kmh: f64, "km/h", "initial speed of the scenario point";
        block: u64, "", "block index (1 ms each)";
        rms_aod_deg: f64, "deg", "RMS AoD pointing error over the runs";
    }
}

mmtrack_io::define_table! {
    /// `beam_valid_tracking`: blocks of valid tracking per scenario point.
    pub const BEAM_VALID_TRACKING = "beam_valid_tracking",
        "Valid-tracking duration per scenario point and tracker (Shaham et al. 2020, Sec. IV): the first block \
whose RMS AoD error exceeds half the beamwidth, null when no simulated block does; beside the paper's number \
where it gives one.";
    /// One row of [`BEAM_VALID_TRACKING`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct BeamValidTrackingRow {
        tracker: String, "", "tracker name";
        snr_db: f64, "dB", "received SNR";
        speed_kmh: f64, "km/h", "initial speed";
        runs: u64, "", "Monte Carlo runs";
        blocks_simulated: u64, "", "blocks per run";
        threshold_deg: f64, "deg", "half the half-power beamwidth at the initial AoD";
        valid_blocks: Option<u64>, "", "first block with RMS AoD error above the threshold; null if none";
        paper_blocks: Option<u64>, "", "the paper's number for this point and tracker; null where it gives none";
    }
}
