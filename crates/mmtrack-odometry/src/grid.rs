//! A uniform grid over 2-D points for fixed-radius neighbour queries.
//!
//! Scans hold a few thousand points and queries use one radius, so a grid
//! with cells of that radius answers a query from the 3 x 3 cells around it.
//! The points are bucketed by a counting sort into one flat array (cells in
//! (x, y) order, each cell's points in insertion order): building is linear,
//! a query reads contiguous memory, and results come in a fixed order, so
//! everything built on it is deterministic.

/// Point indices bucketed by cell.
#[derive(Debug, Clone)]
pub struct GridIndex {
    cell_m: f64,
    /// `1 / cell_m`: a point's cell is `floor(x * cells_per_m)`, one
    /// multiplication instead of a division per coordinate (see [`cell_of`]).
    cells_per_m: f64,
    /// Cell of the lower-left corner of the bounding box.
    origin: (i64, i64),
    /// Cells along x and y.
    size: (i64, i64),
    /// Points of cell `c` (row-major, x-major) are `order[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    order: Vec<u32>,
    /// `xy_m[k]` is the position of point `order[k]`: a query reads the
    /// cells' coordinates contiguously instead of gathering them by index.
    xy_m: Vec<[f64; 2]>,
}

/// Largest grid kept dense; sparser point sets use coarser cells (never
/// finer than `cell_m`: queries stay correct, only a little less selective).
const MAX_CELLS: i64 = 1 << 20;

/// Interleaved counters per cell in [`GridIndex::new`]'s counting sort.
const COUNT_LANES: usize = 4;

impl GridIndex {
    /// Buckets `points` into square cells of side `cell_m` (> 0). Points
    /// with a non-finite coordinate are left out (no finite point is within
    /// any distance of them).
    #[must_use]
    pub fn new(points: impl Iterator<Item = [f64; 2]>, cell_m: f64) -> Self {
        // One pass: the finite points with their indices, sized up front.
        let mut finite: Vec<(u32, [f64; 2])> = Vec::with_capacity(points.size_hint().0);
        for (i, p) in points.enumerate() {
            if p[0].is_finite() && p[1].is_finite() {
                finite.push((i as u32, p));
            }
        }
        if finite.is_empty() {
            return Self {
                cell_m,
                cells_per_m: cell_m.recip(),
                origin: (0, 0),
                size: (0, 0),
                start: vec![0],
                order: Vec::new(),
                xy_m: Vec::new(),
            };
        }
        let mut cell_m = cell_m;
        let mut keys: Vec<(i64, i64)> = Vec::with_capacity(finite.len());
        loop {
            keys.clear();
            let cells_per_m = cell_m.recip();
            let (mut lo, mut hi) = ((i64::MAX, i64::MAX), (i64::MIN, i64::MIN));
            for (_, p) in &finite {
                let (x, y) = cell_of(*p, cells_per_m);
                lo = (lo.0.min(x), lo.1.min(y));
                hi = (hi.0.max(x), hi.1.max(y));
                keys.push((x, y));
            }
            let size = (hi.0.saturating_sub(lo.0).saturating_add(1), hi.1.saturating_sub(lo.1).saturating_add(1));
            if size.0.saturating_mul(size.1) > MAX_CELLS {
                cell_m *= 2.0;
                continue;
            }
            let cells = (size.0 * size.1) as usize;
            // Flat cell of every point, computed once for both passes below.
            let flat: Vec<u32> = keys.iter().map(|&(x, y)| ((x - lo.0) * size.1 + (y - lo.1)) as u32).collect();
            // Points come in runs within one cell (a ray's bins), so one
            // counter per cell would make each increment wait for the last
            // one's store; four interleaved counters per cell do not.
            let mut counts = vec![[0u32; COUNT_LANES]; cells];
            let mut lanes = flat.chunks_exact(COUNT_LANES);
            for run in lanes.by_ref() {
                for (lane, &c) in run.iter().enumerate() {
                    counts[c as usize][lane] += 1;
                }
            }
            for &c in lanes.remainder() {
                counts[c as usize][0] += 1;
            }
            let mut start = Vec::with_capacity(cells + 1);
            let mut before = 0u32;
            start.push(before);
            for count in &counts {
                before += count.iter().sum::<u32>();
                start.push(before);
            }
            let mut next = start.clone();
            let mut order = vec![0u32; flat.len()];
            let mut xy_m = vec![[0.0; 2]; flat.len()];
            for (&(index, p), &c) in finite.iter().zip(&flat) {
                let slot = &mut next[c as usize];
                order[*slot as usize] = index;
                xy_m[*slot as usize] = p;
                *slot += 1;
            }
            return Self { cell_m, cells_per_m, origin: lo, size, start, order, xy_m };
        }
    }

