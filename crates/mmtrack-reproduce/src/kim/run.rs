//! The Monte Carlo of the Kim experiment.
//!
//! On the paper's circular-road world (`mmtrack_sim::slam`), the filter of
//! `mmtrack_slam` runs over Monte Carlo realisations (each its own 10 random
//! SPs, trajectory and noise) of every row of the experiment: the paper's
//! setting with and without `ue_error_floor`, the LOS-only baseline, the
//! same three with the LOS blocked in a stretch of epochs, then the
//! robustness rows (detection probability 0.9, one clutter path per epoch). Reported per row: the mean over runs of the
//! time-averaged UE position, heading, clock-bias (and smoothed speed and
//! turn-rate) errors, the VA and SP localisation errors, and the epochs at
//! which all VAs and all SPs are confirmed.
//!
//! Runs are computed on rayon and collected in run order; each filter's
//! particles draw from streams seeded by (seed, run, epoch, chunk), so the
//! numbers do not depend on the thread count.

use std::time::Instant;

use anyhow::Context;
use mmtrack_core::progress::Progress;
use mmtrack_io::table::{SlamPerEpochRow, SlamSummaryRow};
use mmtrack_sim::slam::SlamScenario;
use mmtrack_slam::SlamConfig;
use rayon::prelude::*;

use super::config::{Config, Row};
use super::evaluate::{EpochErrors, KimRunOutcome, LastFound, RunOutcome, run_filter};
use crate::common::load_average;

/// What one row measured.
#[derive(Debug, Clone)]
pub struct RowResult {
    /// The row.
    pub row: Row,
    /// Means over its runs.
    pub summary: SlamSummaryRow,
    /// Means over its runs, per epoch.
    pub per_epoch: Vec<SlamPerEpochRow>,
    /// Run 0, for the map figure.
    pub first: RunOutcome,
    /// What the summary table does not carry.
    pub extra: RowExtra,
}

/// A row's numbers beyond [`SlamSummaryRow`]: the blocked stretch, false
/// sources over all epochs, the consistency of the UE estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct RowExtra {
    /// Mean over runs of the mean UE position error over the epochs with
    /// the LOS blocked, metres; `None` without a blocked stretch.
    pub blocked_ue_position_error_m: Option<f64>,
    /// False sources per epoch, mean over the epochs of all runs.
    pub false_sources_per_epoch: f64,
    /// Most false sources at any epoch of any run.
    pub false_sources_max: usize,
    /// Mean distance of the false sources (every epoch of every run) to
    /// the nearest true source of their type, metres; `None` without one.
    pub false_source_error_m: Option<f64>,
    /// Mean horizontal-position NEES over the epochs of all runs (2 for a
    /// consistent filter); `None` when no epoch had one.
    pub nees_mean: Option<f64>,
    /// The two-sided 95 % interval of the average NEES of `runs`
    /// independent runs at one epoch of a consistent filter.
    pub nees_interval: [f64; 2],
    /// Share of the epochs whose average NEES over the runs lies in
    /// `nees_interval` (0.95 for a consistent filter).
    pub nees_share_inside: Option<f64>,
    /// Median over runs of the epoch at which all VAs / all SPs are
    /// confirmed (a run that never confirms counts as epochs + 1).
    pub all_va_epoch_median: f64,
    /// The same for the SPs.
    pub all_sp_epoch_median: f64,
    /// Per run, the epoch at which all VAs / all SPs are confirmed
    /// (epochs + 1 when never), in run order.
    pub all_va_epochs: Vec<usize>,
    /// The same for the SPs.
    pub all_sp_epochs: Vec<usize>,
    /// Per run, the VA found last: first measured and first found.
    pub last_va: Vec<Option<LastFound>>,
    /// The same for the SPs that count.
    pub last_sp: Vec<Option<LastFound>>,
}

/// Quantile `p` of the chi-square distribution with `dof` degrees of
/// freedom by the Wilson-Hilferty cube-root approximation,
/// `dof (1 - 2/(9 dof) + z_p sqrt(2/(9 dof)))^3` (Wilson and Hilferty 1931;
/// relative error below 1e-3 from 4 degrees of freedom on, at these
/// tails), for `z_p` the standard normal quantile.
#[must_use]
pub fn chi_square_quantile(dof: f64, z_p: f64) -> f64 {
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + z_p * a.sqrt()).powi(3).max(0.0)
}

/// Standard normal quantile at 0.975.
const Z_975: f64 = 1.959_963_984_540_054;

/// The 95 % interval of the average over `runs` runs of a 2-dof NEES of a
/// consistent filter: `runs * average ~ chi-square(2 runs)` (Bar-Shalom,
/// Li and Kirubarajan 2001, Sec. 5.4.2, eq. (5.4.2-5)).
#[must_use]
pub fn nees_interval(runs: usize) -> [f64; 2] {
    let dof = 2.0 * runs.max(1) as f64;
    let n = runs.max(1) as f64;
    [chi_square_quantile(dof, -Z_975) / n, chi_square_quantile(dof, Z_975) / n]
}

