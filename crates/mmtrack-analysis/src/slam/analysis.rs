//! `mmtrack analyze` on the tables of `mmtrack process slam`: per sequence
//! the paper's metrics (Kim et al. 2018, Sec. V-B, [`super::metrics`]) as a
//! one-run `slam_summary` row and `slam_per_epoch` rows, the map (true and
//! estimated sources, the true and estimated track) and the errors over the
//! epochs as plots, and a report section.
//!
//! A confirmed source matches a true one of its type within
//! [`MATCH_RADIUS_M`]; a true SP counts towards "all SPs confirmed" once
//! seen in [`SP_MIN_DETECTIONS`] epochs: the values of `reproduce kim`
//! (`data/reproduce/kim.toml`).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::Context;
use mmtrack_core::slam::UeState;
use mmtrack_io::Overwrite;
use mmtrack_io::table::{read_table, table_path, write_table};
use mmtrack_io::table_kv::read_key_value_metadata;

use super::metrics::{EpochView, MapTruth, RunOutcome, evaluate};
use super::plots::{EpochCurve, MapFigure, epoch_curves_svg, map_svg};
use mmtrack_io::table::{
    SLAM_MAP, SLAM_TRUE_SOURCES, SLAM_UE, SlamMapRow, SlamPerEpochRow, SlamSummaryRow, SlamTrueSourceRow, SlamUeRow,
};

/// Match radius of a confirmed source, metres (as `reproduce kim`).
pub const MATCH_RADIUS_M: f64 = 5.0;
/// Epochs a true SP must be seen in to count (as `reproduce kim`).
pub const SP_MIN_DETECTIONS: usize = 3;
/// The tables `process slam` writes that the analysis needs.
pub const INPUT_TABLES: [&str; 3] = [SLAM_UE.name, SLAM_MAP.name, SLAM_TRUE_SOURCES.name];
/// Plots per sequence: file and caption.
pub const PLOTS: [(&str, &str); 3] = [
    ("slam_map.svg", "map: true and estimated sources, true and estimated track"),
    ("slam_ue_errors.svg", "UE position and clock-bias errors over the epochs"),
    ("slam_sources.svg", "confirmed VAs and SPs over the epochs"),
];

/// Everything computed for one sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct SlamSequenceResult {
    /// Sequence id.
    pub sequence: String,
    /// The paper's metrics as one `slam_summary` row (row = sequence, runs = 1).
    pub summary: SlamSummaryRow,
    /// Per epoch.
    pub per_epoch: Vec<SlamPerEpochRow>,
    /// The map figure's data.
    pub map: MapFigure,
    /// The evaluation.
    pub outcome: RunOutcome,
}

/// Confirmed VAs and SPs of one epoch, metres.
type ConfirmedMap = (Vec<[f64; 3]>, Vec<[f64; 3]>);

fn truth_of(row: &SlamUeRow) -> Option<UeState> {
    Some(UeState {
        position_m: [row.true_x_m?, row.true_y_m?, row.true_z_m?],
        heading_rad: row.true_heading_rad?,
        speed_mps: row.true_speed_mps?,
        turn_rate_radps: row.true_turn_rate_radps?,
        clock_bias_m: row.true_clock_bias_m?,
    })
}

fn estimate_of(row: &SlamUeRow) -> UeState {
    UeState {
        position_m: [row.x_m, row.y_m, row.z_m],
        heading_rad: row.heading_rad,
        speed_mps: row.speed_mps,
        turn_rate_radps: row.turn_rate_radps,
        clock_bias_m: row.clock_bias_m,
    }
}

/// The settings `process slam` recorded in its run configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunSettings {
    /// UE particles.
    pub particles: u64,
    /// Detection probability of the scenario (else the filter's).
    pub detection_probability: f64,
    /// Clutter paths per epoch of the scenario (0 when unknown).
    pub clutter_per_epoch: u64,
}