    /// Indices of the points in one cell (empty outside the grid).
    #[cfg(test)]
    fn cell(&self, xy: (i64, i64)) -> &[u32] {
        &self.order[self.cell_range(xy)]
    }

    /// The range of `order` (and `xy_m`) holding one cell (empty outside the grid).
    fn cell_range(&self, (x, y): (i64, i64)) -> std::ops::Range<usize> {
        let (x, y) = (x - self.origin.0, y - self.origin.1);
        if x < 0 || y < 0 || x >= self.size.0 || y >= self.size.1 {
            return 0..0;
        }
        let c = (x * self.size.1 + y) as usize;
        self.start[c] as usize..self.start[c + 1] as usize
    }

    /// Indices of the points in the 3 x 3 cells around `p`: a superset of the
    /// points within `cell_m` of `p`; callers check the distance.
    #[cfg(test)]
    pub fn candidates(&self, p: [f64; 2]) -> impl Iterator<Item = usize> + '_ {
        let (cx, cy) = cell_of(p, self.cells_per_m);
        (-1..=1)
            .flat_map(move |dy| (-1..=1).flat_map(move |dx| self.cell((cx + dx, cy + dy)).iter().map(|&i| i as usize)))
    }

    /// Calls `visit(index, position)` for the points of the 3 x 3 cells
    /// around `p` (a superset of the points within `cell_m` of `p`; callers
    /// check the distance), in the order of [`GridIndex::candidates`]: rows
    /// of cells from below, each from the left, each cell's points in
    /// insertion order. Plain loops over the cells' contiguous slices, so
    /// the compiler sees the whole loop (the nested iterator adaptors it
    /// replaces cost about as much as the distance tests).
    #[inline]
    pub fn for_each_candidate(&self, p: [f64; 2], mut visit: impl FnMut(usize, [f64; 2])) {
        let (cx, cy) = cell_of(p, self.cells_per_m);
        for dy in -1..=1 {
            for dx in -1..=1 {
                let range = self.cell_range((cx + dx, cy + dy));
                for (&i, &q) in self.order[range.clone()].iter().zip(&self.xy_m[range]) {
                    visit(i as usize, q);
                }
            }
        }
    }

    /// Calls `visit(positions)` with the points of each of the 3 x 3 cells
    /// around `p`, in the order of [`GridIndex::for_each_candidate`], but
    /// leaves out the cells all of whose area lies farther than `radius_m`
    /// from `p` (`radius_m` at most the cell side; in practice the corner
    /// cells when `p` is not near that corner of its own cell): none of
    /// their points can be within `radius_m`. The cell's nearest distance is
    /// shortened by a margin far above the rounding of `p / cell_m`, so a
    /// point that a caller's own `d^2 <= radius^2` test would keep is never
    /// in a skipped cell.
    #[inline]
    pub fn for_each_cell_near(&self, p: [f64; 2], radius_m: f64, mut visit: impl FnMut(&[[f64; 2]])) {
        let (cx, cy) = cell_of(p, self.cells_per_m);
        // Distances from `p` to the lower and upper sides of its own cell.
        let lower = [p[0] - cx as f64 * self.cell_m, p[1] - cy as f64 * self.cell_m];
        let upper = [(cx + 1) as f64 * self.cell_m - p[0], (cy + 1) as f64 * self.cell_m - p[1]];
        let margin_m = 1e-9 * (self.cell_m + p[0].abs() + p[1].abs());
        let gap = |d: i64, axis: usize| match d {
            -1 => (lower[axis] - margin_m).max(0.0),
            1 => (upper[axis] - margin_m).max(0.0),
            _ => 0.0,
        };
        let radius_sq = radius_m * radius_m;
        for dy in -1..=1 {
            let gap_y = gap(dy, 1);
            for dx in -1..=1 {
                let gap_x = gap(dx, 0);
                if gap_x * gap_x + gap_y * gap_y > radius_sq {
                    continue;
                }
                let range = self.cell_range((cx + dx, cy + dy));
                if !range.is_empty() {
                    visit(&self.xy_m[range]);
                }
            }
        }
    }

    /// Non-empty cells in (x, y) order, each as its points' indices in
    /// insertion order.
    #[cfg(test)]
    pub fn occupied_cells(&self) -> impl Iterator<Item = &[u32]> + '_ {
        self.start.windows(2).filter(|w| w[1] > w[0]).map(|w| &self.order[w[0] as usize..w[1] as usize])
    }

    /// Non-empty cells in (x, y) order, each as its points' positions in
    /// insertion order (those of [`GridIndex::occupied_cells`]).
    pub fn occupied_cell_positions(&self) -> impl Iterator<Item = &[[f64; 2]]> + '_ {
        self.start.windows(2).filter(|w| w[1] > w[0]).map(|w| &self.xy_m[w[0] as usize..w[1] as usize])
    }

    /// Side of the cells actually used, metres (at least the requested side).
    #[must_use]
    pub fn cell_m(&self) -> f64 {
        self.cell_m
    }
}

