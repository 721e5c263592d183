//! SPEBT beam tracking driven by pose estimates, Liu et al. 2024, Sec. IV,
//! Table III and Fig. 5 (PAPERS.md section 1).
//!
//! The vehicle drives a real trajectory (default: the first 6388 poses of
//! the Oxford full-sequence ground truth, one slot per pose) past a base
//! station; the SPEBT EKF (`mmtrack_beam::spebt`) tracks `[|alpha|, AoD,
//! AoA]` from pose estimates that are the truth plus the paper's pose-error
//! model (`mmtrack_sim::beam::spebt_link`), one pilot per slot, and
//! re-initialises from initial access (the true channel) when its estimate
//! leaves the thresholds around the last initial access. Reported: RMSE of
//! `|alpha|` (%), AoD and AoA (deg), re-initialisations per run, against
//! Table III. That is experiment (a), `pose-error-model`; experiment (b),
//! `radar-odometry`, drives the tracker with our own radar odometry on
//! scans simulated along the same trajectory ([`drive`]), as the paper's
//! pipeline does. The experiment, its published numbers and targets are one
//! TOML file (`data/reproduce/spebt.toml`, embedded).
//!
//! Layers: [`config`] (the file, the trajectory) <- [`drive`] (experiment
//! (b)'s odometry) <- `run` (the Monte Carlo) <- `report` (claims, summary,
//! files) <- [`run()`].

pub mod config;
pub mod drive;
mod report;
mod run;

use std::path::Path;

use mmtrack_core::progress::Progress;

pub use self::config::Config;
pub use self::report::README_BLOCK;
pub use self::run::{ExperimentRun, Measured};
use crate::model::{Outcome, ReadmeBlock, RunOptions};

/// The experiment's name (`mmtrack reproduce spebt`).
pub const NAME: &str = "spebt";

/// Checks before any work that `output` may be replaced (`force`) and that
/// `readme` holds the block ([`crate::common::check_start`]).
///
/// # Errors
/// See [`crate::common::check_start`].
pub fn check_start(output: &Path, force: bool, readme: Option<&Path>) -> anyhow::Result<()> {
    crate::common::check_start(output, force, readme, README_BLOCK)
}

/// Runs the experiment: (a) and, unless [`Config::skip_odometry`], (b) at
/// `options.tier` (the file's `quick_runs` or `runs` of each, unless
/// `options.runs`; (b) on the first `quick_slots` slots at the smoke
/// tier), then writes the Parquet tables (summary, per slot), the Fig.
/// 5-style figures, `reproduce.md` and `metrics.json` into
/// `options.output_dir`, replacing it whole. The verdicts are (a)'s
/// (RMSE AoD and AoA after and before re-initialisation, re-initialisation
/// share), then (b)'s, then (a)'s at the `[sensitivity]` pilot powers as
/// variants (not targets).
///
/// # Errors
/// Zero runs, a missing or bad trajectory, a tracker or odometry failure,
/// an output that cannot be written. Missed paper targets are verdicts, not
/// errors.
pub fn run(config: &Config, options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    let measured = run::measure(config, options.tier, options.runs, progress)?;
    let per_experiment: Vec<_> =
        measured.experiments.iter().map(|e| report::verdicts(&config.experiment, &e.result)).collect();
    let summary = report::summary(config, &measured, &per_experiment);
    let metrics = report::all_metrics(config, &measured);
    let files = report::write_outputs(&options.output_dir, config, &measured, &summary, &metrics)?;
    Ok(Outcome {
        experiment: NAME,
        metrics,
        // Named by experiment here, where they stand side by side
        // (`reproduce --all`); the report's per-experiment tables keep the
        // bare names.
        verdicts: measured
            .experiments
            .iter()
            .zip(per_experiment)
            .flat_map(|(e, verdicts)| {
                verdicts.into_iter().map(move |mut v| {
                    v.claim.what = format!("{} ({})", v.claim.what, e.name);
                    v
                })
            })
            .chain(report::variant_verdicts(&config.experiment, &measured))
            .collect(),
        files,
        readme: ReadmeBlock { name: README_BLOCK, body: summary.clone() },
        report: summary,
    })
}
