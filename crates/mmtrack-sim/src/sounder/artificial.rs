//! The artificial channel of Mahler et al. 2017, Sec. IV-A (Fig. 3): two
//! MPCs of equal power approaching each other in delay over consecutive
//! snapshots, plus a noise floor.

use mmtrack_core::random::stream;
use mmtrack_core::{CirSnapshot, Complex64, MpcTruth};
use rand::RngExt;
use serde::Deserialize;

use super::pulse::SounderConfig;
use super::render::{RenderPath, SnapshotStamp, render_snapshot};
use crate::SimError;
use crate::error::{ensure_finite, ensure_non_negative, ensure_positive, invalid};

const NOISE_STREAM: u64 = 0x6e6f_6973_6520_6172;

/// The artificial channel (the `[artificial]` table of a sounder scenario).
///
/// Snapshot `i` of `N` is at `t_i = start_t_ns + i * snapshot_interval_s`
/// (continuous, no set gaps). The two MPCs sit at
/// `centre_delay_s -/+ d_i / 2` (relative to tap 0; `delay_s` in the truth
/// and the CIR's `delay_offset_s` is 0), with the separation falling
/// linearly `d_i = d_0 + (d_end - d_0) i / (N - 1)`. Both have power
/// `mpc_power_db` (`20 log10 |alpha|`) and a random (seeded) initial phase;
/// their phase then turns with the carrier as the delay changes,
/// `alpha(t) = |alpha| exp(j (phi_0 - 2 pi f_c (tau(t) - tau(0))))`, so the
/// Doppler `-f_c d tau / dt` recorded in the truth is what the phases do and
/// the two pulses beat (constructive and destructive superposition) as they
/// merge, as in the paper's Fig. 3.
///
/// # References
/// Mahler, Keusgen, Tufvesson, Zemen, Caire 2017, Sec. IV-A and Fig. 3.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ArtificialChannelConfig {
    /// The sounder (defaults: 5.7 GHz, 1 GHz, 256 taps, -140 dB floor, flat pulse).
    pub sounder: SounderConfig,
    /// Power of each of the two MPCs, dB.
    pub mpc_power_db: f64,
    /// Delay separation at the first snapshot, seconds.
    pub start_separation_s: f64,
    /// Delay separation at the last snapshot, seconds.
    pub end_separation_s: f64,
    /// Midpoint of the two delays, seconds after tap 0.
    pub centre_delay_s: f64,
    /// Number of snapshots, `N >= 2`.
    pub snapshots: usize,
    /// Time between snapshots, seconds (the paper's 0.717 ms).
    pub snapshot_interval_s: f64,
    /// Snapshots per set (the set/snapshot indices only: timing stays
    /// continuous); absent = all snapshots form set 0.
    pub snapshots_per_set: Option<u32>,
    /// Time of the first snapshot, nanoseconds since the UNIX epoch
    /// (default [`crate::DEFAULT_START_T_NS`]).
    pub start_t_ns: i64,
}

impl Default for ArtificialChannelConfig {
    fn default() -> Self {
        Self {
            sounder: SounderConfig::default(),
            mpc_power_db: -116.0,
            start_separation_s: 20e-9,
            end_separation_s: 0.0,
            centre_delay_s: 100e-9,
            snapshots: 100,
            snapshot_interval_s: 0.717e-3,
            snapshots_per_set: None,
            start_t_ns: crate::DEFAULT_START_T_NS,
        }
    }
}

