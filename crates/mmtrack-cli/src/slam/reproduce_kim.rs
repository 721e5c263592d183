//! `mmtrack reproduce kim`: the 5G mmWave vehicular SLAM experiment of Kim
//! et al. 2018, Sec. V (PAPERS.md section 5).
//!
//! On the paper's circular-road world (`mmtrack_sim::slam`), the filter of
//! `mmtrack_slam` runs over Monte Carlo realisations (each its own 10 random
//! SPs, trajectory and noise) of every row of the experiment: the paper's
//! setting, then the robustness rows (detection probability 0.9, one
//! clutter path per epoch). Reported per row: the mean over runs of the
//! time-averaged UE position, heading, clock-bias (and smoothed speed and
//! turn-rate) errors, the VA and SP localisation errors, and the epochs at
//! which all VAs and all SPs are confirmed. The experiment, the paper's
//! numbers and the tolerances are one TOML file (`data/reproduce/kim.toml`,
//! embedded).
//!
//! Runs are computed on rayon and collected in run order; each filter's
//! particles draw from streams seeded by (seed, run, epoch, chunk), so the
//! numbers do not depend on the thread count.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use mmtrack_analysis::slam::plots::{EpochCurve, MapFigure, epoch_curves_svg, map_svg};
use mmtrack_io::Overwrite;
use mmtrack_io::table::{RunInfo, write_table};
use mmtrack_io::table::{SlamPerEpochRow, SlamSummaryRow};
use mmtrack_sim::slam::SlamScenario;
use mmtrack_slam::SlamConfig;
use rayon::prelude::*;
use serde::Deserialize;

use super::evaluate::{RunOutcome, run_filter};
use super::kim_report::{self as report, README_BLOCK};
use crate::threads::ThreadsArg;

/// The experiment, embedded so it runs from any directory.
pub const KIM_EXPERIMENT: &str = include_str!("../../../../data/reproduce/kim.toml");

#[derive(Args)]
pub struct KimArgs {
    /// Output directory (tables/, SVG figures, reproduce.md, metrics.json).
    #[arg(short, long, default_value = "out/reproduce/kim")]
    output: PathBuf,
    /// Replace a previous run's output directory.
    #[arg(long)]
    force: bool,
    /// Experiment file (TOML; default: the embedded data/reproduce/kim.toml).
    #[arg(long, value_name = "EXPERIMENT.toml")]
    experiment: Option<PathBuf>,
    /// Monte Carlo runs per row (default: the experiment's, 20).
    #[arg(long)]
    runs: Option<u64>,
    /// UE particles (default: the filter's, 2000).
    #[arg(long)]
    particles: Option<usize>,
    /// The CI version: the experiment's quick_runs runs with quick_particles
    /// particles, checked with quick_tolerance.
    #[arg(long)]
    quick: bool,
    /// Replace the block `<!-- reproduce-kim:begin -->` ... `end` in this
    /// file with the summary (checked before the run).
    #[arg(long, value_name = "README.md")]
    readme: Option<PathBuf>,
    #[command(flatten)]
    threads: ThreadsArg,
}

/// The experiment file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Experiment {
    pub seed: u64,
    pub runs: u64,
    pub quick_runs: u64,
    pub quick_particles: usize,
    pub match_radius_m: f64,
    pub sp_min_detections: usize,
    #[serde(default)]
    pub scenario: SlamScenario,
    #[serde(default)]
    pub filter: SlamConfig,
    pub rows: Vec<Row>,
    pub targets: Targets,
}

/// One scenario variant.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Row {
    pub name: String,
    pub detection_probability: f64,
    pub clutter_per_epoch: usize,
    pub checked: bool,
}

/// The paper's numbers.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Targets {
    pub ue_position_m: f64,
    pub ue_heading_rad: f64,
    pub ue_clock_bias_m: f64,
    pub va_m: f64,
    pub sp_m: f64,
    pub all_va_epoch: u64,
    pub all_sp_epoch: u64,
    pub tolerance: f64,
    pub quick_tolerance: f64,
}

/// What one row measured.
pub(super) struct RowResult {
    pub row: Row,
    pub summary: SlamSummaryRow,
    pub per_epoch: Vec<SlamPerEpochRow>,
    /// Run 0, for the map figure.
    pub first: RunOutcome,
}

