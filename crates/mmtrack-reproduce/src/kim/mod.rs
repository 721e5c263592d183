//! 5G mmWave vehicular SLAM of Kim et al. 2018, Sec. V (PAPERS.md section 5).
//!
//! On the paper's circular-road world (`mmtrack_sim::slam`), the filter of
//! `mmtrack_slam` runs over Monte Carlo realisations of every row of the
//! experiment (the paper's setting, then the robustness rows); reported
//! per row are the UE, VA and SP errors and the epochs at which all VAs
//! and all SPs are confirmed. The experiment, the paper's numbers and the
//! tolerances are one TOML file (`data/reproduce/kim.toml`, embedded).
//!
//! Layers: [`config`] (the file) <- [`evaluate`] (one run against its
//! truth) <- `run` (the Monte Carlo) <- `report` (claims, summary, files)
//! <- [`run()`].

pub mod config;
pub mod evaluate;
mod report;
mod run;

use std::path::Path;

use mmtrack_core::progress::Progress;

pub use self::config::{Config, Row, Targets};
pub use self::report::README_BLOCK;
pub use self::run::{Measured, RowResult};
use crate::common::run_count;
use crate::model::{Outcome, ReadmeBlock, RunOptions};

/// The experiment's name (`mmtrack reproduce kim`).
pub const NAME: &str = "kim";

/// Checks before any work that `output` may be replaced (`force`) and that
/// `readme` holds the block ([`crate::common::check_start`]).
///
/// # Errors
/// See [`crate::common::check_start`].
pub fn check_start(output: &Path, force: bool, readme: Option<&Path>) -> anyhow::Result<()> {
    crate::common::check_start(output, force, readme, README_BLOCK)
}

/// Runs the experiment: the Monte Carlo of every row at `options.tier`
/// (the file's `quick_runs` with `quick_particles`, or `runs` with the
/// filter's particles; `options.runs` and `particles` replace them), then
/// writes the Parquet tables (summary, per epoch), SVG figures (map,
/// errors, confirmed sources), `reproduce.md` and `metrics.json` into
/// `options.output_dir`, replacing it whole. The smoke tier judges the
/// targets with the file's `quick_tolerance`.
///
/// # Errors
/// Zero runs, an invalid experiment file, a filter failure, an output that
/// cannot be written. Missed paper targets are verdicts, not errors.
pub fn run(
    config: &Config,
    particles: Option<usize>,
    options: &RunOptions,
    progress: &dyn Progress,
) -> anyhow::Result<Outcome> {
    let runs = run_count(options.runs, options.tier, config.quick_runs, config.runs)?;
    anyhow::ensure!(!config.rows.is_empty(), "{}: no [[rows]] (nothing was done)", config.source);
    let filter = config.filter_for(particles, options.tier)?;
    let tolerance = config.tolerance(options.tier);
    let measured = run::measure(config, &filter, runs, progress)?;
    let verdicts = report::verdicts(&config.targets, tolerance, &measured.rows);
    let summary = report::summary(config, &measured, &verdicts, tolerance);
    let metrics = report::metrics(&config.targets, &measured.rows);
    let files = report::write_outputs(&options.output_dir, config, &measured, &summary, &metrics)?;
    Ok(Outcome {
        experiment: NAME,
        metrics,
        verdicts,
        files,
        readme: ReadmeBlock { name: README_BLOCK, body: summary.clone() },
        report: summary,
    })
}
