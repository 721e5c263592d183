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
    /// Cell of the lower-left corner of the bounding box.
    origin: (i64, i64),
    /// Cells along x and y.
    size: (i64, i64),
    /// Points of cell `c` (row-major, x-major) are `order[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    order: Vec<u32>,
}

/// Largest grid kept dense; sparser point sets use coarser cells (never
/// finer than `cell_m`: queries stay correct, only a little less selective).
const MAX_CELLS: i64 = 1 << 20;

impl GridIndex {
    /// Buckets `points` into square cells of side `cell_m` (> 0). Points
    /// with a non-finite coordinate are left out (no finite point is within
    /// any distance of them).
    #[must_use]
    pub fn new(points: impl Iterator<Item = [f64; 2]>, cell_m: f64) -> Self {
        let points: Vec<(u32, [f64; 2])> = points
            .enumerate()
            .filter(|(_, p)| p[0].is_finite() && p[1].is_finite())
            .map(|(i, p)| (i as u32, p))
            .collect();
        let mut cell_m = cell_m;
        loop {
            let keys: Vec<(i64, i64)> = points.iter().map(|(_, p)| cell_of(*p, cell_m)).collect();
            let (mut lo, mut hi) = ((i64::MAX, i64::MAX), (i64::MIN, i64::MIN));
            for &(x, y) in &keys {
                lo = (lo.0.min(x), lo.1.min(y));
                hi = (hi.0.max(x), hi.1.max(y));
            }
            if keys.is_empty() {
                return Self { cell_m, origin: (0, 0), size: (0, 0), start: vec![0], order: Vec::new() };
            }
            let size = (hi.0.saturating_sub(lo.0).saturating_add(1), hi.1.saturating_sub(lo.1).saturating_add(1));
            if size.0.saturating_mul(size.1) > MAX_CELLS {
                cell_m *= 2.0;
                continue;
            }
            let cells = (size.0 * size.1) as usize;
            let flat = |(x, y): (i64, i64)| ((x - lo.0) * size.1 + (y - lo.1)) as usize;
            let mut start = vec![0u32; cells + 1];
            for &k in &keys {
                start[flat(k) + 1] += 1;
            }
            for c in 0..cells {
                start[c + 1] += start[c];
            }
            let mut next = start.clone();
            let mut order = vec![0u32; keys.len()];
            for (&(index, _), &k) in points.iter().zip(&keys) {
                let slot = &mut next[flat(k)];
                order[*slot as usize] = index;
                *slot += 1;
            }
            return Self { cell_m, origin: lo, size, start, order };
        }
    }

    /// Indices of the points in one cell (empty outside the grid).
    fn cell(&self, (x, y): (i64, i64)) -> &[u32] {
        let (x, y) = (x - self.origin.0, y - self.origin.1);
        if x < 0 || y < 0 || x >= self.size.0 || y >= self.size.1 {
            return &[];
        }
        let c = (x * self.size.1 + y) as usize;
        &self.order[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// Indices of the points in the 3 x 3 cells around `p`: a superset of the
    /// points within `cell_m` of `p`; callers check the distance.
    pub fn candidates(&self, p: [f64; 2]) -> impl Iterator<Item = usize> + '_ {
        let (cx, cy) = cell_of(p, self.cell_m);
        (-1..=1)
            .flat_map(move |dy| (-1..=1).flat_map(move |dx| self.cell((cx + dx, cy + dy)).iter().map(|&i| i as usize)))
    }

    /// Non-empty cells in (x, y) order, each as its points' indices in
    /// insertion order.
    pub fn occupied_cells(&self) -> impl Iterator<Item = &[u32]> + '_ {
        self.start.windows(2).filter(|w| w[1] > w[0]).map(|w| &self.order[w[0] as usize..w[1] as usize])
    }

    /// Side of the cells actually used, metres (at least the requested side).
    #[must_use]
    pub fn cell_m(&self) -> f64 {
        self.cell_m
    }
}

/// The cell holding `p`.
#[must_use]
pub fn cell_of(p: [f64; 2], cell_m: f64) -> (i64, i64) {
    ((p[0] / cell_m).floor() as i64, (p[1] / cell_m).floor() as i64)
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
    fn occupied_cells_come_in_x_then_y_order_with_points_in_insertion_order() {
        let points = [[5.0, 0.5], [0.5, 5.0], [0.2, 0.2], [0.4, 0.1], [5.5, -3.0]];
        let index = GridIndex::new(points.iter().copied(), 1.0);
        let cells: Vec<Vec<u32>> = index.occupied_cells().map(<[u32]>::to_vec).collect();
        assert_eq!(cells, vec![vec![2, 3], vec![1], vec![4], vec![0]]);
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
