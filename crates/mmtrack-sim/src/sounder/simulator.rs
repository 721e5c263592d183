//! [`ConvoySimulator`]: the convoy scenario's sets, rendered on demand.

use std::collections::VecDeque;
use std::f64::consts::{PI, TAU};

use mmtrack_core::random::{self, standard_exponential, standard_normal_pair};
use mmtrack_core::sounder::SounderBand;
use mmtrack_core::{CirSnapshot, Complex64, MpcTruth, PathGeometry, Se2, StampedPose};
use rand::RngExt;
use rayon::prelude::*;

use super::convoy::{ConvoyConfig, RoadKind};
use super::geometry::{P2, Road, Wall, blocked, cross, dist, dot, reflection_point, sub, unit};
use super::render::{RenderPath, SnapshotStamp, render_snapshot};
use super::{PathKind, SPEED_OF_LIGHT_MPS};
use crate::SimError;

/// One set of the convoy run: its snapshots, the true MPCs of every
/// snapshot, and both cars' poses at the set's first snapshot.
#[derive(Debug, Clone, PartialEq)]
pub struct SounderSet {
    /// Set index.
    pub set_index: u64,
    /// The set's CIR snapshots, in time order.
    pub snapshots: Vec<CirSnapshot>,
    /// True MPCs of every snapshot (LOS, wall bounces, traffic; the diffuse
    /// scatterers too with [`super::DiffuseConfig::in_truth`]), in snapshot
    /// order then `path_id` order.
    pub truth: Vec<MpcTruth>,
    /// `world_from_vehicle` of the receiver at the set's first snapshot.
    pub rx_pose: StampedPose,
    /// `world_from_vehicle` of the transmitter at the set's first snapshot.
    pub tx_pose: StampedPose,
    /// Where each path of the set's first snapshot that is in the truth
    /// runs (transmitter, interaction points, receiver), in `path_id` order.
    pub paths: Vec<PathGeometry>,
}

/// Smooth speed profile along a lane: `v(t) = v_mid + v_half sin(2 pi t / T + phi)`.
#[derive(Debug, Clone, Copy)]
struct LaneMotion {
    s0_m: f64,
    lane_m: f64,
    v_mid_mps: f64,
    v_half_mps: f64,
    period_s: f64,
    phase_rad: f64,
}

impl LaneMotion {
    fn s_m(&self, t_s: f64) -> f64 {
        let w = TAU / self.period_s;
        self.s0_m + self.v_mid_mps * t_s
            - self.v_half_mps / w * ((w * t_s + self.phase_rad).cos() - self.phase_rad.cos())
    }

    fn speed_mps(&self, t_s: f64) -> f64 {
        self.v_mid_mps + self.v_half_mps * (TAU * t_s / self.period_s + self.phase_rad).sin()
    }
}

/// A point moving along the road: position, velocity, heading.
#[derive(Debug, Clone, Copy)]
struct Kinematics {
    position: P2,
    velocity: P2,
    heading_rad: f64,
}

fn kinematics(road: &Road, s_m: f64, lane_m: f64, speed_mps: f64) -> Kinematics {
    let (position, heading_rad) = road.lane_point(s_m, lane_m);
    let (sin, cos) = heading_rad.sin_cos();
    Kinematics { position, velocity: [speed_mps * cos, speed_mps * sin], heading_rad }
}

#[derive(Debug, Clone, Copy)]
struct Car {
    s0_m: f64,
    lane_m: f64,
    speed_mps: f64,
}

#[derive(Debug, Clone, Copy)]
struct Scatterer {
    point: P2,
    /// Unit tangent of the wall (or roadside) at the scatterer.
    tangent: P2,
    s_centre_m: f64,
    /// Relative amplitude (power draw and Rayleigh magnitude) and static phase.
    gain: f64,
    phase_rad: f64,
}

/// The interaction points of a specular path, in order from the transmitter.
#[derive(Debug, Clone, Copy)]
enum Via {
    Direct,
    One(P2),
    Two(P2, P2),
}

/// A specular path at one instant.
#[derive(Debug, Clone, Copy)]
struct Path {
    id: u64,
    via: Via,
    length_m: f64,
    /// `dL/dt`, metres per second.
    rate_mps: f64,
    /// Linear magnitude on the tap scale.
    magnitude: f64,
    /// Static phase (reflection phases and the seeded random part).
    phase_rad: f64,
}

/// Sets rendered per thread of the rayon pool in one batch.
const SETS_PER_THREAD: usize = 4;

