//! Geometric Doppler-bearing tracking of Zoechmann et al. 2019, Sec. VI and
//! Figs. 4-5 (PAPERS.md section 4).
//!
//! A transmitter car overtakes a receiver car whose 60 GHz UCA measures the
//! azimuth of the strongest beam and the Doppler shift every 20 ms
//! (`mmtrack_sim::beam::overtaking`). Four estimators run on the same Monte
//! Carlo realisations (the proposed recursive tracker on its own beam
//! window, the Ho-Chan batch baseline, the error-free and nullspace genies),
//! beside variants and diagnostics of ours; then the proposed tracker on
//! every path of an overtaking between two walls ([`nlos`]). The experiment,
//! its published numbers and tolerances are one TOML file
//! (`data/reproduce/zoechmann.toml`, embedded).
//!
//! Layers: [`config`] (the file) <- [`nlos`] <- `run` (the Monte Carlo) <-
//! `report` (claims, summary, files) <- [`run()`].

pub mod config;
pub mod nlos;
mod report;
mod run;

use std::path::Path;

use mmtrack_core::progress::Progress;

pub use self::config::{Config, NlosConfig};
pub use self::report::README_BLOCK;
pub use self::run::{ESTIMATORS, ManoeuvreResult, Measured};
use crate::common::run_count;
use crate::model::{Outcome, ReadmeBlock, RunOptions};

/// The experiment's name (`mmtrack reproduce zoechmann`).
pub const NAME: &str = "zoechmann";

/// Checks before any work that `output` may be replaced (`force`) and that
/// `readme` holds the block ([`crate::common::check_start`]).
///
/// # Errors
/// See [`crate::common::check_start`].
pub fn check_start(output: &Path, force: bool, readme: Option<&Path>) -> anyhow::Result<()> {
    crate::common::check_start(output, force, readme, README_BLOCK)
}

/// Runs the experiment: the Monte Carlo of every manoeuvre at
/// `options.tier` (the file's `quick_runs` or `runs`, unless
/// `options.runs`, which also sets the NLOS runs), then writes the Parquet
/// tables (NMSE per epoch, summary, NLOS errors and labels), one SVG figure
/// per manoeuvre, `nlos.svg`, `reproduce.md` and `metrics.json` into
/// `options.output_dir`, replacing it whole.
///
/// # Errors
/// Zero runs, an invalid experiment file, a simulator failure, an output
/// that cannot be written. Missed paper targets are verdicts, not errors.
pub fn run(config: &Config, options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    let runs = run_count(options.runs, options.tier, config.quick_runs, config.runs)?;
    let nlos_runs =
        options.runs.unwrap_or(if options.tier.is_smoke() { config.nlos.quick_runs } else { config.nlos.runs });
    let measured = run::measure(config, runs, nlos_runs, progress)?;
    let verdicts = report::verdicts(config, &measured.manoeuvres, runs, measured.elapsed_s);
    let summary = report::summary(config, &measured, &verdicts);
    let metrics = report::metrics(config, &measured.manoeuvres);
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