pub fn run(args: &KimArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    crate::reproduce_common::check_start(&args.output, args.force, args.readme.as_deref(), README_BLOCK)?;
    let (source, experiment): (String, Experiment) = crate::reproduce_common::load_experiment(
        args.experiment.as_deref(),
        KIM_EXPERIMENT,
        "data/reproduce/kim.toml",
    )?;
    let runs = crate::reproduce_common::run_count(args.runs, args.quick, experiment.quick_runs, experiment.runs)?;
    anyhow::ensure!(!experiment.rows.is_empty(), "{source}: no [[rows]] (nothing was done)");
    let mut filter = experiment.filter.clone();
    if let Some(p) = args.particles {
        filter.particles = p;
    } else if args.quick {
        filter.particles = experiment.quick_particles;
    }
    filter.bs_m = experiment.scenario.bs_m;
    filter.validate().with_context(|| format!("{source}: [filter]"))?;
    experiment.scenario.validate().with_context(|| format!("{source}: [scenario]"))?;
    let tolerance = if args.quick { experiment.targets.quick_tolerance } else { experiment.targets.tolerance };

    let load_before = crate::bench_mpc::load_average();
    let started = Instant::now();
    let (results, threads) = args.threads.install(|| -> anyhow::Result<(Vec<RowResult>, usize)> {
        let bar = crate::progress::bar(runs * experiment.rows.len() as u64, "reproduce kim", "runs", quiet);
        let mut results = Vec::new();
        for row in &experiment.rows {
            let scenario = SlamScenario {
                detection_probability: row.detection_probability,
                clutter_per_epoch: row.clutter_per_epoch,
                ..experiment.scenario.clone()
            };
            scenario.validate().with_context(|| format!("{source}: row {}", row.name))?;
            // The filter assumes the row's detection probability (0.99 for P_D = 1, eq. (3)).
            let config = SlamConfig {
                detection_probability: row.detection_probability.min(filter.detection_probability),
                ..filter.clone()
            };
            let outcomes: Vec<RunOutcome> = (0..runs)
                .into_par_iter()
                .map(|r| {
                    let realised = scenario.realise(experiment.seed, r)?;
                    let filter_seed = experiment.seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ r;
                    let outcome = run_filter(
                        &realised,
                        &config,
                        filter_seed,
                        experiment.match_radius_m,
                        experiment.sp_min_detections,
                    )
                    .with_context(|| format!("row {}, run {r}", row.name));
                    bar.inc(1);
                    outcome
                })
                .collect::<anyhow::Result<_>>()?;
            results.push(aggregate(row, &scenario, &config, &outcomes)?);
        }
        bar.finish_and_clear();
        Ok((results, rayon::current_num_threads()))
    })??;
    let elapsed_s = started.elapsed().as_secs_f64();
    let load = (load_before, crate::bench_mpc::load_average());

    let verdicts = report::verdicts(&experiment.targets, tolerance, &results);
    let summary =
        report::summary(&experiment, &filter, &results, &verdicts, runs, tolerance, (elapsed_s, threads, load));
    write_outputs(args, &experiment, &source, &filter, &results, runs, &summary)?;
    if let Some(readme) = &args.readme {
        crate::readme_block::replace_block(readme, README_BLOCK, &summary)?;
    }
    if !quiet {
        print!("{summary}");
        println!("\noutputs: {}", args.output.display());
    }
    Ok(if verdicts.iter().all(|v| v.met) { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// Means over the runs of one row.
fn aggregate(
    row: &Row,
    scenario: &SlamScenario,
    config: &SlamConfig,
    outcomes: &[RunOutcome],
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
            let opt = |f: &dyn Fn(&super::evaluate::EpochErrors) -> Option<f64>| {
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
    Ok(RowResult { row: row.clone(), summary, per_epoch, first })
}

fn write_outputs(
    args: &KimArgs,
    experiment: &Experiment,
    source: &str,
    filter: &SlamConfig,
    results: &[RowResult],
    runs: u64,
    summary: &str,
) -> anyhow::Result<()> {
    let staging = crate::reproduce_common::Staged::new(&args.output, "kim")?;
    let tables = staging.path().join("tables");
    let info = RunInfo {
        config_json: serde_json::json!({
            "command": "reproduce kim",
            "experiment": source,
            "runs": runs,
            "seed": experiment.seed,
            "filter": filter,
            "mmtrack_version": env!("CARGO_PKG_VERSION"),
        })
        .to_string(),
    };
    let summaries: Vec<SlamSummaryRow> = results.iter().map(|r| r.summary.clone()).collect();
    let per_epoch: Vec<SlamPerEpochRow> = results.iter().flat_map(|r| r.per_epoch.iter().cloned()).collect();
    write_table(&tables, "kim", &summaries, &info, Overwrite::Refuse)?;
    write_table(&tables, "kim", &per_epoch, &info, Overwrite::Refuse)?;
    for (file, svg) in figures(experiment, results)? {
        std::fs::write(staging.path().join(file), svg).with_context(|| file.to_string())?;
    }
    std::fs::write(staging.path().join("reproduce.md"), summary)?;
    crate::reproduce_all::write_metrics(staging.path(), &report::metrics(&experiment.targets, results))?;
    staging.publish()
}

/// The map of the first run of the first row (Fig. 3), the UE errors over
/// the epochs (Fig. 5) and the confirmed sources over the epochs (Fig. 4).
fn figures(experiment: &Experiment, results: &[RowResult]) -> anyhow::Result<Vec<(&'static str, String)>> {
    let mut out = Vec::new();
    if let Some(first) = results.first() {
        let row = &first.row;
        let scenario = SlamScenario {
            detection_probability: row.detection_probability,
            clutter_per_epoch: row.clutter_per_epoch,
            ..experiment.scenario.clone()
        };
        let truth = scenario.realise(experiment.seed, 0)?;
        let xy = |p: &[f64; 3]| [p[0], p[1]];
        let figure = MapFigure {
            bs_m: xy(&truth.world.bs_m),
            true_va_m: truth.world.virtual_anchors_m.iter().map(xy).collect(),
            true_sp_m: truth.world.scattering_points_m.iter().map(xy).collect(),
            estimated_va_m: first.first.final_va_m.iter().map(xy).collect(),
            estimated_sp_m: first.first.final_sp_m.iter().map(xy).collect(),
            true_track_m: truth.truth.iter().map(|t| xy(&t.ue.position_m)).collect(),
            estimated_track_m: first.first.track_m.iter().map(xy).collect(),
        };
        out.push((
            "map.svg",
            map_svg(&format!("Map after {} epochs, run 0, row {}", scenario.epochs, row.name), &figure)?,
        ));
    }
    let curves = |f: &dyn Fn(&SlamPerEpochRow) -> f64, suffix: &str| -> Vec<EpochCurve> {
        results
            .iter()
            .map(|r| EpochCurve {
                label: format!("{} {suffix}", r.row.name),
                values: r.per_epoch.iter().map(f).collect(),
            })
            .collect()
    };
    let mut ue = curves(&|e| e.ue_position_error_m, "position (m)");
    ue.extend(curves(&|e| e.ue_clock_bias_error_m, "clock bias (m)"));
    out.push(("ue_errors.svg", epoch_curves_svg("UE errors, mean over runs (Kim et al. Fig. 5)", "error (m)", &ue)?));
    let heading = curves(&|e| e.ue_heading_error_rad, "heading");
    out.push(("heading_error.svg", epoch_curves_svg("UE heading error, mean over runs", "error (rad)", &heading)?));
    let mut sources = curves(&|e| e.confirmed_va, "VA");
    sources.extend(curves(&|e| e.confirmed_sp, "SP"));
    out.push((
        "confirmed_sources.svg",
        epoch_curves_svg("Confirmed sources, mean over runs (Fig. 4)", "sources", &sources)?,
    ));
    let mut errors = curves(&|e| e.va_error_m.unwrap_or(f64::NAN), "VA");
    errors.extend(curves(&|e| e.sp_error_m.unwrap_or(f64::NAN), "SP"));
    out.push((
        "source_errors.svg",
        epoch_curves_svg("Localisation error of confirmed sources (Fig. 4)", "error (m)", &errors)?,
    ));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_experiment_parses_with_the_papers_targets() {
        let experiment: Experiment = toml::from_str(KIM_EXPERIMENT).unwrap();
        assert!(experiment.runs >= 20);
        assert_eq!(experiment.rows.len(), 3);
        assert_eq!(experiment.targets.all_va_epoch, 26);
        assert_eq!(experiment.targets.all_sp_epoch, 91);
        assert_eq!(experiment.filter, SlamConfig::default());
        assert_eq!(experiment.scenario.epochs, 100);
    }
}
