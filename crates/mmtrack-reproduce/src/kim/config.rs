//! The experiment file of the Kim experiment (`data/reproduce/kim.toml`):
//! the world, the filter, the rows of the table and the paper's numbers
//! with their tolerance.

use std::path::Path;

use anyhow::Context;
use mmtrack_sim::slam::SlamScenario;
use mmtrack_slam::SlamConfig;
use serde::Deserialize;

use crate::common::load_experiment;
use crate::model::Tier;

/// The experiment, embedded so it runs from any directory.
pub const EMBEDDED: &str = include_str!("../../../../data/reproduce/kim.toml");
/// Where the embedded file lives in the repository, for messages.
const EMBEDDED_NAME: &str = "data/reproduce/kim.toml";

/// The experiment file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// Where the file was read from, for messages and the tables'
    /// metadata; set by [`Config::load`].
    #[serde(skip)]
    pub source: String,
    /// Seed of every world, trajectory, measurement and filter.
    pub seed: u64,
    /// Runs per row, full tier.
    pub runs: u64,
    /// Runs per row, smoke tier.
    pub quick_runs: u64,
    /// UE particles, smoke tier (the full tier takes the filter's).
    pub quick_particles: usize,
    /// A confirmed source counts as a true one within this distance, m.
    pub match_radius_m: f64,
    /// Epochs a true SP's path must be detected in before it counts
    /// towards "all SPs confirmed".
    pub sp_min_detections: usize,
    /// The world (defaults: the paper's).
    #[serde(default)]
    pub scenario: SlamScenario,
    /// The filter (defaults: the paper's).
    #[serde(default)]
    pub filter: SlamConfig,
    /// The rows of the table.
    pub rows: Vec<Row>,
    /// The paper's numbers.
    pub targets: Targets,
}

/// One scenario variant.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Row {
    /// Its name in the tables ("paper", "pd-0.9").
    pub name: String,
    /// Probability that a path is detected.
    pub detection_probability: f64,
    /// Clutter paths per epoch.
    pub clutter_per_epoch: usize,
    /// Whether the paper's numbers ([`Targets`]) are judged on this row.
    #[serde(default)]
    pub paper_targets: bool,
    /// Whether the row is a variant of ours: its claims are reported, not
    /// targets.
    #[serde(default)]
    pub variant: bool,
    /// `ue_error_floor` of the filter (ours, not in the paper); `None`
    /// keeps the `[filter]` table's.
    #[serde(default)]
    pub ue_error_floor: Option<bool>,
    /// The LOS-only baseline: no source is ever confirmed (a source needs
    /// more sightings than the run has epochs), so only the LOS path
    /// updates the UE, and an epoch without it only predicts.
    #[serde(default)]
    pub los_only: bool,
    /// First and last epoch (1-based, inclusive) in which the LOS path is
    /// blocked (ours: the paper's LOS is always present).
    #[serde(default)]
    pub los_blocked_epochs: Option<[usize; 2]>,
    /// Name of the LOS-only row on the same world that this row must beat
    /// (UE position error over the blocked epochs, or over the whole run).
    #[serde(default)]
    pub baseline: Option<String>,
}

impl Row {
    /// The scenario of this row: `base` with its detection, clutter and
    /// blocked LOS.
    #[must_use]
    pub fn scenario(&self, base: &SlamScenario) -> SlamScenario {
        SlamScenario {
            detection_probability: self.detection_probability,
            clutter_per_epoch: self.clutter_per_epoch,
            los_blocked_epochs: self.los_blocked_epochs,
            ..base.clone()
        }
    }

    /// The filter of this row: `base` assuming the row's detection
    /// probability (0.99 for P_D = 1, eq. (3)), with its `ue_error_floor`,
    /// and for the LOS-only baseline a confirmation that never happens in
    /// `epochs`.
    #[must_use]
    pub fn filter(&self, base: &SlamConfig, epochs: usize) -> SlamConfig {
        SlamConfig {
            detection_probability: self.detection_probability.min(base.detection_probability),
            ue_error_floor: self.ue_error_floor.unwrap_or(base.ue_error_floor),
            confirm_min_sightings: if self.los_only { epochs + 1 } else { base.confirm_min_sightings },
            ..base.clone()
        }
    }
}

