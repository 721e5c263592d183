//! The sounder's front end: band, pulse spectrum and noise floor (the
//! `sounder` table of a scenario).

use mmtrack_core::Complex64;
use mmtrack_core::sounder::SounderBand;
use serde::Deserialize;

use crate::SimError;
use crate::error::{ensure_non_negative, ensure_positive, ensure_within, invalid};

/// The pulse the sounder sees the channel through, as a spectrum over the
/// band (see [`PulseModel::spectrum`]).
#[derive(Debug, Clone, PartialEq, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum PulseModel {
    /// An ideal flat band, `P[k] = 1`: an on-grid path is exactly one tap.
    #[default]
    Flat,
    /// A measured-like pulse (what a back-to-back cable calibration of a
    /// real sounder shows): raised-cosine band edges plus a small
    /// deterministic amplitude and phase ripple across the band.
    MeasuredLike {
        /// Fraction of the band (at each edge) over which the amplitude
        /// rolls off as a raised cosine to zero at the band edge, `[0, 0.5]`.
        #[serde(default = "default_rolloff")]
        rolloff_fraction: f64,
        /// Peak-to-peak amplitude ripple, dB.
        #[serde(default = "default_ripple_db")]
        ripple_db: f64,
        /// Periods of the amplitude ripple across the band.
        #[serde(default = "default_ripple_cycles")]
        ripple_cycles: f64,
        /// Peak phase ripple, degrees.
        #[serde(default = "default_phase_ripple_deg")]
        phase_ripple_deg: f64,
        /// Periods of the phase ripple across the band.
        #[serde(default = "default_phase_ripple_cycles")]
        phase_ripple_cycles: f64,
    },
}

fn default_rolloff() -> f64 {
    0.1
}
fn default_ripple_db() -> f64 {
    0.5
}
fn default_ripple_cycles() -> f64 {
    3.5
}
fn default_phase_ripple_deg() -> f64 {
    3.0
}
fn default_phase_ripple_cycles() -> f64 {
    2.5
}

impl PulseModel {
    /// The measured-like pulse with its default parameters.
    #[must_use]
    pub fn measured_like() -> Self {
        Self::MeasuredLike {
            rolloff_fraction: default_rolloff(),
            ripple_db: default_ripple_db(),
            ripple_cycles: default_ripple_cycles(),
            phase_ripple_deg: default_phase_ripple_deg(),
            phase_ripple_cycles: default_phase_ripple_cycles(),
        }
    }

    /// Checks the parameters; `prefix` names the table (e.g. `convoy.sounder.pulse`).
    pub fn validate(&self, prefix: &str) -> Result<(), SimError> {
        if let Self::MeasuredLike {
            rolloff_fraction,
            ripple_db,
            ripple_cycles,
            phase_ripple_deg,
            phase_ripple_cycles,
        } = self
        {
            let f = |name: &str| format!("{prefix}.{name}");
            ensure_within(&f("rolloff_fraction"), *rolloff_fraction, 0.0, 0.5, "a fraction in [0, 0.5]")?;
            ensure_within(&f("ripple_db"), *ripple_db, 0.0, 6.0, "a peak-to-peak ripple in [0, 6] dB")?;
            ensure_non_negative(&f("ripple_cycles"), *ripple_cycles)?;
            ensure_within(&f("phase_ripple_deg"), *phase_ripple_deg, 0.0, 90.0, "a phase ripple in [0, 90] deg")?;
            ensure_non_negative(&f("phase_ripple_cycles"), *phase_ripple_cycles)?;
        }
        Ok(())
    }

