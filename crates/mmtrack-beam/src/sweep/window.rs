//! The beam-only window tracker: a constant-velocity Kalman filter on the
//! best beam's (sub-beam) index drives a small measurement window.

use mmtrack_filter::faer::{Col, Mat};
use mmtrack_filter::{ConstantVelocity, Gaussian, KalmanPredictor, KalmanUpdater, LinearMeasurement};

use super::error::{SweepError, check};
use super::search::{BeamProbe, PowerHold, SearchConfig, Window, acquire, search_sweep, subbeam_peak};
use super::{SweepDecision, SweepTracker, dt_s};

/// Settings of [`WindowTracker`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowTrackerConfig {
    /// Window, climb, loss rule and re-acquisition.
    pub search: SearchConfig,
    /// White-acceleration noise of the constant-velocity model, beams / s^2.
    pub sigma_accel_beams_per_s2: f64,
    /// Standard deviation of the sub-beam peak measurement, beams.
    pub measurement_sigma_beams: f64,
    /// Standard deviation of the beam rate after an acquisition, beams / s.
    pub initial_rate_sigma_beams_per_s: f64,
}

impl Default for WindowTrackerConfig {
    /// [`SearchConfig::default`]; acceleration noise 30 beams/s^2 (a car at
    /// 10 m/s passing 15 m from the array sweeps up to about 40 deg/s, 28
    /// beams/s, and changes that rate within about a second); half a beam of
    /// peak noise; an unknown rate of up to about 20 beams/s after an
    /// acquisition.
    fn default() -> Self {
        Self {
            search: SearchConfig::default(),
            sigma_accel_beams_per_s2: 30.0,
            measurement_sigma_beams: 0.5,
            initial_rate_sigma_beams_per_s: 20.0,
        }
    }
}

/// Tracks the best beam of a measured codebook from its own measurements
/// only.
///
/// State `[b, b_dot]`: the best beam's position as a continuous beam index
/// and its rate in beams per second, with the constant-velocity model of
/// [`ConstantVelocity`] (one axis). Each sweep:
///
/// 1. predict the state to the sweep's time;
/// 2. measure the `2 h + 1` beams around the predicted beam, climbing
///    outward (at most `max_extension_beams` more) while the strongest sits
///    at the window's edge;
/// 3. choose the strongest measured beam;
/// 4. loss rule: the climb ran out (the strongest is still at the edge) or
///    its power is `drop_db` below the best chosen power of the last
///    `hold_s` seconds; then re-acquire ([`super::Reacquisition`]) and restart
///    the position from the acquired peak;
/// 5. otherwise update with the sub-beam peak (parabola through the dB
///    powers of the chosen beam and its neighbours).
///
/// The first sweep of a pass is an acquisition. The beam index is tracked
/// rather than an angle because the codebook is uniform in angle (about 1.4
/// degrees per beam for the DeepSense 64-beam, 90-degree codebook), so the
/// two differ by a constant factor.
#[derive(Debug, Clone)]
pub struct WindowTracker {
    config: WindowTrackerConfig,
    predictor: KalmanPredictor<ConstantVelocity>,
    updater: KalmanUpdater,
    track: Option<(Gaussian, i64)>,
    hold: PowerHold,
}

