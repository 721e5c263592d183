//! The overpass link of Shaham et al. 2020, Sec. II and IV-A: a base station
//! on an overpass of height `h`, a vehicle driving on the road below, one
//! line-of-sight path, ULAs at both ends, one pilot per block.
//!
//! Per block `k` (duration `dt`), with `d` the vehicle's horizontal distance
//! from the overpass (negative before it) and `v` its speed:
//!
//! ```text
//! d[k+1] = d[k] + v[k] dt + w[k] dt,   v[k+1] = v[k] + w[k],   w ~ N(0, sigma_w^2)    (11)-(12)
//! alpha[k+1] = rho alpha[k] + xi[k],   xi ~ CN(0, 1 - rho^2),  alpha[0] ~ CN(0, 1)    (9)-(10)
//! AoA theta = atan2(-h, -d),  AoD phi = atan2(h, d)                                   (18)-(19)
//! z[k] = alpha[k] w^H a_r(theta) a_t^H(phi) f + n[k],   n ~ CN(0, sigma_n^2)          (6), (16)
//! ```
//!
//! The arrays see only the direction cosines `cos theta = -d / r` and
//! `cos phi = d / r`, `r = sqrt(h^2 + d^2)` (eq. (20)-(21)). `E|alpha|^2 = 1`
//! and the pilot has unit power, so the SNR is `1 / sigma_n^2`.
//!
//! The paper gives the initial AoD (-135 deg) rather than a position; the
//! start is the distance with that AoD's cosine, `d[0] = h cos(phi0) /
//! |sin(phi0)|` (-3 m for h = 3 m). A ULA sees only the cosine, so the
//! paper's -135 deg AoD and 45 deg AoA are eq. (18)-(19)'s 135 and -45 deg.
//!
//! A realisation ([`OverpassRun`]) holds the truth and the noise of every
//! block, drawn from `(seed, run)` alone, so every tracker sees the same link
//! and a Monte Carlo run does not depend on the thread that computes it.

use mmtrack_core::Complex64;
use mmtrack_core::array::UniformLinearArray;
use mmtrack_core::random::{standard_normal, stream};
use serde::{Deserialize, Serialize};

use crate::SimError;
use crate::error::{ensure_finite, ensure_positive, ensure_within, invalid};

/// The scenario's parameters; the defaults are the paper's (Sec. IV-A).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OverpassScenario {
    /// Overpass height `h`, metres (3).
    pub height_m: f64,
    /// Elements of each ULA, half a wavelength apart (16).
    pub elements: usize,
    /// Block duration `dt`, seconds (1 ms).
    pub block_s: f64,
    /// Gauss-Markov correlation `rho` of the channel coefficient (0.995).
    pub rho: f64,
    /// Standard deviation `sigma_w` of the speed change per block, m/s (0.28).
    pub speed_sigma_mps: f64,
    /// Initial speed, km/h (60).
    pub initial_speed_kmh: f64,
    /// Initial angle of departure, degrees (-135).
    pub initial_aod_deg: f64,
    /// Received SNR `E|alpha|^2 / sigma_n^2`, dB (0).
    pub snr_db: f64,
    /// Blocks per run after the channel estimate at block 0.
    pub blocks: usize,
}

impl Default for OverpassScenario {
    fn default() -> Self {
        Self {
            height_m: 3.0,
            elements: 16,
            block_s: 1e-3,
            rho: 0.995,
            speed_sigma_mps: 0.28,
            initial_speed_kmh: 60.0,
            initial_aod_deg: -135.0,
            snr_db: 0.0,
            blocks: 400,
        }
    }
}

/// The true link state in one block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OverpassState {
    /// Horizontal distance from the overpass `d`, metres (negative before it).
    pub distance_m: f64,
    /// Speed `v`, m/s.
    pub speed_mps: f64,
    /// Channel coefficient `alpha`.
    pub alpha: Complex64,
}

impl OverpassState {
    /// `(cos theta, cos phi)`: the direction cosines of the AoA and AoD at
    /// the receive and transmit arrays (eq. (20)-(21)).
    #[must_use]
    pub fn direction_cosines(&self, height_m: f64) -> (f64, f64) {
        let range_m = height_m.hypot(self.distance_m);
        (-self.distance_m / range_m, self.distance_m / range_m)
    }

    /// Angle of arrival `theta = atan2(-h, -d)`, radians (eq. (18)).
    #[must_use]
    pub fn aoa_rad(&self, height_m: f64) -> f64 {
        (-height_m).atan2(-self.distance_m)
    }