const NOISE_STREAM: u64 = 0x6e6f_6973_6520_636f;

/// Streams the sets of a convoy run (see the [`super`] module docs for the
/// model). Each set is rendered from `(seed, set index)` alone, so the output
/// is bit-identical for any thread count, and [`ConvoySimulator::render_set`]
/// gives any set without the ones before it.
pub struct ConvoySimulator {
    config: ConvoyConfig,
    seed: u64,
    band: SounderBand,
    pulse: Vec<Complex64>,
    road: Road,
    walls: Vec<Wall>,
    scatterers: Vec<Scatterer>,
    cars: Vec<Car>,
    rx: LaneMotion,
    tx: LaneMotion,
    snapshot_ns: i64,
    set_ns: i64,
    next: usize,
    ready: VecDeque<SounderSet>,
}

impl ConvoySimulator {
    /// Checks the configuration and lays out the road, walls, diffuse
    /// scatterers and traffic. Sets are rendered on the current rayon pool,
    /// four per pool thread at a time; the output does not
    /// depend on the thread count.
    pub fn new(config: &ConvoyConfig, seed: u64) -> Result<Self, SimError> {
        config.validate()?;
        let band = config.sounder.band()?;
        let pulse = config.sounder.pulse.spectrum(&band);
        let (snapshot_ns, set_ns) = config.intervals_ns()?;
        let road = Road { radius_m: (config.road.radius_m != 0.0).then_some(config.road.radius_m) };
        let v = &config.vehicles;
        let kmh = 1.0 / 3.6;
        let mut rng = random::stream(seed, &[0x6d6f_7469_6f6e]);
        let mut motion = |s0_m: f64, range: [f64; 2]| LaneMotion {
            s0_m,
            lane_m: v.lane_m,
            v_mid_mps: 0.5 * (range[0] + range[1]) * kmh,
            v_half_mps: 0.5 * (range[1] - range[0]) * kmh,
            period_s: v.speed_period_s,
            phase_rad: rng.random::<f64>() * TAU,
        };
        let rx = motion(0.0, v.rx_speed_kmh);
        let tx = motion(v.start_distance_m, v.tx_speed_kmh);
        let duration_s = config.sets as f64 * set_ns as f64 * 1e-9;
        let reach_m = max_path_m(config);
        let s_min = -reach_m - 50.0;
        let s_max = v.start_distance_m + v.tx_speed_kmh[1] * kmh * duration_s + reach_m + 50.0;
        let walls = match config.road.kind {
            RoadKind::Tunnel => build_walls(&road, config, s_min, s_max),
            RoadKind::Highway => Vec::new(),
        };
        let scatterers = build_scatterers(&road, config, &walls, seed, s_min, s_max);
        let cars = build_cars(config, seed, duration_s, s_min, s_max);
        Ok(Self {
            config: config.clone(),
            seed,
            band,
            pulse,
            road,
            walls,
            scatterers,
            cars,
            rx,
            tx,
            snapshot_ns,
            set_ns,
            next: 0,
            ready: VecDeque::new(),
        })
    }

    /// The pulse spectrum the CIRs are rendered with (FFT order), to give
    /// the MPC detector the same pulse.
    #[must_use]
    pub fn pulse_spectrum(&self) -> &[Complex64] {
        &self.pulse
    }

    /// The frequency grid.
    #[must_use]
    pub fn band(&self) -> SounderBand {
        self.band
    }

    /// Number of sets in the run.
    #[must_use]
    pub fn sets(&self) -> usize {
        self.config.sets
    }

    /// Number of traffic cars (explicit and random); car `i` has path id
    /// `PathKind::TRAFFIC_BASE + i`.
    #[must_use]
    pub fn traffic_cars(&self) -> usize {
        self.cars.len()
    }

    /// Number of diffuse scatterers laid out.
    #[must_use]
    pub fn diffuse_scatterers(&self) -> usize {
        self.scatterers.len()
    }

    fn t_ns(&self, set_index: u64, snapshot_index: u32) -> i64 {
        self.config.start_t_ns + set_index as i64 * self.set_ns + i64::from(snapshot_index) * self.snapshot_ns
    }

    fn vehicle(&self, motion: &LaneMotion, t_s: f64) -> Kinematics {
        kinematics(&self.road, motion.s_m(t_s), motion.lane_m, motion.speed_mps(t_s))
    }

