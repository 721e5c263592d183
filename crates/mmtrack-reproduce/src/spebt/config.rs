//! What the SPEBT experiment runs: the experiment file
//! (`data/reproduce/spebt.toml`, embedded: the paper's Table I link, the
//! tracker's thresholds, Table III's numbers and the targets; its type is
//! [`mmtrack_process::beam::spebt::monte_carlo::SpebtExperiment`], shared
//! with `process beam --tracker spebt`), the trajectory the vehicle drives
//! and whether experiment (b) runs.

use std::path::{Path, PathBuf};

use mmtrack_process::beam::spebt::monte_carlo::{SPEBT_EXPERIMENT, SpebtExperiment};
use mmtrack_process::simulate::radar::TrajectoryFormat;

use crate::common::{DEFAULT_TRAJECTORY, load_experiment};

/// Where the embedded experiment file lives in the repository, for messages.
const EMBEDDED_NAME: &str = "data/reproduce/spebt.toml";

/// The experiment.
#[derive(Debug, Clone)]
pub struct Config {
    /// Where the experiment file was read from, for messages and the
    /// tables' metadata.
    pub source: String,
    /// The experiment file.
    pub experiment: SpebtExperiment,
    /// The trajectory to drive along (its first `slots` poses, one slot each).
    pub trajectory: PathBuf,
    /// Its format.
    pub trajectory_format: TrajectoryFormat,
    /// Run only experiment (a), the pose-error model (no radar simulation).
    pub skip_odometry: bool,
}

impl Config {
    /// The experiment file at `path` (else the embedded one) along
    /// `trajectory`, both experiments.
    ///
    /// # Errors
    /// The file cannot be read or parsed, naming it.
    pub fn load(path: Option<&Path>, trajectory: PathBuf, trajectory_format: TrajectoryFormat) -> anyhow::Result<Self> {
        let (source, experiment) = load_experiment(path, SPEBT_EXPERIMENT, EMBEDDED_NAME)?;
        Ok(Self { source, experiment, trajectory, trajectory_format, skip_odometry: false })
    }

    /// The embedded experiment along the default trajectory (the Oxford
    /// full-sequence ground truth beside the repository), both experiments.
    ///
    /// # Errors
    /// Only if the embedded file does not parse (a test checks it does).
    pub fn embedded() -> anyhow::Result<Self> {
        Self::load(None, PathBuf::from(DEFAULT_TRAJECTORY), TrajectoryFormat::Oxford)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_experiment_parses_with_table_iii() {
        let config = Config::embedded().unwrap();
        assert_eq!(config.source, "embedded data/reproduce/spebt.toml");
        assert_eq!(config.experiment.slots, 6388);
        assert_eq!(config.experiment.paper.rmse_gain_pct, 1.580);
        assert_eq!(config.experiment.odometry.preset, "fast-cfear");
    }
}
