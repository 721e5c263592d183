//! Stages 2 and 3: grid downsampling and oriented surface points.

use crate::filter::FilteredPoint;
use crate::grid::GridIndex;

/// An oriented surface point: the mean of nearby filtered points and the
/// normal of the line they lie on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// Sample mean mu_i of the neighbourhood, metres.
    pub mean_m: [f64; 2],
    /// Unit normal n_i: the eigenvector of the smallest eigenvalue of the
    /// neighbourhood's sample covariance (sign arbitrary).
    pub normal: [f64; 2],
    /// Filtered points in the neighbourhood.
    pub neighbours: u32,
}

/// Parameters of stages 2 and 3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceParams {
    /// Neighbourhood radius d_D, metres.
    pub radius_m: f64,
    /// Downsampling cell side d_D / f_D, metres.
    pub cell_m: f64,
    /// Fewest neighbours for a surface point.
    pub min_neighbours: usize,
    /// Largest eigenvalue ratio.
    pub max_condition_number: f64,
}

/// Grid downsampling (one point per cell: the centroid of the filtered points
/// in it, Sec. III-A.2) followed by one oriented surface point per kept point
/// (Sec. III-A.3): `mu_i = mean(N_i)`, `Sigma_i = cov(N_i)` with
/// `N_i = { p_j in P_F : ||p_i - p_j|| <= d_D }`, the normal the eigenvector of
/// Sigma_i's smallest eigenvalue. As in the authors' code, neighbourhoods with
/// fewer than `min_neighbours` points or a condition number above
/// `max_condition_number` are dropped. Cells are visited in (x, y) order so the
/// output is deterministic.
///
/// The neighbourhood search: a grid of cells of side d_D, so `N_i` lies in
/// the 3 x 3 cells around `p_i`; cells wholly farther than d_D are not
/// read, and each cell's points are tested before the inside ones are
/// summed ([`GridIndex::for_each_cell_near`], `Moments::add_within`). The
/// sums run over the same points in the same order as summing every
/// candidate with `+0.0` for the outside ones, so the surface points are
/// the same to the last bit (tested on the real Oxford scans).
///
/// # References
/// Liu et al., SPEBT, Sec. III-A.2 and III-A.3 (the covariance of eq. (6)).
#[must_use]
pub fn surface_points(filtered: &[FilteredPoint], params: &SurfaceParams) -> Vec<SurfacePoint> {
    let xy = || filtered.iter().map(|p| p.xy_m);
    let index = GridIndex::new(xy(), params.radius_m);
    let separate_cells;
    let cells = if params.cell_m == params.radius_m && index.cell_m() == params.radius_m {
        &index
    } else {
        separate_cells = GridIndex::new(xy(), params.cell_m);
        &separate_cells
    };
    let radius_sq = params.radius_m * params.radius_m;
    let mut out = Vec::new();
    for cell in cells.occupied_cell_positions() {
        let sum = cell.iter().fold([0.0, 0.0], |acc, p| [acc[0] + p[0], acc[1] + p[1]]);
        let count = cell.len() as f64;
        let centre = [sum[0] / count, sum[1] / count];
        let mut moments = Moments::default();
        index.for_each_cell_near(centre, params.radius_m, |cell| moments.add_within(cell, centre, radius_sq));
        if moments.n < params.min_neighbours.max(2) {
            continue;
        }
        if let Some(point) = moments.oriented_point(centre, params.max_condition_number) {
            out.push(point);
        }
    }
    out
}

/// Running sums of a neighbourhood's offsets from its query centre: one pass
/// gives the sample mean and covariance (offsets are at most d_D, so the
/// shifted sums lose no precision).
#[derive(Debug, Default)]
struct Moments {
    n: usize,
    sx: f64,
    sy: f64,
    sxx: f64,
    syy: f64,
    sxy: f64,
}

/// Points [`Moments::add_within`] tests before summing the ones inside.
const MOMENT_CHUNK: usize = 64;

