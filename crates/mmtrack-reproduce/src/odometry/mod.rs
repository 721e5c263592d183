//! Radar odometry drift on a simulated drive along a real trajectory,
//! Liu et al. 2024, Sec. V (PAPERS.md section 1).
//!
//! Oxford-size Navtech scans (400 x 3768) are rendered along the trajectory
//! through a generated street scene (`data/reproduce/odometry-drive.toml`,
//! embedded), the `fast-cfear` and `cfear` presets of `mmtrack_odometry` run
//! on the same scans, and KITTI drift is computed exactly as the devkit does
//! (segments of 100..800 m, a first frame every 10 frames) against the
//! simulator's ground truth. Targets: `fast-cfear` below the paper's
//! 6.56 %; `cfear` at most 1.5 % and 0.5 deg/100 m. The smoke tier drives
//! 300 m with segments of 100 and 200 m.
//!
//! Layers: [`config`] (the scenario, trajectory and targets) <- `run` (the
//! drive) <- `report` (claims, report, files) <- [`run()`].

pub mod config;
mod report;
mod run;

use std::path::Path;

use mmtrack_core::progress::Progress;

pub use self::config::{Config, DRIVE_SCENARIO, Drift, PRESETS, TARGETS, Target};
pub use self::report::README_BLOCK;
pub use self::run::{Measured, PresetResult};
use crate::model::{Outcome, ReadmeBlock, RunOptions};

/// The experiment's name (`mmtrack reproduce odometry`).
pub const NAME: &str = "odometry";

/// Checks before any work that `output` may be replaced (`force`) and that
/// `readme` holds the block ([`crate::common::check_start`]).
///
/// # Errors
/// See [`crate::common::check_start`].
pub fn check_start(output: &Path, force: bool, readme: Option<&Path>) -> anyhow::Result<()> {
    crate::common::check_start(output, force, readme, README_BLOCK)
}

/// Runs the experiment: the drive at `options.tier`, then writes the
/// odometry tables of both presets, the analysis (tables, plots, report),
/// `reproduce.md` and `metrics.json` into `options.output_dir`, replacing
/// it whole. The drive runs once (it is deterministic): `options.runs`
/// must be `None`.
///
/// # Errors
/// `options.runs` given, a missing trajectory, a simulation or odometry
/// failure, an output that cannot be written. Missed paper targets are
/// verdicts, not errors.
pub fn run(config: &Config, options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    anyhow::ensure!(options.runs.is_none(), "the odometry experiment runs once; it takes no run count");
    let measured = run::measure(config, options.tier, progress)?;
    let verdicts = report::verdicts(&measured.presets);
    let metrics = report::metrics(&measured.presets);
    let report = report::report(config, options.tier, &measured, &verdicts);
    let files = report::write_outputs(&options.output_dir, config, measured, &report, &metrics)?;
    Ok(Outcome {
        experiment: NAME,
        metrics,
        verdicts,
        files,
        readme: ReadmeBlock { name: README_BLOCK, body: report.clone() },
        report,
    })
}
