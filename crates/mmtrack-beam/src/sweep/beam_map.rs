//! The beam map: which beam of a measured codebook points at a car seen at a
//! given bearing from the array, fitted from data (the array's boresight and
//! beam spacing are not given).

use mmtrack_core::wrap_angle_rad;

use super::dt_s;
use super::error::SweepError;

/// Bearing of a point `[east, north]` metres from the array: radians
/// clockwise from north (`atan2(east, north)`, in `(-pi, pi]`).
#[must_use]
pub fn bearing_rad(east_north_m: [f64; 2]) -> f64 {
    east_north_m[0].atan2(east_north_m[1])
}

/// The car during one pass: its position relative to the array, east and
/// north metres, at each sweep's time.
#[derive(Debug, Clone, Copy)]
pub struct GnssPass<'a> {
    /// Sweep times, nanoseconds, strictly increasing.
    pub t_ns: &'a [i64],
    /// Car position relative to the array at each sweep, `[east_m, north_m]`.
    pub east_north_m: &'a [[f64; 2]],
}

impl GnssPass<'_> {
    /// Positions moved `offset_s` seconds along the pass: `p + v offset_s`,
    /// with the velocity `v` from central differences (one-sided at the
    /// ends, zero for a one-sweep pass).
    fn shifted(&self, offset_s: f64) -> Result<Vec<[f64; 2]>, SweepError> {
        let n = self.east_north_m.len();
        let mut out = Vec::with_capacity(n);
        for i in 0..n {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            let velocity = if a == b {
                [0.0, 0.0]
            } else {
                let dt = dt_s(self.t_ns[a], self.t_ns[b])?;
                let (pa, pb) = (self.east_north_m[a], self.east_north_m[b]);
                [(pb[0] - pa[0]) / dt, (pb[1] - pa[1]) / dt]
            };
            let p = self.east_north_m[i];
            out.push([p[0] + velocity[0] * offset_s, p[1] + velocity[1] * offset_s]);
        }
        Ok(out)
    }

    fn check(&self, what: &str, expected_len: usize) -> Result<(), SweepError> {
        let bad = |what: String| Err(SweepError::BadInput { what });
        if self.t_ns.len() != expected_len || self.east_north_m.len() != expected_len {
            return bad(format!(
                "{what}: {} times and {} positions for {expected_len} sweeps",
                self.t_ns.len(),
                self.east_north_m.len()
            ));
        }
        if let Some(p) = self.east_north_m.iter().find(|p| !(p[0].is_finite() && p[1].is_finite())) {
            return bad(format!("{what}: car position {p:?} is not finite"));
        }
        for pair in self.t_ns.windows(2) {
            dt_s(pair[0], pair[1])?;
        }
        Ok(())
    }
}

/// One pass of beam-map training data: the car's track and the best beam of
/// each full sweep.
#[derive(Debug, Clone, Copy)]
pub struct MapPass<'a> {
    /// The car's track.
    pub gnss: GnssPass<'a>,
    /// Best beam of each sweep.
    pub best_beam: &'a [usize],
}

/// How [`BeamMap::fit`] searches the GNSS time offset.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamMapConfig {
    /// Candidate offsets between the GNSS positions and the sweeps, seconds.
    pub time_offsets_s: Vec<f64>,
}

impl Default for BeamMapConfig {
    /// -3 s to 3 s in 0.1 s steps (one sweep at 10 Hz).
    fn default() -> Self {
        Self { time_offsets_s: (-30..=30).map(|k| f64::from(k) * 0.1).collect() }
    }
}

