//! The settings of the artificial-channel experiment (it has no experiment
//! file: its few choices are the CLI's flags) and the fixed geometry of the
//! approach.

use mmtrack_sim::sounder::{ArtificialChannelConfig, PulseModel, SounderConfig};

use crate::model::Tier;

/// The sounder pulse of the artificial channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pulse {
    /// Band edges rolled off and a small ripple, as a pulse measured
    /// through an RF cable (what the paper used).
    MeasuredLike,
    /// An ideal band, whose off-grid paths spread over the whole CIR as a
    /// sinc.
    Flat,
}

impl Pulse {
    /// The simulator's pulse model.
    #[must_use]
    pub fn model(self) -> PulseModel {
        match self {
            Self::MeasuredLike => PulseModel::measured_like(),
            Self::Flat => PulseModel::Flat,
        }
    }

    /// Its name in the report.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::MeasuredLike => "measured-like",
            Self::Flat => "flat",
        }
    }
}

/// What the experiment runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Config {
    /// Monte Carlo runs per point (different noise and phases), full tier
    /// (the smoke tier runs [`SMOKE_RUNS`]).
    pub runs: u64,
    /// The sounder pulse.
    pub pulse: Pulse,
    /// Zero the CIR taps below floor + 6 dB before the search (the paper's
    /// step 1); `false` keeps them, a variant showing what zeroing costs.
    pub zero_below_threshold: bool,
}

impl Default for Config {
    /// The paper's setting, 20 runs per point.
    fn default() -> Self {
        Self { runs: 20, pulse: Pulse::MeasuredLike, zero_below_threshold: true }
    }
}

/// Runs per point of the smoke tier.
pub const SMOKE_RUNS: u64 = 3;

/// The approach: from this separation, ns ...
pub const START_SEPARATION_NS: f64 = 20.0;
/// ... down to this one (the paper compares "up to a distance of 2.5 ns").
pub const END_SEPARATION_NS: f64 = 2.5;
/// Width of the separation bands of `results_by_separation.csv`, ns.
pub const SEPARATION_BAND_NS: f64 = 2.5;
/// Number of bands between the end and the start separation.
pub const SEPARATION_BANDS: usize = 7;
const _: () = assert!(END_SEPARATION_NS + SEPARATION_BAND_NS * SEPARATION_BANDS as f64 == START_SEPARATION_NS);
/// Powers in the separation figure (present in both the smoke and the full sweep).
pub const SEPARATION_PLOT_POWERS_DB: [f64; 5] = [-100.0, -112.0, -116.0, -124.0, -126.0];

/// The MPC powers swept, dB: -100..-132 dB in 2 dB steps; the smoke tier
/// -100..-130 dB in 6 dB steps plus -116 and -126 dB (the targets' powers).
#[must_use]
pub fn powers_db(tier: Tier) -> Vec<f64> {
    match tier {
        Tier::Smoke => vec![-100.0, -106.0, -112.0, -116.0, -118.0, -124.0, -126.0, -130.0],
        Tier::Full => (0..=16).map(|i| -100.0 - 2.0 * f64::from(i)).collect(),
    }
}

/// The artificial channel at one MPC power.
#[must_use]
pub fn channel_config(power_db: f64, pulse: &PulseModel) -> ArtificialChannelConfig {
    ArtificialChannelConfig {
        mpc_power_db: power_db,
        start_separation_s: START_SEPARATION_NS * 1e-9,
        end_separation_s: END_SEPARATION_NS * 1e-9,
        sounder: SounderConfig { pulse: pulse.clone(), ..Default::default() },
        ..ArtificialChannelConfig::default()
    }
}
