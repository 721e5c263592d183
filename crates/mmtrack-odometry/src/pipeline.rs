//! The odometry loop: filter, surface points, register against the keyframe
//! submap, keep the constant-velocity model and the keyframes up to date.

use std::collections::VecDeque;
use std::time::Instant;

use mmtrack_core::{OdometryEstimate, OdometryTiming, PolarScan, Se2};

use crate::filter::{BodyVelocity, PolarPoint, SweepMotion, k_strongest, place, sweep_middle_ns};
use crate::register::{Reference, associate, solve};
use crate::surface::{SurfaceParams, SurfacePoint, surface_points};
use crate::{OdometryConfig, OdometryError};

/// Below this translational observability (eigenvalue ratio of the
/// translational normal matrix) the scene constrains one direction too weakly
/// to trust, e.g. a straight featureless tunnel.
pub const MIN_TRANSLATION_OBSERVABILITY: f64 = 1e-3;

/// Starts of the second scan's registration besides rest, in association
/// radii (`grid_m`) straight ahead of the first scan's pose (negative:
/// behind); see [`RadarOdometry::register_from_rest`].
const FROM_REST_STARTS_IN_RADII: [f64; 4] = [1.0, 2.0, 3.0, -1.0];

/// A keyframe: its pose and its surface points, ready for association.
#[derive(Debug, Clone)]
struct Keyframe {
    world_from_vehicle: Se2,
    reference: Reference,
}

/// The previous scan: its stamp, and its pose in the pipeline's frame at the
/// instant its points were placed at (the stamp, or with motion
/// compensation the middle of its sweep).
#[derive(Debug, Clone, Copy)]
struct Previous {
    stamp_ns: i64,
    placed_t_ns: i64,
    world_from_vehicle: Se2,
}

/// One scan's result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanOdometry {
    /// The pose and its diagnostics (deterministic).
    pub estimate: OdometryEstimate,
    /// Time per stage (varies run to run).
    pub timing: OdometryTiming,
}

/// Radar odometry over a sequence of scans, fed one scan at a time in time
/// order. Memory is bounded by the keyframe submap, whatever the sequence length.
///
/// The world frame is the first scan's pose. Each scan: (1) k-strongest filter
/// (with motion compensation: placed at the middle of the sweep with the
/// previous step's velocity), (2)-(3) oriented surface points, (4)
/// registration to the submap starting from the constant-velocity
/// prediction, re-associating `association_rounds` times. When registration
/// cannot be trusted (too few correspondences, a degenerate scene, a
/// non-finite result) the pose follows the prediction and the estimate is
/// flagged `low_confidence`: never a NaN pose.
///
/// Motion compensation as the CFEAR authors' code does it (`Compensate` in
/// their `utils.cpp`, called once per scan before the surface points): each
/// point is moved to the middle of its sweep with the velocity of the step
/// before, once. Placed at the middle, a velocity error `e` only skews the
/// sweep (`e (t - t_mid)` has zero mean); placed at the scan's stamp (Oxford:
/// the first azimuth) it would also shift the whole sweep by `e T / 2`, and
/// with the next velocity taken from the resulting estimate the step errors
/// obey `d_k = -(d_{k-1} - d_{k-2}) / 2`, whose root -1 makes the steps
/// oscillate without decaying. The poses inside the pipeline are at the
/// middle of each sweep; the estimate is moved back to the stamp with the
/// estimated velocity.
#[derive(Debug, Clone)]
pub struct RadarOdometry {
    config: OdometryConfig,
    surface: SurfaceParams,
    keyframes: VecDeque<Keyframe>,
    previous: Option<Previous>,
    velocity: BodyVelocity,
    /// With motion compensation: the world frame (the first scan's pose at
    /// its stamp) from the pipeline's frame (the first scan's pose at the
    /// middle of its sweep), known from the second scan on.
    world_from_pipeline: Option<Se2>,
    /// With motion compensation: the first scan's kept bins and the middle
    /// of its sweep after its stamp (seconds), until the second scan gives
    /// the velocity to place them with.
    first_kept: Option<(Vec<PolarPoint>, f64)>,
    /// Whether a registration has given the velocity (from the second scan on).
    velocity_known: bool,
}