    /// Segment ranges of every wall around the two cars (the part a path
    /// inside the delay window can touch).
    fn ranges(&self, tx: P2, rx: P2) -> Vec<(usize, usize)> {
        let s_mid = 0.5 * (self.road.centre_s(tx) + self.road.centre_s(rx));
        let reach = 0.5 * max_path_m(&self.config) + self.config.road.wall_segment_m;
        self.walls.iter().map(|w| w.segment_range(s_mid - reach, s_mid + reach)).collect()
    }

    /// Set `set_index` (snapshots, truth, poses); `None` past the last set.
    #[must_use]
    pub fn render_set(&self, set_index: u64) -> Option<SounderSet> {
        if set_index >= self.config.sets as u64 {
            return None;
        }
        let t0_ns = self.t_ns(set_index, 0);
        let t0_s = (t0_ns - self.config.start_t_ns) as f64 * 1e-9;
        let (rx0, tx0) = (self.vehicle(&self.rx, t0_s), self.vehicle(&self.tx, t0_s));
        let pose = |k: &Kinematics| StampedPose {
            t_ns: t0_ns,
            parent_from_child: Se2::new(k.position[0], k.position[1], k.heading_rad),
        };
        // Diffuse scatterers: visibility once per set (the cars move about
        // 5 cm during a set's 3.6 ms); delays and phases per snapshot.
        let ranges = self.ranges(tx0.position, rx0.position);
        let visible: Vec<(usize, &Scatterer)> = self.diffuse_candidates(tx0.position, rx0.position, &ranges);
        let mut snapshots = Vec::with_capacity(self.config.snapshots_per_set as usize);
        let mut truth = Vec::new();
        let mut geometry = Vec::new();
        for snapshot_index in 0..self.config.snapshots_per_set {
            let t_ns = self.t_ns(set_index, snapshot_index);
            let t_s = (t_ns - self.config.start_t_ns) as f64 * 1e-9;
            let (rx, tx) = (self.vehicle(&self.rx, t_s), self.vehicle(&self.tx, t_s));
            let paths = self.specular_paths(&tx, &rx, t_s);
            let mut render = Vec::with_capacity(paths.len() + visible.len());
            let fc = self.config.sounder.carrier_hz;
            for p in &paths {
                let Some(relative_delay_s) = self.in_window(p.length_m) else { continue };
                let amplitude = self.amplitude(p.magnitude, p.phase_rad, p.length_m);
                render.push(RenderPath { relative_delay_s, amplitude });
                if 20.0 * p.magnitude.log10() >= self.config.truth_min_power_db {
                    if snapshot_index == 0 {
                        let points_m = match p.via {
                            Via::Direct => vec![tx.position, rx.position],
                            Via::One(q) => vec![tx.position, q, rx.position],
                            Via::Two(q1, q2) => vec![tx.position, q1, q2, rx.position],
                        };
                        geometry.push(PathGeometry { path_id: p.id, points_m });
                    }
                    truth.push(MpcTruth {
                        t_ns,
                        set_index,
                        snapshot_index,
                        path_id: p.id,
                        delay_s: p.length_m / SPEED_OF_LIGHT_MPS,
                        amplitude,
                        doppler_hz: -fc * p.rate_mps / SPEED_OF_LIGHT_MPS,
                    });
                }
            }
            for &(index, s) in &visible {
                let length_m = dist(tx.position, s.point) + dist(s.point, rx.position);
                let Some(relative_delay_s) = self.in_window(length_m) else { continue };
                let lambert = (cross(s.tangent, unit(s.point, tx.position)).abs()
                    * cross(s.tangent, unit(s.point, rx.position)).abs())
                .sqrt();
                let magnitude = self.free_space(length_m) * self.reflection() * s.gain * lambert;
                let amplitude = self.amplitude(magnitude, s.phase_rad, length_m);
                render.push(RenderPath { relative_delay_s, amplitude });
                if self.config.diffuse.in_truth && 20.0 * magnitude.log10() >= self.config.truth_min_power_db {
                    let path_id = PathKind::Diffuse.base() + index as u64;
                    if snapshot_index == 0 {
                        geometry.push(PathGeometry { path_id, points_m: vec![tx.position, s.point, rx.position] });
                    }
                    // dL/dt of TX -> s -> RX with s at rest.
                    let rate_mps =
                        dot(tx.velocity, unit(s.point, tx.position)) + dot(rx.velocity, unit(s.point, rx.position));
                    truth.push(MpcTruth {
                        t_ns,
                        set_index,
                        snapshot_index,
                        path_id,
                        delay_s: length_m / SPEED_OF_LIGHT_MPS,
                        amplitude,
                        doppler_hz: -fc * rate_mps / SPEED_OF_LIGHT_MPS,
                    });
                }
            }
            let stamp = SnapshotStamp {
                t_ns,
                set_index,
                snapshot_index,
                carrier_hz: fc,
                delay_offset_s: self.config.delay_offset_s,
            };
            let sigma = self.config.sounder.noise_sigma();
            snapshots.push(render_snapshot(&self.band, &self.pulse, &render, sigma, [self.seed, NOISE_STREAM], stamp));
        }
        geometry.sort_by_key(|g| g.path_id);
        Some(SounderSet { set_index, snapshots, truth, rx_pose: pose(&rx0), tx_pose: pose(&tx0), paths: geometry })
    }

