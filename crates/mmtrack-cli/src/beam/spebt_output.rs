//! The tables and figure series of `reproduce spebt` from its outcomes.

use std::path::Path;

use mmtrack_analysis::beam::spebt_plots::SpebtTrackingSeries;
use mmtrack_analysis::beam::spebt_tables::{SpebtSlotRow, SpebtSummaryRow};
use mmtrack_core::wrap_angle_rad;

use super::reproduce_spebt::{Experiment, Outcome, initial_access};

/// The `spebt_summary` row of one experiment.
pub(super) fn summary_row(experiment: &Experiment, trajectory: &Path, outcome: &Outcome) -> SpebtSummaryRow {
    let (link, r) = (&outcome.link, &outcome.result);
    let [gain, aod, aoa] = r.rmse();
    let total: u64 = r.reinitialisations.iter().sum();
    let cause = |i: usize| 100.0 * r.causes[i] as f64 / total.max(1) as f64;
    let paper = &experiment.paper;
    SpebtSummaryRow {
        experiment: outcome.name.into(),
        trajectory: trajectory.display().to_string(),
        slots: link.len() as u64,
        runs: r.runs,
        seed: experiment.seed,
        rmse_gain_pct: 100.0 * gain,
        rmse_aod_deg: aod.to_degrees(),
        rmse_aoa_deg: aoa.to_degrees(),
        reinitialisations_mean: r.mean_reinitialisations(),
        reinitialisations_min: r.reinitialisations.iter().copied().min().unwrap_or(0),
        reinitialisations_max: r.reinitialisations.iter().copied().max().unwrap_or(0),
        reinitialisation_share_pct: 100.0 * r.mean_reinitialisations() / r.tracked_slots().max(1) as f64,
        reinit_gain_pct: cause(0),
        reinit_aod_pct: cause(1),
        reinit_aoa_pct: cause(2),
        paper_rmse_gain_pct: paper.rmse_gain_pct,
        paper_rmse_aod_deg: paper.rmse_aod_deg,
        paper_rmse_aoa_deg: paper.rmse_aoa_deg,
        paper_reinitialisation_share_pct: 100.0 * paper.reinitialisations as f64 / paper.slots as f64,
    }
}

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

/// The `spebt_per_slot` rows of one experiment.
pub(super) fn slot_rows(outcome: &Outcome) -> Vec<SpebtSlotRow> {
    let (link, r) = (&outcome.link, &outcome.result);
    let t0 = link.slots()[0].t_ns;
    let runs = r.runs.max(1) as f64;
    link.slots()
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let (estimate, reinitialised) = r.run0.get(k).copied().unwrap_or((initial_access(s), false));
            let rms = |i: usize| (r.sum_squared[i][k] / runs).sqrt();
            SpebtSlotRow {
                slot: k as u64,
                t_s: (s.t_ns - t0) as f64 * 1e-9,
                x_m: s.pose.x_m,
                y_m: s.pose.y_m,
                yaw_deg: wrap_angle_rad(s.pose.yaw_rad).to_degrees(),
                range_m: s.range_m,
                true_gain: s.gain.norm(),
                true_aod_deg: s.aod_rad.to_degrees(),
                true_aoa_deg: s.aoa_rad.to_degrees(),
                run0_gain: estimate.gain_magnitude,
                run0_aod_deg: estimate.aod_rad.to_degrees(),
                run0_aoa_deg: estimate.aoa_rad.to_degrees(),
                run0_reinitialised: reinitialised,
                rmse_gain_pct: 100.0 * rms(0),
                rmse_aod_deg: rms(1).to_degrees(),
                rmse_aoa_deg: rms(2).to_degrees(),
                reinitialisation_rate: r.reinitialised_runs[k] as f64 / runs,
            }
        })
        .collect()
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
