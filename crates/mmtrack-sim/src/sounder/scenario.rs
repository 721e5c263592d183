//! The sounder scenario file (TOML, through serde; unknown keys are errors).
//! Exactly one of `[artificial]` and `[convoy]`:
//!
//! ```toml
//! seed = 5
//!
//! [convoy]                  # every key optional: the paper's set-up (see ConvoyConfig)
//! sets = 1666
//! [convoy.sounder]
//! taps = 512
//! [convoy.sounder.pulse]
//! kind = "measured_like"
//! [convoy.road]
//! kind = "tunnel"
//! radius_m = 600.0
//! ```
//!
//! or
//!
//! ```toml
//! seed = 5
//! [artificial]              # every key optional (see ArtificialChannelConfig)
//! mpc_power_db = -116.0
//! ```

use serde::Deserialize;

use super::artificial::ArtificialChannelConfig;
use super::convoy::ConvoyConfig;
use crate::SimError;
use crate::error::invalid;

/// A channel-sounder scenario: a seed and one channel.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SounderScenario {
    /// Seed of every random draw (phases, noise, traffic, scatterers).
    pub seed: u64,
    /// The paper's artificial two-MPC channel.
    #[serde(default)]
    pub artificial: Option<ArtificialChannelConfig>,
    /// The two-car convoy through a tunnel or on a highway.
    #[serde(default)]
    pub convoy: Option<ConvoyConfig>,
}

impl SounderScenario {
    /// Checks that exactly one channel is given and that it is valid.
    pub fn validate(&self) -> Result<(), SimError> {
        match (&self.artificial, &self.convoy) {
            (Some(a), None) => a.validate(),
            (None, Some(c)) => c.validate(),
            (Some(_), Some(_)) => Err(invalid("artificial", "both [artificial] and [convoy]", "exactly one of them")),
            (None, None) => Err(invalid("convoy", "neither [artificial] nor [convoy]", "exactly one of them")),
        }
    }
}