impl RunSettings {
    /// From `process slam`'s run configuration (JSON); NaN / 0 for what it lacks.
    #[must_use]
    pub fn from_config(json: &serde_json::Value) -> Self {
        let f = |path: &[&str]| path.iter().try_fold(json, |v, k| v.get(k));
        Self {
            particles: f(&["filter", "particles"]).and_then(serde_json::Value::as_u64).unwrap_or(0),
            detection_probability: f(&["scenario", "detection_probability"])
                .or_else(|| f(&["filter", "detection_probability"]))
                .and_then(serde_json::Value::as_f64)
                .unwrap_or(f64::NAN),
            clutter_per_epoch: f(&["scenario", "clutter_per_epoch"]).and_then(serde_json::Value::as_u64).unwrap_or(0),
        }
    }
}

/// The metrics of one sequence from its `slam_ue`, `slam_map` and
/// `slam_true_sources` rows.
///
/// # Errors
/// An epoch of `slam_ue` without its truth, or no epochs.
pub fn sequence_result(
    sequence: &str,
    ue: &[SlamUeRow],
    map: &[SlamMapRow],
    sources: &[SlamTrueSourceRow],
    settings: RunSettings,
) -> Result<SlamSequenceResult, String> {
    if ue.is_empty() {
        return Err(format!("{}: no epochs", SLAM_UE.name));
    }
    // Confirmed VAs and SPs per epoch.
    let mut confirmed: BTreeMap<u64, ConfirmedMap> = BTreeMap::new();
    for r in map {
        let entry = confirmed.entry(r.epoch).or_default();
        match r.status.as_str() {
            "va" => entry.0.push([r.x_m, r.y_m, r.z_m]),
            "sp" => entry.1.push([r.x_m, r.y_m, r.z_m]),
            _ => {}
        }
    }
    let mut views = Vec::with_capacity(ue.len());
    for row in ue {
        let truth = truth_of(row).ok_or_else(|| {
            format!("{}: epoch {} has no true UE state (a recording without ground truth)", SLAM_UE.name, row.epoch)
        })?;
        let (va_m, sp_m) = confirmed.get(&row.epoch).cloned().unwrap_or_default();
        views.push(EpochView {
            estimate: estimate_of(row),
            position_std_m: row.position_std_m,
            position_cov_m2: None,
            truth,
            va_m,
            sp_m,
        });
    }
    let of_kind = |kind: &str| -> (Vec<[f64; 3]>, Vec<usize>) {
        let mut rows: Vec<&SlamTrueSourceRow> = sources.iter().filter(|s| s.kind == kind).collect();
        rows.sort_by_key(|s| s.index);
        let points = rows.iter().map(|s| [s.x_m, s.y_m, s.z_m]).collect();
        let seen = rows.iter().map(|s| s.detected_epochs.map_or(usize::MAX, |d| d as usize)).collect();
        (points, seen)
    };
    let (va, _) = of_kind("va");
    let (sp, detections) = of_kind("sp");
    let bs = sources.iter().find(|s| s.kind == "bs").map_or([0.0; 2], |s| [s.x_m, s.y_m]);
    let truth = MapTruth::new(va, sp, &detections, SP_MIN_DETECTIONS, MATCH_RADIUS_M);
    let mut outcome = evaluate(&truth, &views);
    outcome.skipped_paths = ue.iter().map(|r| r.skipped_paths as usize).sum();
    let epochs = ue.len();
    let never = epochs + 1;
    let avg = outcome.time_averages();
    let (e2, s2) = outcome
        .epochs
        .iter()
        .fold((0.0, 0.0), |(e2, s2), e| (e2 + e.position_m * e.position_m, s2 + e.position_std_m * e.position_std_m));
    let va_epoch = outcome.all_va_epoch.unwrap_or(never);
    let sp_epoch = outcome.all_sp_epoch.unwrap_or(never);
    let summary = SlamSummaryRow {
        row: sequence.to_string(),
        runs: 1,
        epochs: epochs as u64,
        particles: settings.particles,
        detection_probability: settings.detection_probability,
        clutter_per_epoch: settings.clutter_per_epoch,
        ue_position_error_m: avg[0].unwrap_or(f64::NAN),
        ue_error_over_spread: (e2 / s2).sqrt(),
        ue_heading_error_rad: avg[1].unwrap_or(f64::NAN),
        ue_clock_bias_error_m: avg[2].unwrap_or(f64::NAN),
        ue_speed_error_mps: avg[3].unwrap_or(f64::NAN),
        ue_turn_rate_error_radps: avg[4].unwrap_or(f64::NAN),
        va_error_m: avg[5],
        sp_error_m: avg[6],
        all_va_epoch_mean: va_epoch as f64,
        all_va_epoch_max: va_epoch as u64,
        all_sp_epoch_mean: sp_epoch as f64,
        all_sp_epoch_max: sp_epoch as u64,
        false_sources: outcome.false_sources as f64,
        skipped_paths: outcome.skipped_paths as u64,
    };
    let per_epoch = ue
        .iter()
        .zip(&outcome.epochs)
        .map(|(row, e)| SlamPerEpochRow {
            row: sequence.to_string(),
            epoch: row.epoch,
            ue_position_error_m: e.position_m,
            ue_heading_error_rad: e.heading_rad,
            ue_clock_bias_error_m: e.clock_bias_m,
            va_error_m: e.va_m,
            sp_error_m: e.sp_m,
            confirmed_va: e.confirmed_va as f64,
            confirmed_sp: e.confirmed_sp as f64,
        })
        .collect();
    let xy = |p: &[f64; 3]| [p[0], p[1]];
    let map = MapFigure {
        bs_m: bs,
        true_va_m: truth.va_m.iter().map(xy).collect(),
        true_sp_m: truth.sp_m.iter().map(xy).collect(),
        estimated_va_m: outcome.final_va_m.iter().map(xy).collect(),
        estimated_sp_m: outcome.final_sp_m.iter().map(xy).collect(),
        true_track_m: views.iter().map(|v| xy(&v.truth.position_m)).collect(),
        estimated_track_m: outcome.track_m.iter().map(xy).collect(),
    };
    Ok(SlamSequenceResult { sequence: sequence.to_string(), summary, per_epoch, map, outcome })
}