impl RadarOdometry {
    /// A pipeline with a checked configuration.
    pub fn new(config: OdometryConfig) -> Result<Self, OdometryError> {
        config.validate()?;
        let surface = SurfaceParams {
            radius_m: config.grid_m,
            cell_m: config.grid_m / config.resample_factor,
            min_neighbours: config.min_surface_neighbours,
            max_condition_number: config.max_condition_number,
        };
        Ok(Self {
            config,
            surface,
            keyframes: VecDeque::new(),
            previous: None,
            velocity: BodyVelocity::default(),
            world_from_pipeline: None,
            first_kept: None,
            velocity_known: false,
        })
    }

    /// The configuration in use.
    #[must_use]
    pub fn config(&self) -> &OdometryConfig {
        &self.config
    }

    /// Processes the next scan.
    pub fn process(&mut self, scan: &PolarScan) -> Result<ScanOdometry, OdometryError> {
        check_scan(scan)?;
        let t_ns = scan.header.t_ns;
        if let Some(previous) = self.previous
            && t_ns <= previous.stamp_ns
        {
            return Err(OdometryError::NonMonotonicTime { previous_t_ns: previous.stamp_ns, t_ns });
        }
        let config = &self.config;
        let compensate = config.motion_compensation;
        // The instant the points are placed at, and the pose is estimated at.
        let middle_ns = if compensate { sweep_middle_ns(&scan.header) } else { 0 };
        let placed_t_ns = t_ns + middle_ns;
        if let Some(previous) = self.previous
            && placed_t_ns <= previous.placed_t_ns
        {
            let detail = format!(
                "the middle of its sweep (t_ns {placed_t_ns}) is not after the previous scan's (t_ns {})",
                previous.placed_t_ns
            );
            return Err(OdometryError::BadScan { t_ns, detail });
        }
        let mut clock = StageClock::start();
        let kept = k_strongest(scan, config.k_strongest, config.min_power, config.min_range_m, config.max_range_m);
        clock.lap_filter();

        let mut estimate = OdometryEstimate {
            t_ns,
            world_from_vehicle: Se2::IDENTITY,
            filtered_points: kept.len() as u32,
            surface_points: 0,
            correspondences: 0,
            iterations: 0,
            cost_m2: 0.0,
            low_confidence: false,
        };
        let middle_s = middle_ns as f64 * 1e-9;
        let motion = compensate.then_some(SweepMotion { velocity: self.velocity, reference_dt_s: middle_s });
        let mut surface = surface_points(&place(&kept, motion), &self.surface);
        clock.lap_surface();
        let pose = match self.previous {
            None => {
                if compensate {
                    self.first_kept = Some((kept, middle_s));
                }
                Se2::IDENTITY
            }
            Some(previous) => {
                let dt_s = (placed_t_ns - previous.placed_t_ns) as f64 * 1e-9;
                let predicted = previous.world_from_vehicle * self.velocity.motion_over(dt_s);
                let (mut pose, mut trusted) = if self.velocity_known {
                    self.register(&surface, predicted, &mut estimate)
                } else {
                    self.register_from_rest(&surface, predicted, &mut estimate)
                };
                self.velocity_known = true;
                self.velocity = BodyVelocity::from_motion(previous.world_from_vehicle.inverse() * pose, dt_s);
                if let Some((first, first_middle_s)) = self.first_kept.take() {
                    // The second scan: both sweeps were placed without motion
                    // (none was known); place both again with the velocity
                    // between them (constant over both sweeps) and register again.
                    surface = self.place_first_two_again(&first, first_middle_s, &kept, middle_s);
                    clock.lap_surface();
                    (pose, trusted) = self.register(&surface, pose, &mut estimate);
                    self.velocity = BodyVelocity::from_motion(previous.world_from_vehicle.inverse() * pose, dt_s);
                    // The first scan's stamp pose in the pipeline's frame is now known.
                    self.world_from_pipeline = Some(self.velocity.motion_over(-first_middle_s).inverse());
                }
                estimate.low_confidence |= !trusted;
                pose
            }
        };
        estimate.world_from_vehicle = if compensate {
            self.world_from_pipeline.unwrap_or(Se2::IDENTITY) * pose * self.velocity.motion_over(-middle_s)
        } else {
            pose
        };
        estimate.surface_points = surface.len() as u32;
        estimate.low_confidence |= surface.len() < self.config.min_correspondences;
        self.update_keyframes(&surface, pose);
        self.previous = Some(Previous { stamp_ns: t_ns, placed_t_ns, world_from_vehicle: pose });
        clock.lap_register();
        Ok(ScanOdometry { estimate, timing: clock.timing(t_ns) })
    }

