//! The sensor model: geometry, beam, receiver noise and the 8-bit log
//! compression, with defaults calibrated on real Navtech CTS350-X scans (see
//! the [module docs](super) for the numbers).

use mmtrack_core::random::{gamma, standard_normal};
use rand::SeedableRng;
use rand_pcg::Pcg64;
use serde::Deserialize;

use crate::SimError;
use crate::error::{ensure_non_negative, ensure_positive, ensure_within, invalid};

/// Sensor parameters. Every field has a Navtech CTS350-X-like default, so a
/// scenario's `[sensor]` table may be empty.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Sensor {
    /// Azimuth rows per sweep (CTS350-X: 400).
    pub azimuths: usize,
    /// Range bins per row (CTS350-X as in Oxford Radar RobotCar: 3768).
    pub bins: usize,
    /// Range bin size, metres (Oxford SDK: 0.0432).
    pub range_resolution_m: f64,
    /// Sweep period, seconds (4 Hz: 0.25).
    pub sweep_period_s: f64,
    /// One-way -3 dB azimuth beam width, degrees (two-way -6 dB); point
    /// targets spread over the neighbouring rows with this Gaussian pattern.
    pub beam_width_deg: f64,
    /// One-sigma width of a return's Gaussian range profile (power), bins.
    pub range_profile_sigma_bins: f64,
    /// Mean receiver noise power far from the sensor, dB (of the linear power
    /// unit in which `counts = counts_per_ln_amplitude * ln(amplitude)`).
    pub noise_power_db: f64,
    /// Shape `nu` of the gamma texture of the noise floor (K-distributed
    /// clutter; smaller is spikier, large tends to pure Rayleigh noise).
    pub noise_texture_shape: f64,
    /// Extra floor near the sensor from ground and diffuse clutter, dB (its
    /// level below `ground_clutter_range_m`).
    pub ground_clutter_db: f64,
    /// Range where the ground-clutter floor has fallen to half its excess, metres.
    pub ground_clutter_range_m: f64,
    /// Log compression: `counts = round(k ln(n))` for an integer amplitude `n`
    /// (measured: k = 8.56, about 0.99 counts per dB of power).
    pub counts_per_ln_amplitude: f64,
    /// Share of a return's speckle that stays from sweep to sweep for a static
    /// scene (complex-amplitude weight): 0 = fresh every sweep, 1 = frozen.
    pub speckle_static_fraction: f64,
    /// Render multipath ghosts (the beam mirrored once by a building front).
    pub multipath_ghosts: bool,
    /// Loss of a multipath ghost relative to a direct return at the same
    /// path length, dB.
    pub multipath_loss_db: f64,
}

impl Default for Sensor {
    fn default() -> Self {
        Self {
            azimuths: 400,
            bins: 3768,
            range_resolution_m: 0.0432,
            sweep_period_s: 0.25,
            beam_width_deg: 1.8,
            range_profile_sigma_bins: 2.7,
            noise_power_db: 10.8,
            noise_texture_shape: 0.3,
            ground_clutter_db: 6.0,
            ground_clutter_range_m: 60.0,
            counts_per_ln_amplitude: 8.56,
            speckle_static_fraction: 0.7,
            multipath_ghosts: true,
            multipath_loss_db: 12.0,
        }
    }
}