/// What the whole Monte Carlo measured, and how long it took.
#[derive(Debug, Clone)]
pub struct Measured {
    /// Runs per row.
    pub runs: u64,
    /// The filter every row ran (its detection probability adapted per row).
    pub filter: SlamConfig,
    /// One per row, in the file's order.
    pub rows: Vec<RowResult>,
    /// Wall time, seconds.
    pub elapsed_s: f64,
    /// Threads of the rayon pool.
    pub threads: usize,
    /// 1-minute load average before and after.
    pub load: (Option<f64>, Option<f64>),
}

/// Runs `runs` realisations of every row of `experiment` with `filter`.
///
/// # Errors
/// An invalid row, a simulator or filter failure (naming the row and run).
pub fn measure(
    experiment: &Config,
    filter: &SlamConfig,
    runs: u64,
    progress: &dyn Progress,
) -> anyhow::Result<Measured> {
    let source = &experiment.source;
    let load_before = load_average();
    let started = Instant::now();
    progress.start("reproduce kim", runs * experiment.rows.len() as u64, "runs");
    let mut rows = Vec::new();
    for row in &experiment.rows {
        let scenario = row.scenario(&experiment.scenario);
        scenario.validate().with_context(|| format!("{source}: row {}", row.name))?;
        let config = row.filter(filter, scenario.epochs);
        let results: Vec<KimRunOutcome> = (0..runs)
            .into_par_iter()
            .map(|r| {
                progress.check_cancelled()?;
                let realised = scenario.realise(experiment.seed, r)?;
                let filter_seed = experiment.seed.wrapping_mul(mmtrack_core::random::SPLITMIX_GAMMA) ^ r;
                let outcome = run_filter(
                    &realised,
                    &config,
                    filter_seed,
                    experiment.match_radius_m,
                    experiment.sp_min_detections,
                )
                .with_context(|| format!("row {}, run {r}", row.name));
                progress.advance(1);
                outcome
            })
            .collect::<anyhow::Result<_>>()?;
        let last: Vec<[Option<LastFound>; 2]> =
            results.iter().map(|k| [k.last_va.clone(), k.last_sp.clone()]).collect();
        let outcomes: Vec<RunOutcome> = results.into_iter().map(|k| k.outcome).collect();
        rows.push(aggregate(row, &scenario, &config, &outcomes, &last)?);
    }
    progress.finish();
    Ok(Measured {
        runs,
        filter: filter.clone(),
        rows,
        elapsed_s: started.elapsed().as_secs_f64(),
        threads: rayon::current_num_threads(),
        load: (load_before, load_average()),
    })
}