/// Beam index as a straight line in the car's bearing from the array:
///
/// ```text
/// beam(phi) = b_ref + s * wrap(phi(t + tau) - phi_ref)
/// ```
///
/// with `phi` the bearing of the car (clockwise from north) at the sweep's
/// time shifted by the GNSS time offset `tau`, `phi_ref` a reference bearing
/// (the circular mean of the training bearings), `b_ref` the beam there and
/// `s` beams per radian (its sign says which end of the codebook is which).
/// A line fits a codebook uniform in angle, like the 64-beam, 90-degree one
/// of the DeepSense 60 GHz unit; `1 / |s|` is then the angle per beam and
/// the boresight is the bearing of the middle beam `(N - 1) / 2`.
///
/// # Fit
/// [`BeamMap::fit`]: ordinary least squares of the best beam of every full
/// sweep on the car's bearing, for each candidate time offset; the offset
/// with the smallest RMS residual wins (a GNSS latency or timestamp offset
/// shifts the car along its path, and passes driven in opposite directions
/// then disagree). Nothing is typed in per scenario: the boresight, the beam
/// spacing, the codebook's direction and the time offset all come from the
/// data. [`BeamMap::fit_leave_one_pass_out`] fits one map per pass on the
/// other passes, so a map is never scored on the sweeps it was fitted to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamMap {
    reference_bearing_rad: f64,
    beam_at_reference: f64,
    beams_per_rad: f64,
    gnss_time_offset_s: f64,
    rms_residual_beams: f64,
    sample_count: usize,
    beam_count: usize,
}