    /// The second scan's surface points, placed with the current velocity,
    /// after the first scan's keyframe is placed again with it too.
    fn place_first_two_again(
        &mut self,
        first: &[PolarPoint],
        first_middle_s: f64,
        second: &[PolarPoint],
        middle_s: f64,
    ) -> Vec<SurfacePoint> {
        let velocity = self.velocity;
        let first_motion = SweepMotion { velocity, reference_dt_s: first_middle_s };
        let first_surface = surface_points(&place(first, Some(first_motion)), &self.surface);
        if let Some(keyframe) = self.keyframes.front_mut() {
            keyframe.reference = Reference::new(&first_surface, keyframe.world_from_vehicle, self.config.grid_m);
        }
        surface_points(&place(second, Some(SweepMotion { velocity, reference_dt_s: middle_s })), &self.surface)
    }

    /// Registers the scan's surface points against the submap from
    /// `predicted`, re-associating `association_rounds` times at the new
    /// estimate. Fills the estimate's diagnostics and returns the pose and
    /// whether it can be trusted (if not, the pose is the prediction).
    fn register(&self, surface: &[SurfacePoint], predicted: Se2, estimate: &mut OdometryEstimate) -> (Se2, bool) {
        let config = &self.config;
        let references: Vec<&Reference> = self.keyframes.iter().map(|k| &k.reference).collect();
        let mut pose = predicted;
        let mut trusted = true;
        for _ in 0..config.association_rounds {
            let correspondences = associate(surface, &references, pose, config.grid_m, config.max_normal_angle_rad());
            estimate.correspondences = correspondences.len() as u32;
            if correspondences.len() < config.min_correspondences {
                trusted = false;
                break;
            }
            let solution = solve(&correspondences, pose, config.huber_delta_m, config.max_iterations);
            estimate.iterations += solution.iterations;
            estimate.cost_m2 = solution.cost_m2;
            pose = solution.world_from_scan;
            trusted = pose.is_finite() && solution.translation_observability >= MIN_TRANSLATION_OBSERVABILITY;
            if !trusted {
                break;
            }
        }
        if trusted { (pose, true) } else { (predicted, false) }
    }

