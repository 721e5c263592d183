//! What the Kim experiment reports: the metrics of the regression check,
//! the verdicts on the paper's claims, the Markdown summary (also the
//! README block), the tables and the figures.

use std::path::{Path, PathBuf};

use anyhow::Context;
use mmtrack_analysis::slam::plots::{EpochCurve, MapFigure, epoch_curves_svg, map_svg};
use mmtrack_io::Overwrite;
use mmtrack_io::recording::TimeBase;
use mmtrack_io::table::{RunInfo, write_table};
use mmtrack_io::table::{SlamPerEpochRow, SlamSummaryRow};
use mmtrack_sim::slam::SlamScenario;

use super::config::{Config, Targets};
use super::run::{Measured, RowResult};
use crate::common::Staged;
use crate::model::{Claim, Metric, Rule, Verdict, verdict_rows, write_metrics};

/// The README block the summary replaces.
pub const README_BLOCK: &str = "reproduce-kim";

/// Every row's numbers, the paper's beside the paper row's.
#[must_use]
pub fn metrics(targets: &Targets, results: &[RowResult]) -> Vec<Metric> {
    let mut out = Vec::new();
    for r in results {
        let s = &r.summary;
        let paper = |v: f64| r.row.checked.then_some(v);
        let mut push = |name: &str, value: Option<f64>, unit: &str, p: Option<f64>| {
            if let Some(value) = value.filter(|v| v.is_finite()) {
                out.push(Metric { key: format!("{} {name}", r.row.name), value, unit: unit.into(), paper: p });
            }
        };
        push("UE position error", Some(s.ue_position_error_m), "m", paper(targets.ue_position_m));
        push("UE heading error", Some(s.ue_heading_error_rad), "rad", paper(targets.ue_heading_rad));
        push("UE clock-bias error", Some(s.ue_clock_bias_error_m), "m", paper(targets.ue_clock_bias_m));
        push("VA error", s.va_error_m, "m", paper(targets.va_m));
        push("SP error", s.sp_error_m, "m", paper(targets.sp_m));
        push("all VAs confirmed, mean epoch", Some(s.all_va_epoch_mean), "epoch", paper(targets.all_va_epoch as f64));
        push("all SPs confirmed, mean epoch", Some(s.all_sp_epoch_mean), "epoch", paper(targets.all_sp_epoch as f64));
        push("false sources per run", Some(s.false_sources), "sources", None);
    }
    out
}

