//! The experiment file of the Shaham experiment (`data/reproduce/shaham.toml`):
//! the overpass scenario, run counts, and the published numbers with their
//! tolerance.

use std::path::Path;

use mmtrack_sim::beam::overpass::OverpassScenario;
use serde::Deserialize;

use crate::common::load_experiment;

/// The experiment, embedded so it runs from any directory.
pub const EMBEDDED: &str = include_str!("../../../../data/reproduce/shaham.toml");
/// Where the embedded file lives in the repository, for messages.
const EMBEDDED_NAME: &str = "data/reproduce/shaham.toml";

/// The experiment file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// Where the file was read from (`embedded data/reproduce/shaham.toml`
    /// or its path), for messages and the tables' metadata; set by
    /// [`Config::load`].
    #[serde(skip)]
    pub source: String,
    /// Seed of every Monte Carlo realisation.
    pub seed: u64,
    /// Runs per scenario point, full tier.
    pub runs: u64,
    /// Runs per scenario point, smoke tier.
    pub quick_runs: u64,
    /// Blocks simulated per run.
    pub blocks: usize,
    /// Additive angle noise of the angle-state baseline per block, degrees.
    pub angle_sigma_deg: f64,
    /// Relative tolerance on each published number.
    pub tolerance: f64,
    /// The paper's gain of the proposed EKF over the angle-state EKF at
    /// 0 dB, 60 km/h (Fig. 4), percent.
    pub paper_gain_pct: f64,
    /// The overpass link (defaults: the paper's parameters).
    #[serde(default)]
    pub scenario: OverpassScenario,
    /// The published valid-tracking durations.
    pub targets: Vec<Target>,
}

/// A published valid-tracking duration of the proposed EKF.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Target {
    /// Where the paper gives it ("Fig. 2", "Table I").
    pub figure: String,
    /// SNR of the point, dB.
    pub snr_db: f64,
    /// Initial speed of the point, km/h.
    pub speed_kmh: f64,
    /// Valid tracking, blocks.
    pub paper_blocks: u64,
}

/// How many trackers run on each realisation.
pub const TRACKER_COUNT: usize = 4;

/// The trackers, in table order; the targets apply to the first. The last,
/// `open-loop`, is the proposed EKF's predictor without measurement updates
/// (`mmtrack_beam::OpenLoop`): from the channel estimate it extrapolates at
/// constant speed, a baseline of ours that tells what the pilots add.
pub const TRACKERS: [&str; TRACKER_COUNT] = ["pv-ekf", "pv-ekf-paper-table", "angle-ekf", "open-loop"];
/// Index of the angle-state EKF in [`TRACKERS`].
pub const ANGLE_EKF: usize = 2;
/// Index of the open-loop predictor in [`TRACKERS`].
pub const OPEN_LOOP: usize = 3;

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

    /// The distinct (SNR dB, speed km/h) points of the targets, in
    /// first-seen order.
    #[must_use]
    pub fn scenario_points(&self) -> Vec<(f64, f64)> {
        let mut points: Vec<(f64, f64)> = Vec::new();
        for t in &self.targets {
            if !points.contains(&(t.snr_db, t.speed_kmh)) {
                points.push((t.snr_db, t.speed_kmh));
            }
        }
        points
    }
}

/// Half of the half-power beamwidth at the initial AoD, radians: the
/// pointing error at which valid tracking ends.
///
/// # Errors
/// The scenario's array is invalid.
pub fn threshold_rad(scenario: &OverpassScenario) -> anyhow::Result<f64> {
    let array = scenario.array()?;
    Ok(0.5 * array.half_power_beamwidth_rad(scenario.initial_aod_deg.to_radians().abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_experiment_parses_and_has_the_papers_points() {
        let experiment = Config::embedded().unwrap();
        assert_eq!(experiment.source, "embedded data/reproduce/shaham.toml");
        assert_eq!(experiment.runs, 3000);
        assert_eq!(experiment.scenario_points().len(), 6);
        let threshold = threshold_rad(&experiment.scenario).unwrap().to_degrees();
        assert!((threshold - 4.51).abs() < 0.01, "{threshold}");
    }
}
