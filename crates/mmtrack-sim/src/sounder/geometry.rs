//! Plane geometry of the convoy scenario: the road (straight or an arc),
//! wall polylines, specular reflection points and visibility.

/// A point or vector in the world plane, metres.
pub(crate) type P2 = [f64; 2];

pub(crate) fn sub(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}
pub(crate) fn dot(a: P2, b: P2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
pub(crate) fn cross(a: P2, b: P2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
/// Distance (plain `sqrt`, not `hypot`: coordinates here are metres, far
/// from overflow, and `hypot` was a sixth of the run time).
pub(crate) fn dist(a: P2, b: P2) -> f64 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    (dx * dx + dy * dy).sqrt()
}
/// Unit vector from `from` towards `to`.
pub(crate) fn unit(from: P2, to: P2) -> P2 {
    let d = dist(from, to);
    [(to[0] - from[0]) / d, (to[1] - from[1]) / d]
}

/// The road's centreline: straight along +x from the origin, or an arc of
/// signed radius (positive: turning left, centre at `(0, R)`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Road {
    /// Signed radius, metres; `None` for a straight road.
    pub radius_m: Option<f64>,
}

impl Road {
    /// Position and heading of the point at arc length `s_m` along the lane
    /// at lateral offset `lateral_m` (left positive). On an arc, the lane's
    /// own radius is `R - lateral_m`, so `s_m` is distance along the lane.
    pub fn lane_point(&self, s_m: f64, lateral_m: f64) -> (P2, f64) {
        match self.radius_m {
            None => ([s_m, lateral_m], 0.0),
            Some(r) => {
                let lane_r = r - lateral_m;
                let theta = s_m / lane_r;
                let (sin, cos) = theta.sin_cos();
                ([lane_r * sin, r - lane_r * cos], theta)
            }
        }
    }

    /// The point at centreline arc length `s_m`, offset `lateral_m`.
    pub fn centre_point(&self, s_m: f64, lateral_m: f64) -> P2 {
        match self.radius_m {
            None => [s_m, lateral_m],
            Some(r) => {
                let (sin, cos) = (s_m / r).sin_cos();
                [(r - lateral_m) * sin, r - (r - lateral_m) * cos]
            }
        }
    }

    /// Centreline arc length of the point nearest to `p`.
    pub fn centre_s(&self, p: P2) -> f64 {
        match self.radius_m {
            None => p[0],
            Some(r) => {
                // Angle about the centre (0, R), measured so that the start is 0.
                let theta = if r > 0.0 { p[0].atan2(r - p[1]) } else { (-p[0]).atan2(p[1] - r) };
                theta * r
            }
        }
    }
}

/// A wall: a polyline with vertices every `segment_m` of centreline.
#[derive(Debug, Clone)]
pub(crate) struct Wall {
    pub vertices: Vec<P2>,
    /// Centreline arc length of vertex 0, and the spacing.
    pub s0_m: f64,
    pub segment_m: f64,
    /// Sign of `cross(segment direction, p - segment start)` for points on
    /// the road side of the wall.
    pub interior_sign: f64,
}

impl Wall {
    /// Segment indices `[first, last)` covering centreline `[s_lo, s_hi]`.
    pub fn segment_range(&self, s_lo: f64, s_hi: f64) -> (usize, usize) {
        let n = self.vertices.len().saturating_sub(1);
        let lo = ((s_lo - self.s0_m) / self.segment_m).floor().clamp(0.0, n as f64) as usize;
        let hi = ((s_hi - self.s0_m) / self.segment_m).ceil().clamp(0.0, n as f64) as usize;
        (lo, hi.max(lo))
    }

    pub fn segment(&self, j: usize) -> (P2, P2) {
        (self.vertices[j], self.vertices[j + 1])
    }
}