    /// The pulse spectrum `P[k]`, one value per FFT bin of `band` (FFT order).
    ///
    /// With `x = u / (U - 1)` the band position (`u` as in
    /// [`SounderBand::band_position`], lowest frequency first), the
    /// measured-like pulse is
    ///
    /// `P(x) = e(x) 10^(r sin(2 pi c_a x) / 40) exp(j phi sin(2 pi c_p x + 0.7))`,
    ///
    /// `e(x)` the raised-cosine edge (`(1 - cos(pi x / beta)) / 2` for
    /// `x < beta`, mirrored at the top, 1 between), `r` the peak-to-peak
    /// ripple in dB, `phi` the phase ripple. Both pulses are normalised so
    /// that `(1/U) sum_k P[k] = 1`: a path on a tap's delay then peaks at
    /// exactly its amplitude `alpha` in the CIR, so truth powers read on the
    /// same scale as the taps whatever the pulse.
    #[must_use]
    pub fn spectrum(&self, band: &SounderBand) -> Vec<Complex64> {
        let u_max = (band.taps() - 1) as f64;
        let raw: Vec<Complex64> = (0..band.taps())
            .map(|k| {
                let x = band.band_position(k) as f64 / u_max;
                match self {
                    Self::Flat => Complex64::new(1.0, 0.0),
                    Self::MeasuredLike {
                        rolloff_fraction,
                        ripple_db,
                        ripple_cycles,
                        phase_ripple_deg,
                        phase_ripple_cycles,
                    } => {
                        let edge_x = x.min(1.0 - x);
                        let edge = if edge_x < *rolloff_fraction {
                            0.5 * (1.0 - (std::f64::consts::PI * edge_x / rolloff_fraction).cos())
                        } else {
                            1.0
                        };
                        let tau = std::f64::consts::TAU;
                        let ripple = 10f64.powf(ripple_db * (tau * ripple_cycles * x).sin() / 40.0);
                        let phase = phase_ripple_deg.to_radians() * (tau * phase_ripple_cycles * x + 0.7).sin();
                        Complex64::from_polar(edge * ripple, phase)
                    }
                }
            })
            .collect();
        let mean = raw.iter().sum::<Complex64>() / band.taps() as f64;
        raw.into_iter().map(|p| p / mean).collect()
    }
}

/// The sounder: carrier, band, taps, noise floor and pulse.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SounderConfig {
    /// Carrier frequency, hertz (HHI sounder of the paper: 5.7 GHz).
    pub carrier_hz: f64,
    /// Measurement bandwidth, hertz; the taps are `1 / bandwidth_hz` apart
    /// (1 GHz: 1 ns taps, 30 cm of path).
    pub bandwidth_hz: f64,
    /// Taps per CIR (= frequency bins), `U`.
    pub taps: usize,
    /// Mean noise power per CIR tap, dB (`10 log10 E|n|^2` on the tap
    /// scale); `-inf` (TOML `-inf`) for no noise.
    pub noise_floor_db: f64,
    /// The pulse the channel is seen through.
    pub pulse: PulseModel,
}

impl Default for SounderConfig {
    fn default() -> Self {
        Self { carrier_hz: 5.7e9, bandwidth_hz: 1e9, taps: 256, noise_floor_db: -140.0, pulse: PulseModel::Flat }
    }
}

impl SounderConfig {
    /// Checks every field; `prefix` names the table (e.g. `convoy.sounder`).
    pub fn validate(&self, prefix: &str) -> Result<(), SimError> {
        let f = |name: &str| format!("{prefix}.{name}");
        ensure_positive(&f("carrier_hz"), self.carrier_hz)?;
        ensure_positive(&f("bandwidth_hz"), self.bandwidth_hz)?;
        if !(16..=1 << 20).contains(&self.taps) {
            return Err(invalid(f("taps"), self.taps, "between 16 and 1048576 taps"));
        }
        if self.noise_floor_db.is_nan() || self.noise_floor_db == f64::INFINITY {
            return Err(invalid(
                f("noise_floor_db"),
                self.noise_floor_db,
                "a finite power in dB, or -inf for no noise",
            ));
        }
        self.pulse.validate(&f("pulse"))
    }

    /// The frequency grid (checked by [`Self::validate`]).
    pub fn band(&self) -> Result<SounderBand, SimError> {
        SounderBand::new(self.taps, self.tap_spacing_s())
            .map_err(|_| invalid("sounder.taps", self.taps, "a valid sounder band"))
    }

    /// Delay between taps, seconds: `1 / bandwidth_hz`.
    #[must_use]
    pub fn tap_spacing_s(&self) -> f64 {
        1.0 / self.bandwidth_hz
    }

    /// Standard deviation of each of the real and imaginary noise parts.
    #[must_use]
    pub(crate) fn noise_sigma(&self) -> f64 {
        (10f64.powf(self.noise_floor_db / 10.0) / 2.0).sqrt()
    }
}
