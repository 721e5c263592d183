//! The 2D world: reflectors as a scenario file or the generator describes
//! them ([`ReflectorSpec`]), compiled into surface segments and point targets in
//! uniform-grid spatial indexes ([`World`]) so a beam only looks at the cells
//! it crosses, whatever the size of the world.

use serde::Deserialize;

use crate::SimError;
use crate::error::{ensure_finite, ensure_positive, invalid};

/// What an extended surface is made of: its strength, transparency and how
/// its return depends on the incidence angle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Material {
    /// Building facade: strong, opaque, mirrors the beam (multipath).
    Building,
    /// Free-standing (garden) wall: a roof-mounted radar sees partly over it (transmission 0.3).
    Wall,
    /// Fence or railing: lets half the power through (each way).
    Fence,
    /// Vehicle body: strong; a roof-mounted radar sees partly over it (transmission 0.4).
    Car,
    /// Hedge or tree crown: diffuse (no incidence dependence), lets a third of the power through.
    Vegetation,
}

/// The radar properties of a [`Material`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceProperties {
    /// Return level at 10 m, broadside incidence, dB of linear power.
    pub strength_db: f64,
    /// One-way power transmission through the surface (0 = opaque).
    pub transmission: f64,
    /// Share of the return that does not depend on incidence; the rest
    /// scales with `cos^2` of the incidence angle.
    pub diffuse_fraction: f64,
    /// Whether the surface mirrors the beam into multipath ghosts.
    pub mirror: bool,
    /// Depth of the scattering volume behind the surface, metres: the return
    /// trails off behind its peak as `exp(-x / depth_m)` (window recesses,
    /// foliage, a car's interior), so it covers more bins than the profile.
    pub depth_m: f64,
}

impl Material {
    /// Default properties (strengths calibrated with the module's scenes
    /// against the real scans' k-strongest statistics).
    #[must_use]
    pub fn properties(self) -> SurfaceProperties {
        let (strength_db, transmission, diffuse_fraction, mirror, depth_m) = match self {
            Self::Building => (114.0, 0.0, 0.2, true, 0.05),
            Self::Wall => (108.0, 0.3, 0.25, false, 0.05),
            Self::Fence => (102.0, 0.5, 0.5, false, 0.05),
            Self::Car => (114.0, 0.4, 0.3, false, 0.1),
            Self::Vegetation => (104.0, 0.35, 1.0, false, 0.6),
        };
        SurfaceProperties { strength_db, transmission, diffuse_fraction, mirror, depth_m }
    }
}

/// Default return level of a pole at 10 m, dB.
pub const POLE_STRENGTH_DB: f64 = 120.0;

fn building() -> Material {
    Material::Building
}
fn wall() -> Material {
    Material::Wall
}
fn car_length() -> f64 {
    4.5
}
fn car_width() -> f64 {
    1.8
}

/// A reflector as scenario files write it (`[[reflectors]]` with a `kind`),
/// world coordinates in metres.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ReflectorSpec {
    /// A straight surface from `a_m` to `b_m` (default material: wall).
    Wall {
        /// One end.
        a_m: [f64; 2],
        /// Other end.
        b_m: [f64; 2],
        /// Material (default `wall`).
        #[serde(default = "wall")]
        material: Material,
        /// Overrides the material's strength, dB at 10 m.
        #[serde(default)]
        strength_db: Option<f64>,
    },
    /// A closed outline (building footprint, hedge), at least 3 vertices.
    Polygon {
        /// Vertices in order; the last connects back to the first.
        vertices_m: Vec<[f64; 2]>,
        /// Material (default `building`).
        #[serde(default = "building")]
        material: Material,
        /// Overrides the material's strength, dB at 10 m.
        #[serde(default)]
        strength_db: Option<f64>,
    },
    /// A parked car: a rectangle centred at `(x_m, y_m)`, long axis at `yaw_deg`
    /// (counter-clockwise from world x).
    Car {
        /// Centre x.
        x_m: f64,
        /// Centre y.
        y_m: f64,
        /// Heading of the long axis, degrees.
        yaw_deg: f64,
        /// Length, metres (default 4.5).
        #[serde(default = "car_length")]
        length_m: f64,
        /// Width, metres (default 1.8).
        #[serde(default = "car_width")]
        width_m: f64,
    },
    /// A pole (lamp post, sign post, tree trunk): a point target.
    Pole {
        /// Position x.
        x_m: f64,
        /// Position y.
        y_m: f64,
        /// Overrides the default strength (120 dB at 10 m).
        #[serde(default)]
        strength_db: Option<f64>,
    },
    /// Any other small scatterer (bin, bollard, bicycle): a point target.
    Point {
        /// Position x.
        x_m: f64,
        /// Position y.
        y_m: f64,
        /// Return level at 10 m, dB.
        strength_db: f64,
    },
}

