//! Tables of the beam-sweep pipeline: what each tracker chose for each
//! measured sweep, and what that cost against the sweep's best beam.

use super::TableFrame;

crate::define_table! {
    /// `beam_sweeps_tracked`: one tracked sweep per row.
    pub const BEAM_SWEEPS_TRACKED = "beam_sweeps_tracked",
        "One beam sweep of one sequence (a vehicle pass) as one beam-sweep tracker handled it: the beam it chose, \
the best beam of the full sweep, how many beams it measured and the received-power loss; rows of one tracker are \
consecutive and in time order. Trackers see only the beams they measure; the full sweep scores them.",
        frame: TableFrame::NotApplicable;
    /// One row of [`BEAM_SWEEPS_TRACKED`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct BeamSweepTracked {
        tracker: String, "",
            "policy: window, gnss-window, last-full-sweep or gnss-map (the run config holds their settings)";
        site: String, "",
            "the array and place (recording metadata beam.site); beam maps are fitted within a site";
        t_ns: i64, "ns", "sweep time";
        sweep: u64, "", "index of the sweep within the sequence, from 0";
        beam_count: u32, "", "beams of the codebook (a full sweep measures them all)";
        chosen_beam: u32, "", "beam the tracker chose for this sweep";
        best_beam: u32, "", "strongest beam of the full sweep (the lowest index among equal powers)";
        beams_measured: u32, "",
            "distinct beams the tracker measured in this sweep, re-acquisition included (beam_count for a full sweep)";
        reinitialised: bool, "", "true when the tracker (re-)acquired the beam in this sweep (pass start or loss)";
        loss_db: f64, "dB", "received-power loss of the chosen beam against the best: 10 log10(P_best / P_chosen) >= 0, dB re the best beam's received power in the full sweep";
        gnss_beam: Option<f64>, "",
            "beam the vehicle's GNSS position predicts through the beam map (continuous index); null without a map";
    }
}
