//! What the odometry experiment reports: the metrics of the regression
//! check, the verdicts on the targets, the Markdown report and the files
//! (odometry tables, analysis, `reproduce.md`, `metrics.json`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use mmtrack_analysis::output::write_results;
use mmtrack_analysis::pipeline::TrajectoryResult;
use mmtrack_io::Overwrite;
use mmtrack_io::recording::TimeBase;
use mmtrack_io::table::RunInfo;
use mmtrack_process::odometry::{self, OdometryRun};
use mmtrack_process::output::RunDir;

use super::config::{Config, Drift, TARGETS};
use super::run::{Measured, PresetResult, sequence_of};
use crate::common::Staged;
use crate::model::{Claim, Metric, Rule, Tier, Verdict, write_metrics};

/// The README block the report would replace (the README has none today).
pub const README_BLOCK: &str = "reproduce-odometry";

/// The numbers `reproduce --all` checks: KITTI drift of both presets (the
/// paper's 6.56 % is fast-cfear's on Oxford) and their ATE RMSE.
#[must_use]
pub fn metrics(presets: &[PresetResult]) -> Vec<Metric> {
    let mut out = Vec::new();
    for r in presets {
        let m = &r.result.metrics;
        let paper = (r.preset == "fast-cfear").then_some(6.56);
        if let Some(v) = m.kitti_translational_pct {
            out.push(Metric::new(format!("{} KITTI translational drift", r.preset), v, "%", paper));
        }
        if let Some(v) = m.kitti_rotational_deg_per_100m {
            out.push(Metric::new(format!("{} KITTI rotational drift", r.preset), v, "deg/100 m", None));
        }
        out.push(Metric::new(format!("{} ATE RMSE", r.preset), m.ate_rmse_m, "m", None));
    }
    out
}

/// Each target of [`TARGETS`] against the drift measured.
#[must_use]
pub fn verdicts(presets: &[PresetResult]) -> Vec<Verdict> {
    TARGETS
        .iter()
        .map(|target| {
            let metrics = presets.iter().find(|r| r.preset == target.preset).map(|r| &r.result.metrics);
            let measured = metrics.and_then(|m| match target.drift {
                Drift::Translational => m.kitti_translational_pct,
                Drift::Rotational => m.kitti_rotational_deg_per_100m,
            });
            let (rule, relation) = if target.strict {
                (Rule::Below { bound: target.bound }, "<")
            } else {
                (Rule::AtMost { bound: target.bound }, "<=")
            };
            let claim = Claim::new(
                format!("{} {}", target.preset, target.drift.name()),
                target.drift.unit(),
                target.paper,
                format!("{relation} {}", target.bound),
                rule,
            );
            Verdict::judged(claim, measured, measured.map_or("-".to_string(), |m| format!("{m:.3}")))
        })
        .collect()
}

/// The Markdown report: the drive, a row per preset, the verdicts.
#[must_use]
pub fn report(config: &Config, tier: Tier, measured: &Measured, verdicts: &[Verdict]) -> String {
    let presets = &measured.presets;
    let path_m = presets.first().map_or(0.0, |r| r.result.metrics.path_length_m);
    let mut out = format!(
        "# reproduce odometry{}\n\nSimulated drive: {} scans, {path_m:.0} m along {} (scenario {}); \
         simulation and both presets took {:.1} s.\n\n",
        if tier.is_smoke() { " (quick)" } else { "" },
        measured.ground_truth.len(),
        config.trajectory.display(),
        config.source,
        measured.elapsed_s,
    );
    out.push_str(
        "| preset | KITTI drift % | deg/100 m | segments | ATE RMSE m | end-point error m | low-confidence scans |\n",
    );
    out.push_str("|---|---|---|---|---|---|---|\n");
    for r in presets {
        let m = &r.result.metrics;
        let fmt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.2}"));
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {:.2} | {:.2} | {} |",
            r.preset,
            fmt(m.kitti_translational_pct),
            fmt(m.kitti_rotational_deg_per_100m),
            m.kitti_segments,
            m.ate_rmse_m,
            m.final_position_error_m,
            r.low_confidence,
        );
    }
    out.push_str("\n| target | bound | measured | verdict |\n|---|---|---|---|\n");
    out.push_str(&crate::model::verdict_rows(verdicts));
    out
}

/// Writes each preset's odometry tables (`tables/`), the analysis of both
/// (`analysis/`), `reproduce.md` (`report`) and `metrics.json` into a
/// staging directory that replaces `output` whole; returns the files
/// written.
///
/// # Errors
/// A table or file cannot be written.
pub fn write_outputs(
    output: &Path,
    config: &Config,
    measured: Measured,
    report: &str,
    metrics: &[Metric],
) -> anyhow::Result<Vec<PathBuf>> {
    let staging = Staged::new(output, "odometry")?;
    let tables = staging.path().join("tables");
    let Measured { scenario, drift, ground_truth, presets, elapsed_s } = measured;
    let mut analysis: Vec<TrajectoryResult> = Vec::new();
    // The simulator's rule for its recordings (`simulate radar`): UNIX time
    // when the trajectory puts the drive at a date, scenario time otherwise.
    let first_t_ns = ground_truth.first().map_or(0, |p| p.t_ns);
    let time_base = TimeBase::unix_or(first_t_ns, TimeBase::ScenarioStart);
    for r in presets {
        let sequence = sequence_of(r.preset);
        let run = OdometryRun {
            estimates: r.estimates,
            timings: r.timings,
            ground_truth: ground_truth.clone(),
            sequence_id: sequence.clone(),
            time_base,
            recording_extra: std::collections::BTreeMap::new(),
            elapsed_s,
        };
        let out = RunDir { path: tables.clone(), overwrite: Overwrite::Refuse };
        odometry::write_outputs(&out, &sequence, &run, &r.config, r.preset, Path::new(&config.source))?;
        analysis.push(r.result);
    }
    let mut config_json = serde_json::json!({
        "command": "reproduce odometry",
        "scenario": config.source,
        "trajectory": config.trajectory.display().to_string(),
        "max_distance_m": scenario.max_distance_m,
        "seed": scenario.seed,
    });
    if let Some(fields) = config_json.as_object_mut() {
        fields.extend(drift.config_fields());
    }
    config_json["mmtrack_version"] = serde_json::json!(env!("CARGO_PKG_VERSION"));
    let info = RunInfo { config_json: config_json.to_string(), time_base: time_base.into(), frame: None };
    write_results(&staging.path().join("analysis"), &analysis, &[], &drift, &info, Overwrite::Refuse)?;
    std::fs::write(staging.path().join("reproduce.md"), report)?;
    write_metrics(staging.path(), metrics)?;
    let files = staging.files()?;
    staging.publish()?;
    Ok(files)
}
