//! The experiment file of the Zoechmann experiment
//! (`data/reproduce/zoechmann.toml`): the overtaking scenario and
//! manoeuvres, the proposed tracker's parameters, the published numbers
//! with their tolerances, and the non-line-of-sight run.

use std::path::Path;

use mmtrack_beam::geometric::GeometricTrackerConfig;
use mmtrack_sim::beam::overtaking::{Manoeuvre, OvertakingScenario};
use mmtrack_sim::beam::overtaking_paths::Walls;
use serde::Deserialize;

use crate::common::load_experiment;

/// The experiment, embedded so it runs from any directory.
pub const EMBEDDED: &str = include_str!("../../../../data/reproduce/zoechmann.toml");
/// Where the embedded file lives in the repository, for messages.
const EMBEDDED_NAME: &str = "data/reproduce/zoechmann.toml";

/// The experiment file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// Where the file was read from, for messages and the tables'
    /// metadata; set by [`Config::load`].
    #[serde(skip)]
    pub source: String,
    /// Seed of every Monte Carlo realisation.
    pub seed: u64,
    /// Runs per manoeuvre, full tier.
    pub runs: u64,
    /// Runs per manoeuvre, smoke tier.
    pub quick_runs: u64,
    /// H-infinity level of the proposed tracker.
    pub gamma: f64,
    /// `c` of its initial information `P_0^-1 = c I`.
    pub initial_information: f64,
    /// Distinct azimuths before the hand-over to RLS.
    pub distinct_azimuths_for_rls: usize,
    /// Full scans before the beam window.
    pub full_scan_epochs: usize,
    /// Beams measured around the projected azimuth.
    pub window_beams: usize,
    /// The manoeuvre whose hand-over time is checked.
    pub convergence_manoeuvre: String,
    /// The paper's hand-over time, seconds ...
    pub paper_convergence_s: f64,
    /// ... and the accepted deviation of the median, seconds.
    pub convergence_tolerance_s: f64,
    /// The paper's saving per tracked epoch (128 / 3).
    pub paper_saving: f64,
    /// Relative tolerance on the saving.
    pub saving_tolerance: f64,
    /// The saving counts only where the window holds the strongest beam in
    /// at least this share of its epochs (ours: the paper states no figure;
    /// a window that misses the strongest beam saves measurements of a
    /// link it has lost).
    pub saving_min_window_hit_share: f64,
    /// Wall-time target of the full run, seconds ...
    pub time_target_s: f64,
    /// ... and the runs it applies to.
    pub time_target_runs: u64,
    /// The receiver and the measurement noise.
    #[serde(default)]
    pub scenario: OvertakingScenario,
    /// The manoeuvres, in report order.
    pub manoeuvres: Vec<Manoeuvre>,
    /// The non-line-of-sight run.
    pub nlos: NlosConfig,
}

/// The `[nlos]` table of the experiment file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NlosConfig {
    /// Name of the manoeuvre (one of `[[manoeuvres]]`).
    pub manoeuvre: String,
    /// Runs, full tier.
    pub runs: u64,
    /// Runs, smoke tier.
    pub quick_runs: u64,
    /// The two walls.
    pub walls: Walls,
}

impl Config {
    /// The experiment file at `path`, else the embedded default.
    ///
    /// # Errors
    /// The file cannot be read or parsed, naming it.
    pub fn load(path: Option<&Path>) -> anyhow::Result<Self> {
        let (source, mut config): (String, Self) = load_experiment(path, EMBEDDED, EMBEDDED_NAME)?;
        config.source = source;
        Ok(config)
    }

    /// The embedded default.
    ///
    /// # Errors
    /// Only if the embedded file does not parse (a test checks it does).
    pub fn embedded() -> anyhow::Result<Self> {
        Self::load(None)
    }

    /// The proposed tracker's configuration.
    #[must_use]
    pub fn tracker_config(&self) -> GeometricTrackerConfig {
        GeometricTrackerConfig {
            wavelength_m: self.scenario.wavelength_m(),
            gamma: self.gamma,
            initial_information: self.initial_information,
            distinct_azimuths_for_rls: self.distinct_azimuths_for_rls,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_experiment_parses_and_has_the_papers_manoeuvres() {
        let experiment = Config::embedded().unwrap();
        assert_eq!(experiment.runs, 100_000);
        let names: Vec<&str> = experiment.manoeuvres.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["half-overtaking", "full-overtaking"]);
        assert_eq!(experiment.manoeuvres[0], Manoeuvre::half_overtaking());
        assert_eq!(experiment.manoeuvres[1], Manoeuvre::full_overtaking());
        assert!(experiment.tracker_config().validate().is_ok());
    }
}
