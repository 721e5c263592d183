//! Procedural urban scenes along any trajectory: street canyons of building
//! fronts with gaps at junctions, open stretches with trees and fences,
//! parked cars, poles and small clutter on both sides of the path, seeded.
//!
//! The path is walked by arc length on each side. A side alternates blocks
//! and junction gaps; a block is either built (a row of buildings whose
//! fronts follow the path at the block's street half-width, with parked cars
//! and poles in front) or open (trees, a fence line). Every generated
//! reflector is then checked against the whole path (sampled every metre):
//! anything closer than `clearance_m` to it is dropped, so the inner side of
//! sharp turns, loops and revisits never puts a wall on the road.

use mmtrack_core::Se2;
use mmtrack_core::random::stream;
use rand::RngExt;
use rand_pcg::Pcg64;
use serde::Deserialize;

use super::grid::Grid;
use super::trajectory::Trajectory;
use super::world::{Material, ReflectorSpec, point_segment_distance_m};
use crate::SimError;
use crate::error::{ensure_positive, ensure_within, invalid};

/// Knobs of the generator (`[generator]` in a scenario). Ranges `[lo, hi]`
/// are drawn uniformly.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GeneratorConfig {
    /// Distance from the path to the building fronts, metres.
    pub street_half_width_m: [f64; 2],
    /// Length of a block between junctions, metres.
    pub block_length_m: [f64; 2],
    /// Width of a junction (gap in the fronts), metres.
    pub junction_gap_m: [f64; 2],
    /// Share of blocks that are open stretches (no buildings).
    pub open_block_fraction: f64,
    /// Frontage of one building, metres.
    pub building_length_m: [f64; 2],
    /// Depth of one building, metres.
    pub building_depth_m: [f64; 2],
    /// Gap between neighbouring buildings of a block, metres.
    pub building_gap_m: [f64; 2],
    /// Share of buildings with a second-row building behind them.
    pub second_row_fraction: f64,
    /// Share of 6 m kerb slots holding a parked car.
    pub parked_car_fraction: f64,
    /// Mean spacing of poles along built blocks, metres.
    pub pole_spacing_m: f64,
    /// Small scatterers (bins, bollards, signs) per 100 m of each side.
    pub clutter_per_100m: f64,
    /// Share of 12 m slots holding a tree crown (built blocks: on the pavement; open: anywhere).
    pub tree_fraction: f64,
    /// No reflector comes closer than this to the path, metres.
    pub clearance_m: f64,
}

impl Default for GeneratorConfig {
    fn default() -> Self {
        Self {
            street_half_width_m: [8.0, 14.0],
            block_length_m: [40.0, 110.0],
            junction_gap_m: [14.0, 30.0],
            open_block_fraction: 0.15,
            building_length_m: [8.0, 30.0],
            building_depth_m: [8.0, 20.0],
            building_gap_m: [0.5, 6.0],
            second_row_fraction: 0.8,
            parked_car_fraction: 0.5,
            pole_spacing_m: 20.0,
            clutter_per_100m: 25.0,
            tree_fraction: 0.3,
            clearance_m: 2.5,
        }
    }
}

fn check_range(field: &str, r: [f64; 2]) -> Result<(), SimError> {
    if !(r[0].is_finite() && r[1].is_finite() && r[0] >= 0.0 && r[0] <= r[1]) {
        return Err(invalid(format!("generator.{field}"), format!("{r:?}"), "[lo, hi] with 0 <= lo <= hi"));
    }
    Ok(())
}

impl GeneratorConfig {
    /// Checks every field; errors name it (`generator.<name>`).
    pub fn validate(&self) -> Result<(), SimError> {
        check_range("street_half_width_m", self.street_half_width_m)?;
        check_range("block_length_m", self.block_length_m)?;
        check_range("junction_gap_m", self.junction_gap_m)?;
        check_range("building_length_m", self.building_length_m)?;
        check_range("building_depth_m", self.building_depth_m)?;
        check_range("building_gap_m", self.building_gap_m)?;
        ensure_positive("generator.block_length_m[0]", self.block_length_m[0])?;
        ensure_positive("generator.building_length_m[0]", self.building_length_m[0])?;
        for (field, v) in [
            ("open_block_fraction", self.open_block_fraction),
            ("parked_car_fraction", self.parked_car_fraction),
            ("second_row_fraction", self.second_row_fraction),
            ("tree_fraction", self.tree_fraction),
        ] {
            ensure_within(&format!("generator.{field}"), v, 0.0, 1.0, "a fraction in [0, 1]")?;
        }
        ensure_positive("generator.pole_spacing_m", self.pole_spacing_m)?;
        ensure_within("generator.clutter_per_100m", self.clutter_per_100m, 0.0, 1e4, "a count in [0, 10000]")?;
        ensure_positive("generator.clearance_m", self.clearance_m)
    }
}