    /// Angle of departure `phi = atan2(h, d)`, radians (eq. (19)).
    #[must_use]
    pub fn aod_rad(&self, height_m: f64) -> f64 {
        height_m.atan2(self.distance_m)
    }
}

/// One realisation of the link: truth and receiver noise for blocks
/// `0..=blocks` (block 0 is the channel estimate the trackers start from).
#[derive(Debug, Clone, PartialEq)]
pub struct OverpassRun {
    height_m: f64,
    array: UniformLinearArray,
    states: Vec<OverpassState>,
    noise: Vec<Complex64>,
}

impl OverpassScenario {
    /// Checks every parameter.
    ///
    /// # Errors
    /// [`SimError::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<(), SimError> {
        ensure_positive("height_m", self.height_m)?;
        ensure_positive("block_s", self.block_s)?;
        ensure_within("rho", self.rho, 0.0, 1.0, "a correlation in [0, 1]")?;
        ensure_within("speed_sigma_mps", self.speed_sigma_mps, 0.0, f64::MAX, "a finite number >= 0")?;
        ensure_finite("initial_speed_kmh", self.initial_speed_kmh)?;
        ensure_finite("snr_db", self.snr_db)?;
        ensure_within("initial_aod_deg", self.initial_aod_deg.abs(), 1e-6, 180.0 - 1e-6, "an angle off the road axis")?;
        if self.elements == 0 {
            return Err(invalid("elements", 0, "at least one antenna element"));
        }
        if self.blocks == 0 {
            return Err(invalid("blocks", 0, "at least one block"));
        }
        Ok(())
    }

    /// Noise variance `sigma_n^2 = 10^(-SNR/10)` (unit-power channel).
    #[must_use]
    pub fn noise_variance(&self) -> f64 {
        10f64.powf(-self.snr_db / 10.0)
    }

    /// The ULA at each end.
    ///
    /// # Errors
    /// [`SimError::InvalidParameter`] for zero elements.
    pub fn array(&self) -> Result<UniformLinearArray, SimError> {
        UniformLinearArray::half_wavelength(self.elements).map_err(|e| invalid("elements", self.elements, leak(e)))
    }

    /// Initial distance from the initial AoD (module docs), metres.
    #[must_use]
    pub fn initial_distance_m(&self) -> f64 {
        let phi0 = self.initial_aod_deg.to_radians();
        self.height_m * phi0.cos() / phi0.sin().abs()
    }

    /// Realisation `run` of the scenario under `seed`.
    ///
    /// # Errors
    /// [`SimError::InvalidParameter`] when the scenario does not validate.
    pub fn realise(&self, seed: u64, run: u64) -> Result<OverpassRun, SimError> {
        self.validate()?;
        let array = self.array()?;
        let mut rng = stream(seed, &[0x6f76_6572, run]);
        let sigma_n = (0.5 * self.noise_variance()).sqrt();
        let sigma_xi = (0.5 * (1.0 - self.rho * self.rho)).sqrt();
        let sqrt_half = 0.5f64.sqrt();
        let mut state = OverpassState {
            distance_m: self.initial_distance_m(),
            speed_mps: self.initial_speed_kmh / 3.6,
            alpha: Complex64::new(sqrt_half * standard_normal(&mut rng), sqrt_half * standard_normal(&mut rng)),
        };
        let mut states = Vec::with_capacity(self.blocks + 1);
        let mut noise = Vec::with_capacity(self.blocks + 1);
        for _ in 0..=self.blocks {
            states.push(state);
            noise.push(Complex64::new(sigma_n * standard_normal(&mut rng), sigma_n * standard_normal(&mut rng)));
            let w = self.speed_sigma_mps * standard_normal(&mut rng);
            let xi = Complex64::new(sigma_xi * standard_normal(&mut rng), sigma_xi * standard_normal(&mut rng));
            state = OverpassState {
                distance_m: state.distance_m + (state.speed_mps + w) * self.block_s,
                speed_mps: state.speed_mps + w,
                alpha: self.rho * state.alpha + xi,
            };
        }
        Ok(OverpassRun { height_m: self.height_m, array, states, noise })
    }
}

impl OverpassRun {
    /// True states of blocks `0..=blocks`.
    #[must_use]
    pub fn states(&self) -> &[OverpassState] {
        &self.states
    }

