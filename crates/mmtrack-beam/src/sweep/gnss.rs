//! The GNSS-driven window tracker: the window tracker's constant-velocity
//! filter on the beam index, with the beam the car's GNSS position predicts
//! (through the fitted beam map) as a second, coarser measurement.

use mmtrack_filter::faer::{Col, Mat};
use mmtrack_filter::{ConstantVelocity, Gaussian, KalmanPredictor, KalmanUpdater, LinearMeasurement};

use super::error::{SweepError, check};
use super::search::{BeamProbe, PowerHold, Window, acquire, search_sweep, subbeam_peak};
use super::{Reacquisition, SweepDecision, SweepTracker, WindowTrackerConfig, dt_s};

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
    config: GnssTrackerConfig,
    predictor: KalmanPredictor<ConstantVelocity>,
    peak: KalmanUpdater,
    gnss: KalmanUpdater,
    track: Option<(Gaussian, i64)>,
    hold: PowerHold,
}

impl GnssWindowTracker {
    /// Checks `config` and builds a tracker with no track.
    ///
    /// # Errors
    /// [`SweepError::BadConfig`] for a bad search config, or a noise level,
    /// GNSS sigma or window factor that is not positive and finite.
    pub fn new(config: GnssTrackerConfig) -> Result<Self, SweepError> {
        let GnssTrackerConfig { window, gnss_sigma_beams: sigma_g, initial_window_sigmas: k } = config;
        window.search.validate()?;
        check(
            "sigma_accel_beams_per_s2",
            window.sigma_accel_beams_per_s2,
            window.sigma_accel_beams_per_s2 > 0.0,
            "> 0",
        )?;
        check("measurement_sigma_beams", window.measurement_sigma_beams, window.measurement_sigma_beams > 0.0, "> 0")?;
        check(
            "initial_rate_sigma_beams_per_s",
            window.initial_rate_sigma_beams_per_s,
            window.initial_rate_sigma_beams_per_s > 0.0,
            "> 0",
        )?;
        check("gnss_sigma_beams", sigma_g, sigma_g > 0.0 && sigma_g.is_finite(), "> 0")?;
        check("initial_window_sigmas", k, k > 0.0 && k.is_finite(), "> 0")?;
        let bad = |field: &'static str| SweepError::BadConfig {
            field,
            value: "rejected by the filter".into(),
            expected: "> 0",
        };
        let model =
            ConstantVelocity::new(1, window.sigma_accel_beams_per_s2).map_err(|_| bad("sigma_accel_beams_per_s2"))?;
        let peak = LinearMeasurement::position(1, window.measurement_sigma_beams)
            .map_err(|_| bad("measurement_sigma_beams"))?;
        let gnss = LinearMeasurement::position(1, sigma_g).map_err(|_| bad("gnss_sigma_beams"))?;
        Ok(Self {
            config,
            predictor: KalmanPredictor::new(model),
            peak: KalmanUpdater::new(peak),
            gnss: KalmanUpdater::new(gnss),
            track: None,
            hold: PowerHold::new(window.search.hold_s),
        })
    }

    /// A track at `beam` (variance `beam_var`) with rate `rate_beams_per_s`.
    fn start(&self, beam: f64, beam_var: f64, rate_beams_per_s: f64, t_ns: i64) -> Result<Gaussian, SweepError> {
        let mean = Col::from_fn(2, |i| if i == 0 { beam } else { rate_beams_per_s });
        let rate_var = self.config.window.initial_rate_sigma_beams_per_s.powi(2);
        let cov = Mat::from_fn(2, 2, |i, j| match (i, j) {
            (0, 0) => beam_var,
            (1, 1) => rate_var,
            _ => 0.0,
        });
        Gaussian::new(mean, cov).map_err(|source| SweepError::Filter { t_ns, source })
    }
}

impl SweepTracker for GnssWindowTracker {
    fn start_pass(&mut self) {
        self.track = None;
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
        let filter_error = |source| SweepError::Filter { t_ns, source };
        let search = self.config.window.search;
        let peak_var = self.config.window.measurement_sigma_beams.powi(2);
        let (prior, half) = match self.track.take() {
            None => {
                let sigma_g = self.config.gnss_sigma_beams;
                let half = (self.config.initial_window_sigmas * sigma_g).ceil().min(probe.beam_count() as f64) as usize;
                let half = half.max(search.half_window_beams);
                let acquisition_beams = match search.reacquisition {
                    Reacquisition::Coarse { stride } => probe.beam_count().div_ceil(stride),
                    Reacquisition::FullSweep => probe.beam_count(),
                };
                if 2 * half + 1 >= acquisition_beams {
                    // The GNSS window would cost more than acquiring.
                    let peak = acquire(probe, search.reacquisition)?;
                    let beam = subbeam_peak(probe, peak.beam);
                    self.hold.clear();
                    self.hold.push(t_ns, peak.power_db);
                    self.track = Some((self.start(beam, peak_var, 0.0, t_ns)?, t_ns));
                    return Ok(SweepDecision { chosen_beam: peak.beam, reinitialised: true, track_beam: Some(beam) });
                }
                (self.start(gnss_beam, sigma_g * sigma_g, 0.0, t_ns)?, half)
            }
            Some((previous, previous_t_ns)) => {
                let predicted = self.predictor.predict(&previous, dt_s(previous_t_ns, t_ns)?).map_err(filter_error)?;
                let z = Col::from_fn(1, |_| gnss_beam);
                (self.gnss.update(&predicted, &z).map_err(filter_error)?, search.half_window_beams)
            }
        };
        let outcome = search_sweep(probe, Window { center: prior.mean()[0], half }, &search, &mut self.hold)?;
        let posterior = if outcome.reacquired {
            self.start(outcome.subbeam, peak_var, prior.mean()[1], t_ns)?
        } else {
            self.peak.update(&prior, &Col::from_fn(1, |_| outcome.subbeam)).map_err(filter_error)?
        };
        let track_beam = posterior.mean()[0];
        self.track = Some((posterior, t_ns));
        Ok(SweepDecision {
            chosen_beam: outcome.peak.beam,
            reinitialised: outcome.reacquired,
            track_beam: Some(track_beam),
        })
    }
}