/// A sequence left out and why.
pub type Skipped = (String, String);

/// The SLAM results of `sequences` under the table directory `root`, and
/// the sequences left out with the reason (no ground truth: a recording
/// without `/slam/ue_truth`).
///
/// # Errors
/// A table that cannot be read, or another of [`sequence_result`]'s errors,
/// naming the directory and sequence.
pub fn analyze_slam_all(root: &Path, sequences: &[String]) -> anyhow::Result<(Vec<SlamSequenceResult>, Vec<Skipped>)> {
    let mut out = Vec::with_capacity(sequences.len());
    let mut skipped = Vec::new();
    for sequence in sequences {
        let ue_path = table_path(root, SLAM_UE.name, sequence)?;
        let ue: Vec<SlamUeRow> = read_table(&ue_path)?;
        if let Some(row) = ue.iter().find(|r| truth_of(r).is_none()) {
            skipped.push((
                sequence.clone(),
                format!(
                    "has {} without the true UE state (epoch {}): the SLAM metrics need a recording with ground truth",
                    SLAM_UE.name, row.epoch
                ),
            ));
            continue;
        }
        let map: Vec<SlamMapRow> = read_table(&table_path(root, SLAM_MAP.name, sequence)?)?;
        let sources: Vec<SlamTrueSourceRow> = read_table(&table_path(root, SLAM_TRUE_SOURCES.name, sequence)?)?;
        let kv = read_key_value_metadata(&ue_path)?;
        let config = kv
            .get("mmtrack.run_config")
            .and_then(|j| serde_json::from_str::<serde_json::Value>(j).ok())
            .unwrap_or(serde_json::Value::Null);
        let result = sequence_result(sequence, &ue, &map, &sources, RunSettings::from_config(&config))
            .map_err(|e| anyhow::anyhow!("{}: sequence {sequence}: {e}", root.display()))?;
        out.push(result);
    }
    Ok((out, skipped))
}

