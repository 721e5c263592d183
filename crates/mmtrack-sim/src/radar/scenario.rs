//! The scenario file (TOML, through serde; unknown keys are errors):
//!
//! ```toml
//! seed = 7
//! start_t_ns = 1_700_000_000_000_000_000   # time of the start, UNIX ns (default: mmtrack_sim::DEFAULT_START_T_NS)
//! max_scans = 12                           # optional cut
//! max_distance_m = 500.0                   # optional cut
//!
//! [sensor]          # every key optional: Navtech CTS350-X defaults (see Sensor)
//! bins = 900
//!
//! [motion]          # constant turn; the CLI's --trajectory replaces it
//! speed_mps = 8.0
//! yaw_rate_radps = 0.05
//! duration_s = 4.0
//!
//! [generator]       # optional: a procedural street scene along the trajectory
//! street_half_width_m = [7.0, 10.0]
//!
//! [[reflectors]]    # optional explicit reflectors (see ReflectorSpec)
//! kind = "pole"
//! x_m = 12.0
//! y_m = 5.0
//! ```

use mmtrack_core::{PolarScan, StampedPose};
use serde::Deserialize;

use super::generator::{GeneratorConfig, generate_world};
use super::trajectory::{ConstantTurn, ScanLimits, Trajectory};
use super::{RadarSimulator, ReflectorSpec, Sensor, SimOptions, World};
use crate::SimError;
use crate::error::ensure_positive;

/// Constant-turn motion of a scenario.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Motion {
    /// Forward speed, metres per second.
    pub speed_mps: f64,
    /// Yaw rate, radians per second, counter-clockwise positive.
    pub yaw_rate_radps: f64,
    /// Length of the drive, seconds.
    pub duration_s: f64,
}

fn default_start_t_ns() -> i64 {
    crate::DEFAULT_START_T_NS
}

/// A radar scenario: sensor, scene, motion, cuts and seed.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Seed of every random draw (scene generation, noise, speckle).
    pub seed: u64,
    /// Time of the start of the constant-turn motion, nanoseconds since the
    /// UNIX epoch (default [`crate::DEFAULT_START_T_NS`]).
    #[serde(default = "default_start_t_ns")]
    pub start_t_ns: i64,
    /// Render at most this many sweeps.
    #[serde(default)]
    pub max_scans: Option<usize>,
    /// Stop before the first sweep that starts farther along the path, metres.
    #[serde(default)]
    pub max_distance_m: Option<f64>,
    /// The sensor.
    #[serde(default)]
    pub sensor: Sensor,
    /// Constant-turn motion (not needed when the caller brings a trajectory).
    #[serde(default)]
    pub motion: Option<Motion>,
    /// Procedural scene along the trajectory.
    #[serde(default)]
    pub generator: Option<GeneratorConfig>,
    /// Explicit reflectors, added to the generated ones.
    #[serde(default)]
    pub reflectors: Vec<ReflectorSpec>,
}

impl Scenario {
    /// Checks everything that can be checked without a trajectory.
    pub fn validate(&self) -> Result<(), SimError> {
        self.sensor.validate()?;
        if let Some(m) = &self.motion {
            Trajectory::constant_turn(
                ConstantTurn { speed_mps: m.speed_mps, yaw_rate_radps: m.yaw_rate_radps },
                0,
                m.duration_s,
            )?;
        }
        if let Some(g) = &self.generator {
            g.validate()?;
        }
        if let Some(d) = self.max_distance_m {
            ensure_positive("max_distance_m", d)?;
        }
        World::new(&self.reflectors).map(|_| ())
    }

    /// The scenario's own constant-turn trajectory.
    pub fn motion_trajectory(&self) -> Result<Trajectory, SimError> {
        let m = self.motion.ok_or_else(|| SimError::TrajectoryTooShort {
            detail: "the scenario has no [motion] table and no trajectory was given".into(),
        })?;
        let turn = ConstantTurn { speed_mps: m.speed_mps, yaw_rate_radps: m.yaw_rate_radps };
        Trajectory::constant_turn(turn, self.start_t_ns, m.duration_s)
    }

    /// The world for `trajectory`: generated scene (if any) plus the explicit reflectors.
    pub fn build_world(&self, trajectory: &Trajectory) -> Result<World, SimError> {
        let mut reflectors = match &self.generator {
            Some(config) => generate_world(config, trajectory, self.seed)?,
            None => Vec::new(),
        };
        reflectors.extend(self.reflectors.iter().cloned());
        World::new(&reflectors)
    }

    /// Run options from the scenario (seed and cuts).
    #[must_use]
    pub fn options(&self) -> SimOptions {
        SimOptions {
            seed: self.seed,
            limits: ScanLimits { max_scans: self.max_scans, max_distance_m: self.max_distance_m },
        }
    }
}

/// Renders a whole scenario on its own motion into memory: for small
/// fixtures and tests. Long drives should iterate a [`RadarSimulator`].
pub fn simulate_scenario(scenario: &Scenario) -> Result<(Vec<PolarScan>, Vec<StampedPose>), SimError> {
    scenario.validate()?;
    let trajectory = scenario.motion_trajectory()?;
    let world = scenario.build_world(&trajectory)?;
    Ok(RadarSimulator::new(&world, &scenario.sensor, &trajectory, scenario.options())?.unzip())
}
