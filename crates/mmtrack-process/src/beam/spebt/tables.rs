//! The `spebt_summary` and `spebt_per_slot` rows of one SPEBT experiment
//! (one recording of `process beam --tracker spebt`, one experiment of
//! `reproduce spebt`).

use std::path::Path;

use mmtrack_core::wrap_angle_rad;
use mmtrack_io::table::{SpebtSlotRow, SpebtSummaryRow};
use mmtrack_sim::beam::spebt_link::SpebtLink;

use super::monte_carlo::{ExperimentResult, SpebtExperiment, initial_access};

/// The `spebt_summary` row of one experiment.
#[must_use]
pub fn summary_row(
    experiment: &SpebtExperiment,
    trajectory: &Path,
    name: &str,
    link: &SpebtLink,
    r: &ExperimentResult,
) -> SpebtSummaryRow {
    let [gain, aod, aoa] = r.rmse();
    let [gain_before, aod_before, aoa_before] = r.rmse_before_reset();
    let total: u64 = r.reinitialisations.iter().sum();
    let cause = |i: usize| 100.0 * r.causes[i] as f64 / total.max(1) as f64;
    let paper = &experiment.paper;
    SpebtSummaryRow {
        experiment: name.into(),
        trajectory: trajectory.display().to_string(),
        slots: link.len() as u64,
        runs: r.runs,
        seed: experiment.seed,
        rmse_gain_pct: 100.0 * gain,
        rmse_aod_rad: aod,
        rmse_aoa_rad: aoa,
        rmse_gain_before_reset_pct: 100.0 * gain_before,
        rmse_aod_before_reset_rad: aod_before,
        rmse_aoa_before_reset_rad: aoa_before,
        reinitialisations_mean: r.mean_reinitialisations(),
        reinitialisations_min: r.reinitialisations.iter().copied().min().unwrap_or(0),
        reinitialisations_max: r.reinitialisations.iter().copied().max().unwrap_or(0),
        reinitialisation_share_pct: 100.0 * r.mean_reinitialisations() / r.tracked_slots().max(1) as f64,
        reinit_gain_pct: cause(0),
        reinit_aod_pct: cause(1),
        reinit_aoa_pct: cause(2),
        paper_rmse_gain_pct: paper.rmse_gain_pct,
        paper_rmse_aod_rad: paper.rmse_aod_deg.to_radians(),
        paper_rmse_aoa_rad: paper.rmse_aoa_deg.to_radians(),
        paper_reinitialisation_share_pct: 100.0 * paper.reinitialisations as f64 / paper.slots as f64,
    }
}

/// The `spebt_per_slot` rows of one experiment.
#[must_use]
pub fn slot_rows(link: &SpebtLink, r: &ExperimentResult) -> Vec<SpebtSlotRow> {
    let runs = r.runs.max(1) as f64;
    link.slots()
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let (estimate, reinitialised) = r.run0.get(k).copied().unwrap_or((initial_access(s), false));
            let rms = |i: usize| (r.sum_squared[i][k] / runs).sqrt();
            SpebtSlotRow {
                slot: k as u64,
                t_ns: s.t_ns,
                x_m: s.pose.x_m,
                y_m: s.pose.y_m,
                yaw_rad: wrap_angle_rad(s.pose.yaw_rad),
                range_m: s.range_m,
                true_gain: s.gain.norm(),
                true_aod_rad: s.aod_rad,
                true_aoa_rad: s.aoa_rad,
                run0_gain: estimate.gain_magnitude,
                run0_aod_rad: estimate.aod_rad,
                run0_aoa_rad: estimate.aoa_rad,
                run0_reinitialised: reinitialised,
                rmse_gain_pct: 100.0 * rms(0),
                rmse_aod_rad: rms(1),
                rmse_aoa_rad: rms(2),
                reinitialisation_rate: r.reinitialised_runs[k] as f64 / runs,
            }
        })
        .collect()
}
