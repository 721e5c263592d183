//! One paper experiment asked for by name with the options of
//! `mmtrack reproduce <experiment>`: the check before the work, the
//! experiment file, the run and the README block, in the order the CLI and
//! the Python package both need. The front ends only print (or return) the
//! [`Outcome`].

use std::path::PathBuf;

use anyhow::bail;
use mmtrack_core::progress::Progress;
use mmtrack_process::simulate::radar::TrajectoryFormat;

use crate::common::DEFAULT_TRAJECTORY;
use crate::model::{Outcome, RunOptions, Tier};
use crate::{kim, mpc_artificial, mpc_convoy, odometry, readme_block, shaham, spebt, zoechmann};

/// The experiment names, as `mmtrack reproduce <name>` takes them.
pub const EXPERIMENT_NAMES: [&str; 7] =
    [odometry::NAME, mpc_artificial::NAME, mpc_convoy::NAME, shaham::NAME, spebt::NAME, zoechmann::NAME, kim::NAME];

/// The options of one experiment; each applies to the experiments named in
/// its doc, and one given to another experiment is refused by name.
#[derive(Debug, Clone, Default)]
pub struct ExperimentRequest {
    /// Output directory (default `out/reproduce/<name>`).
    pub output_dir: Option<PathBuf>,
    /// Replace a previous run's output directory.
    pub force: bool,
    /// The CI version (smoke tier).
    pub quick: bool,
    /// Monte Carlo runs (all but odometry and mpc-convoy; mpc-artificial: runs per point,
    /// default 20).
    pub runs: Option<u64>,
    /// README whose block the run rewrites (all but odometry).
    pub readme: Option<PathBuf>,
    /// `--experiment`: the experiment file (shaham, spebt, zoechmann, kim).
    pub experiment_file: Option<PathBuf>,
    /// `--scenario`: the drive scenario (odometry).
    pub scenario: Option<PathBuf>,
    /// `--trajectory` (odometry, spebt; default [`DEFAULT_TRAJECTORY`]).
    pub trajectory: Option<PathBuf>,
    /// `--trajectory-format`: `oxford` (default), `tum` or `kitti` (odometry, spebt).
    pub trajectory_format: Option<String>,
    /// `--max-distance-m` (odometry).
    pub max_distance_m: Option<f64>,
    /// `--skip-odometry` (spebt).
    pub skip_odometry: bool,
    /// `--particles` (kim).
    pub particles: Option<usize>,
    /// `--pulse`: `measured-like` (default) or `flat` (mpc-artificial).
    pub pulse: Option<String>,
    /// `--keep-taps-below-threshold` (mpc-artificial).
    pub keep_taps_below_threshold: bool,
}

