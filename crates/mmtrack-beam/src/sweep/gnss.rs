//! The GNSS-driven window tracker: the car's position, through the fitted
//! beam map, moves the window; the measurements correct the map's offset.

use super::error::{SweepError, check};
use super::search::{BeamProbe, PowerHold, SearchConfig, Window, search_sweep};
use super::{SweepDecision, SweepTracker, dt_s};

/// Settings of [`GnssWindowTracker`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssTrackerConfig {
    /// Window, climb, loss rule and re-acquisition.
    pub search: SearchConfig,
    /// Random-walk rate of the map offset, beams / sqrt(s).
    pub offset_walk_beams_per_sqrt_s: f64,
    /// Standard deviation of the sub-beam peak measurement, beams.
    pub measurement_sigma_beams: f64,
    /// Standard deviation of the map offset at a pass start, beams: the
    /// beam map's residual (its [`super::BeamMap::rms_residual_beams`]).
    pub initial_offset_sigma_beams: f64,
    /// Half-width of the first window of a pass, in initial standard
    /// deviations (rounded up to whole beams, at least the usual window).
    pub initial_window_sigmas: f64,
}

impl Default for GnssTrackerConfig {
    /// [`SearchConfig::default`]; the offset wanders 2 beams per sqrt(s)
    /// (GNSS errors of about a metre at 15 m range and the map's
    /// non-linearity change it over a pass); half a beam of peak noise; 3
    /// beams of initial offset, searched over +-2 sigma.
    fn default() -> Self {
        Self {
            search: SearchConfig::default(),
            offset_walk_beams_per_sqrt_s: 2.0,
            measurement_sigma_beams: 0.5,
            initial_offset_sigma_beams: 3.0,
            initial_window_sigmas: 2.0,
        }
    }
}

/// Tracks the best beam with the car's GNSS position as the motion input:
/// the SPEBT idea of Liu et al. 2024, with GNSS fixes in place of radar
/// odometry.
///
/// In SPEBT the beam-tracking filter's state evolution is driven by the
/// vehicle's estimated pose (Liu et al., Sec. III-B, Proposition 2): the
/// angle the next slot needs follows from where the vehicle has moved, so
/// the filter only has to absorb the pose error. Here the pose is the car's
/// GNSS position, turned into a beam `g_k` (continuous index) by the fitted
/// [`super::BeamMap`], and the filter state is the scalar offset `o` between
/// the measured best beam and `g_k` (GNSS errors, latency and map error),
/// a random walk:
///
/// ```text
/// predict:  o_k = o_{k-1},                  P_k = P_{k-1} + q^2 dt
/// window:   around g_k + o_k
/// update:   z_k = b_hat_k - g_k,  K = P_k / (P_k + r^2),
///           o_k += K (z_k - o_k),  P_k *= 1 - K
/// ```
///
/// with `b_hat_k` the sub-beam peak of the chosen beam, `q` the walk rate
/// and `r` the peak noise. The window, climb, loss rule and re-acquisition
/// are those of [`super::WindowTracker`]; after a re-acquisition the offset
/// restarts at `z_k` with variance `r^2`. A pass starts from the GNSS beam
/// alone (offset 0, variance `sigma_0^2`, a first window of `+-ceil(k
/// sigma_0)` beams), so no sweep is spent on acquisition unless that window
/// misses.
///
/// # References
/// C. Liu, G. Zhu, F. Liu, Y. Liu, "Successive Pose Estimation and Beam
/// Tracking for mmWave Vehicular Communication Systems", 2024 (SPEBT),
/// Sec. III-B; `../shared/seeds/liu2024-spebt-fast-cfear.md`.
#[derive(Debug, Clone)]
pub struct GnssWindowTracker {
    config: GnssTrackerConfig,
    /// Offset mean and variance (beams, beams^2) and the last sweep time.
    offset: Option<(f64, f64, i64)>,
    hold: PowerHold,
}

impl GnssWindowTracker {
    /// Checks `config` and builds a tracker with no track.
    ///
    /// # Errors
    /// [`SweepError::BadConfig`] for a bad search config, a negative walk,
    /// or a non-positive noise, initial sigma or window factor.
    pub fn new(config: GnssTrackerConfig) -> Result<Self, SweepError> {
        config.search.validate()?;
        let GnssTrackerConfig {
            offset_walk_beams_per_sqrt_s: walk,
            measurement_sigma_beams: r,
            initial_offset_sigma_beams: sigma0,
            initial_window_sigmas: k,
            ..
        } = config;
        check("offset_walk_beams_per_sqrt_s", walk, walk >= 0.0, ">= 0")?;
        check("measurement_sigma_beams", r, r > 0.0, "> 0")?;
        check("initial_offset_sigma_beams", sigma0, sigma0 > 0.0, "> 0")?;
        check("initial_window_sigmas", k, k > 0.0, "> 0")?;
        Ok(Self { config, offset: None, hold: PowerHold::new(config.search.hold_s) })
    }
}

impl SweepTracker for GnssWindowTracker {
    fn start_pass(&mut self) {
        self.offset = None;
        self.hold.clear();
    }

    fn step(&mut self, probe: &mut BeamProbe<'_>, gnss_beam: Option<f64>) -> Result<SweepDecision, SweepError> {
        let t_ns = probe.t_ns();
        let gnss_beam = match gnss_beam {
            Some(beam) if beam.is_finite() => beam,
            other => {
                return Err(SweepError::BadInput {
                    what: format!("sweep at {t_ns} ns: the GNSS tracker needs a finite GNSS beam, got {other:?}"),
                });
            }
        };
        let config = &self.config;
        let r2 = config.measurement_sigma_beams.powi(2);
        let (offset, variance, window) = match self.offset {
            None => {
                let sigma0 = config.initial_offset_sigma_beams;
                let half = (config.initial_window_sigmas * sigma0).ceil().min(probe.beam_count() as f64) as usize;
                let half = half.max(config.search.half_window_beams);
                // Contiguous, not strided like a coarse re-acquisition: far
                // from the array the beam pattern is flat (3.5 dB from the
                // best beam to the median on DeepSense scenario 3), and a
                // strided search then climbs onto a bump.
                (0.0, sigma0 * sigma0, Window { center: gnss_beam, half })
            }
            Some((offset, variance, previous_t_ns)) => {
                let dt = dt_s(previous_t_ns, t_ns)?;
                let variance = variance + config.offset_walk_beams_per_sqrt_s.powi(2) * dt;
                (offset, variance, Window { center: gnss_beam + offset, half: config.search.half_window_beams })
            }
        };
        let outcome = search_sweep(probe, window, &config.search, &mut self.hold)?;
        let z = outcome.subbeam - gnss_beam;
        let (offset, variance) = if outcome.reacquired {
            (z, r2)
        } else {
            let gain = variance / (variance + r2);
            (offset + gain * (z - offset), variance * (1.0 - gain))
        };
        self.offset = Some((offset, variance, t_ns));
        Ok(SweepDecision {
            chosen_beam: outcome.peak.beam,
            reinitialised: outcome.reacquired,
            track_beam: Some(gnss_beam + offset),
        })
    }
}