impl ArtificialChannelConfig {
    /// Checks every field (names in errors start with `artificial.`).
    pub fn validate(&self) -> Result<(), SimError> {
        self.sounder.validate("artificial.sounder")?;
        ensure_finite("artificial.mpc_power_db", self.mpc_power_db)?;
        ensure_non_negative("artificial.start_separation_s", self.start_separation_s)?;
        ensure_non_negative("artificial.end_separation_s", self.end_separation_s)?;
        ensure_positive("artificial.snapshot_interval_s", self.snapshot_interval_s)?;
        let limit = mmtrack_core::limits::SNAPSHOTS_IN_MEMORY;
        if self.snapshots < 2 || !limit.allows_count(self.snapshots as u64) {
            return Err(invalid("artificial.snapshots", self.snapshots, limit.expected));
        }
        if self.snapshots_per_set == Some(0) {
            return Err(invalid("artificial.snapshots_per_set", 0, "at least 1 snapshot per set"));
        }
        let window_s = self.sounder.taps as f64 * self.sounder.tap_spacing_s();
        let reach = 0.5 * self.start_separation_s.max(self.end_separation_s);
        if !(self.centre_delay_s.is_finite()
            && self.centre_delay_s - reach >= 0.0
            && self.centre_delay_s + reach < window_s)
        {
            return Err(invalid(
                "artificial.centre_delay_s",
                self.centre_delay_s,
                "a delay keeping both MPCs inside the CIR window [0, taps / bandwidth)",
            ));
        }
        let step_ns = (self.snapshot_interval_s * 1e9).round();
        if step_ns < 1.0 || (self.snapshots as f64 * step_ns) > 1e17 {
            return Err(invalid("artificial.snapshot_interval_s", self.snapshot_interval_s, "at least 1 ns"));
        }
        Ok(())
    }
}

/// The artificial channel's snapshots and truth (two [`MpcTruth`] per
/// snapshot, `path_id` 0 for the earlier MPC, 1 for the later). A cheap pure
/// function of `(config, seed)`: the Monte Carlo sweeps of
/// `reproduce mpc-artificial` call it once per power, separation and run.
pub fn artificial_channel(
    config: &ArtificialChannelConfig,
    seed: u64,
) -> Result<(Vec<CirSnapshot>, Vec<MpcTruth>), SimError> {
    config.validate()?;
    let band = config.sounder.band()?;
    let pulse = config.sounder.pulse.spectrum(&band);
    let sigma = config.sounder.noise_sigma();
    let magnitude = 10f64.powf(config.mpc_power_db / 20.0);
    let mut rng = stream(seed, &[0x6172_7469]);
    let phases: [f64; 2] = [rng.random::<f64>() * std::f64::consts::TAU, rng.random::<f64>() * std::f64::consts::TAU];
    let n = config.snapshots;
    let step_ns = (config.snapshot_interval_s * 1e9).round() as i64;
    let dt_s = step_ns as f64 * 1e-9;
    // d(separation)/dt: each MPC moves at half of it, in opposite directions.
    let rate = (config.end_separation_s - config.start_separation_s) / ((n - 1) as f64 * dt_s);
    let delay = |i: usize, which: usize| {
        let separation = config.start_separation_s
            + (config.end_separation_s - config.start_separation_s) * i as f64 / (n - 1) as f64;
        if which == 0 { config.centre_delay_s - 0.5 * separation } else { config.centre_delay_s + 0.5 * separation }
    };
    let fc = config.sounder.carrier_hz;
    let mut snapshots = Vec::with_capacity(n);
    let mut truth = Vec::with_capacity(2 * n);
    for i in 0..n {
        let (set_index, snapshot_index) = match config.snapshots_per_set {
            Some(per_set) => ((i / per_set as usize) as u64, (i % per_set as usize) as u32),
            None => (0, i as u32),
        };
        let t_ns = config.start_t_ns + i as i64 * step_ns;
        let mut paths = [RenderPath { relative_delay_s: 0.0, amplitude: Complex64::default() }; 2];
        for (which, path) in paths.iter_mut().enumerate() {
            let tau = delay(i, which);
            let phase = phases[which] - std::f64::consts::TAU * fc * (tau - delay(0, which));
            let amplitude = Complex64::from_polar(magnitude, phase);
            *path = RenderPath { relative_delay_s: tau, amplitude };
            let tau_rate = if which == 0 { -0.5 * rate } else { 0.5 * rate };
            truth.push(MpcTruth {
                t_ns,
                set_index,
                snapshot_index,
                path_id: which as u64,
                delay_s: tau,
                amplitude,
                doppler_hz: -fc * tau_rate,
            });
        }
        let stamp = SnapshotStamp { t_ns, set_index, snapshot_index, carrier_hz: fc, delay_offset_s: 0.0 };
        snapshots.push(render_snapshot(&band, &pulse, &paths, sigma, [seed, NOISE_STREAM], stamp));
    }
    Ok((snapshots, truth))
}
