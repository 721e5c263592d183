//! `mmtrack analyze` as one library call: table directories in, metric
//! tables, plots and reports out.
//!
//! One table directory (no `run=<ID>` folders) is analyzed straight into the
//! output; several directories, or one holding `run=<ID>` folders, give one
//! run each: every run analyzed into `<output>/run=<ID>/`, then all side by
//! side ([`crate::output::write_campaign`]).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use mmtrack_io::Overwrite;
use mmtrack_io::table::{RunInfo, TableTimeBase};

use crate::campaign::{RunTables, discover_runs};
use crate::mpc::MpcOptions;
use crate::output::{WrittenResults, check_output, write_all_results, write_campaign};
use crate::pipeline::{RunResults, analyze_run};
use crate::trajectory::DriftOptions;

/// The options of [`analyze`].
#[derive(Debug, Clone)]
pub struct AnalyzeOptions {
    /// KITTI segment lengths and first-frame step.
    pub drift: DriftOptions,
    /// MPC statistics (the first path's dynamic range).
    pub mpc: MpcOptions,
    /// Replace earlier results in the output directory.
    pub overwrite: Overwrite,
}

impl AnalyzeOptions {
    /// The options of `mmtrack analyze`'s flags (the Python keywords are the
    /// same words): `--segment-lengths-m` (default the devkit's 100..800 m),
    /// `--step-frames` or `--step-m` (default a first frame every 10
    /// frames, as the devkit), `--first-path-range-db`, `--force`.
    ///
    /// # Errors
    /// Both steps given.
    pub fn from_flags(
        segment_lengths_m: Option<Vec<f64>>,
        step_frames: Option<usize>,
        step_m: Option<f64>,
        first_path_range_db: f64,
        force: bool,
    ) -> anyhow::Result<Self> {
        use crate::trajectory::{FirstFrameStep, KITTI_SEGMENT_LENGTHS_M, KITTI_STEP_FRAMES};
        let step = match (step_m, step_frames) {
            (Some(_), Some(_)) => {
                bail!("--step-frames and --step-m: give one (a first frame every N frames or every X metres)")
            }
            (Some(m), None) => FirstFrameStep::Metres(m),
            (None, n) => FirstFrameStep::Frames(n.unwrap_or(KITTI_STEP_FRAMES)),
        };
        Ok(Self {
            drift: DriftOptions {
                segment_lengths_m: segment_lengths_m.unwrap_or_else(|| KITTI_SEGMENT_LENGTHS_M.to_vec()),
                step,
            },
            mpc: MpcOptions { first_path_dynamic_range_db: first_path_range_db },
            overwrite: if force { Overwrite::Replace } else { Overwrite::Refuse },
        })
    }
}

/// What [`analyze`] wrote.
pub enum Analyzed {
    /// One run, written straight into the output.
    Run {
        /// Its results.
        results: Box<RunResults>,
        /// The files written.
        written: WrittenResults,
    },
    /// Several runs, each under `run=<ID>/` and side by side.
    Campaign {
        /// Each run and its results.
        runs: Vec<(RunTables, RunResults)>,
        /// The files written.
        written: WrittenResults,
    },
}

/// Refuses an output directory that is, or contains, the input.
fn check_not_inside(tables: &Path, output: &Path) -> anyhow::Result<()> {
    let (Ok(tables), Ok(output)) = (tables.canonicalize(), output.canonicalize()) else { return Ok(()) };
    if tables.starts_with(&output) {
        bail!("{}: the output directory contains the input tables; choose another output", output.display());
    }
    Ok(())
}

/// Analyzes the table directories `tables` into `output`.
///
/// # Errors
/// An input that is not a directory or lies inside the output, an existing
/// output without overwrite, bad options (before the tables are read), bad
/// tables (naming file, row and column), or a file that cannot be written.
pub fn analyze(tables: &[PathBuf], output: &Path, options: &AnalyzeOptions) -> anyhow::Result<Analyzed> {
    for dir in tables {
        if !dir.is_dir() {
            bail!("{}: not a directory (expected a table directory written by `mmtrack process`)", dir.display());
        }
        check_not_inside(dir, output)?;
    }
    check_output(output, options.overwrite)?;
    // Options are checked by the metric too, but a usage error should not wait for the tables to load.
    crate::trajectory::kitti_drift(&[], &[], &options.drift)
        .map_err(|e| mmtrack_core::error::UsageError(format!("--segment-lengths-m / --step-*: {e}")))?;
    let range_db = options.mpc.first_path_dynamic_range_db;
    if !(range_db.is_finite() && range_db >= 0.0) {
        let message = format!("--first-path-range-db {range_db}: expected a finite, non-negative number of dB");
        return Err(mmtrack_core::error::UsageError(message).into());
    }
    let runs = discover_runs(tables)?;
    // The run's time base: its inputs' (each sequence's tables then carry their own, `RunResults::time_bases`).
    let mut stated = Vec::new();
    for run in &runs {
        stated.extend(crate::pipeline::time_bases(&run.tables)?.into_values());
    }
    // Asked after the analysis, so an input without tables gets its own message first.
    let time_base = || {
        TableTimeBase::pooled(&stated).with_context(|| {
            format!(
                "{}: no input table states its time base (key time_base; tables written by an mmtrack before it); \
                 process the recordings again",
                tables.iter().map(|t| t.display().to_string()).collect::<Vec<_>>().join(", ")
            )
        })
    };
    // The options that shaped the results: the drift's for trajectories,
    // the first path's for MPC tables.
    let config = |tables: serde_json::Value, results: &[&RunResults]| -> anyhow::Result<RunInfo> {
        let mut json = serde_json::Map::new();
        json.insert("command".into(), serde_json::json!("analyze"));
        json.insert("tables".into(), tables);
        if results.iter().any(|r| !r.trajectory.is_empty()) {
            json.extend(options.drift.config_fields());
        }
        if results.iter().any(|r| !r.mpc.is_empty()) {
            json.insert("first_path_range_db".into(), serde_json::json!(range_db));
        }
        json.insert("mmtrack_version".into(), serde_json::json!(env!("CARGO_PKG_VERSION")));
        let config_json = serde_json::Value::Object(json).to_string();
        Ok(RunInfo { config_json, time_base: time_base()?, frame: None })
    };
    // One run: its results straight into the output, as always.
    if let [only] = runs.as_slice()
        && tables.len() == 1
        && only.tables == tables[0]
    {
        let results = analyze_run(&only.tables, &options.drift, &options.mpc)?;
        let run = config(serde_json::json!(only.tables.display().to_string()), &[&results])?;
        let written = write_all_results(output, &results, &options.drift, &run, options.overwrite)?;
        return Ok(Analyzed::Run { results: Box::new(results), written });
    }
    let mut analyzed = Vec::new();
    for run in &runs {
        let results =
            analyze_run(&run.tables, &options.drift, &options.mpc).with_context(|| format!("run {}", run.id))?;
        analyzed.push((run.clone(), results));
    }
    let inputs: serde_json::Map<String, serde_json::Value> =
        runs.iter().map(|r| (r.id.clone(), serde_json::json!(r.tables.display().to_string()))).collect();
    let all: Vec<&RunResults> = analyzed.iter().map(|(_, r)| r).collect();
    let run = config(serde_json::Value::Object(inputs), &all)?;
    let written = write_campaign(output, &analyzed, &options.drift, &run, options.overwrite)?;
    Ok(Analyzed::Campaign { runs: analyzed, written })
}