/// The path by arc length: poses every metre or so and their distances.
struct Path {
    poses: Vec<Se2>,
    s_m: Vec<f64>,
}

impl Path {
    fn new(trajectory: &Trajectory) -> Self {
        let poses = trajectory.path_samples(1.0);
        let mut s_m = Vec::with_capacity(poses.len());
        let mut s = 0.0;
        for (i, p) in poses.iter().enumerate() {
            if let Some(q) = i.checked_sub(1).and_then(|j| poses.get(j)) {
                s += (p.x_m - q.x_m).hypot(p.y_m - q.y_m);
            }
            s_m.push(s);
        }
        Self { poses, s_m }
    }

    fn length_m(&self) -> f64 {
        self.s_m.last().copied().unwrap_or(0.0)
    }

    /// The point `offset_m` to the left (negative: right) of the path at arc length `s`.
    fn offset(&self, s: f64, offset_m: f64) -> [f64; 2] {
        let i = self.s_m.partition_point(|v| *v <= s).clamp(1, self.poses.len().max(2) - 1);
        let (a, b) = (self.poses[i - 1], self.poses[i]);
        let span = (self.s_m[i] - self.s_m[i - 1]).max(1e-9);
        // Beyond the ends the first / last step is extended in a straight line.
        let f = (s - self.s_m[i - 1]) / span;
        let (x, y) = (a.x_m + f * (b.x_m - a.x_m), a.y_m + f * (b.y_m - a.y_m));
        let (dx, dy) = if span > 1e-6 { ((b.x_m - a.x_m) / span, (b.y_m - a.y_m) / span) } else { a.yaw_rad.sin_cos() };
        [x - dy * offset_m, y + dx * offset_m]
    }

    /// Heading of the path at `s`, degrees.
    fn heading_deg(&self, s: f64) -> f64 {
        let (p, q) = (self.offset(s - 0.5, 0.0), self.offset(s + 0.5, 0.0));
        (q[1] - p[1]).atan2(q[0] - p[0]).to_degrees()
    }
}

/// Generates the scene for `trajectory` (deterministic in `seed`).
pub fn generate_world(
    config: &GeneratorConfig,
    trajectory: &Trajectory,
    seed: u64,
) -> Result<Vec<ReflectorSpec>, SimError> {
    config.validate()?;
    let path = Path::new(trajectory);
    if path.poses.len() < 2 {
        return Ok(Vec::new());
    }
    // Refused before generating: an estimate of the reflectors per metre on
    // both sides (a pole every pole_spacing_m, clutter_per_100m, one
    // building and one block at their shortest lengths).
    let per_m = 2.0
        * (1.0 / config.pole_spacing_m
            + config.clutter_per_100m / 100.0
            + 1.0 / config.building_length_m[0]
            + 1.0 / config.block_length_m[0]);
    let limit = mmtrack_core::limits::REFLECTORS;
    if !limit.allows(per_m * path.length_m()) {
        return Err(invalid("generator.pole_spacing_m", config.pole_spacing_m, limit.expected));
    }
    let mut out = Vec::new();
    for (side_index, side) in [1.0, -1.0].into_iter().enumerate() {
        let mut rng = stream(seed, &[0x0067_656e, side_index as u64]);
        generate_side(config, &path, side, &mut rng, &mut out);
    }
    let boxes: Vec<[f64; 4]> = path.poses.iter().map(|p| [p.x_m, p.y_m, p.x_m, p.y_m]).collect();
    let index = Grid::build(&boxes, 10.0);
    // Path samples are at most ~1 m apart, so a sample lies within 0.5 m of any path point.
    let keep = config.clearance_m + 0.5;
    out.retain(|r| clear_of_path(r, &path, &index, keep));
    Ok(out)
}

