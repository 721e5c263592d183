//! One SLAM run against its ground truth: the filter over a simulated run,
//! measured by the paper's metrics (Kim et al. 2018, Sec. V-B) of
//! [`mmtrack_analysis::slam::metrics`], which `mmtrack analyze` applies to
//! the tables of `mmtrack process slam`.

use anyhow::Context;
pub use mmtrack_analysis::slam::metrics::{EpochErrors, RunOutcome};
use mmtrack_analysis::slam::metrics::{EpochView, MapTruth, evaluate};
use mmtrack_core::slam::PathOrigin;
use mmtrack_sim::slam::SlamRun;
use mmtrack_slam::{SlamConfig, SlamFilter, SourceStatus};

/// Runs the filter (prior centred on the true first state, Sec. V-A) over
/// `run` and measures it.
///
/// # Errors
/// A run without epochs, or a filter step fails (naming the epoch).
pub fn run_filter(
    run: &SlamRun,
    config: &SlamConfig,
    seed: u64,
    match_radius_m: f64,
    sp_min_detections: usize,
) -> anyhow::Result<RunOutcome> {
    let first = run.truth.first().context("a run without epochs")?;
    let mut filter = SlamFilter::new(config.clone(), first.ue, seed)?;
    let true_sp = &run.world.scattering_points_m;
    let mut detections = vec![0usize; true_sp.len()];
    for truth in &run.truth {
        for origin in &truth.origins {
            if let PathOrigin::ScatteringPoint(i) = origin
                && let Some(d) = detections.get_mut(*i)
            {
                *d += 1;
            }
        }
    }
    let map_truth = MapTruth::new(
        run.world.virtual_anchors_m.clone(),
        true_sp.clone(),
        &detections,
        sp_min_detections,
        match_radius_m,
    );
    let mut views = Vec::with_capacity(run.epochs.len());
    let mut skipped_paths = 0;
    for (k, (epoch, truth)) in run.epochs.iter().zip(&run.truth).enumerate() {
        let report = filter.step(epoch).with_context(|| format!("epoch {}", k + 1))?;
        skipped_paths += report.skipped_paths;
        let of = |status: SourceStatus| -> Vec<[f64; 3]> {
            filter.sources().iter().filter(|s| s.status == status).map(|s| s.belief.mean_m).collect()
        };
        views.push(EpochView {
            estimate: report.estimate.state,
            position_std_m: report.estimate.position_std_m,
            position_cov_m2: Some(report.estimate.position_cov_m2),
            truth: truth.ue,
            va_m: of(SourceStatus::VirtualAnchor),
            sp_m: of(SourceStatus::ScatteringPoint),
        });
    }
    let mut outcome = evaluate(&map_truth, &views);
    outcome.skipped_paths = skipped_paths;
    Ok(outcome)
}
