//! 5G mmWave SLAM worlds (Kim et al. 2018, Sec. V-A): one base station,
//! reflecting walls (each seen as a virtual anchor, footnote 1), scattering
//! points visible within a radius, and a UE driving by the constant
//! turn-rate velocity model (1) with clock-bias drift. Every epoch yields the
//! set of path measurements (TOA, DOA and DOD azimuth and elevation, eq. (2))
//! in random order, with the true UE state and the origin of every path.
//!
//! [`SlamScenario::default`] is the paper's world: BS at (0, 0, 40) m, walls
//! at x = +/-100 m and y = +/-100 m (VAs at (+/-200, 0, 40) and (0, +/-200,
//! 40) m), 10 random SPs near the circular road (radius v/omega = 70.73 m),
//! visible within 50 m, P_D = 1, no clutter, sigma 0.1 m (TOA) and 0.01 rad
//! (angles). The same struct configures other worlds: other roads (initial
//! state, turn rate 0 for a straight road), more walls, explicit SPs, a
//! detection probability below 1 and clutter paths.
//!
//! The paper does not say where its random SPs are; here they are uniform in
//! angle around the road centre, `sp_ring_offset_m` inside or outside the
//! circle (at least `sp_min_offset_m` from it, so that none sits on the road)
//! and `sp_height_m` high. Clutter paths are uniform: TOA between the LOS TOA
//! and `clutter_max_excess_m` beyond it, azimuths over the circle, DOA
//! elevation in [-pi/4, pi/4], DOD elevation in [-pi/2, 0]. A noisy elevation
//! that would pass a pole is clamped to +/-pi/2.
//!
//! A run depends on `(seed, run)` only: [`SlamScenario::realise`] draws the
//! world, the trajectory and every measurement from one stream.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

use mmtrack_core::limits;
use mmtrack_core::random::{standard_normal, stream};
use mmtrack_core::slam::{
    PathMeasurement, PathOrigin, SlamEpoch, SourceType, UeState, dot3, incidence_point, predict_path, sub3,
    virtual_anchor,
};
use mmtrack_core::wrap_angle_rad;
use rand::RngExt;
use rand_pcg::Pcg64;
use serde::{Deserialize, Serialize};

use crate::SimError;
use crate::error::{ensure_finite, ensure_non_negative, ensure_positive, ensure_within, invalid};

/// A reflecting wall: an infinite plane through `point_m` with normal `normal`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    /// A point on the wall, metres.
    pub point_m: [f64; 3],
    /// The wall's normal (any length).
    pub normal: [f64; 3],
}

/// The initial UE state (`x_1` of Sec. V-A).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialState {
    /// Position, metres.
    pub position_m: [f64; 3],
    /// Heading, radians.
    pub heading_rad: f64,
    /// Speed, m/s.
    pub speed_mps: f64,
    /// Turn rate, rad/s.
    pub turn_rate_radps: f64,
    /// Clock bias, metres.
    pub clock_bias_m: f64,
}

impl From<InitialState> for UeState {
    fn from(s: InitialState) -> Self {
        Self {
            position_m: s.position_m,
            heading_rad: s.heading_rad,
            speed_mps: s.speed_mps,
            turn_rate_radps: s.turn_rate_radps,
            clock_bias_m: s.clock_bias_m,
        }
    }
}