impl Sensor {
    /// Checks every field; the error names the field (`sensor.<name>`).
    pub fn validate(&self) -> Result<(), SimError> {
        if self.azimuths == 0 {
            return Err(invalid("sensor.azimuths", 0, "at least 1 azimuth per sweep"));
        }
        if self.bins == 0 {
            return Err(invalid("sensor.bins", 0, "at least 1 range bin"));
        }
        let pixels = mmtrack_core::limits::SCAN_PIXELS;
        if !pixels.allows(self.azimuths as f64 * self.bins as f64) {
            return Err(invalid("sensor.bins", self.bins, pixels.expected));
        }
        ensure_positive("sensor.range_resolution_m", self.range_resolution_m)?;
        ensure_positive("sensor.sweep_period_s", self.sweep_period_s)?;
        if (self.sweep_period_s * 1e9) < self.azimuths as f64 {
            return Err(invalid("sensor.sweep_period_s", self.sweep_period_s, "at least 1 ns per azimuth"));
        }
        ensure_within("sensor.beam_width_deg", self.beam_width_deg, 1e-3, 90.0, "a width in (0, 90] degrees")?;
        ensure_positive("sensor.range_profile_sigma_bins", self.range_profile_sigma_bins)?;
        ensure_within("sensor.noise_power_db", self.noise_power_db, -100.0, 200.0, "a level in [-100, 200] dB")?;
        ensure_positive("sensor.noise_texture_shape", self.noise_texture_shape)?;
        ensure_non_negative("sensor.ground_clutter_db", self.ground_clutter_db)?;
        ensure_positive("sensor.ground_clutter_range_m", self.ground_clutter_range_m)?;
        ensure_positive("sensor.counts_per_ln_amplitude", self.counts_per_ln_amplitude)?;
        ensure_within(
            "sensor.speckle_static_fraction",
            self.speckle_static_fraction,
            0.0,
            1.0,
            "a fraction in [0, 1]",
        )?;
        if self.multipath_ghosts {
            ensure_non_negative("sensor.multipath_loss_db", self.multipath_loss_db)?;
        }
        Ok(())
    }

    /// Sweep period, nanoseconds.
    #[must_use]
    pub fn sweep_ns(&self) -> i64 {
        (self.sweep_period_s * 1e9).round() as i64
    }

    /// Largest range the scan covers, metres.
    #[must_use]
    pub fn max_range_m(&self) -> f64 {
        self.bins as f64 * self.range_resolution_m
    }

    /// Linear power of a return whose level is `db` (power = 10^(db / 10)).
    #[must_use]
    pub fn db_to_power(db: f64) -> f64 {
        10f64.powf(db / 10.0)
    }
}

/// Length of the pre-drawn noise buffer rows are cut from (about 70 rows' worth).
const NOISE_BUFFER_LEN: usize = 1 << 18;
/// Amplitudes below this are converted to counts by table look-up.
const TABLE_AMPLITUDES: usize = 1 << 12;
/// Spacing of the noise texture's knots, bins.
const TEXTURE_STEP: usize = 16;

/// What a sensor needs at render time, computed once: the noise buffer, the
/// per-bin floor, the compression table.
#[derive(Debug, Clone)]
pub(crate) struct Prepared {
    /// Noise power samples (mean 1), correlated along range like the real
    /// floor; each row reads `bins` of them from a seeded offset.
    pub noise: Vec<f32>,
    /// Mean noise power per bin (receiver noise plus ground clutter).
    pub floor: Vec<f32>,
    /// Counts of integer amplitudes `0..TABLE_AMPLITUDES`.
    pub counts: Vec<u8>,
    /// `counts_per_ln_amplitude`.
    pub k: f64,
}

impl Prepared {
    pub(crate) fn new(sensor: &Sensor, seed: u64) -> Self {
        let noise_mean = Sensor::db_to_power(sensor.noise_power_db);
        let clutter = Sensor::db_to_power(sensor.ground_clutter_db) - 1.0;
        let floor = (0..sensor.bins)
            .map(|b| {
                let r = (b as f64 + 0.5) * sensor.range_resolution_m / sensor.ground_clutter_range_m;
                (noise_mean * (1.0 + clutter / (1.0 + r.powi(4)))) as f32
            })
            .collect();
        let k = sensor.counts_per_ln_amplitude;
        let counts = (0..TABLE_AMPLITUDES)
            .map(|n| if n <= 1 { 0 } else { (k * (n as f64).ln()).round().min(255.0) as u8 })
            .collect();
        Self {
            noise: noise_buffer(sensor.noise_texture_shape, seed, NOISE_BUFFER_LEN.max(4 * sensor.bins)),
            floor,
            counts,
            k,
        }
    }

    /// 8-bit counts of a linear power: the integer amplitude `n = round(sqrt(p))`
    /// compressed as `round(k ln n)` (0 for n <= 1), saturating at 255.
    #[inline]
    pub(crate) fn quantize(&self, power: f32) -> u8 {
        let n = (power.max(0.0).sqrt() + 0.5) as usize;
        match self.counts.get(n) {
            Some(c) => *c,
            // The sensor's 8-bit output saturates: this is the model, not input clamping.
            None => (self.k * (n as f64).ln()).round().min(255.0) as u8,
        }
    }
}