    /// Delay after tap 0 when the path lies inside the usable window.
    fn in_window(&self, length_m: f64) -> Option<f64> {
        let tap = self.band.tap_spacing_s();
        let relative = length_m / SPEED_OF_LIGHT_MPS - self.config.delay_offset_s;
        let lo = self.config.guard_taps as f64 * tap;
        let hi = (self.config.sounder.taps - self.config.noise_tail_taps) as f64 * tap;
        (lo..=hi).contains(&relative).then_some(relative)
    }

    fn wavelength_m(&self) -> f64 {
        SPEED_OF_LIGHT_MPS / self.config.sounder.carrier_hz
    }

    /// `g lambda / (4 pi L)`.
    fn free_space(&self, length_m: f64) -> f64 {
        10f64.powf(self.config.system_gain_db / 20.0) * self.wavelength_m() / (2.0 * TAU * length_m)
    }

    fn reflection(&self) -> f64 {
        10f64.powf(-self.config.road.wall_reflection_loss_db / 20.0)
    }

    /// `|a| exp(j (phi - 2 pi f_c L / c))`: the carrier phase turns with the
    /// path length, so the phases carry the Doppler.
    fn amplitude(&self, magnitude: f64, phase_rad: f64, length_m: f64) -> Complex64 {
        let carrier = TAU * (length_m / self.wavelength_m()).fract();
        Complex64::from_polar(magnitude, phase_rad - carrier)
    }

    fn static_phase(&self, id: u64) -> f64 {
        let mut rng = random::stream(self.seed, &[0x0070_6861_7365, id]);
        rng.random::<f64>() * TAU
    }

    /// The scatterers visible from both cars, with their index in
    /// `self.scatterers` (their stable identity), in index order.
    fn diffuse_candidates(&self, tx: P2, rx: P2, ranges: &[(usize, usize)]) -> Vec<(usize, &Scatterer)> {
        let s_mid = 0.5 * (self.road.centre_s(tx) + self.road.centre_s(rx));
        let reach = 0.5 * max_path_m(&self.config);
        let lo = self.scatterers.partition_point(|s| s.s_centre_m < s_mid - reach);
        let hi = self.scatterers.partition_point(|s| s.s_centre_m <= s_mid + reach);
        (lo..hi)
            .map(|i| (i, &self.scatterers[i]))
            .filter(|(_, s)| !blocked(&self.walls, ranges, tx, s.point) && !blocked(&self.walls, ranges, s.point, rx))
            .collect()
    }