/// A compiled straight surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Segment {
    pub a: [f64; 2],
    pub b: [f64; 2],
    /// Linear power at 10 m, broadside.
    pub power_10m: f64,
    pub transmission: f64,
    pub diffuse_fraction: f64,
    pub mirror: bool,
    pub depth_m: f64,
}

/// A compiled point target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PointTarget {
    pub p: [f64; 2],
    /// Linear power at 10 m on the beam axis.
    pub power_10m: f64,
}

/// A ray's crossing of a segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Hit {
    pub range_m: f64,
    pub segment: u32,
    /// Distance from the segment's first end to the hit, metres (speckle patch).
    pub along_m: f64,
    /// |cos| of the incidence angle.
    pub cos_incidence: f64,
}

/// The compiled world: segments and points in uniform grids.
#[derive(Debug, Clone)]
pub struct World {
    pub(crate) segments: Vec<Segment>,
    pub(crate) points: Vec<PointTarget>,
    segment_grid: super::grid::Grid,
    point_grid: super::grid::Grid,
}

/// Edge of a grid cell, metres: a few times the typical segment length, so a
/// beam visits about `range / 8` cells.
const CELL_M: f64 = 8.0;

impl World {
    /// Compiles reflectors; errors name the reflector (index) and field.
    pub fn new(reflectors: &[ReflectorSpec]) -> Result<Self, SimError> {
        let mut segments = Vec::new();
        let mut points = Vec::new();
        for (index, reflector) in reflectors.iter().enumerate() {
            compile(index, reflector, &mut segments, &mut points)?;
        }
        let segment_boxes: Vec<[f64; 4]> = segments
            .iter()
            .map(|s| [s.a[0].min(s.b[0]), s.a[1].min(s.b[1]), s.a[0].max(s.b[0]), s.a[1].max(s.b[1])])
            .collect();
        let point_boxes: Vec<[f64; 4]> = points.iter().map(|p| [p.p[0], p.p[1], p.p[0], p.p[1]]).collect();
        Ok(Self {
            segment_grid: super::grid::Grid::build(&segment_boxes, CELL_M),
            point_grid: super::grid::Grid::build(&point_boxes, CELL_M),
            segments,
            points,
        })
    }

    /// Number of surface segments (polygon edges, car sides, walls).
    #[must_use]
    pub fn segment_count(&self) -> usize {
        self.segments.len()
    }

    /// Number of point targets (poles, clutter).
    #[must_use]
    pub fn point_count(&self) -> usize {
        self.points.len()
    }

    /// Distance from `p` to the nearest reflector, metres (infinite in an
    /// empty world). Linear in the world size: for tests and checks.
    #[must_use]
    pub fn distance_to_nearest_m(&self, p: [f64; 2]) -> f64 {
        let to_segments = self.segments.iter().map(|s| point_segment_distance_m(p, s.a, s.b));
        let to_points = self.points.iter().map(|t| (t.p[0] - p[0]).hypot(t.p[1] - p[1]));
        to_segments.chain(to_points).fold(f64::INFINITY, f64::min)
    }

    /// Hits of the ray `origin + t dir` (`dir` unit), `0 < t <= max_range_m`,
    /// sorted by range, stopping after the first opaque surface.
    pub(crate) fn cast(&self, origin: [f64; 2], dir: [f64; 2], max_range_m: f64, scratch: &mut Scratch) -> Vec<Hit> {
        scratch.begin_ray(self.segments.len());
        let mut hits: Vec<Hit> = Vec::new();
        let mut nearest_opaque_m = f64::INFINITY;
        self.segment_grid.walk_ray(origin, dir, max_range_m, &mut |ids, cell_exit_m| {
            for &id in ids {
                if !scratch.first_visit(id) {
                    continue;
                }
                let Some(segment) = self.segments.get(id as usize) else { continue };
                if let Some(hit) = intersect(origin, dir, segment, id)
                    && hit.range_m <= max_range_m
                {
                    if segment.transmission <= 0.0 {
                        nearest_opaque_m = nearest_opaque_m.min(hit.range_m);
                    }
                    hits.push(hit);
                }
            }
            // Keep walking until the nearest opaque hit lies inside the visited cells.
            nearest_opaque_m > cell_exit_m
        });
        hits.sort_by(|a, b| a.range_m.total_cmp(&b.range_m).then(a.segment.cmp(&b.segment)));
        hits.retain(|h| h.range_m <= nearest_opaque_m);
        hits
    }

