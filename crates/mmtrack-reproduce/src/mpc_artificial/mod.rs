//! The artificial two-MPC channel of Mahler et al. 2017, Sec. IV-A,
//! Figs. 4-5 (issue #5, PAPERS.md section 2).
//!
//! Two equal-power MPCs approach in delay from 20 to 2.5 ns over a -140 dB
//! noise floor while the MPC power is swept; with and without the Kaiser
//! window, the proposed tracker, the GM-PHD baseline (Table I) and its
//! matched-noise sensitivity variant run on the same detections
//! (details in `run`).
//!
//! Targets (PAPERS.md section 2): mean delay error below 0.03 ns at
//! -116 dB (proposed, Kaiser window); exactly two tracks in every run down
//! to -126 dB (proposed, Kaiser window).
//!
//! Layers: [`config`] <- `run` (the Monte Carlo) <- [`report`] (claims,
//! tables, figures) <- [`run()`].

pub mod config;
pub mod report;
mod run;

use std::path::Path;

use mmtrack_core::progress::Progress;

pub use self::config::{Config, Pulse};
pub use self::report::README_BLOCK;
pub use self::run::Sweep;
use crate::model::{Outcome, ReadmeBlock, RunOptions};

/// The experiment's name (`mmtrack reproduce mpc-artificial`).
pub const NAME: &str = "mpc-artificial";

/// Checks before any work that `output` does not exist unless `force`
/// (then its files are replaced one by one; the directory is not emptied)
/// and that `readme` holds the block.
///
/// # Errors
/// `output` exists without `force`; the README lacks the block.
pub fn check_start(output: &Path, force: bool, readme: Option<&Path>) -> anyhow::Result<()> {
    crate::common::check_start(output, force, readme, README_BLOCK)
}

/// Runs the experiment: the power sweep at `options.tier` (full: -100 to
/// -132 dB, `config.runs` runs per point unless `options.runs`; smoke: 8
/// powers, [`config::SMOKE_RUNS`] runs), then writes `results.csv`,
/// `results_by_separation.csv`, `reproduce.md`, `metrics.json` and three
/// SVG figures into `options.output_dir`. The README block links the
/// figures relative to `options.readme`.
///
/// # Errors
/// Zero runs, a detector or simulator failure, an output that cannot be
/// written. Missed paper targets are verdicts, not errors.
pub fn run(config: &Config, options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    let runs = if options.tier.is_smoke() { config::SMOKE_RUNS } else { options.runs.unwrap_or(config.runs) };
    let sweep = run::measure(config, &config::powers_db(options.tier), runs, progress)?;
    let markdown = report::markdown(&sweep);
    let metrics = report::metrics(&sweep);
    let verdicts = report::verdicts(&sweep);
    let output = &options.output_dir;
    let files = report::write_outputs(output, &sweep, &markdown, &metrics)?;
    let figures = match &options.readme {
        Some(readme) => report::figures_location(readme, output),
        None => report::FiguresAt::Elsewhere(output.clone()),
    };
    Ok(Outcome {
        experiment: NAME,
        metrics,
        verdicts,
        files,
        report: markdown,
        readme: ReadmeBlock { name: README_BLOCK, body: report::readme_summary(&sweep, &figures) },
    })
}