/// The cell holding `p` in a grid of `cells_per_m` cells per metre (the
/// reciprocal of the cell side). Multiplying by the reciprocal can put a
/// point within a rounding error of a cell boundary in the neighbouring
/// cell, as dividing can; the index and its queries use this one function,
/// and a query's reach into neighbouring cells has a margin for it
/// ([`GridIndex::for_each_cell_near`]).
#[must_use]
#[inline]
pub fn cell_of(p: [f64; 2], cells_per_m: f64) -> (i64, i64) {
    (floor_to_i64(p[0] * cells_per_m), floor_to_i64(p[1] * cells_per_m))
}

/// `x.floor() as i64` (saturating, NaN to 0) without the call to libm's
/// `floor` that the baseline x86-64 target makes for it (no SSE4.1 `round`):
/// truncate, then step down when truncation went up. The same value for
/// every input, tested.
#[inline]
fn floor_to_i64(x: f64) -> i64 {
    let truncated = x as i64;
    if (truncated as f64) > x { truncated.saturating_sub(1) } else { truncated }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn candidates_hold_every_point_within_the_cell_side() {
        let points: Vec<[f64; 2]> =
            (0..400).map(|i| [((i * 37) % 101) as f64 * 0.7 - 30.0, ((i * 53) % 97) as f64 * 0.6 - 25.0]).collect();
        let index = GridIndex::new(points.iter().copied(), 3.0);
        for q in [[0.0, 0.0], [-29.0, 30.0], [40.0, 33.1], [500.0, 0.0]] {
            let mut found: Vec<usize> =
                index.candidates(q).filter(|&i| (points[i][0] - q[0]).hypot(points[i][1] - q[1]) <= 3.0).collect();
            found.sort_unstable();
            let expected: Vec<usize> =
                (0..points.len()).filter(|&i| (points[i][0] - q[0]).hypot(points[i][1] - q[1]) <= 3.0).collect();
            assert_eq!(found, expected, "query {q:?}");
        }
    }

    #[test]
    fn for_each_candidate_visits_the_candidates_in_their_order_with_their_positions() {
        let points: Vec<[f64; 2]> =
            (0..300).map(|i| [((i * 41) % 89) as f64 * 0.4 - 9.0, ((i * 29) % 83) as f64 * 0.35 - 12.0]).collect();
        let index = GridIndex::new(points.iter().copied(), 2.0);
        for q in [[0.0, 0.0], [-8.5, -11.0], [20.0, 20.0], [5.3, 1.7]] {
            let mut visited = Vec::new();
            index.for_each_candidate(q, |i, p| visited.push((i, p)));
            let expected: Vec<(usize, [f64; 2])> = index.candidates(q).map(|i| (i, points[i])).collect();
            assert_eq!(visited, expected, "query {q:?}");
        }
        let mut visited = 0;
        index.for_each_candidate([0.0, 0.0], |_, _| visited += 1);
        assert!(visited > 0, "the query at the centre finds points");
    }

    #[test]
    fn cells_near_keep_every_point_within_the_radius_in_candidate_order_and_skip_far_corners() {
        let points: Vec<[f64; 2]> =
            (0..2000).map(|i| [((i * 37) % 211) as f64 * 0.05 - 3.0, ((i * 53) % 199) as f64 * 0.05 - 4.0]).collect();
        let cell_m = 1.5;
        let index = GridIndex::new(points.iter().copied(), cell_m);
        // Queries all over, and at distances of 1e-12 m and less from cell
        // corners and sides, where the skip test is tightest.
        let mut queries: Vec<[f64; 2]> =
            (0..300).map(|i| [((i * 17) % 101) as f64 * 0.11 - 3.3, ((i * 29) % 97) as f64 * 0.09 - 4.1]).collect();
        for (kx, ky) in [(0.0, 0.0), (1.0, 1.0), (-1.0, 2.0), (2.0, -2.0)] {
            for (ex, ey) in [(1e-12, 1e-12), (-1e-12, 1e-12), (0.0, 0.0), (-1e-15, -1e-15), (0.7, 1e-13)] {
                queries.push([kx * cell_m + ex, ky * cell_m + ey]);
            }
        }
        let mut skipped = 0;
        for radius_m in [cell_m, 0.8] {
            for &q in &queries {
                let within =
                    |p: &[f64; 2]| (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) <= radius_m * radius_m;
                let mut expected = Vec::new();
                index.for_each_candidate(q, |_, p| expected.push(p));
                let all_candidates = expected.len();
                expected.retain(within);
                let mut near = Vec::new();
                index.for_each_cell_near(q, radius_m, |cell| near.extend_from_slice(cell));
                skipped += all_candidates - near.len();
                near.retain(within);
                assert_eq!(near, expected, "query {q:?}, radius {radius_m}");
            }
        }
        assert!(skipped > 10_000, "{skipped} candidates skipped");
    }

    #[test]
    fn floor_to_i64_is_floor_then_a_saturating_cast() {
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.999_999_999_999_999_6,
            -2.999_999_999_999_999_6,
            4503599627370495.5,
            -4503599627370495.5,
            9.3e18,
            -9.3e18,
            -9223372036854775808.0,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        values.extend((-2000..2000).map(|i| i as f64 * 0.37 / 3.0));
        for x in values {
            assert_eq!(floor_to_i64(x), x.floor() as i64, "{x:e}");
        }
    }

    #[test]
    fn occupied_cells_come_in_x_then_y_order_with_points_in_insertion_order() {
        let points = [[5.0, 0.5], [0.5, 5.0], [0.2, 0.2], [0.4, 0.1], [5.5, -3.0]];
        let index = GridIndex::new(points.iter().copied(), 1.0);
        let cells: Vec<Vec<u32>> = index.occupied_cells().map(<[u32]>::to_vec).collect();
        assert_eq!(cells, vec![vec![2, 3], vec![1], vec![4], vec![0]]);
        let positions: Vec<Vec<[f64; 2]>> = index.occupied_cell_positions().map(<[[f64; 2]]>::to_vec).collect();
        let expected: Vec<Vec<[f64; 2]>> =
            cells.iter().map(|cell| cell.iter().map(|&i| points[i as usize]).collect()).collect();
        assert_eq!(positions, expected);
    }

    #[test]
    fn far_apart_points_coarsen_the_grid_instead_of_exhausting_memory() {
        let points = [[0.0, 0.0], [1e7, 1e7], [1e7 + 0.5, 1e7]];
        let index = GridIndex::new(points.iter().copied(), 0.5);
        assert!(index.cell_m() > 0.5);
        let near: Vec<usize> = index.candidates([1e7, 1e7]).collect();
        assert!(near.contains(&1) && near.contains(&2), "{near:?}");
        assert!(GridIndex::new(std::iter::empty(), 1.0).candidates([0.0, 0.0]).next().is_none());
        let with_nan = GridIndex::new([[f64::NAN, 0.0], [1.0, f64::INFINITY], [2.0, 2.0]].into_iter(), 1.0);
        assert_eq!(with_nan.candidates([2.0, 2.0]).collect::<Vec<_>>(), vec![2]);
    }
}