    /// The received pilot of `block` through a receive beam steered to
    /// direction cosine `rx_steer_u` and a transmit beam steered to
    /// `tx_steer_u` (eq. (6), (16)): `alpha (w^H a_r) (a_t^H f) + n`.
    ///
    /// # Panics
    /// When `block` is beyond the realisation (a caller's loop bound).
    #[must_use]
    pub fn pilot(&self, block: usize, rx_steer_u: f64, tx_steer_u: f64) -> Complex64 {
        let state = &self.states[block];
        let (rx_u, tx_u) = state.direction_cosines(self.height_m);
        let rx = self.array.array_factor(rx_steer_u, rx_u);
        let tx = self.array.array_factor(tx_steer_u, tx_u).conj();
        state.alpha * rx * tx + self.noise[block]
    }
}

/// The core error's text as the `expected` of an invalid parameter.
fn leak(error: mmtrack_core::CoreError) -> &'static str {
    match error {
        mmtrack_core::CoreError::OutOfRange { expected, .. } => expected,
        _ => "a valid array",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_papers_start_and_statistics() {
        let scenario = OverpassScenario::default();
        assert!((scenario.initial_distance_m() + 3.0).abs() < 1e-12);
        let run = scenario.realise(1, 0).unwrap();
        let first = run.states()[0];
        assert!((first.aod_rad(3.0).to_degrees() - 135.0).abs() < 1e-9);
        // The paper's -135 / 45 deg: the same cosines as atan2's 135 / -45 deg.
        assert!((first.aoa_rad(3.0).to_degrees() + 45.0).abs() < 1e-9);
        let (cos_theta, cos_phi) = first.direction_cosines(3.0);
        assert!((cos_theta - 45f64.to_radians().cos()).abs() < 1e-12 && (cos_phi + cos_theta).abs() < 1e-12);
        assert_eq!(run.states().len(), scenario.blocks + 1);
        // 1 ms at 60 km/h: 16.7 mm per block.
        let step = run.states()[1].distance_m - first.distance_m;
        assert!((step - 60.0 / 3.6 * 1e-3).abs() < 0.28 * 1e-3 * 5.0, "{step}");
    }

    #[test]
    fn noise_and_gain_have_the_stated_variances() {
        // 4000 runs x first block: E|alpha|^2 = 1, E|n|^2 = sigma_n^2 = 0.1 at 10 dB.
        let scenario = OverpassScenario { snr_db: 10.0, blocks: 1, ..OverpassScenario::default() };
        let (mut alpha_power, mut noise_power) = (0.0, 0.0);
        let runs = 4000;
        for run in 0..runs {
            let r = scenario.realise(7, run).unwrap();
            alpha_power += r.states()[0].alpha.norm_sqr();
            noise_power += r.noise[0].norm_sqr();
        }
        // Exponential(1) mean over 4000 draws: standard error 1.6 %, 5 sigma = 8 %.
        assert!((alpha_power / runs as f64 - 1.0).abs() < 0.08, "{alpha_power}");
        assert!((noise_power / runs as f64 / 0.1 - 1.0).abs() < 0.08, "{noise_power}");
    }

    #[test]
    fn pilot_on_the_true_beams_is_alpha_plus_noise() {
        let scenario = OverpassScenario::default();
        let run = scenario.realise(3, 5).unwrap();
        let state = run.states()[10];
        let (rx_u, tx_u) = state.direction_cosines(3.0);
        let z = run.pilot(10, rx_u, tx_u);
        assert!((z - state.alpha - run.noise[10]).norm() < 1e-12);
        // Deterministic per (seed, run), different across runs.
        assert_eq!(scenario.realise(3, 5).unwrap(), run);
        assert_ne!(scenario.realise(3, 6).unwrap().states()[0], state);
    }

    #[test]
    fn bad_parameters_are_named() {
        for (scenario, field) in [
            (OverpassScenario { height_m: 0.0, ..OverpassScenario::default() }, "height_m"),
            (OverpassScenario { rho: 1.5, ..OverpassScenario::default() }, "rho"),
            (OverpassScenario { elements: 0, ..OverpassScenario::default() }, "elements"),
            (OverpassScenario { snr_db: f64::NAN, ..OverpassScenario::default() }, "snr_db"),
            (OverpassScenario { initial_aod_deg: 0.0, ..OverpassScenario::default() }, "initial_aod_deg"),
        ] {
            let err = scenario.realise(1, 0).unwrap_err().to_string();
            assert!(err.starts_with(field), "{err}");
        }
    }
}
