//! The metrics and figure series of `reproduce spebt` from its outcomes.

use mmtrack_analysis::beam::spebt_plots::SpebtTrackingSeries;
use mmtrack_io::table::SpebtSummaryRow;

use super::reproduce_spebt::Outcome;

/// The numbers `reproduce --all` checks for one experiment: RMSE of
/// |alpha|, AoD and AoA and the re-initialisation share, with the paper's.
pub(super) fn metrics(row: &SpebtSummaryRow) -> Vec<crate::reproduce_all::Metric> {
    use crate::reproduce_all::Metric;
    let e = &row.experiment;
    vec![
        Metric::new(format!("{e} RMSE abs(alpha)"), row.rmse_gain_pct, "%", Some(row.paper_rmse_gain_pct)),
        Metric::new(format!("{e} RMSE AoD"), row.rmse_aod_deg, "deg", Some(row.paper_rmse_aod_deg)),
        Metric::new(format!("{e} RMSE AoA"), row.rmse_aoa_deg, "deg", Some(row.paper_rmse_aoa_deg)),
        Metric::new(
            format!("{e} re-initialisation share"),
            row.reinitialisation_share_pct,
            "%",
            Some(row.paper_reinitialisation_share_pct),
        ),
    ]
}

/// Run 0 against the truth, for the Fig. 5 figure.
pub(super) fn tracking_series(outcome: &Outcome) -> SpebtTrackingSeries {
    let (link, r) = (&outcome.link, &outcome.result);
    let mut series = SpebtTrackingSeries::default();
    for (s, (estimate, reinitialised)) in link.slots().iter().zip(&r.run0) {
        series.true_gain.push(s.gain.norm());
        series.true_aod_deg.push(s.aod_rad.to_degrees());
        series.true_aoa_deg.push(s.aoa_rad.to_degrees());
        series.estimate_gain.push(estimate.gain_magnitude);
        series.estimate_aod_deg.push(estimate.aod_rad.to_degrees());
        series.estimate_aoa_deg.push(estimate.aoa_rad.to_degrees());
        series.reinitialised.push(*reinitialised);
    }
    series
}
