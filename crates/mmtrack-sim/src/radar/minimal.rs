//! The minimal renderer that came first: point and wall reflectors with a
//! fixed strength law, uniform noise, no speckle. Kept (unchanged in output)
//! because `mmtrack bench io` builds its synthetic scans with it; new code
//! uses [`super::RadarSimulator`], whose model is calibrated on real scans.
//!
//! Per azimuth `a` at time `t_a`, the sensor pose is `world_from_vehicle(t_a)`
//! (so vehicle motion during the sweep distorts the scan, as on the real
//! sensor). The beam points along azimuth angle `theta_a`, measured clockwise
//! from the vehicle's forward axis as Navtech encoders count (seen from above):
//! direction in the vehicle frame `(cos theta, -sin theta)`.
//!
//! Returns: each reflector hit by the beam adds a peak of height
//! `strength_counts * (r_ref / r)^2` (range loss in 8-bit power counts, a
//! simplification of the radar equation's r^-4 after the sensor's log
//! compression) with a Gaussian range profile of `range_spread_bins`. Walls
//! occlude what lies behind them along the beam. Receiver noise is uniform
//! in `[0, noise_counts]`. The sum saturates at 255 like the sensor's 8-bit
//! output.

use std::f64::consts::TAU;

use mmtrack_core::{AzimuthSample, PolarScan, PolarScanHeader, Se2, StampedPose};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use serde::Deserialize;

use super::trajectory::ConstantTurn;

/// Sensor parameters.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RadarSensor {
    /// Azimuth rows per sweep (Navtech: 400).
    pub azimuths: usize,
    /// Range bins per row.
    pub bins: usize,
    /// Range bin size, metres.
    pub range_resolution_m: f64,
    /// Sweep period, seconds (Navtech CTS350-X: 0.25).
    pub sweep_period_s: f64,
    /// Width of a return's Gaussian range profile (1 sigma), bins.
    pub range_spread_bins: f64,
    /// Upper bound of uniform receiver noise, power counts.
    pub noise_counts: u8,
}

/// A reflector of the scene, in world coordinates.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Reflector {
    /// A pole or other point-like target.
    Point {
        /// World x, metres.
        x_m: f64,
        /// World y, metres.
        y_m: f64,
        /// Peak power at 10 m, counts.
        strength_counts: f64,
    },
    /// A wall segment from `a` to `b`.
    Wall {
        /// One end, world metres.
        a_m: [f64; 2],
        /// Other end, world metres.
        b_m: [f64; 2],
        /// Peak power at 10 m, counts.
        strength_counts: f64,
    },
}

/// A radar scenario: sensor, scene, motion, length and seed.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RadarScenario {
    /// Seed of the noise generator.
    pub seed: u64,
    /// Time of the first sweep, nanoseconds (a UNIX time, so fixtures look like real files).
    pub start_t_ns: i64,
    /// Number of sweeps.
    pub scans: usize,
    /// The sensor.
    pub sensor: RadarSensor,
    /// The vehicle motion.
    pub motion: ConstantTurn,
    /// The scene.
    pub reflectors: Vec<Reflector>,
}

/// Reference range of `strength_counts`, metres.
const REFERENCE_RANGE_M: f64 = 10.0;

/// Range along a beam from `origin` in direction `dir` to the segment a-b, if hit.
fn ray_segment_range_m(origin: [f64; 2], dir: [f64; 2], a: [f64; 2], b: [f64; 2]) -> Option<f64> {
    let edge = [b[0] - a[0], b[1] - a[1]];
    let denominator = dir[0] * edge[1] - dir[1] * edge[0];
    if denominator.abs() < 1e-12 {
        return None;
    }
    let to_a = [a[0] - origin[0], a[1] - origin[1]];
    let range_m = (to_a[0] * edge[1] - to_a[1] * edge[0]) / denominator;
    let along = (to_a[0] * dir[1] - to_a[1] * dir[0]) / denominator;
    (range_m > 0.0 && (0.0..=1.0).contains(&along)).then_some(range_m)
}

/// Renders every sweep of a scenario; returns the scans and the ground-truth
/// pose at each scan's stamp (the time of its first azimuth).
#[must_use]
pub fn simulate(scenario: &RadarScenario) -> (Vec<PolarScan>, Vec<StampedPose>) {
    let mut rng = Pcg64::seed_from_u64(scenario.seed);
    let sensor = &scenario.sensor;
    let sweep_ns = (sensor.sweep_period_s * 1e9).round() as i64;
    let azimuth_ns = sweep_ns / sensor.azimuths.max(1) as i64;
    let beam_half_width_rad = 0.5 * TAU / sensor.azimuths.max(1) as f64;
    let mut scans = Vec::with_capacity(scenario.scans);
    let mut truth = Vec::with_capacity(scenario.scans);
    for s in 0..scenario.scans {
        let scan_t_ns = scenario.start_t_ns + s as i64 * sweep_ns;
        let mut azimuths = Vec::with_capacity(sensor.azimuths);
        let mut power = Vec::with_capacity(sensor.azimuths * sensor.bins);
        for a in 0..sensor.azimuths {
            let t_ns = scan_t_ns + a as i64 * azimuth_ns;
            let azimuth_rad = a as f64 * TAU / sensor.azimuths as f64;
            let pose = scenario.motion.pose_at((t_ns - scenario.start_t_ns) as f64 * 1e-9);
            azimuths.push(AzimuthSample { t_ns, azimuth_rad, valid: true });
            let mut row: Vec<f64> =
                (0..sensor.bins).map(|_| f64::from(rng.random_range(0..=sensor.noise_counts))).collect();
            for (range_m, strength) in beam_returns(scenario, pose, azimuth_rad, beam_half_width_rad) {
                add_return(&mut row, sensor, range_m, strength * (REFERENCE_RANGE_M / range_m.max(1.0)).powi(2));
            }
            // The sensor's 8-bit output saturates: this is the model, not input clamping.
            power.extend(row.iter().map(|v| v.round().clamp(0.0, 255.0) as u8));
        }
        let header = PolarScanHeader {
            t_ns: scan_t_ns,
            range_resolution_m: sensor.range_resolution_m,
            range_offset_m: 0.0,
            bins_per_azimuth: sensor.bins,
            azimuths,
        };
        scans.push(PolarScan { header, power });
        truth.push(StampedPose {
            t_ns: scan_t_ns,
            parent_from_child: scenario.motion.pose_at((scan_t_ns - scenario.start_t_ns) as f64 * 1e-9),
        });
    }
    (scans, truth)
}

