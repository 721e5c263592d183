//! The odometry loop: filter, surface points, register against the keyframe
//! submap, keep the constant-velocity model and the keyframes up to date.

use std::collections::VecDeque;
use std::time::Instant;

use mmtrack_core::{OdometryEstimate, OdometryTiming, PolarScan, Se2};

use crate::filter::{BodyVelocity, PolarPoint, k_strongest, place};
use crate::register::{Reference, associate, solve};
use crate::surface::{SurfaceParams, SurfacePoint, surface_points};
use crate::{OdometryConfig, OdometryError};

/// Below this translational observability (eigenvalue ratio of the
/// translational normal matrix) the scene constrains one direction too weakly
/// to trust, e.g. a straight featureless tunnel.
pub const MIN_TRANSLATION_OBSERVABILITY: f64 = 1e-3;

/// A keyframe: its pose and its surface points, ready for association.
#[derive(Debug, Clone)]
struct Keyframe {
    world_from_vehicle: Se2,
    reference: Reference,
}

/// The previous scan's estimate.
#[derive(Debug, Clone, Copy)]
struct Previous {
    t_ns: i64,
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
/// (motion-compensated with the current velocity when configured), (2)-(3)
/// oriented surface points, (4) registration to the submap starting from the
/// constant-velocity prediction, re-associating `association_rounds` times.
/// When registration cannot be trusted (too few correspondences, a degenerate
/// scene, a non-finite result) the pose follows the prediction and the estimate
/// is flagged `low_confidence`: never a NaN pose.
#[derive(Debug, Clone)]
pub struct RadarOdometry {
    config: OdometryConfig,
    surface: SurfaceParams,
    keyframes: VecDeque<Keyframe>,
    previous: Option<Previous>,
    velocity: BodyVelocity,
    /// With motion compensation: the first scan's kept bins, until the second
    /// scan gives a velocity to place them with (the first scan's own velocity
    /// is unknown when it arrives).
    first_kept: Option<Vec<PolarPoint>>,
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
            first_kept: None,
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
            && t_ns <= previous.t_ns
        {
            return Err(OdometryError::NonMonotonicTime { previous_t_ns: previous.t_ns, t_ns });
        }
        let config = &self.config;
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
        let surface = match self.previous {
            None => {
                let surface = surface_points(&place(&kept, None), &self.surface);
                clock.lap_surface();
                if self.config.motion_compensation {
                    self.first_kept = Some(kept);
                }
                surface
            }
            Some(previous) => {
                let dt_s = (t_ns - previous.t_ns) as f64 * 1e-9;
                let predicted = previous.world_from_vehicle * self.velocity.motion_over(dt_s);
                let (surface, first_reference) = self.register(&kept, previous, predicted, &mut estimate, &mut clock);
                if let (Some(reference), Some(first)) = (first_reference, self.keyframes.front_mut()) {
                    first.reference = reference;
                }
                self.first_kept = None;
                let motion = previous.world_from_vehicle.inverse() * estimate.world_from_vehicle;
                self.velocity = BodyVelocity::from_motion(motion, dt_s);
                surface
            }
        };
        estimate.surface_points = surface.len() as u32;
        estimate.low_confidence |= surface.len() < self.config.min_correspondences;
        self.update_keyframes(&surface, estimate.world_from_vehicle);
        self.previous = Some(Previous { t_ns, world_from_vehicle: estimate.world_from_vehicle });
        clock.lap_register();
        Ok(ScanOdometry { estimate, timing: clock.timing(t_ns) })
    }

    /// Registers the scan against the submap from `predicted`, re-associating
    /// `association_rounds` times; with motion compensation, each round places
    /// the points with the velocity implied by the current estimate (so the
    /// compensation and the estimate agree, instead of feeding one scan's error
    /// into the next scan's compensation). Fills the estimate, falling back to
    /// the prediction when the result is doubtful, and returns the scan's
    /// surface points as placed for the final estimate. On the second scan with
    /// motion compensation, the first scan is placed with the same velocity in
    /// every round (constant velocity over both sweeps); its re-placed
    /// reference is returned too.
    fn register(
        &self,
        kept: &[PolarPoint],
        previous: Previous,
        predicted: Se2,
        estimate: &mut OdometryEstimate,
        clock: &mut StageClock,
    ) -> (Vec<SurfacePoint>, Option<Reference>) {
        let config = &self.config;
        let dt_s = (estimate.t_ns - previous.t_ns) as f64 * 1e-9;
        let velocity_at = |pose: Se2| {
            config
                .motion_compensation
                .then(|| BodyVelocity::from_motion(previous.world_from_vehicle.inverse() * pose, dt_s))
        };
        let first_reference_at = |pose: Se2| {
            self.first_kept.as_ref().map(|first| {
                let first_surface = surface_points(&place(first, velocity_at(pose)), &self.surface);
                Reference::new(&first_surface, previous.world_from_vehicle, config.grid_m)
            })
        };
        let mut first_reference = first_reference_at(predicted);
        let mut surface = surface_points(&place(kept, velocity_at(predicted)), &self.surface);
        clock.lap_surface();
        let sweep_s = kept.iter().map(|p| p.dt_s.abs()).fold(0.0, f64::max);
        let mut placed_for = predicted;
        let mut pose = predicted;
        let mut trusted = true;
        for _ in 0..config.association_rounds {
            if config.motion_compensation && !same_placement(velocity_at(placed_for), velocity_at(pose), sweep_s) {
                surface = surface_points(&place(kept, velocity_at(pose)), &self.surface);
                first_reference = first_reference_at(pose);
                placed_for = pose;
                clock.lap_surface();
            }
            let references: Vec<&Reference> = match &first_reference {
                Some(first) => vec![first],
                None => self.keyframes.iter().map(|k| &k.reference).collect(),
            };
            let correspondences = associate(&surface, &references, pose, config.grid_m, config.max_normal_angle_rad());
            estimate.correspondences = correspondences.len() as u32;
            if correspondences.len() < config.min_correspondences {
                trusted = false;
                break;
            }
            let solution = solve(&correspondences, pose, config.huber_delta_m, config.max_iterations);
            estimate.iterations += solution.iterations;
            estimate.cost_m2 = solution.cost_m2;
            pose = solution.world_from_scan;
            clock.lap_register();
            trusted = pose.is_finite() && solution.translation_observability >= MIN_TRANSLATION_OBSERVABILITY;
            if !trusted {
                break;
            }
        }
        estimate.low_confidence |= !trusted;
        estimate.world_from_vehicle = if trusted { pose } else { predicted };
        if config.motion_compensation
            && !same_placement(velocity_at(placed_for), velocity_at(estimate.world_from_vehicle), sweep_s)
        {
            surface = surface_points(&place(kept, velocity_at(estimate.world_from_vehicle)), &self.surface);
            first_reference = first_reference_at(estimate.world_from_vehicle);
            clock.lap_surface();
        }
        (surface, first_reference)
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

/// True when two compensation velocities place every point of a sweep of
/// `sweep_s` within 1 mm and 1e-5 rad of each other: re-placing the points
/// would not change the surface points measurably, so it is skipped.
fn same_placement(a: Option<BodyVelocity>, b: Option<BodyVelocity>, sweep_s: f64) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => {
            let translation_m = (a.vx_mps - b.vx_mps).hypot(a.vy_mps - b.vy_mps) * sweep_s;
            let rotation_rad = (a.yaw_rate_radps - b.yaw_rate_radps).abs() * sweep_s;
            translation_m < 1e-3 && rotation_rad < 1e-5
        }
        (None, None) => true,
        _ => false,
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