fn uniform(rng: &mut Pcg64, r: [f64; 2]) -> f64 {
    if r[1] > r[0] { rng.random_range(r[0]..r[1]) } else { r[0] }
}

fn generate_side(config: &GeneratorConfig, path: &Path, side: f64, rng: &mut Pcg64, out: &mut Vec<ReflectorSpec>) {
    let length = path.length_m();
    let mut s = -uniform(rng, config.block_length_m) * 0.5; // start inside a block
    while s < length + 20.0 {
        let block = uniform(rng, config.block_length_m);
        let half_width = uniform(rng, config.street_half_width_m);
        let (start, end) = (s, s + block);
        if rng.random_bool(config.open_block_fraction) {
            open_block(config, path, side, start, end, half_width, rng, out);
        } else {
            built_block(config, path, side, start, end, half_width, rng, out);
        }
        scatter_clutter(config, path, side, start, end, half_width, rng, out);
        s = end + uniform(rng, config.junction_gap_m);
    }
}

#[allow(clippy::too_many_arguments)]
fn built_block(
    config: &GeneratorConfig,
    path: &Path,
    side: f64,
    start: f64,
    end: f64,
    half_width: f64,
    rng: &mut Pcg64,
    out: &mut Vec<ReflectorSpec>,
) {
    let mut s = start;
    while s < end {
        let frontage = uniform(rng, config.building_length_m).min(end - s);
        let front = half_width + rng.random_range(-0.5..0.5);
        let back = front + uniform(rng, config.building_depth_m);
        let steps = (frontage / 3.0).ceil().max(1.0) as usize;
        let along: Vec<f64> = (0..=steps).map(|k| s + frontage * k as f64 / steps as f64).collect();
        out.push(building(path, side, &along, front, back));
        if rng.random_bool(config.second_row_fraction) {
            // A building of the next row, seen through gaps and junctions.
            let front2 = back + rng.random_range(4.0..20.0);
            out.push(building(path, side, &along, front2, front2 + uniform(rng, config.building_depth_m)));
        }
        s += frontage + uniform(rng, config.building_gap_m);
    }
    let kerb = half_width - 3.2; // car centres: a 2.5 m pavement and half a car
    let mut slot = start + 3.0;
    while slot + 3.0 < end {
        if rng.random_bool(config.parked_car_fraction) {
            let p = path.offset(slot, side * kerb);
            let yaw_deg = path.heading_deg(slot) + rng.random_range(-4.0..4.0);
            out.push(ReflectorSpec::Car { x_m: p[0], y_m: p[1], yaw_deg, length_m: 4.5, width_m: 1.8 });
        }
        slot += 6.0;
    }
    let mut pole = start + rng.random_range(0.0..config.pole_spacing_m);
    while pole < end {
        let p = path.offset(pole, side * (half_width - 1.2));
        out.push(ReflectorSpec::Pole { x_m: p[0], y_m: p[1], strength_db: None });
        pole += config.pole_spacing_m * rng.random_range(0.7..1.3);
    }
    trees(config, path, side, start, end, [half_width - 1.8, half_width - 1.8], [1.0, 1.8], rng, out);
}

/// A building outline between offsets `front` and `back`, following the path over `along`.
fn building(path: &Path, side: f64, along: &[f64], front: f64, back: f64) -> ReflectorSpec {
    let mut vertices: Vec<[f64; 2]> = along.iter().map(|a| path.offset(*a, side * front)).collect();
    vertices.extend(along.iter().rev().map(|a| path.offset(*a, side * back)));
    ReflectorSpec::Polygon { vertices_m: vertices, material: Material::Building, strength_db: None }
}

#[allow(clippy::too_many_arguments)]
fn open_block(
    config: &GeneratorConfig,
    path: &Path,
    side: f64,
    start: f64,
    end: f64,
    half_width: f64,
    rng: &mut Pcg64,
    out: &mut Vec<ReflectorSpec>,
) {
    if rng.random_bool(0.5) {
        // A fence line along the block, in 10 m panels.
        let offset = half_width + rng.random_range(-1.0..1.0);
        let mut s = start;
        while s < end {
            let next = (s + 10.0).min(end);
            out.push(ReflectorSpec::Wall {
                a_m: path.offset(s, side * offset),
                b_m: path.offset(next, side * offset),
                material: Material::Fence,
                strength_db: None,
            });
            s = next;
        }
    }
    trees(config, path, side, start, end, [half_width - 2.0, half_width + 15.0], [1.5, 3.5], rng, out);
}