    /// LOS, single and double wall bounces and traffic reflections at time
    /// `t_s` (visible ones only), sorted by path id.
    fn specular_paths(&self, tx: &Kinematics, rx: &Kinematics, t_s: f64) -> Vec<Path> {
        let ranges = self.ranges(tx.position, rx.position);
        let (a, b) = (tx.position, rx.position);
        let clear = |p: P2, q: P2| !blocked(&self.walls, &ranges, p, q);
        let mut paths = Vec::new();
        if clear(a, b) {
            let length_m = dist(a, b);
            paths.push(Path {
                id: PathKind::Los.base(),
                via: Via::Direct,
                length_m,
                rate_mps: dot(sub(tx.velocity, rx.velocity), unit(b, a)),
                magnitude: self.free_space(length_m),
                phase_rad: self.static_phase(PathKind::Los.base()),
            });
        }
        // Fermat: the path length is stationary in the reflection points, so
        // dL/dt only involves the cars' velocities along the end legs.
        let end_rate = |first: P2, last: P2| dot(tx.velocity, unit(first, a)) + dot(rx.velocity, unit(last, b));
        for (w, wall) in self.walls.iter().enumerate() {
            let Some((p, _)) = reflection_point(wall, ranges[w], a, b) else { continue };
            if clear(a, p) && clear(p, b) {
                let id = PathKind::SingleBounce.base() + w as u64;
                let length_m = dist(a, p) + dist(p, b);
                paths.push(Path {
                    id,
                    via: Via::One(p),
                    length_m,
                    rate_mps: end_rate(p, p),
                    magnitude: self.free_space(length_m) * self.reflection(),
                    phase_rad: self.static_phase(id) + PI,
                });
            }
        }
        if self.config.road.double_bounces {
            for (first, second) in [(0usize, 1usize), (1, 0)] {
                if self.walls.len() < 2 {
                    break;
                }
                let Some((p1, p2)) = double_bounce(&self.walls, &ranges, first, second, a, b) else { continue };
                if clear(a, p1) && clear(p1, p2) && clear(p2, b) {
                    let id = PathKind::DoubleBounce.base() + first as u64;
                    let length_m = dist(a, p1) + dist(p1, p2) + dist(p2, b);
                    let rho = self.reflection();
                    paths.push(Path {
                        id,
                        via: Via::Two(p1, p2),
                        length_m,
                        rate_mps: end_rate(p1, p2),
                        magnitude: self.free_space(length_m) * rho * rho,
                        phase_rad: self.static_phase(id),
                    });
                }
            }
        }
        let sigma_m2 = 10f64.powf(self.config.traffic.rcs_dbsm / 10.0);
        let gain = 10f64.powf(self.config.system_gain_db / 20.0);
        for (i, car) in self.cars.iter().enumerate() {
            let c = kinematics(&self.road, car.s0_m + car.speed_mps * t_s, car.lane_m, car.speed_mps);
            let (d1, d2) = (dist(a, c.position), dist(c.position, b));
            if !(clear(a, c.position) && clear(c.position, b)) {
                continue;
            }
            let id = PathKind::Traffic.base() + i as u64;
            let rate_mps = end_rate(c.position, c.position)
                + dot(c.velocity, unit(a, c.position))
                + dot(c.velocity, unit(b, c.position));
            // Bistatic radar equation: |a| = g lambda sqrt(sigma) / ((4 pi)^(3/2) d1 d2).
            let magnitude = gain * self.wavelength_m() * sigma_m2.sqrt() / ((2.0 * TAU).powf(1.5) * d1 * d2);
            paths.push(Path {
                id,
                via: Via::One(c.position),
                length_m: d1 + d2,
                rate_mps,
                magnitude,
                phase_rad: self.static_phase(id),
            });
        }
        paths
    }
}

/// Longest path whose delay lies inside the usable window, metres.
fn max_path_m(config: &ConvoyConfig) -> f64 {
    let tap = 1.0 / config.sounder.bandwidth_hz;
    (config.delay_offset_s + (config.sounder.taps - config.noise_tail_taps) as f64 * tap) * SPEED_OF_LIGHT_MPS
}

/// Wall `first` then wall `second`: the stationary path by alternating the
/// single-bounce minimisation of each point (the length is convex in the two
/// points on a pair of segments; each round solves one point exactly, and on
/// near-parallel walls the error shrinks by about 10 per round).
fn double_bounce(
    walls: &[Wall],
    ranges: &[(usize, usize)],
    first: usize,
    second: usize,
    a: P2,
    b: P2,
) -> Option<(P2, P2)> {
    let (mut p1, _) = reflection_point(&walls[first], ranges[first], a, b)?;
    let mut p2 = b;
    for _ in 0..60 {
        let (q2, _) = reflection_point(&walls[second], ranges[second], p1, b)?;
        let (q1, _) = reflection_point(&walls[first], ranges[first], a, q2)?;
        let change = dist(q1, p1) + dist(q2, p2);
        (p1, p2) = (q1, q2);
        if change < 1e-12 {
            break;
        }
    }
    Some((p1, p2))
}

fn build_walls(road: &Road, config: &ConvoyConfig, s_min: f64, s_max: f64) -> Vec<Wall> {
    let seg = config.road.wall_segment_m;
    let n = ((s_max - s_min) / seg).ceil() as usize;
    let half = config.road.half_width_m;
    // Wall 0 on the left (+half): the road is to the right of its direction.
    [(half, -1.0), (-half, 1.0)]
        .into_iter()
        .map(|(lateral, interior_sign)| Wall {
            vertices: (0..=n).map(|i| road.centre_point(s_min + i as f64 * seg, lateral)).collect(),
            s0_m: s_min,
            segment_m: seg,
            interior_sign,
        })
        .collect()
}