/// Noise power with unit mean: `|z|^2 * g`, where `z` is complex Gaussian
/// smoothed along range (sigma 2 bins: the sensor's range window correlates
/// neighbouring bins) and `g` a gamma texture of shape `nu` drawn every 16
/// bins and interpolated (clutter patches), i.e. K-distributed. Fitted to the
/// real far-range floor: count CDF within 0.04, range autocorrelation of the
/// counts 0.90 / 0.52 at lags 1 / 5 (real 0.95 / 0.57).
fn noise_buffer(nu: f64, seed: u64, len: usize) -> Vec<f32> {
    let mut rng = Pcg64::seed_from_u64(seed ^ 0x6e6f_6973_655f_6275);
    let n = len;
    let re: Vec<f64> = (0..n).map(|_| standard_normal(&mut rng)).collect();
    let im: Vec<f64> = (0..n).map(|_| standard_normal(&mut rng)).collect();
    let smooth_re = smooth(&re, 2.0);
    let smooth_im = smooth(&im, 2.0);
    // Texture: gamma draws (mean 1) every TEXTURE_STEP bins, linearly interpolated.
    let knots: Vec<f64> = (0..=n / TEXTURE_STEP + 1).map(|_| gamma(&mut rng, nu) / nu).collect();
    let texture = |i: usize| {
        let (k, f) = (i / TEXTURE_STEP, (i % TEXTURE_STEP) as f64 / TEXTURE_STEP as f64);
        knots.get(k).copied().unwrap_or(1.0) * (1.0 - f) + knots.get(k + 1).copied().unwrap_or(1.0) * f
    };
    let raw: Vec<f64> = (0..n).map(|i| (smooth_re[i].powi(2) + smooth_im[i].powi(2)) * texture(i)).collect();
    let mean = raw.iter().sum::<f64>() / n as f64;
    raw.iter().map(|v| (v / mean) as f32).collect()
}

/// Circular Gaussian smoothing with one-sigma `sigma` samples, keeping the mean.
fn smooth(x: &[f64], sigma: f64) -> Vec<f64> {
    let reach = (3.0 * sigma).ceil() as isize;
    let weights: Vec<f64> = (-reach..=reach).map(|d| (-0.5 * (d as f64 / sigma).powi(2)).exp()).collect();
    let norm: f64 = weights.iter().sum();
    let n = x.len() as isize;
    (0..n)
        .map(|i| {
            weights.iter().zip(-reach..=reach).map(|(w, d)| w * x[(i + d).rem_euclid(n) as usize]).sum::<f64>() / norm
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantizer_reproduces_the_real_low_levels() {
        // The real scans hold only 0, 6, 9, 12, 14, 15, 17, 18, ... at low
        // levels: round(8.56 ln n) for n = 1, 2, 3, ...
        let p = Prepared::new(&Sensor { bins: 10, ..Sensor::default() }, 1);
        let levels: Vec<u8> = (1..=8).map(|n| p.quantize((n * n) as f32)).collect();
        assert_eq!(levels, vec![0, 6, 9, 12, 14, 15, 17, 18]);
        assert_eq!(p.quantize(1e30), 255);
        assert_eq!(p.quantize(-1.0), 0);
    }

    #[test]
    fn noise_buffer_has_unit_mean() {
        let noise = noise_buffer(0.3, 3, 1 << 16);
        let mean = noise.iter().map(|v| f64::from(*v)).sum::<f64>() / noise.len() as f64;
        assert!((mean - 1.0).abs() < 1e-4, "{mean}");
    }

    #[test]
    fn gamma_has_the_asked_mean() {
        let mut rng = Pcg64::seed_from_u64(5);
        for nu in [0.4, 2.0] {
            let m = (0..20_000).map(|_| gamma(&mut rng, nu) / nu).sum::<f64>() / 20_000.0;
            // Standard error of the mean is 1/sqrt(nu * 20000) <= 0.011; 5 sigma.
            assert!((m - 1.0).abs() < 0.06, "nu {nu}: {m}");
        }
    }
}