    /// Ids of the point targets within `radius_m` of `centre`, ascending.
    pub(crate) fn points_near(&self, centre: [f64; 2], radius_m: f64) -> Vec<u32> {
        let mut out = Vec::new();
        let query = [centre[0] - radius_m, centre[1] - radius_m, centre[0] + radius_m, centre[1] + radius_m];
        self.point_grid.visit_box(query, &mut |ids| {
            for &id in ids {
                if let Some(p) = self.points.get(id as usize)
                    && (p.p[0] - centre[0]).hypot(p.p[1] - centre[1]) <= radius_m
                {
                    out.push(id);
                }
            }
        });
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// Per-thread scratch of the ray caster: which segments a ray already tested.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    stamps: Vec<u32>,
    ray: u32,
}

impl Scratch {
    fn begin_ray(&mut self, segments: usize) {
        if self.stamps.len() != segments || self.ray == u32::MAX {
            self.stamps = vec![0; segments];
            self.ray = 0;
        }
        self.ray += 1;
    }

    fn first_visit(&mut self, id: u32) -> bool {
        match self.stamps.get_mut(id as usize) {
            Some(stamp) if *stamp != self.ray => {
                *stamp = self.ray;
                true
            }
            _ => false,
        }
    }
}

fn intersect(origin: [f64; 2], dir: [f64; 2], s: &Segment, id: u32) -> Option<Hit> {
    let edge = [s.b[0] - s.a[0], s.b[1] - s.a[1]];
    let denominator = dir[0] * edge[1] - dir[1] * edge[0];
    if denominator.abs() < 1e-12 {
        return None;
    }
    let to_a = [s.a[0] - origin[0], s.a[1] - origin[1]];
    let range_m = (to_a[0] * edge[1] - to_a[1] * edge[0]) / denominator;
    let along = (to_a[0] * dir[1] - to_a[1] * dir[0]) / denominator;
    if range_m <= 1e-6 || !(0.0..=1.0).contains(&along) {
        return None;
    }
    let length = edge[0].hypot(edge[1]);
    let cos_incidence = (denominator / length).abs(); // |dir x edge| / |edge| = |dir . normal|
    Some(Hit { range_m, segment: id, along_m: along * length, cos_incidence })
}

/// Distance from `p` to the segment a-b, metres.
#[must_use]
pub fn point_segment_distance_m(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let length2 = ab[0] * ab[0] + ab[1] * ab[1];
    let s =
        if length2 > 0.0 { (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / length2).clamp(0.0, 1.0) } else { 0.0 };
    (a[0] + s * ab[0] - p[0]).hypot(a[1] + s * ab[1] - p[1])
}

fn surface(a: [f64; 2], b: [f64; 2], material: Material, strength_db: Option<f64>) -> Segment {
    let props = material.properties();
    Segment {
        a,
        b,
        power_10m: super::Sensor::db_to_power(strength_db.unwrap_or(props.strength_db)),
        transmission: props.transmission,
        diffuse_fraction: props.diffuse_fraction,
        mirror: props.mirror,
        depth_m: props.depth_m,
    }
}

fn check_xy(index: usize, field: &str, p: [f64; 2]) -> Result<(), SimError> {
    ensure_finite(&format!("reflectors[{index}].{field}[0]"), p[0])?;
    ensure_finite(&format!("reflectors[{index}].{field}[1]"), p[1])
}

fn check_strength(index: usize, strength_db: Option<f64>) -> Result<(), SimError> {
    match strength_db {
        Some(db) if !(db.is_finite() && (-50.0..=250.0).contains(&db)) => {
            Err(invalid(format!("reflectors[{index}].strength_db"), db, "a level in [-50, 250] dB"))
        }
        _ => Ok(()),
    }
}

fn compile(
    index: usize,
    reflector: &ReflectorSpec,
    segments: &mut Vec<Segment>,
    points: &mut Vec<PointTarget>,
) -> Result<(), SimError> {
    match reflector {
        ReflectorSpec::Wall { a_m, b_m, material, strength_db } => {
            check_xy(index, "a_m", *a_m)?;
            check_xy(index, "b_m", *b_m)?;
            check_strength(index, *strength_db)?;
            segments.push(surface(*a_m, *b_m, *material, *strength_db));
        }
        ReflectorSpec::Polygon { vertices_m, material, strength_db } => {
            if vertices_m.len() < 3 {
                return Err(invalid(
                    format!("reflectors[{index}].vertices_m"),
                    vertices_m.len(),
                    "at least 3 vertices",
                ));
            }
            check_strength(index, *strength_db)?;
            for (i, v) in vertices_m.iter().enumerate() {
                check_xy(index, &format!("vertices_m[{i}]"), *v)?;
                let next = vertices_m[(i + 1) % vertices_m.len()];
                segments.push(surface(*v, next, *material, *strength_db));
            }
        }
        ReflectorSpec::Car { x_m, y_m, yaw_deg, length_m, width_m } => {
            check_xy(index, "x_m/y_m", [*x_m, *y_m])?;
            ensure_finite(&format!("reflectors[{index}].yaw_deg"), *yaw_deg)?;
            ensure_positive(&format!("reflectors[{index}].length_m"), *length_m)?;
            ensure_positive(&format!("reflectors[{index}].width_m"), *width_m)?;
            let (s, c) = yaw_deg.to_radians().sin_cos();
            let corner = |l: f64, w: f64| [x_m + c * l - s * w, y_m + s * l + c * w];
            let (hl, hw) = (0.5 * length_m, 0.5 * width_m);
            let corners = [corner(hl, hw), corner(-hl, hw), corner(-hl, -hw), corner(hl, -hw)];
            for i in 0..4 {
                segments.push(surface(corners[i], corners[(i + 1) % 4], Material::Car, None));
            }
        }
        ReflectorSpec::Pole { x_m, y_m, strength_db } => {
            check_xy(index, "x_m/y_m", [*x_m, *y_m])?;
            check_strength(index, *strength_db)?;
            let db = strength_db.unwrap_or(POLE_STRENGTH_DB);
            points.push(PointTarget { p: [*x_m, *y_m], power_10m: super::Sensor::db_to_power(db) });
        }
        ReflectorSpec::Point { x_m, y_m, strength_db } => {
            check_xy(index, "x_m/y_m", [*x_m, *y_m])?;
            check_strength(index, Some(*strength_db))?;
            points.push(PointTarget { p: [*x_m, *y_m], power_10m: super::Sensor::db_to_power(*strength_db) });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wall(a: [f64; 2], b: [f64; 2], material: Material) -> ReflectorSpec {
        ReflectorSpec::Wall { a_m: a, b_m: b, material, strength_db: None }
    }

    #[test]
    fn the_nearest_opaque_surface_ends_the_ray() {
        let world = World::new(&[
            wall([30.0, -5.0], [30.0, 5.0], Material::Building),
            wall([10.0, -5.0], [10.0, 5.0], Material::Vegetation),
            wall([20.0, -5.0], [20.0, 5.0], Material::Building),
        ])
        .unwrap();
        let hits = world.cast([0.0, 0.0], [1.0, 0.0], 100.0, &mut Scratch::default());
        let ranges: Vec<f64> = hits.iter().map(|h| h.range_m).collect();
        assert_eq!(ranges, vec![10.0, 20.0]); // the facade at 30 m is hidden
        assert!((hits[0].cos_incidence - 1.0).abs() < 1e-12);
    }

    #[test]
    fn rays_from_outside_the_grid_and_long_walls_are_found() {
        let world = World::new(&[wall([-500.0, 40.0], [500.0, 40.0], Material::Building)]).unwrap();
        let dir = [0.6, 0.8];
        let hits = world.cast([-450.0, -10.0], dir, 200.0, &mut Scratch::default());
        assert_eq!(hits.len(), 1);
        assert!((hits[0].range_m - 62.5).abs() < 1e-9, "{}", hits[0].range_m);
        assert!(world.cast([-450.0, -10.0], dir, 60.0, &mut Scratch::default()).is_empty());
    }

    #[test]
    fn bad_reflectors_are_named() {
        let err = World::new(&[ReflectorSpec::Polygon {
            vertices_m: vec![[0.0, 0.0], [1.0, 0.0]],
            material: Material::Building,
            strength_db: None,
        }])
        .unwrap_err();
        assert!(err.to_string().contains("reflectors[0].vertices_m"), "{err}");
        let err = World::new(&[ReflectorSpec::Pole { x_m: f64::NAN, y_m: 0.0, strength_db: None }]).unwrap_err();
        assert!(err.to_string().contains("reflectors[0].x_m/y_m"), "{err}");
    }
}