impl BeamMap {
    /// Fits a map to `passes` of a codebook of `beam_count` beams (module
    /// docs).
    ///
    /// # Errors
    /// [`SweepError::BadInput`] for mismatched lengths, non-finite positions
    /// or a best beam outside the codebook; [`SweepError::NonIncreasingTime`];
    /// [`SweepError::DegenerateFit`] for fewer than two distinct bearings or
    /// no candidate offsets.
    pub fn fit(passes: &[MapPass<'_>], beam_count: usize, config: &BeamMapConfig) -> Result<Self, SweepError> {
        for (index, pass) in passes.iter().enumerate() {
            pass.gnss.check(&format!("beam map pass {index}"), pass.best_beam.len())?;
            if let Some(&beam) = pass.best_beam.iter().find(|&&b| b >= beam_count) {
                return Err(SweepError::BadInput {
                    what: format!("beam map pass {index}: best beam {beam} outside a codebook of {beam_count}"),
                });
            }
        }
        let bearings_at = |offset_s: f64| -> Result<Vec<f64>, SweepError> {
            let mut out = Vec::new();
            for pass in passes {
                out.extend(pass.gnss.shifted(offset_s)?.into_iter().map(bearing_rad));
            }
            Ok(out)
        };
        let beams: Vec<f64> = passes.iter().flat_map(|p| p.best_beam.iter().map(|&b| b as f64)).collect();
        let reference_bearing_rad = circular_mean(&bearings_at(0.0)?)
            .ok_or(SweepError::DegenerateFit { what: "no sweeps, or bearings that cancel out" })?;
        let mut best: Option<Self> = None;
        for &offset_s in &config.time_offsets_s {
            let x: Vec<f64> =
                bearings_at(offset_s)?.iter().map(|&phi| wrap_angle_rad(phi - reference_bearing_rad)).collect();
            let Some((intercept, slope, rms)) = least_squares_line(&x, &beams) else {
                continue;
            };
            if best.is_none_or(|b| rms < b.rms_residual_beams) {
                best = Some(Self {
                    reference_bearing_rad,
                    beam_at_reference: intercept,
                    beams_per_rad: slope,
                    gnss_time_offset_s: offset_s,
                    rms_residual_beams: rms,
                    sample_count: beams.len(),
                    beam_count,
                });
            }
        }
        best.ok_or(SweepError::DegenerateFit { what: "fewer than two distinct bearings, or no candidate time offsets" })
    }

    /// One map per pass, each fitted on all the other passes.
    ///
    /// # Errors
    /// As [`BeamMap::fit`] (a single pass leaves nothing to fit on:
    /// [`SweepError::DegenerateFit`]).
    pub fn fit_leave_one_pass_out(
        passes: &[MapPass<'_>],
        beam_count: usize,
        config: &BeamMapConfig,
    ) -> Result<Vec<Self>, SweepError> {
        (0..passes.len())
            .map(|left_out| {
                let others: Vec<MapPass<'_>> =
                    passes.iter().enumerate().filter(|&(i, _)| i != left_out).map(|(_, p)| *p).collect();
                Self::fit(&others, beam_count, config)
            })
            .collect()
    }

    /// Continuous beam index pointing at bearing `bearing_rad` (not limited
    /// to the codebook).
    #[must_use]
    pub fn beam_at_bearing(&self, bearing_rad: f64) -> f64 {
        self.beam_at_reference + self.beams_per_rad * wrap_angle_rad(bearing_rad - self.reference_bearing_rad)
    }

    /// Bearing, radians clockwise from north, of continuous beam `beam`.
    #[must_use]
    pub fn bearing_of_beam(&self, beam: f64) -> f64 {
        wrap_angle_rad(self.reference_bearing_rad + (beam - self.beam_at_reference) / self.beams_per_rad)
    }

    /// The array's boresight: the bearing of the middle beam `(N - 1) / 2`.
    #[must_use]
    pub fn boresight_bearing_rad(&self) -> f64 {
        self.bearing_of_beam(0.5 * (self.beam_count as f64 - 1.0))
    }

    /// Angle between adjacent beams, radians.
    #[must_use]
    pub fn beam_spacing_rad(&self) -> f64 {
        1.0 / self.beams_per_rad.abs()
    }

    /// Beams per radian of bearing; negative when the beam index falls as
    /// the bearing turns clockwise.
    #[must_use]
    pub fn beams_per_rad(&self) -> f64 {
        self.beams_per_rad
    }

    /// The fitted GNSS time offset, seconds: sweep `t` sees the car where
    /// its GNSS track puts it at `t + offset` (positive: the fixes lag).
    #[must_use]
    pub fn gnss_time_offset_s(&self) -> f64 {
        self.gnss_time_offset_s
    }

    /// RMS residual of the fit, beams.
    #[must_use]
    pub fn rms_residual_beams(&self) -> f64 {
        self.rms_residual_beams
    }

    /// Sweeps the map was fitted on.
    #[must_use]
    pub fn sample_count(&self) -> usize {
        self.sample_count
    }

    /// The GNSS beam prediction for each sweep of `pass`: the map at the
    /// car's bearing, shifted by the fitted time offset.
    ///
    /// # Errors
    /// [`SweepError::BadInput`] for mismatched lengths or non-finite
    /// positions; [`SweepError::NonIncreasingTime`].
    pub fn predict_pass(&self, pass: &GnssPass<'_>) -> Result<Vec<f64>, SweepError> {
        pass.check("beam map prediction", pass.t_ns.len())?;
        Ok(pass.shifted(self.gnss_time_offset_s)?.into_iter().map(|p| self.beam_at_bearing(bearing_rad(p))).collect())
    }
}

/// Direction of the mean unit vector of `angles_rad`; `None` when empty or
/// when the vectors cancel out.
fn circular_mean(angles_rad: &[f64]) -> Option<f64> {
    let (sin, cos) = angles_rad.iter().fold((0.0, 0.0), |(s, c), a| (s + a.sin(), c + a.cos()));
    (sin.hypot(cos) > 1e-9 * angles_rad.len() as f64).then(|| sin.atan2(cos))
}

/// Least-squares line `y = a + b x`: `(a, b, rms residual)`; `None` for fewer
/// than two points or no spread in `x`.
fn least_squares_line(x: &[f64], y: &[f64]) -> Option<(f64, f64, f64)> {
    let n = x.len() as f64;
    if x.len() < 2 || x.len() != y.len() {
        return None;
    }
    let (mean_x, mean_y) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|v| (v - mean_x).powi(2)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(u, v)| (u - mean_x) * (v - mean_y)).sum();
    // No spread: all bearings equal to rounding (1e-12 rad^2 per sample).
    if sxx <= 1e-12 * n {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = mean_y - slope * mean_x;
    let sse: f64 = x.iter().zip(y).map(|(u, v)| (v - intercept - slope * u).powi(2)).sum();
    Some((intercept, slope, (sse / n).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pass along the north-south line 15 m west of the array, at 10 m/s,
    /// `sweeps` sweeps at 10 Hz starting `north0_m` north, heading `sign`
    /// (+1 north).
    fn straight_pass(sweeps: usize, north0_m: f64, sign: f64) -> (Vec<i64>, Vec<[f64; 2]>) {
        let t_ns: Vec<i64> = (0..sweeps as i64).map(|k| k * 100_000_000).collect();
        let pos = t_ns.iter().map(|&t| [-15.0, north0_m + sign * 10.0 * t as f64 * 1e-9]).collect();
        (t_ns, pos)
    }

    /// Best beams of a 64-beam codebook with boresight `boresight_rad`, 1.5
    /// degrees per beam, beam index falling clockwise, seen from where the car
    /// is `lag_s` later than its track says (the track lags by `-lag_s`).
    fn true_beams(t_ns: &[i64], pos: &[[f64; 2]], boresight_rad: f64, lag_s: f64) -> Vec<usize> {
        let pass = GnssPass { t_ns, east_north_m: pos };
        let spacing_rad = 1.5_f64.to_radians();
        pass.shifted(lag_s)
            .unwrap()
            .into_iter()
            .map(|p| {
                (31.5 - wrap_angle_rad(bearing_rad(p) - boresight_rad) / spacing_rad).round().clamp(0.0, 63.0) as usize
            })
            .collect()
    }

    #[test]
    fn fit_recovers_boresight_spacing_and_time_offset() {
        // Boresight west-north-west; passes both ways, the true positions
        // 0.3 s ahead of the track.
        let boresight_rad = -100_f64.to_radians();
        let passes: Vec<_> = [(30, -20.0, 1.0), (30, 10.0, -1.0), (25, -15.0, 1.0)]
            .into_iter()
            .map(|(n, north0, sign)| {
                let (t, p) = straight_pass(n, north0, sign);
                let beams = true_beams(&t, &p, boresight_rad, 0.3);
                (t, p, beams)
            })
            .collect();
        let map_passes: Vec<MapPass<'_>> = passes
            .iter()
            .map(|(t, p, b)| MapPass { gnss: GnssPass { t_ns: t, east_north_m: p }, best_beam: b })
            .collect();
        let map = BeamMap::fit(&map_passes, 64, &BeamMapConfig::default()).unwrap();
        // Integer best beams: +-0.5 beam of rounding noise, about 0.29 beam
        // RMS, shifts the fitted line by a fraction of a beam.
        assert!(map.rms_residual_beams() < 0.35, "{map:?}");
        assert!((map.gnss_time_offset_s() - 0.3).abs() < 0.051, "{map:?}");
        // 0.2 deg on a 1.5 deg spacing (a 2 % slope error from the rounding).
        assert!((map.beam_spacing_rad().to_degrees() - 1.5).abs() < 0.03, "{map:?}");
        assert!(map.beams_per_rad() < 0.0, "index falls clockwise");
        // Half a beam of boresight error at most.
        assert!((wrap_angle_rad(map.boresight_bearing_rad() - boresight_rad)).abs() < 0.75_f64.to_radians(), "{map:?}");
        // Predictions reproduce the training beams to rounding.
        let (t, p, b) = &passes[1];
        let predicted = map.predict_pass(&GnssPass { t_ns: t, east_north_m: p }).unwrap();
        assert!(predicted.iter().zip(b).all(|(&x, &y)| (x - y as f64).abs() < 1.0));
        // Leave-one-pass-out: one map per pass, each close to the full fit.
        let maps = BeamMap::fit_leave_one_pass_out(&map_passes, 64, &BeamMapConfig::default()).unwrap();
        assert_eq!(maps.len(), 3);
        assert!(maps.iter().all(|m| (m.beam_spacing_rad().to_degrees() - 1.5).abs() < 0.05), "{maps:?}");
    }

    #[test]
    fn degenerate_and_bad_input_are_errors() {
        let t = [0, 100_000_000];
        let still = [[-15.0, 0.0], [-15.0, 0.0]];
        let pass = MapPass { gnss: GnssPass { t_ns: &t, east_north_m: &still }, best_beam: &[3, 4] };
        assert!(matches!(BeamMap::fit(&[pass], 64, &BeamMapConfig::default()), Err(SweepError::DegenerateFit { .. })));
        let short = MapPass { best_beam: &[3], ..pass };
        assert!(matches!(BeamMap::fit(&[short], 64, &BeamMapConfig::default()), Err(SweepError::BadInput { .. })));
        let outside = MapPass { best_beam: &[3, 64], ..pass };
        assert!(matches!(BeamMap::fit(&[outside], 64, &BeamMapConfig::default()), Err(SweepError::BadInput { .. })));
        let backwards = [100_000_000, 0];
        let moving = [[-15.0, 0.0], [-15.0, 1.0]];
        let pass = MapPass { gnss: GnssPass { t_ns: &backwards, east_north_m: &moving }, best_beam: &[3, 4] };
        assert!(matches!(
            BeamMap::fit(&[pass], 64, &BeamMapConfig::default()),
            Err(SweepError::NonIncreasingTime { .. })
        ));
    }
}