/// The point of wall `wall` (segments `range`) minimising
/// `|a - p| + |p - b|`, with `a` and `b` both on the road side: per segment
/// the image-method specular point clamped to the segment (the sum of
/// distances is convex along a line, so the clamp is that segment's
/// minimum), then the best segment. `None` when no segment has both points
/// on its road side or the minimum sits at the ends of `range` (the
/// reflection lies outside the part of the wall considered).
pub(crate) fn reflection_point(wall: &Wall, range: (usize, usize), a: P2, b: P2) -> Option<(P2, usize)> {
    let mut best: Option<(f64, P2, usize)> = None;
    for j in range.0..range.1 {
        let (p, q) = wall.segment(j);
        let d = sub(q, p);
        let ha = cross(d, sub(a, p)) * wall.interior_sign;
        let hb = cross(d, sub(b, p)) * wall.interior_sign;
        if ha <= 0.0 || hb <= 0.0 {
            continue;
        }
        let dd = dot(d, d);
        let ta = dot(sub(a, p), d) / dd;
        let tb = dot(sub(b, p), d) / dd;
        let t = (ta + (tb - ta) * ha / (ha + hb)).clamp(0.0, 1.0);
        let point = [p[0] + t * d[0], p[1] + t * d[1]];
        let length = dist(a, point) + dist(point, b);
        if best.is_none_or(|(l, _, _)| length < l) {
            best = Some((length, point, j));
        }
    }
    let (_, point, j) = best?;
    let first = wall.vertices[range.0];
    let last = wall.vertices[range.1];
    if dist(point, first) < 1e-9 || dist(point, last) < 1e-9 {
        return None;
    }
    Some((point, j))
}

/// Whether the open segment `a`-`b` crosses any wall segment in `ranges`
/// (touching at `a` or `b` itself does not count, so legs that start on a
/// wall are not blocked by it).
pub(crate) fn blocked(walls: &[Wall], ranges: &[(usize, usize)], a: P2, b: P2) -> bool {
    let d = sub(b, a);
    let (min_x, max_x) = (a[0].min(b[0]), a[0].max(b[0]));
    let (min_y, max_y) = (a[1].min(b[1]), a[1].max(b[1]));
    for (wall, &(lo, hi)) in walls.iter().zip(ranges) {
        for j in lo..hi {
            let (p, q) = wall.segment(j);
            if p[0].max(q[0]) < min_x || p[0].min(q[0]) > max_x || p[1].max(q[1]) < min_y || p[1].min(q[1]) > max_y {
                continue;
            }
            let e = sub(q, p);
            let denom = cross(d, e);
            if denom.abs() < 1e-15 {
                continue;
            }
            let ap = sub(p, a);
            let t = cross(ap, e) / denom;
            let u = cross(ap, d) / denom;
            if t > 1e-9 && t < 1.0 - 1e-9 && (-1e-12..=1.0 + 1e-12).contains(&u) {
                return true;
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    fn straight_wall(y: f64, interior_sign: f64) -> Wall {
        Wall {
            vertices: (0..=50).map(|i| [i as f64 * 4.0 - 100.0, y]).collect(),
            s0_m: -100.0,
            segment_m: 4.0,
            interior_sign,
        }
    }

    #[test]
    fn reflection_off_a_straight_wall_is_the_image_point() {
        // Wall y = 5 (interior below: cross((1,0), (x, y - 5)) = y - 5 < 0).
        let wall = straight_wall(5.0, -1.0);
        let (p, _) = reflection_point(&wall, (0, 50), [0.0, 0.0], [30.0, 2.0]).unwrap();
        // Image of a = (0, 10); line to (30, 2) crosses y = 5 at x = 30 * 5 / 8.
        assert!((p[0] - 18.75).abs() < 1e-12 && (p[1] - 5.0).abs() < 1e-15, "{p:?}");
    }

    #[test]
    fn arc_points_and_lane_headings() {
        let road = Road { radius_m: Some(500.0) };
        let (p, heading) = road.lane_point(0.0, -1.75);
        assert!((p[0]).abs() < 1e-12 && (p[1] + 1.75).abs() < 1e-12 && heading == 0.0);
        let (p, heading) = road.lane_point(100.0, 2.0);
        // On the lane's own circle of radius 498 about (0, 500).
        assert!((dist(p, [0.0, 500.0]) - 498.0).abs() < 1e-9);
        assert!((heading - 100.0 / 498.0).abs() < 1e-15);
        assert!((road.centre_s(road.centre_point(123.0, 3.0)) - 123.0).abs() < 1e-9);
        let right = Road { radius_m: Some(-400.0) };
        assert!((right.centre_s(right.centre_point(77.0, -2.0)) - 77.0).abs() < 1e-9);
    }

    #[test]
    fn a_wall_blocks_a_crossing_leg_only() {
        let wall = straight_wall(5.0, -1.0);
        assert!(blocked(std::slice::from_ref(&wall), &[(0, 50)], [0.0, 0.0], [10.0, 10.0]));
        assert!(!blocked(std::slice::from_ref(&wall), &[(0, 50)], [0.0, 0.0], [10.0, 4.0]));
        // A leg starting on the wall is not blocked by it.
        assert!(!blocked(std::slice::from_ref(&wall), &[(0, 50)], [2.0, 5.0], [10.0, 0.0]));
    }
}