/// The paper row's numbers against the targets: at most `paper * (1 +
/// tolerance)`.
#[must_use]
pub fn verdicts(targets: &Targets, tolerance: f64, results: &[RowResult]) -> Vec<Verdict> {
    let mut out = Vec::new();
    for r in results.iter().filter(|r| r.row.checked) {
        let s = &r.summary;
        let bound = |paper: f64| paper * (1.0 + tolerance);
        let mut check = |claim: &str, paper: f64, measured: Option<f64>, unit: &str, digits: usize| {
            let claim = Claim::new(
                format!("{claim} ({})", r.row.name),
                unit,
                Some(paper),
                format!("{paper} {unit}"),
                Rule::AtMost { bound: bound(paper) },
            );
            let text = measured.map_or("none confirmed".into(), |m| format!("{m:.digits$} {unit}"));
            out.push(Verdict::judged(claim, measured, text));
        };
        check("mean UE position error", targets.ue_position_m, Some(s.ue_position_error_m), "m", 3);
        check("mean UE heading error", targets.ue_heading_rad, Some(s.ue_heading_error_rad), "rad", 4);
        check("mean UE clock-bias error", targets.ue_clock_bias_m, Some(s.ue_clock_bias_error_m), "m", 3);
        check("mean VA localisation error", targets.va_m, s.va_error_m, "m", 3);
        check("mean SP localisation error", targets.sp_m, s.sp_error_m, "m", 3);
        let epochs = |claim: &str, paper: u64, mean: f64, max: u64| {
            let claim = Claim::new(
                format!("{claim} ({}), mean over runs", r.row.name),
                "epoch",
                Some(paper as f64),
                format!("epoch {paper}"),
                Rule::AtMost { bound: bound(paper as f64) },
            );
            Verdict::judged(claim, Some(mean), format!("epoch {mean:.1} (worst run {max})"))
        };
        out.push(epochs("all VAs confirmed by", targets.all_va_epoch, s.all_va_epoch_mean, s.all_va_epoch_max));
        out.push(epochs("all SPs confirmed by", targets.all_sp_epoch, s.all_sp_epoch_mean, s.all_sp_epoch_max));
    }
    out
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

/// The Markdown summary: setup, per-row table, verdicts, speed.
#[must_use]
pub fn summary(experiment: &Config, measured: &Measured, verdicts: &[Verdict], tolerance: f64) -> String {
    let Measured { runs, filter, rows: results, elapsed_s, threads, load } = measured;
    let (runs, elapsed_s, threads) = (*runs, *elapsed_s, *threads);
    let s = &experiment.scenario;
    let mut out = format!(
        "Written by `mmtrack reproduce kim`. Circular road (start ({}, {}, {}) m, {} m/s, {:.4} rad/s, clock bias {} m), \
         BS at ({}, {}, {}) m, {} walls (VAs), {} random SPs seen within {} m, {} epochs of {} s, sigma {} m (TOA) and \
         {} rad (angles). {runs} Monte Carlo runs per row (seed {}), {} particles, {} iterations, prior centred on the \
         true first state. Errors are time averages over the epochs, then means over the runs; a confirmed source \
         counts when a true source of its type is within {} m (the others are false sources).\n\n",
        s.initial.position_m[0],
        s.initial.position_m[1],
        s.initial.position_m[2],
        s.initial.speed_mps,
        s.initial.turn_rate_radps,
        s.initial.clock_bias_m,
        s.bs_m[0],
        s.bs_m[1],
        s.bs_m[2],
        s.walls.len(),
        s.random_scattering_points + s.scattering_points_m.len(),
        s.sp_visibility_m,
        s.epochs,
        s.epoch_s,
        s.toa_std_m,
        s.angle_std_rad,
        experiment.seed,
        filter.particles,
        filter.iterations,
        experiment.match_radius_m,
    );
    out.push_str(
        "| row | P_D | clutter/epoch | UE position (m) | error / spread | heading (rad) | clock bias (m) | speed (m/s) | turn rate (rad/s) \
         | VA (m) | SP (m) | all VAs by epoch (mean / worst) | all SPs by epoch (mean / worst) | false sources/run |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let t = &experiment.targets;
    out.push_str(&format!(
        "| Kim et al. (one run) | 1 | 0 | {} | - | {} | {} | < 1.5 | < 0.6 | {} | {} | {} | {} | 0 |\n",
        t.ue_position_m, t.ue_heading_rad, t.ue_clock_bias_m, t.va_m, t.sp_m, t.all_va_epoch, t.all_sp_epoch
    ));
    for r in results {
        let s = &r.summary;
        out.push_str(&format!(
            "| {} | {} | {} | {:.3} | {:.1} | {:.4} | {:.3} | {:.3} | {:.4} | {} | {} | {:.1} / {} | {:.1} / {} | {:.2} |\n",
            s.row,
            s.detection_probability,
            s.clutter_per_epoch,
            s.ue_position_error_m,
            s.ue_error_over_spread,
            s.ue_heading_error_rad,
            s.ue_clock_bias_error_m,
            s.ue_speed_error_mps,
            s.ue_turn_rate_error_radps,
            opt(s.va_error_m, 3),
            opt(s.sp_error_m, 3),
            s.all_va_epoch_mean,
            s.all_va_epoch_max,
            s.all_sp_epoch_mean,
            s.all_sp_epoch_max,
            s.false_sources,
        ));
    }
    out.push_str(&format!(
        "\n| claim (at most the paper's number{}) | paper | measured | verdict |\n|---|---|---|---|\n",
        if tolerance > 0.0 { format!(" times {}", 1.0 + tolerance) } else { String::new() }
    ));
    out.push_str(&verdict_rows(verdicts));
    let load_text = |l: Option<f64>| l.map_or("-".into(), |v| format!("{v:.2}"));
    out.push_str(&format!(
        "\n{:.1} s on {threads} threads (load average {} before, {} after).\n",
        elapsed_s,
        load_text(load.0),
        load_text(load.1)
    ));
    out
}

/// Writes the tables, the figures, `reproduce.md` (`summary`) and
/// `metrics.json` into a staging directory that replaces `output` whole;
/// returns the files written.
///
/// # Errors
/// A table, figure or file cannot be written.
pub fn write_outputs(
    output: &Path,
    experiment: &Config,
    measured: &Measured,
    summary: &str,
    metrics: &[Metric],
) -> anyhow::Result<Vec<PathBuf>> {
    let Measured { runs, filter, rows: results, .. } = measured;
    let staging = Staged::new(output, "kim")?;
    let tables = staging.path().join("tables");
    let info = RunInfo {
        config_json: serde_json::json!({
            "command": "reproduce kim",
            "experiment": experiment.source,
            "runs": runs,
            "seed": experiment.seed,
            "filter": filter,
            "mmtrack_version": env!("CARGO_PKG_VERSION"),
        })
        .to_string(),
        // A simulated experiment: times count from the start of its scenario.
        time_base: TimeBase::ScenarioStart.into(),
        frame: None,
    };
    let summaries: Vec<SlamSummaryRow> = results.iter().map(|r| r.summary.clone()).collect();
    let per_epoch: Vec<SlamPerEpochRow> = results.iter().flat_map(|r| r.per_epoch.iter().cloned()).collect();
    write_table(&tables, "kim", &summaries, &info, Overwrite::Refuse)?;
    write_table(&tables, "kim", &per_epoch, &info, Overwrite::Refuse)?;
    for (file, svg) in figures(experiment, results)? {
        std::fs::write(staging.path().join(file), svg).with_context(|| file.to_string())?;
    }
    std::fs::write(staging.path().join("reproduce.md"), summary)?;
    write_metrics(staging.path(), metrics)?;
    let files = staging.files()?;
    staging.publish()?;
    Ok(files)
}

/// The map of the first run of the first row (Fig. 3), the UE errors over
/// the epochs (Fig. 5) and the confirmed sources over the epochs (Fig. 4).
fn figures(experiment: &Config, results: &[RowResult]) -> anyhow::Result<Vec<(&'static str, String)>> {
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
