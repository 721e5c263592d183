//! One SLAM run against its ground truth: the filter over a simulated run,
//! and the paper's metrics (Kim et al. 2018, Sec. V-B) per epoch.

use anyhow::Context;
use mmtrack_core::slam::{PathOrigin, norm3, sub3};
use mmtrack_core::wrap_angle_rad;
use mmtrack_sim::slam::SlamRun;
use mmtrack_slam::{SlamConfig, SlamFilter, SourceStatus};

/// Errors and map size of one epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochErrors {
    pub position_m: f64,
    /// The filter's horizontal position spread (root of the covariance trace).
    pub position_std_m: f64,
    pub heading_rad: f64,
    pub clock_bias_m: f64,
    pub speed_mps: f64,
    pub turn_rate_radps: f64,
    /// Mean error of the confirmed VAs that match a true VA; `None` without one.
    pub va_m: Option<f64>,
    /// Mean error of the confirmed SPs that match a true SP; `None` without one.
    pub sp_m: Option<f64>,
    pub confirmed_va: usize,
    pub confirmed_sp: usize,
}

/// What one run measured.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    pub epochs: Vec<EpochErrors>,
    /// First epoch (1-based) at which every true VA had a confirmed VA
    /// within the match radius.
    pub all_va_epoch: Option<usize>,
    /// The same for every true SP detected in at least `sp_min_detections` epochs.
    pub all_sp_epoch: Option<usize>,
    /// Confirmed sources at the end with no true source of their type nearby.
    pub false_sources: usize,
    pub skipped_paths: usize,
    /// Final confirmed VAs and SPs (for the map figure).
    pub final_va_m: Vec<[f64; 3]>,
    pub final_sp_m: Vec<[f64; 3]>,
    /// Estimated track.
    pub track_m: Vec<[f64; 3]>,
}

fn nearest(points: &[[f64; 3]], at: [f64; 3]) -> f64 {
    points.iter().map(|p| norm3(sub3(*p, at))).fold(f64::INFINITY, f64::min)
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Runs the filter (prior centred on the true first state, Sec. V-A) over
/// `run` and measures it.
pub fn run_filter(
    run: &SlamRun,
    config: &SlamConfig,
    seed: u64,
    match_radius_m: f64,
    sp_min_detections: usize,
) -> anyhow::Result<RunOutcome> {
    let first = run.truth.first().context("a run without epochs")?;
    let mut filter = SlamFilter::new(config.clone(), first.ue, seed)?;
    let true_va = &run.world.virtual_anchors_m;
    let true_sp = &run.world.scattering_points_m;
    // The SPs that count: detected in enough epochs.
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
    let seen_sp: Vec<[f64; 3]> =
        true_sp.iter().zip(&detections).filter(|(_, d)| **d >= sp_min_detections).map(|(p, _)| *p).collect();
    let mut outcome = RunOutcome {
        epochs: Vec::with_capacity(run.epochs.len()),
        all_va_epoch: None,
        all_sp_epoch: None,
        false_sources: 0,
        skipped_paths: 0,
        final_va_m: Vec::new(),
        final_sp_m: Vec::new(),
        track_m: Vec::with_capacity(run.epochs.len()),
    };
    for (k, (epoch, truth)) in run.epochs.iter().zip(&run.truth).enumerate() {
        let report = filter.step(epoch).with_context(|| format!("epoch {}", k + 1))?;
        outcome.skipped_paths += report.skipped_paths;
        let e = report.estimate.state;
        outcome.track_m.push(e.position_m);
        let of = |status: SourceStatus| -> Vec<[f64; 3]> {
            filter.sources().iter().filter(|s| s.status == status).map(|s| s.belief.mean_m).collect()
        };
        let (va, sp) = (of(SourceStatus::VirtualAnchor), of(SourceStatus::ScatteringPoint));
        let errors = |est: &[[f64; 3]], truth: &[[f64; 3]]| -> Vec<f64> {
            est.iter().map(|p| nearest(truth, *p)).filter(|d| *d <= match_radius_m).collect()
        };
        let found = |est: &[[f64; 3]], truth: &[[f64; 3]]| truth.iter().all(|t| nearest(est, *t) <= match_radius_m);
        if outcome.all_va_epoch.is_none() && found(&va, true_va) {
            outcome.all_va_epoch = Some(k + 1);
        }
        if outcome.all_sp_epoch.is_none() && found(&sp, &seen_sp) {
            outcome.all_sp_epoch = Some(k + 1);
        }
        outcome.epochs.push(EpochErrors {
            position_m: norm3(sub3(e.position_m, truth.ue.position_m)),
            position_std_m: report.estimate.position_std_m,
            heading_rad: wrap_angle_rad(e.heading_rad - truth.ue.heading_rad).abs(),
            clock_bias_m: (e.clock_bias_m - truth.ue.clock_bias_m).abs(),
            speed_mps: (e.speed_mps - truth.ue.speed_mps).abs(),
            turn_rate_radps: (e.turn_rate_radps - truth.ue.turn_rate_radps).abs(),
            va_m: mean(&errors(&va, true_va)),
            sp_m: mean(&errors(&sp, true_sp)),
            confirmed_va: va.len(),
            confirmed_sp: sp.len(),
        });
        if k + 1 == run.epochs.len() {
            outcome.false_sources = va.iter().filter(|p| nearest(true_va, **p) > match_radius_m).count()
                + sp.iter().filter(|p| nearest(true_sp, **p) > match_radius_m).count();
            outcome.final_va_m = va;
            outcome.final_sp_m = sp;
        }
    }
    Ok(outcome)
}

impl RunOutcome {
    /// Time averages over the epochs: UE errors, and the source errors over
    /// the epochs that had a confirmed source.
    pub fn time_averages(&self) -> [Option<f64>; 7] {
        let avg = |f: &dyn Fn(&EpochErrors) -> Option<f64>| {
            let v: Vec<f64> = self.epochs.iter().filter_map(f).collect();
            mean(&v)
        };
        [
            avg(&|e| Some(e.position_m)),
            avg(&|e| Some(e.heading_rad)),
            avg(&|e| Some(e.clock_bias_m)),
            avg(&|e| Some(e.speed_mps)),
            avg(&|e| Some(e.turn_rate_radps)),
            avg(&|e| e.va_m),
            avg(&|e| e.sp_m),
        ]
    }
}
