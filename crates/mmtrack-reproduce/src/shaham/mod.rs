//! Valid beam tracking on the overpass link of Shaham et al. 2020, Sec. IV,
//! Figs. 2-4 and Table I (PAPERS.md section 3).
//!
//! On the simulated overpass link (`mmtrack_sim::beam::overpass`), four
//! trackers run on the same Monte Carlo realisations of each scenario point
//! (SNR 0/5/10 dB at 60 km/h; 50/60/70/80 km/h at 0 dB): the proposed
//! position-velocity EKF (`pv-ekf`, the kinematic process model), the same
//! filter with eq. (14)-(15) as printed (`pv-ekf-paper-table`), the
//! angle-state EKF of Va et al. 2016 (`angle-ekf`), and the proposed EKF's
//! predictor without measurement updates (`open-loop`, a baseline of ours).
//! Per block, the RMS over
//! runs of the transmit beam's pointing error; valid tracking ends at the
//! first block where it exceeds half the beamwidth. The experiment, its
//! published numbers and tolerances are one TOML file
//! (`data/reproduce/shaham.toml`, embedded).
//!
//! Layers: [`config`] (the file) <- [`overpass`] (the trackers on a run) <-
//! `run` (the Monte Carlo) <- `report` (claims, summary, files) <- [`run()`].

pub mod config;
pub mod overpass;
mod report;
mod run;

use std::path::Path;

use mmtrack_core::progress::Progress;

pub use self::config::{Config, TRACKERS, Target};
pub use self::report::README_BLOCK;
pub use self::run::{Measured, PointResult};
use crate::common::run_count;
use crate::model::{Outcome, ReadmeBlock, RunOptions};

/// The experiment's name (`mmtrack reproduce shaham`).
pub const NAME: &str = "shaham";

/// Checks before any work that `output` may be replaced (`force`) and that
/// `readme` holds the block ([`crate::common::check_start`]).
///
/// # Errors
/// See [`crate::common::check_start`].
pub fn check_start(output: &Path, force: bool, readme: Option<&Path>) -> anyhow::Result<()> {
    crate::common::check_start(output, force, readme, README_BLOCK)
}

/// Runs the experiment: the Monte Carlo at `options.tier` (the file's
/// `quick_runs` or `runs` per point, unless `options.runs`), then writes
/// the Parquet tables (RMS error per block, valid tracking), four SVG
/// figures (the paper's Figs. 2-4 and the RMS error against the distance
/// from the overpass), `reproduce.md` (the summary with the figures) and
/// `metrics.json` into `options.output_dir`,
/// replacing it whole.
///
/// # Errors
/// Zero runs, an invalid experiment file, a tracker failure, an output that
/// cannot be written. Missed paper targets are verdicts, not errors.
pub fn run(config: &Config, options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    let runs = run_count(options.runs, options.tier, config.quick_runs, config.runs)?;
    let measured = run::measure(config, runs, progress)?;
    let verdicts = report::verdicts(config, &measured.points);
    let summary = report::summary(config, &measured, &verdicts);
    let metrics = report::metrics(config, &measured.points);
    let files = report::write_outputs(&options.output_dir, config, &measured, &summary, &metrics)?;
    Ok(Outcome {
        experiment: NAME,
        metrics,
        verdicts,
        files,
        report: report::report_markdown(&summary),
        readme: ReadmeBlock { name: README_BLOCK, body: summary },
    })
}