/// Means over the runs of one row.
fn aggregate(
    row: &Row,
    scenario: &SlamScenario,
    config: &SlamConfig,
    outcomes: &[RunOutcome],
    last: &[[Option<LastFound>; 2]],
) -> anyhow::Result<RowResult> {
    let first = outcomes.first().context("no runs")?.clone();
    let n = outcomes.len() as f64;
    let never = scenario.epochs + 1;
    let averages: Vec<[Option<f64>; 7]> = outcomes.iter().map(RunOutcome::time_averages).collect();
    let mean_of = |i: usize| -> Option<f64> {
        let v: Vec<f64> = averages.iter().filter_map(|a| a[i]).collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    let epochs_of = |f: &dyn Fn(&RunOutcome) -> Option<usize>| -> (f64, u64) {
        let v: Vec<usize> = outcomes.iter().map(|o| f(o).unwrap_or(never)).collect();
        (v.iter().sum::<usize>() as f64 / n, v.iter().copied().max().unwrap_or(never) as u64)
    };
    let (va_mean, va_max) = epochs_of(&|o| o.all_va_epoch);
    let (sp_mean, sp_max) = epochs_of(&|o| o.all_sp_epoch);
    let median_of = |f: &dyn Fn(&RunOutcome) -> Option<usize>| -> f64 {
        let mut v: Vec<f64> = outcomes.iter().map(|o| f(o).unwrap_or(never) as f64).collect();
        v.sort_by(f64::total_cmp);
        mmtrack_core::stats::quantile(&v, 0.5).unwrap_or(never as f64)
    };
    let all_epochs = || outcomes.iter().flat_map(|o| o.epochs.iter());
    let blocked_ue_position_error_m = scenario.los_blocked_epochs.map(|[first, last]| {
        let per_run: Vec<f64> = outcomes
            .iter()
            .map(|o| {
                let stretch = &o.epochs[first - 1..last.min(o.epochs.len())];
                stretch.iter().map(|e| e.position_m).sum::<f64>() / stretch.len().max(1) as f64
            })
            .collect();
        per_run.iter().sum::<f64>() / n
    });
    let epoch_count = all_epochs().count().max(1) as f64;
    let false_errors: Vec<f64> =
        all_epochs().filter_map(|e| e.false_source_error_m.map(|m| m * e.false_sources as f64)).collect();
    let false_total: usize = all_epochs().map(|e| e.false_sources).sum();
    let nees: Vec<f64> = all_epochs().filter_map(|e| e.position_nees).collect();
    let interval = nees_interval(outcomes.len());
    let per_epoch_nees: Vec<f64> = (0..scenario.epochs)
        .filter_map(|k| {
            let v: Vec<f64> = outcomes.iter().filter_map(|o| o.epochs.get(k).and_then(|e| e.position_nees)).collect();
            (v.len() == outcomes.len()).then(|| v.iter().sum::<f64>() / v.len() as f64)
        })
        .collect();
    let extra = RowExtra {
        blocked_ue_position_error_m,
        false_sources_per_epoch: false_total as f64 / epoch_count,
        false_sources_max: all_epochs().map(|e| e.false_sources).max().unwrap_or(0),
        false_source_error_m: (false_total > 0).then(|| false_errors.iter().sum::<f64>() / false_total as f64),
        nees_mean: (!nees.is_empty()).then(|| nees.iter().sum::<f64>() / nees.len() as f64),
        nees_interval: interval,
        nees_share_inside: (!per_epoch_nees.is_empty()).then(|| {
            per_epoch_nees.iter().filter(|v| (interval[0]..=interval[1]).contains(*v)).count() as f64
                / per_epoch_nees.len() as f64
        }),
        all_va_epoch_median: median_of(&|o| o.all_va_epoch),
        all_sp_epoch_median: median_of(&|o| o.all_sp_epoch),
        all_va_epochs: outcomes.iter().map(|o| o.all_va_epoch.unwrap_or(never)).collect(),
        all_sp_epochs: outcomes.iter().map(|o| o.all_sp_epoch.unwrap_or(never)).collect(),
        last_va: last.iter().map(|l| l[0].clone()).collect(),
        last_sp: last.iter().map(|l| l[1].clone()).collect(),
    };
    let summary = SlamSummaryRow {
        row: row.name.clone(),
        runs: outcomes.len() as u64,
        epochs: scenario.epochs as u64,
        particles: config.particles as u64,
        detection_probability: row.detection_probability,
        clutter_per_epoch: row.clutter_per_epoch as u64,
        ue_position_error_m: mean_of(0).unwrap_or(f64::NAN),
        ue_error_over_spread: {
            let all = || outcomes.iter().flat_map(|o| o.epochs.iter());
            let e2: f64 = all().map(|e| e.position_m * e.position_m).sum();
            let s2: f64 = all().map(|e| e.position_std_m * e.position_std_m).sum();
            (e2 / s2).sqrt()
        },
        ue_heading_error_rad: mean_of(1).unwrap_or(f64::NAN),
        ue_clock_bias_error_m: mean_of(2).unwrap_or(f64::NAN),
        ue_speed_error_mps: mean_of(3).unwrap_or(f64::NAN),
        ue_turn_rate_error_radps: mean_of(4).unwrap_or(f64::NAN),
        va_error_m: mean_of(5),
        sp_error_m: mean_of(6),
        all_va_epoch_mean: va_mean,
        all_va_epoch_max: va_max,
        all_sp_epoch_mean: sp_mean,
        all_sp_epoch_max: sp_max,
        false_sources: outcomes.iter().map(|o| o.false_sources as f64).sum::<f64>() / n,
        skipped_paths: outcomes.iter().map(|o| o.skipped_paths as u64).sum(),
    };
    let per_epoch = (0..scenario.epochs)
        .map(|k| {
            let at: Vec<_> = outcomes.iter().filter_map(|o| o.epochs.get(k)).collect();
            let m = at.len().max(1) as f64;
            let opt = |f: &dyn Fn(&EpochErrors) -> Option<f64>| {
                let v: Vec<f64> = at.iter().filter_map(|e| f(e)).collect();
                (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
            };
            SlamPerEpochRow {
                row: row.name.clone(),
                epoch: k as u64 + 1,
                ue_position_error_m: at.iter().map(|e| e.position_m).sum::<f64>() / m,
                ue_heading_error_rad: at.iter().map(|e| e.heading_rad).sum::<f64>() / m,
                ue_clock_bias_error_m: at.iter().map(|e| e.clock_bias_m).sum::<f64>() / m,
                va_error_m: opt(&|e| e.va_m),
                sp_error_m: opt(&|e| e.sp_m),
                confirmed_va: at.iter().map(|e| e.confirmed_va as f64).sum::<f64>() / m,
                confirmed_sp: at.iter().map(|e| e.confirmed_sp as f64).sum::<f64>() / m,
            }
        })
        .collect();
    Ok(RowResult { row: row.clone(), summary, per_epoch, first, extra })
}