/// The world and measurement parameters; the defaults are the paper's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SlamScenario {
    /// Base station position, metres ((0, 0, 40)).
    pub bs_m: [f64; 3],
    /// Reflecting walls (x = +/-100 m, y = +/-100 m).
    pub walls: Vec<Wall>,
    /// Scattering points at fixed positions, metres (none).
    pub scattering_points_m: Vec<[f64; 3]>,
    /// Random scattering points added around the road (10).
    pub random_scattering_points: usize,
    /// Largest distance of a random SP from the circular road, metres (25).
    pub sp_ring_offset_m: f64,
    /// Smallest distance of a random SP from the circular road, metres (5).
    pub sp_min_offset_m: f64,
    /// Height range of the random SPs, metres ([0, 5]).
    pub sp_height_m: [f64; 2],
    /// An SP is seen when the UE is within this distance, metres (50).
    pub sp_visibility_m: f64,
    /// The UE state at the first epoch.
    pub initial: InitialState,
    /// Epoch duration `Delta`, seconds (0.2).
    pub epoch_s: f64,
    /// Number of epochs (100: one lap).
    pub epochs: usize,
    /// Process noise `sigma_v`, m/s (0.1).
    pub speed_std_mps: f64,
    /// Process noise `sigma_omega`, rad/s (0.001).
    pub turn_rate_std_radps: f64,
    /// Process noise `sigma_B`, metres (0.1).
    pub clock_bias_std_m: f64,
    /// TOA noise standard deviation, metres (0.1).
    pub toa_std_m: f64,
    /// DOA/DOD noise standard deviation, radians (0.01).
    pub angle_std_rad: f64,
    /// Probability that a path is detected (1).
    pub detection_probability: f64,
    /// Clutter paths per epoch (0).
    pub clutter_per_epoch: usize,
    /// Largest clutter TOA beyond the LOS TOA, metres (300).
    pub clutter_max_excess_m: f64,
    /// First and last epoch (1-based, inclusive) in which the line of
    /// sight is blocked: its path is absent, the others are unchanged
    /// (none; not in Kim et al., whose LOS is always present).
    pub los_blocked_epochs: Option<[usize; 2]>,
    /// Time of the first epoch, nanoseconds since the UNIX epoch (not in
    /// the paper; default [`crate::DEFAULT_START_T_NS`]).
    pub start_t_ns: i64,
}

impl Default for SlamScenario {
    fn default() -> Self {
        let wall = |point_m: [f64; 3], normal: [f64; 3]| Wall { point_m, normal };
        Self {
            bs_m: [0.0, 0.0, 40.0],
            walls: vec![
                wall([100.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
                wall([0.0, 100.0, 0.0], [0.0, 1.0, 0.0]),
                wall([-100.0, 0.0, 0.0], [-1.0, 0.0, 0.0]),
                wall([0.0, -100.0, 0.0], [0.0, -1.0, 0.0]),
            ],
            scattering_points_m: Vec::new(),
            random_scattering_points: 10,
            sp_ring_offset_m: 25.0,
            sp_min_offset_m: 5.0,
            sp_height_m: [0.0, 5.0],
            sp_visibility_m: 50.0,
            initial: InitialState {
                position_m: [70.73, 0.0, 0.0],
                heading_rad: FRAC_PI_2,
                speed_mps: 22.22,
                turn_rate_radps: PI / 10.0,
                clock_bias_m: 300.0,
            },
            epoch_s: 0.2,
            epochs: 100,
            speed_std_mps: 0.1,
            turn_rate_std_radps: 0.001,
            clock_bias_std_m: 0.1,
            toa_std_m: 0.1,
            angle_std_rad: 0.01,
            detection_probability: 1.0,
            clutter_per_epoch: 0,
            clutter_max_excess_m: 300.0,
            los_blocked_epochs: None,
            start_t_ns: crate::DEFAULT_START_T_NS,
        }
    }
}

/// The true map of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct SlamWorld {
    /// Base station, metres.
    pub bs_m: [f64; 3],
    /// The walls, in the scenario's order.
    pub walls: Vec<Wall>,
    /// Virtual anchors, one per wall, metres.
    pub virtual_anchors_m: Vec<[f64; 3]>,
    /// Scattering points (explicit ones first), metres.
    pub scattering_points_m: Vec<[f64; 3]>,
}

/// Ground truth of one epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct SlamTruth {
    /// The true UE state.
    pub ue: UeState,
    /// The origin of each measured path (same order as the epoch's paths).
    pub origins: Vec<PathOrigin>,
}

/// One realisation: the world, the measurements and the truth per epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct SlamRun {
    /// The true map.
    pub world: SlamWorld,
    /// Measurements per epoch.
    pub epochs: Vec<SlamEpoch>,
    /// Truth per epoch.
    pub truth: Vec<SlamTruth>,
}