/// The paper's numbers.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Targets {
    /// Mean UE position error, m.
    pub ue_position_m: f64,
    /// Mean UE heading error, rad.
    pub ue_heading_rad: f64,
    /// Mean UE clock-bias error, m.
    pub ue_clock_bias_m: f64,
    /// Mean VA localisation error, m.
    pub va_m: f64,
    /// Mean SP localisation error, m.
    pub sp_m: f64,
    /// Epoch by which all VAs are confirmed.
    pub all_va_epoch: u64,
    /// Epoch by which all SPs are confirmed.
    pub all_sp_epoch: u64,
    /// False sources at any epoch ("All unconfirmed sources are detected
    /// correctly").
    pub false_sources: f64,
    /// A target is met at most at `paper * (1 + tolerance)`, full tier ...
    pub tolerance: f64,
    /// ... and smoke tier.
    pub quick_tolerance: f64,
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

    /// The filter a run uses: `particles` when given, else the tier's
    /// count, with the scenario's base station.
    ///
    /// # Errors
    /// An invalid filter or scenario, naming the file.
    pub fn filter_for(&self, particles: Option<usize>, tier: Tier) -> anyhow::Result<SlamConfig> {
        let mut filter = self.filter.clone();
        if let Some(p) = particles {
            // The flag's fault, not the experiment file's (exit 2, as `process slam --particles`).
            mmtrack_core::limits::PARTICLES.check_flag("--particles", p as u64, 2)?;
            filter.particles = p;
        } else if tier.is_smoke() {
            filter.particles = self.quick_particles;
        }
        filter.bs_m = self.scenario.bs_m;
        filter.validate().with_context(|| format!("{}: [filter]", self.source))?;
        self.scenario.validate().with_context(|| format!("{}: [scenario]", self.source))?;
        for row in &self.rows {
            if let Some(name) = &row.baseline {
                let baseline = self.rows.iter().find(|r| &r.name == name);
                anyhow::ensure!(
                    baseline.is_some_and(|b| b.los_only && b.los_blocked_epochs == row.los_blocked_epochs),
                    "{}: row {}: baseline `{name}`; expected the name of a los_only row with the same \
                     los_blocked_epochs",
                    self.source,
                    row.name
                );
            }
        }
        Ok(filter)
    }

    /// The relative tolerance of the targets at `tier`.
    #[must_use]
    pub fn tolerance(&self, tier: Tier) -> f64 {
        if tier.is_smoke() { self.targets.quick_tolerance } else { self.targets.tolerance }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_experiment_parses_with_the_papers_targets() {
        let experiment = Config::embedded().unwrap();
        assert!(experiment.runs >= 20);
        // The paper row is judged without our ue_error_floor, with its LOS-only baseline.
        let paper = experiment.rows.iter().find(|r| r.paper_targets && !r.variant).unwrap();
        assert_eq!(paper.ue_error_floor, Some(false));
        let baseline = experiment.rows.iter().find(|r| Some(&r.name) == paper.baseline.as_ref()).unwrap();
        assert!(baseline.los_only && baseline.los_blocked_epochs.is_none());
        let blocked = experiment.rows.iter().find(|r| r.los_blocked_epochs.is_some() && !r.los_only).unwrap();
        assert!(blocked.baseline.is_some() && !blocked.variant);
        experiment.filter_for(None, Tier::Full).unwrap();
        assert_eq!(experiment.targets.all_va_epoch, 26);
        assert_eq!(experiment.targets.all_sp_epoch, 91);
        assert_eq!(experiment.filter, SlamConfig::default());
        assert_eq!(experiment.scenario.epochs, 100);
    }
}