impl Moments {
    /// [`Moments::add`] for each point of `points` within `radius_sq` of
    /// `centre` (squared distance `<= radius_sq`), in their order. Two passes
    /// per chunk of [`MOMENT_CHUNK`] points: the distance tests write every
    /// offset into a buffer but advance its end only past the inside ones
    /// (no branch, no misprediction), then the inside offsets are summed.
    /// The sums are the same as [`Moments::add_if`] over all the points
    /// (which adds `+0.0` for the outside ones), term for term, but the
    /// dependent chain of additions, the cost of a neighbourhood, runs over
    /// the inside points only (about a third of the candidates).
    #[inline]
    fn add_within(&mut self, points: &[[f64; 2]], centre: [f64; 2], radius_sq: f64) {
        let mut dx_m = [0.0; MOMENT_CHUNK];
        let mut dy_m = [0.0; MOMENT_CHUNK];
        for chunk in points.chunks(MOMENT_CHUNK) {
            let mut inside = 0;
            for q in chunk {
                let (dx, dy) = (q[0] - centre[0], q[1] - centre[1]);
                // `inside` <= the index of `q` < MOMENT_CHUNK: the mask only drops the bounds check.
                dx_m[inside & (MOMENT_CHUNK - 1)] = dx;
                dy_m[inside & (MOMENT_CHUNK - 1)] = dy;
                inside += usize::from(dx * dx + dy * dy <= radius_sq);
            }
            for (&dx, &dy) in dx_m[..inside].iter().zip(&dy_m[..inside]) {
                self.add(dx, dy);
            }
        }
    }

    /// [`Moments::add`] when `inside`, else nothing, without a branch: about
    /// a third of a query's candidates are inside, in no predictable order,
    /// so a branch would be mispredicted often. Adding `+0.0` for the others
    /// leaves every sum as it was (the sums start at `+0.0` and a
    /// round-to-nearest sum that cancels to zero is `+0.0`, so none is ever
    /// `-0.0`, the one value `+0.0` would change), and the selected terms
    /// are the same products in the same order as `add`'s.
    #[cfg(test)]
    fn add_if(&mut self, inside: bool, dx: f64, dy: f64) {
        let pick = |v: f64| if inside { v } else { 0.0 };
        self.n += usize::from(inside);
        self.sx += pick(dx);
        self.sy += pick(dy);
        self.sxx += pick(dx * dx);
        self.syy += pick(dy * dy);
        self.sxy += pick(dx * dy);
    }

    #[inline]
    fn add(&mut self, dx: f64, dy: f64) {
        self.n += 1;
        self.sx += dx;
        self.sy += dy;
        self.sxx += dx * dx;
        self.syy += dy * dy;
        self.sxy += dx * dy;
    }

    /// Mean, covariance and normal (two or more points), or `None` when the
    /// covariance is degenerate or too elongated.
    fn oriented_point(&self, centre: [f64; 2], max_condition_number: f64) -> Option<SurfacePoint> {
        let n = self.n as f64;
        let (mx, my) = (self.sx / n, self.sy / n);
        let sxx = (self.sxx - n * mx * mx) / (n - 1.0);
        let syy = (self.syy - n * my * my) / (n - 1.0);
        let sxy = (self.sxy - n * mx * my) / (n - 1.0);
        let normal = smallest_eigenvector(sxx, syy, sxy, max_condition_number)?;
        Some(SurfacePoint { mean_m: [centre[0] + mx, centre[1] + my], normal, neighbours: self.n as u32 })
    }
}