#[allow(clippy::too_many_arguments)]
fn trees(
    config: &GeneratorConfig,
    path: &Path,
    side: f64,
    start: f64,
    end: f64,
    offset_m: [f64; 2],
    radius_m: [f64; 2],
    rng: &mut Pcg64,
    out: &mut Vec<ReflectorSpec>,
) {
    let mut s = start + 6.0;
    while s < end {
        if rng.random_bool(config.tree_fraction) {
            let centre = path.offset(s, side * uniform(rng, offset_m));
            let r = uniform(rng, radius_m);
            let vertices = (0..8)
                .map(|k| {
                    let a = f64::from(k) * std::f64::consts::TAU / 8.0;
                    [centre[0] + r * a.cos(), centre[1] + r * a.sin()]
                })
                .collect();
            out.push(ReflectorSpec::Polygon {
                vertices_m: vertices,
                material: Material::Vegetation,
                strength_db: None,
            });
        }
        s += 12.0;
    }
}

#[allow(clippy::too_many_arguments)]
fn scatter_clutter(
    config: &GeneratorConfig,
    path: &Path,
    side: f64,
    start: f64,
    end: f64,
    half_width: f64,
    rng: &mut Pcg64,
    out: &mut Vec<ReflectorSpec>,
) {
    let count = (config.clutter_per_100m * (end - start) / 100.0).round() as usize;
    for _ in 0..count {
        let s = rng.random_range(start..end.max(start + 1e-6));
        let offset = rng.random_range((half_width - 2.5).max(0.0)..half_width - 0.3);
        let p = path.offset(s, side * offset);
        out.push(ReflectorSpec::Point { x_m: p[0], y_m: p[1], strength_db: rng.random_range(100.0..112.0) });
    }
}

/// Points of a reflector every metre along its outline (or its position).
fn outline_points(reflector: &ReflectorSpec) -> Vec<[f64; 2]> {
    let edges: Vec<([f64; 2], [f64; 2])> = match reflector {
        ReflectorSpec::Wall { a_m, b_m, .. } => vec![(*a_m, *b_m)],
        ReflectorSpec::Polygon { vertices_m, .. } => {
            (0..vertices_m.len()).map(|i| (vertices_m[i], vertices_m[(i + 1) % vertices_m.len()])).collect()
        }
        ReflectorSpec::Car { x_m, y_m, .. } => return vec![[*x_m, *y_m]],
        ReflectorSpec::Pole { x_m, y_m, .. } | ReflectorSpec::Point { x_m, y_m, .. } => return vec![[*x_m, *y_m]],
    };
    let mut out = Vec::new();
    for (a, b) in edges {
        let n = ((b[0] - a[0]).hypot(b[1] - a[1])).ceil().max(1.0) as usize;
        out.extend((0..=n).map(|k| {
            let f = k as f64 / n as f64;
            [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
        }));
    }
    out
}

fn clear_of_path(reflector: &ReflectorSpec, path: &Path, index: &Grid, keep_m: f64) -> bool {
    // A car's body reaches 2.4 m from its centre.
    let extra = if matches!(reflector, ReflectorSpec::Car { .. }) { 2.4 } else { 0.0 };
    let reach = keep_m + extra;
    outline_points(reflector).iter().all(|p| {
        let mut clear = true;
        index.visit_box([p[0] - reach, p[1] - reach, p[0] + reach, p[1] + reach], &mut |ids| {
            for &id in ids {
                if let Some(q) = path.poses.get(id as usize)
                    && (q.x_m - p[0]).hypot(q.y_m - p[1]) < reach
                {
                    clear = false;
                }
            }
        });
        clear
    })
}

/// Distance from `p` to the polyline through `poses`, metres (for tests and checks).
#[must_use]
pub fn distance_to_path_m(p: [f64; 2], poses: &[Se2]) -> f64 {
    poses
        .windows(2)
        .map(|w| point_segment_distance_m(p, [w[0].x_m, w[0].y_m], [w[1].x_m, w[1].y_m]))
        .fold(f64::INFINITY, f64::min)
}