/// Poisson scatterers along both walls (or roadsides), sorted by
/// centreline position, exactly on the wall polylines.
fn build_scatterers(
    road: &Road,
    config: &ConvoyConfig,
    walls: &[Wall],
    seed: u64,
    s_min: f64,
    s_max: f64,
) -> Vec<Scatterer> {
    let density = config.diffuse.scatterers_per_m;
    let mut out = Vec::new();
    if density <= 0.0 {
        return out;
    }
    let [lo_db, hi_db] = config.diffuse.relative_power_db;
    for (side, lateral) in [config.road.half_width_m, -config.road.half_width_m].into_iter().enumerate() {
        let mut rng = random::stream(seed, &[0x6469_6666, side as u64]);
        let mut s = s_min;
        loop {
            s += standard_exponential(&mut rng) / density;
            if s >= s_max {
                break;
            }
            let (point, tangent) = match walls.get(side) {
                Some(wall) => {
                    let j = (((s - wall.s0_m) / wall.segment_m).floor() as usize).min(wall.vertices.len() - 2);
                    let (p, q) = wall.segment(j);
                    let f = ((s - wall.s0_m) / wall.segment_m - j as f64).clamp(0.0, 1.0);
                    ([p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1])], unit(p, q))
                }
                None => {
                    let p = road.centre_point(s, lateral);
                    (p, unit(p, road.centre_point(s + 1.0, lateral)))
                }
            };
            let db = if hi_db > lo_db { rng.random_range(lo_db..hi_db) } else { lo_db };
            let (re, im) = standard_normal_pair(&mut rng);
            let rayleigh = (0.5 * (re * re + im * im)).sqrt();
            let gain = 10f64.powf(db / 20.0) * rayleigh;
            out.push(Scatterer { point, tangent, s_centre_m: s, gain, phase_rad: im.atan2(re) });
        }
    }
    out.sort_by(|x, y| x.s_centre_m.total_cmp(&y.s_centre_m));
    out
}

/// Explicit cars first, then Poisson oncoming and same-direction cars.
fn build_cars(config: &ConvoyConfig, seed: u64, duration_s: f64, s_min: f64, s_max: f64) -> Vec<Car> {
    let t = &config.traffic;
    let kmh = 1.0 / 3.6;
    let mut cars: Vec<Car> =
        t.cars.iter().map(|c| Car { s0_m: c.start_s_m, lane_m: c.lane_m, speed_mps: c.speed_kmh * kmh }).collect();
    let streams = [
        (t.oncoming_per_km, t.oncoming_lane_m, t.oncoming_speed_kmh, -1.0),
        (t.same_direction_per_km, t.same_direction_lane_m, t.same_direction_speed_kmh, 1.0),
    ];
    for (stream, (per_km, lane_m, speed_kmh, sign)) in streams.into_iter().enumerate() {
        if per_km <= 0.0 {
            continue;
        }
        let mut rng = random::stream(seed, &[0x7472_6166, stream as u64]);
        // Start positions over the stretch the cars can cross the convoy's
        // surroundings from during the run.
        let travel = speed_kmh[1] * kmh * duration_s;
        let (lo, hi) = if sign < 0.0 { (s_min, s_max + travel) } else { (s_min - travel, s_max) };
        let mut s = lo;
        loop {
            s += standard_exponential(&mut rng) / (per_km / 1000.0);
            if s >= hi {
                break;
            }
            let v =
                if speed_kmh[1] > speed_kmh[0] { rng.random_range(speed_kmh[0]..speed_kmh[1]) } else { speed_kmh[0] };
            cars.push(Car { s0_m: s, lane_m, speed_mps: sign * v * kmh });
        }
    }
    cars
}

impl Iterator for ConvoySimulator {
    type Item = SounderSet;

    fn next(&mut self) -> Option<SounderSet> {
        if self.ready.is_empty() {
            let end = (self.next + SETS_PER_THREAD * rayon::current_num_threads()).min(self.config.sets);
            let rendered: Vec<Option<SounderSet>> =
                (self.next as u64..end as u64).into_par_iter().map(|i| self.render_set(i)).collect();
            self.next = end;
            self.ready.extend(rendered.into_iter().flatten());
        }
        self.ready.pop_front()
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.config.sets - self.next + self.ready.len();
        (left, Some(left))
    }
}

impl ExactSizeIterator for ConvoySimulator {}