/// Writes `slam_summary` and `slam_per_epoch` per sequence and the plots;
/// returns the number of files.
///
/// # Errors
/// A table or plot that cannot be written.
pub(crate) fn write_slam_into(
    dir: &Path,
    results: &[SlamSequenceResult],
    run: &crate::sequence_run::SequenceRun<'_>,
) -> anyhow::Result<usize> {
    let tables = dir.join("tables");
    let mut files = 0;
    for r in results {
        let seq = &r.sequence;
        write_table(&tables, seq, std::slice::from_ref(&r.summary), &run.at(seq), Overwrite::Refuse)?;
        write_table(&tables, seq, &r.per_epoch, &run.at(seq), Overwrite::Refuse)?;
        let plot_dir = dir.join("plots").join(seq);
        mmtrack_io::create_output_dirs(&plot_dir).with_context(|| plot_dir.display().to_string())?;
        let curve = |label: &str, f: &dyn Fn(&SlamPerEpochRow) -> f64| EpochCurve {
            label: label.to_string(),
            values: r.per_epoch.iter().map(f).collect(),
        };
        let svgs = [
            map_svg(&format!("Map after {} epochs, sequence {seq}", r.per_epoch.len()), &r.map),
            epoch_curves_svg(
                "UE errors",
                "error (m)",
                &[
                    curve("position (m)", &|e| e.ue_position_error_m),
                    curve("clock bias (m)", &|e| e.ue_clock_bias_error_m),
                ],
            ),
            epoch_curves_svg(
                "Confirmed sources",
                "sources",
                &[curve("VA", &|e| e.confirmed_va), curve("SP", &|e| e.confirmed_sp)],
            ),
        ];
        for ((file, _), svg) in PLOTS.iter().zip(svgs) {
            let path = plot_dir.join(file);
            let svg = svg.with_context(|| format!("sequence {seq}: {file}"))?;
            std::fs::write(&path, svg).with_context(|| path.display().to_string())?;
        }
        files += 2 + PLOTS.len();
    }
    Ok(files)
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "-".to_string(), |v| format!("{v:.digits$}"))
}

fn epoch(e: u64, epochs: u64) -> String {
    if e > epochs { "never".to_string() } else { e.to_string() }
}

/// The report section.
pub fn section(out: &mut String, results: &[SlamSequenceResult]) {
    out.push_str(
        "## 5G mmWave SLAM (tables `slam_ue`, `slam_map`, `slam_true_sources`)\n\n\
         Time-averaged errors of the UE estimate and of the confirmed virtual anchors (VA) and scattering points (SP) \
         against the truth (Kim et al. 2018, Sec. V-B; a source matches a true one of its type within 5 m), and the \
         epochs at which every VA and every SP seen in at least 3 epochs were confirmed. The paper's targets: UE 0.5 m, \
         0.02 rad, 0.3 m; VA 0.8 m; SP 0.6 m; all VAs by epoch 26, all SPs by epoch 91.\n\n\
         | sequence | epochs | particles | UE position (m) | heading (rad) | clock bias (m) | VA (m) | SP (m) | all VAs \
         at epoch | all SPs at epoch | false sources | skipped paths |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in results {
        let s = &r.summary;
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.3} | {:.4} | {:.3} | {} | {} | {} | {} | {} | {} |",
            r.sequence,
            s.epochs,
            s.particles,
            s.ue_position_error_m,
            s.ue_heading_error_rad,
            s.ue_clock_bias_error_m,
            opt(s.va_error_m, 3),
            opt(s.sp_error_m, 3),
            epoch(s.all_va_epoch_max, s.epochs),
            epoch(s.all_sp_epoch_max, s.epochs),
            s.false_sources,
            s.skipped_paths,
        );
    }
    out.push('\n');
    for r in results {
        let _ = writeln!(out, "### `{}` (SLAM)\n", r.sequence);
        for (file, caption) in PLOTS {
            let _ = writeln!(out, "![{caption}](plots/{}/{file})", r.sequence);
        }
        out.push('\n');
    }
}

/// One line per sequence for the terminal.
#[must_use]
pub fn one_lines(results: &[SlamSequenceResult]) -> Vec<String> {
    results
        .iter()
        .map(|r| {
            let s = &r.summary;
            format!(
                "{}: UE {:.3} m / {:.4} rad / clock bias {:.3} m, VA {} m, SP {} m, all VAs at epoch {}, all SPs at epoch {}",
                r.sequence,
                s.ue_position_error_m,
                s.ue_heading_error_rad,
                s.ue_clock_bias_error_m,
                opt(s.va_error_m, 3),
                opt(s.sp_error_m, 3),
                epoch(s.all_va_epoch_max, s.epochs),
                epoch(s.all_sp_epoch_max, s.epochs)
            )
        })
        .collect()
}