impl WindowTracker {
    /// Checks `config` and builds a tracker with no track.
    ///
    /// # Errors
    /// [`SweepError::BadConfig`] for a bad search config or a noise level
    /// that is not positive and finite.
    pub fn new(config: WindowTrackerConfig) -> Result<Self, SweepError> {
        config.search.validate()?;
        let WindowTrackerConfig {
            sigma_accel_beams_per_s2,
            measurement_sigma_beams,
            initial_rate_sigma_beams_per_s,
            ..
        } = config;
        check("sigma_accel_beams_per_s2", sigma_accel_beams_per_s2, sigma_accel_beams_per_s2 > 0.0, "> 0")?;
        check("measurement_sigma_beams", measurement_sigma_beams, measurement_sigma_beams > 0.0, "> 0")?;
        check(
            "initial_rate_sigma_beams_per_s",
            initial_rate_sigma_beams_per_s,
            initial_rate_sigma_beams_per_s > 0.0,
            "> 0",
        )?;
        let bad = |field: &'static str| SweepError::BadConfig {
            field,
            value: "rejected by the filter".into(),
            expected: "> 0",
        };
        let model = ConstantVelocity::new(1, sigma_accel_beams_per_s2).map_err(|_| bad("sigma_accel_beams_per_s2"))?;
        let measurement =
            LinearMeasurement::position(1, measurement_sigma_beams).map_err(|_| bad("measurement_sigma_beams"))?;
        Ok(Self {
            config,
            predictor: KalmanPredictor::new(model),
            updater: KalmanUpdater::new(measurement),
            track: None,
            hold: PowerHold::new(config.search.hold_s),
        })
    }

    /// A track at `beam` (variance `beam_var`, beams^2) with rate
    /// `rate_beams_per_s` (variance from `initial_rate_sigma_beams_per_s`).
    fn track_at(&self, beam: f64, beam_var: f64, rate_beams_per_s: f64, t_ns: i64) -> Result<Gaussian, SweepError> {
        let mean = Col::from_fn(2, |i| if i == 0 { beam } else { rate_beams_per_s });
        let rate_var = self.config.initial_rate_sigma_beams_per_s.powi(2);
        let cov = Mat::from_fn(2, 2, |i, j| match (i, j) {
            (0, 0) => beam_var,
            (1, 1) => rate_var,
            _ => 0.0,
        });
        Gaussian::new(mean, cov).map_err(|source| SweepError::Filter { t_ns, source })
    }

    /// One sweep of the filter, with two hooks for a tracker that adds a
    /// measurement source ([`super::GnssWindowTracker`]): at a pass start,
    /// `pass_start` (beam, variance, half-width of the first window) replaces
    /// the acquisition; on a running track, `aid` (an updater and its
    /// measurement of the beam index) updates the predicted state before the
    /// window is placed. With neither, the steps of the type docs.
    pub(super) fn step_aided(
        &mut self,
        probe: &mut BeamProbe<'_>,
        pass_start: Option<(f64, f64, usize)>,
        aid: Option<(&KalmanUpdater, f64)>,
    ) -> Result<SweepDecision, SweepError> {
        let t_ns = probe.t_ns();
        let filter_error = |source| SweepError::Filter { t_ns, source };
        let peak_var = self.config.measurement_sigma_beams.powi(2);
        let search = self.config.search;
        let (prior, half) = match (self.track.take(), pass_start) {
            (None, None) => {
                let peak = acquire(probe, search.reacquisition)?;
                let beam = subbeam_peak(probe, peak.beam);
                self.hold.clear();
                self.hold.push(t_ns, peak.power_db);
                self.track = Some((self.track_at(beam, peak_var, 0.0, t_ns)?, t_ns));
                return Ok(SweepDecision { chosen_beam: peak.beam, reinitialised: true, track_beam: Some(beam) });
            }
            (None, Some((beam, beam_var, half))) => (self.track_at(beam, beam_var, 0.0, t_ns)?, half),
            (Some((previous, previous_t_ns)), _) => {
                let predicted = self.predictor.predict(&previous, dt_s(previous_t_ns, t_ns)?).map_err(filter_error)?;
                let prior = match aid {
                    Some((updater, z)) => updater.update(&predicted, &Col::from_fn(1, |_| z)).map_err(filter_error)?,
                    None => predicted,
                };
                (prior, search.half_window_beams)
            }
        };
        let outcome = search_sweep(probe, Window { center: prior.mean()[0], half }, &search, &mut self.hold)?;
        let posterior = if outcome.reacquired {
            self.track_at(outcome.subbeam, peak_var, prior.mean()[1], t_ns)?
        } else {
            self.updater.update(&prior, &Col::from_fn(1, |_| outcome.subbeam)).map_err(filter_error)?
        };
        let track_beam = posterior.mean()[0];
        self.track = Some((posterior, t_ns));
        Ok(SweepDecision {
            chosen_beam: outcome.peak.beam,
            reinitialised: outcome.reacquired,
            track_beam: Some(track_beam),
        })
    }

    /// Whether a pass is under way (a track is held).
    pub(super) fn has_track(&self) -> bool {
        self.track.is_some()
    }

    /// The settings.
    pub(super) fn config(&self) -> &WindowTrackerConfig {
        &self.config
    }
}

impl SweepTracker for WindowTracker {
    fn start_pass(&mut self) {
        self.track = None;
        self.hold.clear();
    }

    fn step(&mut self, probe: &mut BeamProbe<'_>, _gnss_beam: Option<f64>) -> Result<SweepDecision, SweepError> {
        self.step_aided(probe, None, None)
    }
}