/// `(range_m, strength_counts)` of every reflector the beam sees, nearest wall occluding.
fn beam_returns(scenario: &RadarScenario, pose: Se2, azimuth_rad: f64, half_width_rad: f64) -> Vec<(f64, f64)> {
    let heading = pose.yaw_rad - azimuth_rad;
    let dir = [heading.cos(), heading.sin()];
    let origin = [pose.x_m, pose.y_m];
    let nearest_wall_m = scenario
        .reflectors
        .iter()
        .filter_map(|r| match r {
            Reflector::Wall { a_m, b_m, .. } => ray_segment_range_m(origin, dir, *a_m, *b_m),
            Reflector::Point { .. } => None,
        })
        .fold(f64::INFINITY, f64::min);
    let mut out = Vec::new();
    for reflector in &scenario.reflectors {
        match reflector {
            Reflector::Wall { a_m, b_m, strength_counts } => {
                if let Some(range_m) = ray_segment_range_m(origin, dir, *a_m, *b_m)
                    && range_m <= nearest_wall_m
                {
                    out.push((range_m, *strength_counts));
                }
            }
            Reflector::Point { x_m, y_m, strength_counts } => {
                let p_in_vehicle = pose.inverse().transform_point([*x_m, *y_m]);
                let range_m = p_in_vehicle[0].hypot(p_in_vehicle[1]);
                let bearing_cw_rad = (-p_in_vehicle[1]).atan2(p_in_vehicle[0]).rem_euclid(TAU);
                let off_rad = mmtrack_core::wrap_angle_rad(bearing_cw_rad - azimuth_rad).abs();
                if off_rad <= half_width_rad && range_m < nearest_wall_m {
                    out.push((range_m, *strength_counts));
                }
            }
        }
    }
    out
}

fn add_return(row: &mut [f64], sensor: &RadarSensor, range_m: f64, peak_counts: f64) {
    let centre_bin = range_m / sensor.range_resolution_m;
    let spread = sensor.range_spread_bins.max(0.1);
    let reach = (4.0 * spread).ceil() as i64;
    let centre = centre_bin.round() as i64;
    for bin in (centre - reach)..=(centre + reach) {
        if let Some(value) = usize::try_from(bin).ok().and_then(|b| row.get_mut(b)) {
            let z = (bin as f64 - centre_bin) / spread;
            *value += peak_counts * (-0.5 * z * z).exp();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scenario() -> RadarScenario {
        RadarScenario {
            seed: 7,
            start_t_ns: 1_000_000_000,
            scans: 2,
            sensor: RadarSensor {
                azimuths: 400,
                bins: 500,
                range_resolution_m: 0.1,
                sweep_period_s: 0.25,
                range_spread_bins: 1.0,
                noise_counts: 2,
            },
            motion: ConstantTurn { speed_mps: 0.0, yaw_rate_radps: 0.0 },
            reflectors: vec![Reflector::Point { x_m: 20.0, y_m: 0.0, strength_counts: 200.0 }],
        }
    }

    #[test]
    fn point_ahead_appears_at_its_range_on_azimuth_zero() {
        let (scans, truth) = simulate(&scenario());
        assert_eq!(truth.len(), 2);
        let row = scans[0].row(0).unwrap();
        let peak_bin = row.iter().enumerate().max_by_key(|(_, v)| **v).unwrap().0;
        assert_eq!(peak_bin, 200); // 20 m / 0.1 m
        // 200 counts * (10/20)^2 = 50 counts above noise of at most 2.
        assert!((48..=52).contains(&row[200]), "{}", row[200]);
        // Nothing on the opposite azimuth.
        assert!(scans[0].row(200).unwrap().iter().all(|v| *v <= 2));
    }

    #[test]
    fn same_seed_same_bytes() {
        assert_eq!(simulate(&scenario()), simulate(&scenario()));
    }

    #[test]
    fn wall_occludes_point_behind_it() {
        let mut s = scenario();
        s.reflectors.push(Reflector::Wall { a_m: [10.0, -5.0], b_m: [10.0, 5.0], strength_counts: 100.0 });
        let (scans, _) = simulate(&s);
        let row = scans[0].row(0).unwrap();
        assert!(row[100] > 50, "wall at 10 m");
        assert!(row[200] <= 2, "point at 20 m hidden");
    }
}