impl SlamScenario {
    /// Checks every parameter.
    ///
    /// # Errors
    /// [`SimError::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<(), SimError> {
        for (i, v) in self.bs_m.iter().enumerate() {
            ensure_finite(&format!("bs_m[{i}]"), *v)?;
        }
        for (w, wall) in self.walls.iter().enumerate() {
            virtual_anchor(self.bs_m, wall.point_m, wall.normal).map_err(|_| {
                invalid(format!("walls[{w}].normal"), format!("{:?}", wall.normal), "a non-zero normal")
            })?;
            for v in wall.point_m {
                ensure_finite(&format!("walls[{w}].point_m"), v)?;
            }
        }
        for (s, sp) in self.scattering_points_m.iter().enumerate() {
            for v in sp {
                ensure_finite(&format!("scattering_points_m[{s}]"), *v)?;
            }
        }
        ensure_non_negative("sp_ring_offset_m", self.sp_ring_offset_m)?;
        ensure_within("sp_min_offset_m", self.sp_min_offset_m, 0.0, self.sp_ring_offset_m, "in [0, sp_ring_offset_m]")?;
        ensure_finite("sp_height_m[0]", self.sp_height_m[0])?;
        ensure_within("sp_height_m[1]", self.sp_height_m[1], self.sp_height_m[0], f64::MAX, ">= sp_height_m[0]")?;
        ensure_positive("sp_visibility_m", self.sp_visibility_m)?;
        let i = &self.initial;
        for v in i.position_m {
            ensure_finite("initial.position_m", v)?;
        }
        ensure_finite("initial.heading_rad", i.heading_rad)?;
        ensure_finite("initial.speed_mps", i.speed_mps)?;
        ensure_finite("initial.turn_rate_radps", i.turn_rate_radps)?;
        ensure_finite("initial.clock_bias_m", i.clock_bias_m)?;
        ensure_positive("epoch_s", self.epoch_s)?;
        if self.epochs == 0 || !limits::SLAM_EPOCHS.allows_count(self.epochs as u64) {
            return Err(invalid("epochs", self.epochs, limits::SLAM_EPOCHS.expected));
        }
        let run_ns = self.epochs as f64 * self.epoch_s * 1e9;
        if !run_ns.is_finite() || run_ns >= (i64::MAX - self.start_t_ns.max(0)) as f64 {
            return Err(invalid("start_t_ns", self.start_t_ns, "a start whose last epoch ends before the year 2262"));
        }
        if !limits::CLUTTER_PER_EPOCH.allows_count(self.clutter_per_epoch as u64) {
            return Err(invalid("clutter_per_epoch", self.clutter_per_epoch, limits::CLUTTER_PER_EPOCH.expected));
        }
        if !limits::SCATTERING_POINTS.allows_count(self.random_scattering_points as u64) {
            return Err(invalid(
                "random_scattering_points",
                self.random_scattering_points,
                limits::SCATTERING_POINTS.expected,
            ));
        }
        ensure_non_negative("speed_std_mps", self.speed_std_mps)?;
        ensure_non_negative("turn_rate_std_radps", self.turn_rate_std_radps)?;
        ensure_non_negative("clock_bias_std_m", self.clock_bias_std_m)?;
        ensure_non_negative("toa_std_m", self.toa_std_m)?;
        ensure_non_negative("angle_std_rad", self.angle_std_rad)?;
        ensure_within("detection_probability", self.detection_probability, 0.0, 1.0, "a probability in [0, 1]")?;
        ensure_positive("clutter_max_excess_m", self.clutter_max_excess_m)?;
        if let Some([first, last]) = self.los_blocked_epochs
            && !(1 <= first && first <= last && last <= self.epochs)
        {
            return Err(invalid(
                "los_blocked_epochs",
                format!("[{first}, {last}]"),
                "[first, last] with 1 <= first <= last <= epochs",
            ));
        }
        Ok(())
    }

    /// Centre and radius of the circular road (`v/omega` to the left of the
    /// initial heading); `None` for a straight road.
    fn road_circle(&self) -> Option<([f64; 2], f64)> {
        let i = &self.initial;
        if i.turn_rate_radps.abs() < 1e-12 {
            return None;
        }
        let r = i.speed_mps / i.turn_rate_radps;
        let (s, c) = i.heading_rad.sin_cos();
        Some(([i.position_m[0] - r * s, i.position_m[1] + r * c], r.abs()))
    }

    /// Realisation `run` under `seed`.
    ///
    /// # Errors
    /// [`SimError::InvalidParameter`] when the scenario does not validate.
    pub fn realise(&self, seed: u64, run: u64) -> Result<SlamRun, SimError> {
        self.validate()?;
        let mut rng = stream(seed, &[0x0073_6c61_6d00, run]);
        let world = self.draw_world(&mut rng)?;
        let mut ue = UeState::from(self.initial);
        let mut epochs = Vec::with_capacity(self.epochs);
        let mut truth = Vec::with_capacity(self.epochs);
        for k in 0..self.epochs {
            let t_ns = self.start_t_ns + (k as f64 * self.epoch_s * 1e9).round() as i64;
            let los_blocked = self.los_blocked_epochs.is_some_and(|[first, last]| (first..=last).contains(&(k + 1)));
            let (paths, origins) = self.measure(&world, &ue, los_blocked, &mut rng);
            epochs.push(SlamEpoch { t_ns, paths });
            truth.push(SlamTruth { ue, origins });
            ue = ue.ctrv_step(self.epoch_s);
            ue.speed_mps += self.speed_std_mps * standard_normal(&mut rng);
            ue.turn_rate_radps += self.turn_rate_std_radps * standard_normal(&mut rng);
            ue.clock_bias_m += self.clock_bias_std_m * standard_normal(&mut rng);
        }
        Ok(SlamRun { world, epochs, truth })
    }

    fn draw_world(&self, rng: &mut Pcg64) -> Result<SlamWorld, SimError> {
        let mut virtual_anchors_m = Vec::with_capacity(self.walls.len());
        for (w, wall) in self.walls.iter().enumerate() {
            virtual_anchors_m.push(
                virtual_anchor(self.bs_m, wall.point_m, wall.normal)
                    .map_err(|_| invalid(format!("walls[{w}].normal"), "zero", "a non-zero normal"))?,
            );
        }
        let mut scattering_points_m = self.scattering_points_m.clone();
        for _ in 0..self.random_scattering_points {
            let offset = self.sp_min_offset_m + (self.sp_ring_offset_m - self.sp_min_offset_m) * rng.random::<f64>();
            let side = if rng.random::<bool>() { 1.0 } else { -1.0 };
            let z = self.sp_height_m[0] + (self.sp_height_m[1] - self.sp_height_m[0]) * rng.random::<f64>();
            let p = match self.road_circle() {
                Some((centre, radius)) => {
                    let angle = TAU * rng.random::<f64>();
                    let r = (radius + side * offset).max(0.0);
                    [centre[0] + r * angle.cos(), centre[1] + r * angle.sin(), z]
                }
                None => {
                    // A straight road: uniform along the drive, beside it.
                    let i = &self.initial;
                    let along = i.speed_mps * self.epoch_s * self.epochs as f64 * rng.random::<f64>();
                    let (s, c) = i.heading_rad.sin_cos();
                    [
                        i.position_m[0] + along * c - side * offset * s,
                        i.position_m[1] + along * s + side * offset * c,
                        z,
                    ]
                }
            };
            scattering_points_m.push(p);
        }
        Ok(SlamWorld { bs_m: self.bs_m, walls: self.walls.clone(), virtual_anchors_m, scattering_points_m })
    }

    /// The paths of one epoch (detected ones, plus clutter), shuffled;
    /// without the line of sight when `los_blocked`.
    fn measure(
        &self,
        world: &SlamWorld,
        ue: &UeState,
        los_blocked: bool,
        rng: &mut Pcg64,
    ) -> (Vec<PathMeasurement>, Vec<PathOrigin>) {
        let mut sources: Vec<(PathOrigin, SourceType, [f64; 3])> =
            vec![(PathOrigin::LineOfSight, SourceType::BaseStation, world.bs_m)];
        for (v, (va, wall)) in world.virtual_anchors_m.iter().zip(&world.walls).enumerate() {
            if reflects(world.bs_m, *wall, *va, ue.position_m) {
                sources.push((PathOrigin::VirtualAnchor(v), SourceType::VirtualAnchor, *va));
            }
        }
        for (s, sp) in world.scattering_points_m.iter().enumerate() {
            if mmtrack_core::slam::norm3(sub3(*sp, ue.position_m)) <= self.sp_visibility_m {
                sources.push((PathOrigin::ScatteringPoint(s), SourceType::ScatteringPoint, *sp));
            }
        }
        let mut paths = Vec::with_capacity(sources.len() + self.clutter_per_epoch);
        let mut origins = Vec::with_capacity(paths.capacity());
        let mut los_toa_m = ue.clock_bias_m;
        for (origin, kind, at) in sources {
            // Every draw happens whether or not the path is detected, so P_D
            // does not shift the noise of the other paths.
            let detected = rng.random::<f64>() < self.detection_probability;
            let noise: [f64; 5] = std::array::from_fn(|_| standard_normal(rng));
            let Some(z) = predict_path(ue, world.bs_m, kind, at) else { continue };
            if origin == PathOrigin::LineOfSight {
                los_toa_m = z.toa_m;
            }
            if !detected {
                continue;
            }
            let a = self.angle_std_rad;
            paths.push(PathMeasurement {
                toa_m: z.toa_m + self.toa_std_m * noise[0],
                doa_az_rad: wrap_angle_rad(z.doa_az_rad + a * noise[1]),
                doa_el_rad: (z.doa_el_rad + a * noise[2]).clamp(-FRAC_PI_2, FRAC_PI_2),
                dod_az_rad: wrap_angle_rad(z.dod_az_rad + a * noise[3]),
                dod_el_rad: (z.dod_el_rad + a * noise[4]).clamp(-FRAC_PI_2, FRAC_PI_2),
            });
            origins.push(origin);
        }
        for _ in 0..self.clutter_per_epoch {
            paths.push(PathMeasurement {
                toa_m: los_toa_m + self.clutter_max_excess_m * rng.random::<f64>(),
                doa_az_rad: wrap_angle_rad(TAU * rng.random::<f64>()),
                doa_el_rad: FRAC_PI_4 * (2.0 * rng.random::<f64>() - 1.0),
                dod_az_rad: wrap_angle_rad(TAU * rng.random::<f64>()),
                dod_el_rad: -FRAC_PI_2 * rng.random::<f64>(),
            });
            origins.push(PathOrigin::Clutter);
        }
        // The measurement set has no order (Sec. II-B): Fisher-Yates.
        for i in (1..paths.len()).rev() {
            let j = rng.random_range(0..=i);
            paths.swap(i, j);
            origins.swap(i, j);
        }
        // A blocked LOS is removed only now, after every draw, so the other
        // paths, their noise and the trajectory are those of the open run.
        if los_blocked && let Some(i) = origins.iter().position(|o| *o == PathOrigin::LineOfSight) {
            paths.remove(i);
            origins.remove(i);
        }
        (paths, origins)
    }
}

