//! The GNSS-driven window tracker: the window tracker's constant-velocity
//! filter on the beam index, with the beam the car's GNSS position predicts
//! (through the fitted beam map) as a second, coarser measurement.

use mmtrack_filter::{KalmanUpdater, LinearMeasurement};

use super::error::{SweepError, check};
use super::search::BeamProbe;
use super::{Reacquisition, SweepDecision, SweepTracker, WindowTracker, WindowTrackerConfig};

/// Settings of [`GnssWindowTracker`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssTrackerConfig {
    /// The beam-only filter it extends: window, climb, loss rule,
    /// re-acquisition, motion noise, peak noise and initial rate.
    pub window: WindowTrackerConfig,
    /// Standard deviation of the GNSS beam about the best beam, beams: the
    /// RMS residual of the beam map on the passes it was fitted on
    /// ([`super::BeamMap::rms_residual_beams`]), so the data, not a setting,
    /// say how far the GNSS beam is to be trusted.
    pub gnss_sigma_beams: f64,
    /// Half-width of the first window of a pass, in `gnss_sigma_beams`
    /// (rounded up to whole beams, at least the usual window).
    pub initial_window_sigmas: f64,
}

impl Default for GnssTrackerConfig {
    /// [`WindowTrackerConfig::default`]; a GNSS beam good to 3 beams (callers
    /// give the map's residual instead); a first window of +-2 sigma.
    fn default() -> Self {
        Self { window: WindowTrackerConfig::default(), gnss_sigma_beams: 3.0, initial_window_sigmas: 2.0 }
    }
}

/// Tracks the best beam with the car's GNSS position as a motion input: the
/// SPEBT idea of Liu et al. 2024, with GNSS fixes in place of radar
/// odometry.
///
/// In SPEBT the beam-tracking filter is driven by the vehicle's estimated
/// pose (Liu et al., Sec. III-B, Proposition 2): where the vehicle has
/// moved says which angle the next slot needs, and the filter absorbs the
/// pose error. Here the pose is the car's GNSS position, turned into a beam
/// `g_k` (continuous index) by the fitted [`super::BeamMap`]. The state is
/// the [`super::WindowTracker`]'s `[b, b_dot]` (beam index and rate, constant
/// velocity), and each sweep:
///
/// ```text
/// predict:       x_k = F x_{k-1},             P_k = F P F^T + Q     (constant velocity)
/// GNSS update:   z = g_k,      H = [1 0],     R = sigma_g^2
/// window:        around the GNSS-updated b_k (window, climb, loss rule
///                and re-acquisition of the window tracker)
/// peak update:   z = b_hat_k,  H = [1 0],     R = r^2
/// ```
///
/// with `sigma_g` the beam map's residual and `r` the sub-beam peak noise.
/// The GNSS beam is a measurement, not the window's centre: its errors
/// (metres of position error at ranges of 10-30 m are several beams, and on
/// the DeepSense passes they change from sweep to sweep by a median 0.9-2
/// beams) pull the track in proportion to how far the map says GNSS is to be
/// trusted, and the measured peak, ten times finer, dominates while the
/// track holds. After a re-acquisition the track restarts at the acquired
/// peak. A pass starts from the GNSS beam (variance `sigma_g^2`, a first
/// window of `+-ceil(k sigma_g)` beams), unless that window would read at
/// least as many beams as the re-acquisition does; then the pass starts
/// with a re-acquisition, as the window tracker's does.
///
/// # References
/// C. Liu, G. Zhu, F. Liu, Y. Liu, "Successive Pose Estimation and Beam
/// Tracking for mmWave Vehicular Communication Systems", 2024 (SPEBT),
/// Sec. III-B; `../shared/seeds/liu2024-spebt-fast-cfear.md`.
#[derive(Debug, Clone)]
pub struct GnssWindowTracker {
    /// The beam-only filter, search and power hold.
    window: WindowTracker,
    /// The GNSS beam's measurement update.
    gnss: KalmanUpdater,
    gnss_sigma_beams: f64,
    initial_window_sigmas: f64,
}

impl GnssWindowTracker {
    /// Checks `config` and builds a tracker with no track.
    ///
    /// # Errors
    /// [`WindowTracker::new`]'s, or a GNSS sigma or window factor that is not
    /// positive and finite.
    pub fn new(config: GnssTrackerConfig) -> Result<Self, SweepError> {
        let GnssTrackerConfig { window, gnss_sigma_beams: sigma_g, initial_window_sigmas: k } = config;
        let window = WindowTracker::new(window)?;
        check("gnss_sigma_beams", sigma_g, sigma_g > 0.0 && sigma_g.is_finite(), "> 0")?;
        check("initial_window_sigmas", k, k > 0.0 && k.is_finite(), "> 0")?;
        let gnss = LinearMeasurement::position(1, sigma_g).map_err(|_| SweepError::BadConfig {
            field: "gnss_sigma_beams",
            value: "rejected by the filter".into(),
            expected: "> 0",
        })?;
        Ok(Self { window, gnss: KalmanUpdater::new(gnss), gnss_sigma_beams: sigma_g, initial_window_sigmas: k })
    }
}

impl SweepTracker for GnssWindowTracker {
    fn start_pass(&mut self) {
        self.window.start_pass();
    }

    fn step(&mut self, probe: &mut BeamProbe<'_>, gnss_beam: Option<f64>) -> Result<SweepDecision, SweepError> {
        let gnss_beam = match gnss_beam {
            Some(beam) if beam.is_finite() => beam,
            other => {
                return Err(SweepError::BadInput {
                    what: format!(
                        "sweep at {} ns: the GNSS tracker needs a finite GNSS beam, got {other:?}",
                        probe.t_ns()
                    ),
                });
            }
        };
        if self.window.has_track() {
            return self.window.step_aided(probe, None, Some((&self.gnss, gnss_beam)));
        }
        // A pass start: from the GNSS window, unless it would read at least
        // as many beams as the acquisition does.
        let search = self.window.config().search;
        let sigma_g = self.gnss_sigma_beams;
        let half = (self.initial_window_sigmas * sigma_g).ceil().min(probe.beam_count() as f64) as usize;
        let half = half.max(search.half_window_beams);
        let acquisition_beams = match search.reacquisition {
            Reacquisition::Coarse { stride } => probe.beam_count().div_ceil(stride),
            Reacquisition::FullSweep => probe.beam_count(),
        };
        let start = (2 * half + 1 < acquisition_beams).then_some((gnss_beam, sigma_g * sigma_g, half));
        self.window.step_aided(probe, start, None)
    }
}
