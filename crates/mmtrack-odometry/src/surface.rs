//! Stages 2 and 3: grid downsampling and oriented surface points.

use std::collections::BTreeMap;

use crate::filter::FilteredPoint;
use crate::grid::{GridIndex, cell_of};

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
/// # References
/// Liu et al., SPEBT, Sec. III-A.2 and III-A.3 (the covariance of eq. (6)).
#[must_use]
pub fn surface_points(filtered: &[FilteredPoint], params: &SurfaceParams) -> Vec<SurfacePoint> {
    let mut cells: BTreeMap<(i64, i64), ([f64; 2], u32)> = BTreeMap::new();
    for p in filtered {
        let entry = cells.entry(cell_of(p.xy_m, params.cell_m)).or_insert(([0.0, 0.0], 0));
        entry.0[0] += p.xy_m[0];
        entry.0[1] += p.xy_m[1];
        entry.1 += 1;
    }
    let index = GridIndex::new(filtered.iter().map(|p| p.xy_m), params.radius_m);
    let radius_sq = params.radius_m * params.radius_m;
    let mut out = Vec::with_capacity(cells.len());
    let mut neighbourhood: Vec<[f64; 2]> = Vec::new();
    for (sum, count) in cells.values() {
        let centre = [sum[0] / f64::from(*count), sum[1] / f64::from(*count)];
        neighbourhood.clear();
        neighbourhood.extend(index.candidates(centre).map(|i| filtered[i].xy_m).filter(|q| {
            let (dx, dy) = (q[0] - centre[0], q[1] - centre[1]);
            dx * dx + dy * dy <= radius_sq
        }));
        if neighbourhood.len() < params.min_neighbours.max(2) {
            continue;
        }
        if let Some(point) = oriented_point(&neighbourhood, params.max_condition_number) {
            out.push(point);
        }
    }
    out
}

/// Mean, covariance and normal of one neighbourhood (two or more points), or
/// `None` when the covariance is degenerate or too elongated.
fn oriented_point(points: &[[f64; 2]], max_condition_number: f64) -> Option<SurfacePoint> {
    let n = points.len() as f64;
    let mean = points.iter().fold([0.0, 0.0], |acc, p| [acc[0] + p[0], acc[1] + p[1]]);
    let mean = [mean[0] / n, mean[1] / n];
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for p in points {
        let (dx, dy) = (p[0] - mean[0], p[1] - mean[1]);
        sxx += dx * dx;
        syy += dy * dy;
        sxy += dx * dy;
    }
    let (sxx, syy, sxy) = (sxx / (n - 1.0), syy / (n - 1.0), sxy / (n - 1.0));
    // Closed-form eigen-decomposition of the symmetric 2x2 [[sxx, sxy], [sxy, syy]].
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
    let normal = if norm > 0.0 { [v[0] / norm, v[1] / norm] } else { [1.0, 0.0] };
    Some(SurfacePoint { mean_m: mean, normal, neighbours: points.len() as u32 })
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
            let p = oriented_point(&pts, 1e9).unwrap();
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
