//! A uniform grid over 2-D points for fixed-radius neighbour queries.
//!
//! Scans hold a few thousand points and queries use one radius, so a hash
//! grid with cells of that radius answers a query from the 3 x 3 cells around
//! it. Results come in a fixed order (cells row by row, points in insertion
//! order), so everything built on it is deterministic.

use std::collections::HashMap;

/// Point indices bucketed by cell.
#[derive(Debug, Clone)]
pub struct GridIndex {
    cell_m: f64,
    cells: HashMap<(i64, i64), Vec<u32>>,
}

impl GridIndex {
    /// Buckets `points` into square cells of side `cell_m` (> 0).
    #[must_use]
    pub fn new(points: impl Iterator<Item = [f64; 2]>, cell_m: f64) -> Self {
        let mut cells: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
        for (index, p) in points.enumerate() {
            cells.entry(cell_of(p, cell_m)).or_default().push(index as u32);
        }
        Self { cell_m, cells }
    }

    /// Indices of the points in the 3 x 3 cells around `p`: a superset of the
    /// points within `cell_m` of `p`; callers check the distance.
    pub fn candidates(&self, p: [f64; 2]) -> impl Iterator<Item = usize> + '_ {
        let (cx, cy) = cell_of(p, self.cell_m);
        (-1..=1).flat_map(move |dy| {
            (-1..=1).flat_map(move |dx| {
                self.cells.get(&(cx + dx, cy + dy)).into_iter().flat_map(|v| v.iter().map(|&i| i as usize))
            })
        })
    }
}

/// The cell holding `p`.
#[must_use]
pub fn cell_of(p: [f64; 2], cell_m: f64) -> (i64, i64) {
    ((p[0] / cell_m).floor() as i64, (p[1] / cell_m).floor() as i64)
}