impl ExperimentRequest {
    /// The flags given, with the experiments each belongs to.
    fn given(&self) -> Vec<(&'static str, &'static [&'static str])> {
        let monte_carlo: &'static [&'static str] =
            &[mpc_artificial::NAME, shaham::NAME, spebt::NAME, zoechmann::NAME, kim::NAME];
        let all_but_odometry: &'static [&'static str] =
            &[mpc_artificial::NAME, mpc_convoy::NAME, shaham::NAME, spebt::NAME, zoechmann::NAME, kim::NAME];
        let flags: [(&'static str, bool, &'static [&'static str]); 11] = [
            ("--runs", self.runs.is_some(), monte_carlo),
            ("--readme", self.readme.is_some(), all_but_odometry),
            ("--experiment", self.experiment_file.is_some(), &[shaham::NAME, spebt::NAME, zoechmann::NAME, kim::NAME]),
            ("--scenario", self.scenario.is_some(), &[odometry::NAME]),
            ("--trajectory", self.trajectory.is_some(), &[odometry::NAME, spebt::NAME]),
            ("--trajectory-format", self.trajectory_format.is_some(), &[odometry::NAME, spebt::NAME]),
            ("--max-distance-m", self.max_distance_m.is_some(), &[odometry::NAME]),
            ("--skip-odometry", self.skip_odometry, &[spebt::NAME]),
            ("--particles", self.particles.is_some(), &[kim::NAME]),
            ("--pulse", self.pulse.is_some(), &[mpc_artificial::NAME]),
            ("--keep-taps-below-threshold", self.keep_taps_below_threshold, &[mpc_artificial::NAME]),
        ];
        flags.into_iter().filter(|(_, given, _)| *given).map(|(flag, _, names)| (flag, names)).collect()
    }

    fn trajectory(&self) -> anyhow::Result<(PathBuf, TrajectoryFormat)> {
        let format = TrajectoryFormat::parse(self.trajectory_format.as_deref().unwrap_or("oxford"))
            .map_err(|e| anyhow::anyhow!("--trajectory-format {e}"))?;
        Ok((self.trajectory.clone().unwrap_or_else(|| PathBuf::from(DEFAULT_TRAJECTORY)), format))
    }
}

/// Runs the experiment `name` as `mmtrack reproduce <name>` does: refuses
/// an existing output (without `force`) and a missing README block before
/// any work, runs on the caller's thread pool, and rewrites the README block
/// when asked. Whether the paper's targets were met is the outcome's
/// ([`Outcome::targets_met`]); the CLI exits 1 when not.
///
/// # Errors
/// An unknown experiment, an option of another experiment, a bad
/// experiment file, and the experiment's own errors.
pub fn run_experiment(name: &str, request: &ExperimentRequest, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    if !EXPERIMENT_NAMES.contains(&name) {
        bail!("unknown experiment '{name}': expected one of {}", EXPERIMENT_NAMES.join(", "));
    }
    if let Some((flag, names)) = request.given().into_iter().find(|(_, names)| !names.contains(&name)) {
        bail!("{flag} is an option of reproduce {} only", names.join(" / "));
    }
    let options = RunOptions {
        tier: if request.quick { Tier::Smoke } else { Tier::Full },
        runs: request.runs,
        output_dir: request.output_dir.clone().unwrap_or_else(|| PathBuf::from(format!("out/reproduce/{name}"))),
        readme: request.readme.clone(),
    };
    let (output, force, readme) = (&options.output_dir, request.force, options.readme.as_deref());
    let experiment = request.experiment_file.as_deref();
    let outcome = match name {
        odometry::NAME => {
            odometry::check_start(output, force, readme)?;
            let (trajectory, format) = request.trajectory()?;
            let mut config = odometry::Config::load(request.scenario.as_deref(), trajectory, format)?;
            config.max_distance_m = request.max_distance_m;
            odometry::run(&config, &options, progress)?
        }
        mpc_artificial::NAME => {
            let runs = request.runs.unwrap_or(mpc_artificial::Config::default().runs);
            if runs == 0 {
                let message = "--runs 0: expected at least 1 (nothing was done)";
                return Err(mmtrack_core::error::UsageError::new(message).into());
            }
            mpc_artificial::check_start(output, force, readme)?;
            let pulse = match request.pulse.as_deref().unwrap_or("measured-like") {
                "measured-like" => mpc_artificial::Pulse::MeasuredLike,
                "flat" => mpc_artificial::Pulse::Flat,
                other => bail!("--pulse '{other}': expected measured-like or flat"),
            };
            let config =
                mpc_artificial::Config { runs, pulse, zero_below_threshold: !request.keep_taps_below_threshold };
            // The runs are the config's; the tier picks smoke or full.
            mpc_artificial::run(&config, &RunOptions { runs: None, ..options.clone() }, progress)?
        }
        mpc_convoy::NAME => {
            mpc_convoy::check_start(output, force, readme)?;
            mpc_convoy::run(&mpc_convoy::Config::embedded()?, &options, progress)?
        }
        shaham::NAME => {
            shaham::check_start(output, force, readme)?;
            shaham::run(&shaham::Config::load(experiment)?, &options, progress)?
        }
        spebt::NAME => {
            spebt::check_start(output, force, readme)?;
            let (trajectory, format) = request.trajectory()?;
            let mut config = spebt::Config::load(experiment, trajectory, format)?;
            config.skip_odometry = request.skip_odometry;
            spebt::run(&config, &options, progress)?
        }
        zoechmann::NAME => {
            zoechmann::check_start(output, force, readme)?;
            zoechmann::run(&zoechmann::Config::load(experiment)?, &options, progress)?
        }
        _ => {
            kim::check_start(output, force, readme)?;
            kim::run(&kim::Config::load(experiment)?, request.particles, &options, progress)?
        }
    };
    if let Some(readme) = &options.readme {
        readme_block::replace_block(readme, outcome.readme.name, &outcome.readme.body)?;
    }
    Ok(outcome)
}