/// Unit eigenvector of the smallest eigenvalue of the symmetric 2x2
/// `[[sxx, sxy], [sxy, syy]]` (closed form), or `None` when the matrix is not
/// positive definite or its condition number exceeds `max_condition_number`.
fn smallest_eigenvector(sxx: f64, syy: f64, sxy: f64, max_condition_number: f64) -> Option<[f64; 2]> {
    let half_trace = 0.5 * (sxx + syy);
    let root = (0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy).sqrt();
    let (large, small) = (half_trace + root, half_trace - root);
    let positive_definite = small > 0.0;
    if !positive_definite || large / small > max_condition_number {
        return None;
    }
    // Eigenvector of `small`: (sxy, small - sxx) or (small - syy, sxy), whichever is better conditioned.
    let (a, b) = (sxy, small - sxx);
    let (c, d) = (small - syy, sxy);
    let v = if a * a + b * b >= c * c + d * d { [a, b] } else { [c, d] };
    let norm = v[0].hypot(v[1]);
    Some(if norm > 0.0 { [v[0] / norm, v[1] / norm] } else { [1.0, 0.0] })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> SurfaceParams {
        SurfaceParams { radius_m: 3.5, cell_m: 3.5, min_neighbours: 6, max_condition_number: 1e5 }
    }

    fn points(xy: impl Iterator<Item = [f64; 2]>) -> Vec<FilteredPoint> {
        xy.map(|xy_m| FilteredPoint { xy_m, power: 100 }).collect()
    }

    /// The search before the pruned one: every point of the 3 x 3 cells,
    /// added with `+0.0` when outside the radius.
    fn surface_points_full_3x3(filtered: &[FilteredPoint], params: &SurfaceParams) -> Vec<SurfacePoint> {
        assert_eq!(params.cell_m, params.radius_m, "the real-scan presets use f_D = 1");
        let index = GridIndex::new(filtered.iter().map(|p| p.xy_m), params.radius_m);
        let radius_sq = params.radius_m * params.radius_m;
        let mut out = Vec::new();
        for cell in index.occupied_cell_positions() {
            let sum = cell.iter().fold([0.0, 0.0], |acc, p| [acc[0] + p[0], acc[1] + p[1]]);
            let count = cell.len() as f64;
            let centre = [sum[0] / count, sum[1] / count];
            let mut moments = Moments::default();
            index.for_each_candidate(centre, |_, q| {
                let (dx, dy) = (q[0] - centre[0], q[1] - centre[1]);
                moments.add_if(dx * dx + dy * dy <= radius_sq, dx, dy);
            });
            if moments.n < params.min_neighbours.max(2) {
                continue;
            }
            if let Some(point) = moments.oriented_point(centre, params.max_condition_number) {
                out.push(point);
            }
        }
        out
    }

    /// Every downsampled centre with its neighbour count over all filtered
    /// points (no grid): what the neighbourhood search must find.
    fn brute_force_counts(filtered: &[FilteredPoint], params: &SurfaceParams) -> Vec<([f64; 2], usize)> {
        let index = GridIndex::new(filtered.iter().map(|p| p.xy_m), params.cell_m);
        let radius_sq = params.radius_m * params.radius_m;
        index
            .occupied_cell_positions()
            .map(|cell| {
                let sum = cell.iter().fold([0.0, 0.0], |acc, p| [acc[0] + p[0], acc[1] + p[1]]);
                let centre = [sum[0] / cell.len() as f64, sum[1] / cell.len() as f64];
                let inside = filtered
                    .iter()
                    .filter(|p| {
                        let (dx, dy) = (p.xy_m[0] - centre[0], p.xy_m[1] - centre[1]);
                        dx * dx + dy * dy <= radius_sq
                    })
                    .count();
                (centre, inside)
            })
            .collect()
    }

    fn preset_params(config: &crate::OdometryConfig) -> SurfaceParams {
        SurfaceParams {
            radius_m: config.grid_m,
            cell_m: config.grid_m / config.resample_factor,
            min_neighbours: config.min_surface_neighbours,
            max_condition_number: config.max_condition_number,
        }
    }

    #[test]
    fn on_real_scans_the_pruned_search_gives_the_full_searchs_surface_points_bit_for_bit() {
        use crate::filter::{BodyVelocity, SweepMotion, k_strongest, place};
        let Some(scans) = crate::real_scans::oxford() else { return };
        let bits = |points: &[SurfacePoint]| -> Vec<(u32, [u64; 4])> {
            points
                .iter()
                .map(|p| (p.neighbours, [p.mean_m[0], p.mean_m[1], p.normal[0], p.normal[1]].map(f64::to_bits)))
                .collect()
        };
        // Both presets; the sweep as instantaneous and motion-compensated
        // (a turning drive placed at the middle of its sweep, as cfear places it).
        let turning = BodyVelocity { vx_mps: 8.3, vy_mps: -0.2, yaw_rate_radps: 0.21 };
        let mut compared = 0;
        for config in [crate::OdometryConfig::fast_cfear(), crate::OdometryConfig::cfear()] {
            let params = preset_params(&config);
            for scan in &scans {
                let kept =
                    k_strongest(scan, config.k_strongest, config.min_power, config.min_range_m, config.max_range_m);
                for motion in [None, Some(SweepMotion { velocity: turning, reference_dt_s: 0.125 })] {
                    let filtered = place(&kept, motion);
                    let pruned = surface_points(&filtered, &params);
                    let full = surface_points_full_3x3(&filtered, &params);
                    assert!(pruned.len() > 50, "{} surface points: too few to test anything", pruned.len());
                    assert_eq!(bits(&pruned), bits(&full), "k = {}, {motion:?}", config.k_strongest);
                    compared += pruned.len();
                }
            }
        }
        assert!(compared > 5_000, "{compared}");
    }

    #[test]
    fn on_real_scans_every_neighbour_within_the_radius_is_found() {
        use crate::filter::{k_strongest, place};
        let Some(scans) = crate::real_scans::oxford() else { return };
        // Three scans with cfear's k = 40 (the densest neighbourhoods): the
        // pruned grid search from every downsampled centre against a count
        // over every filtered point; a missed or extra neighbour changes it.
        let config = crate::OdometryConfig::cfear();
        let params = preset_params(&config);
        let radius_sq = params.radius_m * params.radius_m;
        for scan in scans.iter().step_by(5) {
            let kept = k_strongest(scan, config.k_strongest, config.min_power, config.min_range_m, config.max_range_m);
            let filtered = place(&kept, None);
            let index = GridIndex::new(filtered.iter().map(|p| p.xy_m), params.radius_m);
            let truth = brute_force_counts(&filtered, &params);
            assert!(truth.len() > 200 && filtered.len() > 10_000, "{} centres, {} points", truth.len(), filtered.len());
            let mut pairs = 0;
            for &(centre, expected) in &truth {
                let mut moments = Moments::default();
                index.for_each_cell_near(centre, params.radius_m, |cell| moments.add_within(cell, centre, radius_sq));
                assert_eq!(moments.n, expected, "neighbours of the centre at {centre:?}");
                pairs += expected;
            }
            assert!(pairs > 10 * truth.len(), "{pairs} neighbours for {} centres", truth.len());
        }
    }

    #[test]
    fn a_noisy_wall_gives_normals_across_it() {
        // Points along y = 10 with a small deterministic wiggle: normals along y.
        let wall = points((0..200).map(|i| [i as f64 * 0.1, 10.0 + 0.05 * ((i * 7 % 5) as f64 - 2.0)]));
        let surface = surface_points(&wall, &params());
        assert!(surface.len() >= 5, "{}", surface.len());
        for s in &surface {
            assert!(s.normal[1].abs() > 0.99, "{s:?}");
            assert!((s.mean_m[1] - 10.0).abs() < 0.1, "{s:?}");
        }
    }

    #[test]
    fn add_if_is_add_for_inside_points_and_nothing_for_the_others() {
        let offsets: Vec<(f64, f64)> =
            (0..200).map(|i| (((i * 37) % 23) as f64 * 0.31 - 3.4, ((i * 11) % 19) as f64 * -0.27 + 2.5)).collect();
        let (mut branchless, mut branching) = (Moments::default(), Moments::default());
        for &(dx, dy) in &offsets {
            let inside = dx * dx + dy * dy <= 9.0;
            branchless.add_if(inside, dx, dy);
            if inside {
                branching.add(dx, dy);
            }
        }
        assert!(branching.n > 10 && branching.n < offsets.len(), "{}", branching.n);
        let bits = |m: &Moments| (m.n, [m.sx, m.sy, m.sxx, m.syy, m.sxy].map(f64::to_bits));
        assert_eq!(bits(&branchless), bits(&branching));
    }

    #[test]
    fn a_perfect_line_is_ill_conditioned_and_dropped() {
        let line = points((0..50).map(|i| [i as f64 * 0.1, 3.0]));
        assert!(surface_points(&line, &params()).is_empty());
    }

    #[test]
    fn sparse_neighbourhoods_are_dropped() {
        let few = points((0..5).map(|i| [i as f64 * 0.3, (i % 2) as f64 * 0.2]));
        assert!(surface_points(&few, &params()).is_empty());
    }

    #[test]
    fn normal_is_the_smallest_eigenvector_for_any_orientation() {
        for k in 0..12 {
            let angle = k as f64 * 0.3;
            let (s, c) = angle.sin_cos();
            let pts: Vec<[f64; 2]> = (0..40)
                .map(|i| {
                    let along = i as f64 * 0.1 - 2.0;
                    let across = 0.02 * ((i * 3 % 7) as f64 - 3.0);
                    [c * along - s * across, s * along + c * across]
                })
                .collect();
            let mut moments = Moments::default();
            pts.iter().for_each(|q| moments.add(q[0] - 0.3, q[1] + 0.2));
            let p = moments.oriented_point([0.3, -0.2], 1e9).unwrap();
            // The normal solves the eigen-equation Sigma n = lambda n with the smaller lambda.
            let n = pts.len() as f64;
            let cov = |u: [f64; 2], v: [f64; 2]| {
                pts.iter()
                    .map(|q| {
                        let d = [q[0] - p.mean_m[0], q[1] - p.mean_m[1]];
                        (d[0] * u[0] + d[1] * u[1]) * (d[0] * v[0] + d[1] * v[1])
                    })
                    .sum::<f64>()
                    / (n - 1.0)
            };
            let normal = p.normal;
            let tangent = [-normal[1], normal[0]];
            assert!(cov(normal, tangent).abs() < 1e-12, "angle {angle}: not an eigenvector");
            assert!(cov(normal, normal) < cov(tangent, tangent), "angle {angle}: not the smaller eigenvalue");
            // And it is close to the perpendicular of the line's direction (c, s).
            assert!((normal[0] * c + normal[1] * s).abs() < 0.01, "angle {angle}: {p:?}");
        }
    }
}