    /// The second scan's registration, before any velocity is known: from
    /// rest (`at_rest`, the first scan's pose), as CFEAR does. A vehicle that
    /// moved farther than the association radius (`grid_m`) between the two
    /// scans (scans skipped, or fast from the start) is not found from
    /// there: the registration settles near rest with few correspondences,
    /// and every later prediction inherits that velocity. So when fewer than
    /// half of the scan's surface points found a correspondence (on the real
    /// Oxford sample's second scan 0.72 / 0.74 did for `cfear` /
    /// `fast-cfear`; with every other scan, 4.7 m apart, 0.40 / 0.38), the
    /// registration also starts from [`FROM_REST_STARTS_IN_RADII`] ahead or
    /// behind, and the trusted start with the most correspondences wins (rest
    /// on a tie); the estimate's diagnostics are the winner's. Ours, not the
    /// paper's.
    fn register_from_rest(
        &self,
        surface: &[SurfacePoint],
        at_rest: Se2,
        estimate: &mut OdometryEstimate,
    ) -> (Se2, bool) {
        let mut best = self.register(surface, at_rest, estimate);
        if 2 * estimate.correspondences as usize >= surface.len() {
            return best;
        }
        let mut best_estimate = *estimate;
        for radii in FROM_REST_STARTS_IN_RADII {
            let start = at_rest * Se2::new(radii * self.config.grid_m, 0.0, 0.0);
            let mut candidate = OdometryEstimate { correspondences: 0, iterations: 0, cost_m2: 0.0, ..*estimate };
            let (pose, trusted) = self.register(surface, start, &mut candidate);
            if trusted && (!best.1 || candidate.correspondences > best_estimate.correspondences) {
                (best, best_estimate) = ((pose, trusted), candidate);
            }
        }
        *estimate = best_estimate;
        best
    }

    /// Adds the scan as a keyframe when it moved far enough from the last one.
    fn update_keyframes(&mut self, surface: &[SurfacePoint], world_from_vehicle: Se2) {
        let config = &self.config;
        if surface.len() < config.min_correspondences {
            return;
        }
        let is_keyframe = self.keyframes.back().is_none_or(|last| {
            let moved = last.world_from_vehicle.inverse() * world_from_vehicle;
            moved.translation_norm_m() >= config.keyframe_min_distance_m
                || moved.yaw_rad.abs().to_degrees() >= config.keyframe_min_rotation_deg
        });
        if is_keyframe {
            let reference = Reference::new(surface, world_from_vehicle, config.grid_m);
            self.keyframes.push_back(Keyframe { world_from_vehicle, reference });
            while self.keyframes.len() > config.submap_keyframes {
                self.keyframes.pop_front();
            }
        }
    }
}

/// Geometry checks the pipeline relies on.
fn check_scan(scan: &PolarScan) -> Result<(), OdometryError> {
    let t_ns = scan.header.t_ns;
    scan.header.validate().map_err(|e| OdometryError::BadScan { t_ns, detail: e.to_string() })?;
    if scan.header.azimuths.is_empty() || scan.header.bins_per_azimuth == 0 {
        return Err(OdometryError::BadScan { t_ns, detail: "the scan has no azimuths or no range bins".into() });
    }
    let mut seen: Vec<(f64, usize)> =
        scan.header.azimuths.iter().enumerate().map(|(i, a)| (a.azimuth_rad, i)).collect();
    seen.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    if let Some(w) = seen.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(OdometryError::DuplicateAzimuth {
            t_ns,
            first_row: w[0].1,
            second_row: w[1].1,
            azimuth_rad: w[0].0,
        });
    }
    Ok(())
}

/// Accumulates wall-clock time per stage; stages may interleave.
struct StageClock {
    last: Instant,
    filter_s: f64,
    surface_s: f64,
    register_s: f64,
}

impl StageClock {
    fn start() -> Self {
        Self { last: Instant::now(), filter_s: 0.0, surface_s: 0.0, register_s: 0.0 }
    }

    fn lap(&mut self) -> f64 {
        let now = Instant::now();
        let seconds = (now - self.last).as_secs_f64();
        self.last = now;
        seconds
    }

    fn lap_filter(&mut self) {
        self.filter_s += self.lap();
    }

    fn lap_surface(&mut self) {
        self.surface_s += self.lap();
    }

    fn lap_register(&mut self) {
        self.register_s += self.lap();
    }

    fn timing(&self, t_ns: i64) -> OdometryTiming {
        OdometryTiming { t_ns, filter_s: self.filter_s, surface_s: self.surface_s, register_s: self.register_s }
    }
}