/// Whether a wall reflects the BS's signal to the UE: both on the same side
/// of it and the incidence point (11) exists.
fn reflects(bs_m: [f64; 3], wall: Wall, va_m: [f64; 3], ue_m: [f64; 3]) -> bool {
    let side_bs = dot3(sub3(bs_m, wall.point_m), wall.normal);
    let side_ue = dot3(sub3(ue_m, wall.point_m), wall.normal);
    side_bs * side_ue > 0.0 && incidence_point(va_m, bs_m, ue_m).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;
    use mmtrack_core::slam::norm3;

    #[test]
    fn the_paper_world_has_its_sources_and_paths() {
        let scenario = SlamScenario::default();
        let run = scenario.realise(7, 0).unwrap();
        let va = &run.world.virtual_anchors_m;
        assert_eq!(va.len(), 4);
        for expected in [[200.0, 0.0, 40.0], [0.0, 200.0, 40.0], [-200.0, 0.0, 40.0], [0.0, -200.0, 40.0]] {
            assert!(va.iter().any(|v| norm3(sub3(*v, expected)) < 1e-9), "{expected:?} missing from {va:?}");
        }
        assert_eq!(run.world.scattering_points_m.len(), 10);
        assert_eq!(run.epochs.len(), 100);
        // Epoch 1: LOS + 4 VAs + the SPs within 50 m, each exactly once.
        let first = &run.truth[0];
        assert_eq!(first.ue.position_m, [70.73, 0.0, 0.0]);
        let visible_sp =
            run.world.scattering_points_m.iter().filter(|p| norm3(sub3(**p, first.ue.position_m)) <= 50.0).count();
        assert_eq!(run.epochs[0].paths.len(), 5 + visible_sp);
        assert_eq!(first.origins.iter().filter(|o| **o == PathOrigin::LineOfSight).count(), 1);
        // After one lap (100 epochs of 0.2 s at pi/10 rad/s) the UE is back near the start.
        let last = run.truth.last().unwrap().ue.ctrv_step(0.2);
        assert!(norm3(sub3(last.position_m, [70.73, 0.0, 0.0])) < 10.0, "{:?}", last.position_m);
        // Every measurement is valid and noise is at the configured scale.
        let mut toa_residuals = Vec::new();
        for (epoch, truth) in run.epochs.iter().zip(&run.truth) {
            for (z, origin) in epoch.paths.iter().zip(&truth.origins) {
                z.validate().unwrap();
                let (kind, at) = match origin {
                    PathOrigin::LineOfSight => (SourceType::BaseStation, run.world.bs_m),
                    PathOrigin::VirtualAnchor(i) => (SourceType::VirtualAnchor, run.world.virtual_anchors_m[*i]),
                    PathOrigin::ScatteringPoint(i) => (SourceType::ScatteringPoint, run.world.scattering_points_m[*i]),
                    PathOrigin::Clutter => unreachable!("no clutter by default"),
                };
                let clean = predict_path(&truth.ue, run.world.bs_m, kind, at).unwrap();
                toa_residuals.push(z.toa_m - clean.toa_m);
            }
        }
        let rms = (toa_residuals.iter().map(|r| r * r).sum::<f64>() / toa_residuals.len() as f64).sqrt();
        // ~1000 residuals of sigma 0.1 m: the RMS is within 10 % of 0.1 (4 sigma of its spread).
        assert!((rms - 0.1).abs() < 0.01, "{rms}");
    }

    #[test]
    fn a_blocked_line_of_sight_removes_only_its_path_in_the_stretch() {
        let open = SlamScenario::default().realise(7, 0).unwrap();
        let blocked =
            SlamScenario { los_blocked_epochs: Some([41, 60]), ..SlamScenario::default() }.realise(7, 0).unwrap();
        assert_eq!(open.truth.len(), blocked.truth.len());
        for (k, ((a, ta), (b, tb))) in
            open.epochs.iter().zip(&open.truth).zip(blocked.epochs.iter().zip(&blocked.truth)).enumerate()
        {
            assert_eq!(ta.ue, tb.ue, "epoch {}: the same trajectory", k + 1);
            let los = |origins: &[PathOrigin]| origins.iter().filter(|o| **o == PathOrigin::LineOfSight).count();
            let in_stretch = (41..=60).contains(&(k + 1));
            assert_eq!(los(&ta.origins), 1);
            assert_eq!(los(&tb.origins), usize::from(!in_stretch), "epoch {}", k + 1);
            // The other paths and their noise are those of the open run.
            let others = |e: &SlamEpoch, t: &SlamTruth| {
                let mut v: Vec<(String, u64)> = e
                    .paths
                    .iter()
                    .zip(&t.origins)
                    .filter(|(_, o)| **o != PathOrigin::LineOfSight)
                    .map(|(z, o)| (format!("{o:?}"), z.toa_m.to_bits()))
                    .collect();
                v.sort();
                v
            };
            assert_eq!(others(a, ta), others(b, tb), "epoch {}", k + 1);
        }
        for bad in [[0, 5], [6, 5], [90, 101]] {
            let s = SlamScenario { los_blocked_epochs: Some(bad), ..SlamScenario::default() };
            assert!(s.validate().unwrap_err().to_string().contains("los_blocked_epochs"), "{bad:?}");
        }
    }

    #[test]
    fn detection_and_clutter_and_determinism() {
        let scenario = SlamScenario { detection_probability: 0.5, clutter_per_epoch: 2, ..SlamScenario::default() };
        let a = scenario.realise(3, 4).unwrap();
        assert_eq!(a, scenario.realise(3, 4).unwrap());
        assert_ne!(a, scenario.realise(3, 5).unwrap());
        let clutter: usize =
            a.truth.iter().map(|t| t.origins.iter().filter(|o| **o == PathOrigin::Clutter).count()).sum();
        assert_eq!(clutter, 200);
        let real: usize = a.truth.iter().map(|t| t.origins.len()).sum::<usize>() - clutter;
        let full: usize = SlamScenario::default().realise(3, 4).unwrap().truth.iter().map(|t| t.origins.len()).sum();
        // Half of ~1000 paths detected: within 10 % (more than 6 binomial sigmas).
        let ratio = real as f64 / full as f64;
        assert!((ratio - 0.5).abs() < 0.1, "{ratio}");
        for e in &a.epochs {
            for z in &e.paths {
                z.validate().unwrap();
            }
        }
    }

    #[test]
    fn a_straight_road_with_more_walls() {
        // Straight along +x at 15 m/s, a fifth wall at y = 30 m, SPs beside the road.
        let mut walls = SlamScenario::default().walls;
        walls.push(Wall { point_m: [0.0, 30.0, 0.0], normal: [0.0, 1.0, 0.0] });
        let scenario = SlamScenario {
            walls,
            initial: InitialState {
                position_m: [-50.0, -10.0, 0.0],
                heading_rad: 0.0,
                speed_mps: 15.0,
                turn_rate_radps: 0.0,
                clock_bias_m: 0.0,
            },
            turn_rate_std_radps: 0.0,
            epochs: 30,
            ..SlamScenario::default()
        };
        let run = scenario.realise(1, 0).unwrap();
        assert_eq!(run.world.virtual_anchors_m.len(), 5);
        // The wall y = 30 mirrors the BS (0, 0, 40) to (0, 60, 40).
        assert!(norm3(sub3(run.world.virtual_anchors_m[4], [0.0, 60.0, 40.0])) < 1e-9);
        for sp in &run.world.scattering_points_m {
            let off = (sp[1] + 10.0).abs();
            assert!((5.0..=25.0).contains(&off) && (-50.0..=40.0).contains(&sp[0]), "{sp:?}");
        }
        // The heading stays 0 and y stays -10 (no turn-rate noise).
        let last = run.truth.last().unwrap().ue;
        assert!(last.heading_rad.abs() < 1e-12 && (last.position_m[1] + 10.0).abs() < 1e-9, "{last:?}");
        // Every epoch sees the LOS and the five reflections (all walls face the road).
        for truth in &run.truth {
            let reflections = truth.origins.iter().filter(|o| matches!(o, PathOrigin::VirtualAnchor(_))).count();
            assert_eq!(reflections, 5);
        }
    }

    #[test]
    fn bad_parameters_are_named() {
        let s = SlamScenario { detection_probability: 1.5, ..SlamScenario::default() };
        assert!(s.validate().unwrap_err().to_string().contains("detection_probability"));
        let s = SlamScenario { walls: vec![Wall { point_m: [0.0; 3], normal: [0.0; 3] }], ..SlamScenario::default() };
        assert!(s.validate().unwrap_err().to_string().contains("walls[0].normal"));
    }
}
