//! One SLAM run against its ground truth: the filter over a simulated run,
//! measured by the paper's metrics (Kim et al. 2018, Sec. V-B) of
//! [`mmtrack_analysis::slam::metrics`], which `mmtrack analyze` applies to
//! the tables of `mmtrack process slam`.

use anyhow::Context;
pub use mmtrack_analysis::slam::metrics::{EpochErrors, RunOutcome};
use mmtrack_analysis::slam::metrics::{EpochView, MapTruth, evaluate};
use mmtrack_core::slam::{PathOrigin, norm3, sub3};
use mmtrack_sim::slam::SlamRun;
use mmtrack_slam::{SlamConfig, SlamFilter, SourceStatus};

/// The true source found last in a run (the one that completes "all VAs" or
/// "all SPs"): when its paths were first measured and when a confirmed
/// source of its type first came within the match radius, so a late run can
/// be told apart as late seen (geometry) or late mapped (the filter).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LastFound {
    /// Its index in the world's list of VAs or SPs.
    pub source: usize,
    /// The epochs (1-based) with a path from it, up to `found_epoch` (or all),
    /// as inclusive ranges.
    pub measured_epochs: Vec<[usize; 2]>,
    /// First epoch (1-based) with a confirmed source of its type within the
    /// match radius; `None` if never.
    pub found_epoch: Option<usize>,
}

/// A run's outcome and its last-found VA and SP.
#[derive(Debug, Clone, PartialEq)]
pub struct KimRunOutcome {
    /// The paper's metrics.
    pub outcome: RunOutcome,
    /// The VA found last.
    pub last_va: Option<LastFound>,
    /// The SP found last, among those that count (seen in at least the
    /// minimum number of epochs).
    pub last_sp: Option<LastFound>,
}

/// Of `sources` (index, position), the one whose first epoch with a
/// confirmed estimate (`confirmed[k]`, epoch `k + 1`) within `radius_m` comes
/// last (never counts as last of all).
fn last_found(
    sources: &[(usize, [f64; 3])],
    confirmed: &[Vec<[f64; 3]>],
    measured: &[Vec<usize>],
    radius_m: f64,
) -> Option<LastFound> {
    let found_epoch = |p: [f64; 3]| confirmed.iter().position(|est| est.iter().any(|q| norm3(sub3(*q, p)) <= radius_m));
    sources
        .iter()
        .map(|&(source, p)| {
            let found = found_epoch(p).map(|k| k + 1);
            let epochs = measured.get(source).map_or(&[][..], Vec::as_slice);
            let mut ranges: Vec<[usize; 2]> = Vec::new();
            for &k in epochs.iter().take_while(|&&k| found.is_none_or(|f| k <= f)) {
                match ranges.last_mut() {
                    Some(range) if range[1] + 1 == k => range[1] = k,
                    _ => ranges.push([k, k]),
                }
            }
            LastFound { source, measured_epochs: ranges, found_epoch: found }
        })
        .max_by_key(|l| (l.found_epoch.is_none(), l.found_epoch))
}

impl LastFound {
    /// "epochs 1-2, 88-92" (or "never").
    #[must_use]
    pub fn measured_text(&self) -> String {
        if self.measured_epochs.is_empty() {
            return "never".into();
        }
        let ranges: Vec<String> =
            self.measured_epochs.iter().map(|[a, b]| if a == b { a.to_string() } else { format!("{a}-{b}") }).collect();
        format!("epochs {}", ranges.join(", "))
    }
}

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
) -> anyhow::Result<KimRunOutcome> {
    let first = run.truth.first().context("a run without epochs")?;
    let mut filter = SlamFilter::new(config.clone(), first.ue, seed)?;
    let true_sp = &run.world.scattering_points_m;
    let mut detections = vec![0usize; true_sp.len()];
    let mut sp_measured = vec![Vec::new(); true_sp.len()];
    let mut va_measured = vec![Vec::new(); run.world.virtual_anchors_m.len()];
    // Epoch `epoch` into a source's list of measured epochs (once per epoch).
    let note = |epochs: &mut Vec<usize>, epoch: usize| {
        if epochs.last() != Some(&epoch) {
            epochs.push(epoch);
        }
    };
    for (k, truth) in run.truth.iter().enumerate() {
        for origin in &truth.origins {
            match *origin {
                PathOrigin::ScatteringPoint(i) if i < true_sp.len() => {
                    detections[i] += 1;
                    note(&mut sp_measured[i], k + 1);
                }
                PathOrigin::VirtualAnchor(j) if j < va_measured.len() => note(&mut va_measured[j], k + 1),
                _ => {}
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
    let vas: Vec<(usize, [f64; 3])> = run.world.virtual_anchors_m.iter().copied().enumerate().collect();
    let sps: Vec<(usize, [f64; 3])> =
        true_sp.iter().copied().enumerate().filter(|(i, _)| detections[*i] >= sp_min_detections).collect();
    let confirmed_va: Vec<Vec<[f64; 3]>> = views.iter().map(|v| v.va_m.clone()).collect();
    let confirmed_sp: Vec<Vec<[f64; 3]>> = views.iter().map(|v| v.sp_m.clone()).collect();
    Ok(KimRunOutcome {
        last_va: last_found(&vas, &confirmed_va, &va_measured, match_radius_m),
        last_sp: last_found(&sps, &confirmed_sp, &sp_measured, match_radius_m),
        outcome,
    })
}

#[cfg(test)]
mod last_found_tests {
    use super::*;

    #[test]
    fn the_last_found_source_names_when_it_was_measured_until_found() {
        // Source 0 found at epoch 2; source 1 (measured in epochs 1, 2 and
        // 5-6) found at epoch 6, within 1 m; the far estimate never counts.
        let sources = [(0, [0.0, 0.0, 0.0]), (1, [10.0, 0.0, 0.0])];
        let confirmed = vec![
            vec![[50.0, 0.0, 0.0]],
            vec![[0.5, 0.0, 0.0]],
            vec![[0.5, 0.0, 0.0]],
            vec![[0.5, 0.0, 0.0], [13.0, 0.0, 0.0]],
            vec![[0.5, 0.0, 0.0], [12.0, 0.0, 0.0]],
            vec![[0.5, 0.0, 0.0], [10.5, 0.0, 0.0]],
        ];
        let measured = vec![vec![1, 2, 3], vec![1, 2, 5, 6, 7]];
        let last = last_found(&sources, &confirmed, &measured, 1.0).unwrap();
        assert_eq!(last.source, 1);
        assert_eq!(last.found_epoch, Some(6));
        assert_eq!(last.measured_epochs, vec![[1, 2], [5, 6]]);
        assert_eq!(last.measured_text(), "epochs 1-2, 5-6");
        // A source never found is the last of all.
        let never = last_found(&[(0, [99.0, 0.0, 0.0])], &confirmed, &[vec![]], 1.0).unwrap();
        assert_eq!((never.found_epoch, never.measured_text()), (None, "never".to_string()));
    }
}
