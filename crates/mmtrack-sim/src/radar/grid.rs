//! A uniform grid over the world's bounding box, each cell listing the items
//! (by id) whose bounding box touches it, stored compressed (CSR). A ray
//! walks the cells it crosses (Amanatides & Woo, "A fast voxel traversal
//! algorithm", Eurographics 1987), so its cost depends on its length, not on
//! the size of the world.
//!
//! Written here rather than taken from a crate: an R-tree or KD-tree crate
//! answers nearest/box queries, not "cells along a ray, nearest first, stop
//! early", which is what occlusion needs.

/// Most cells a grid may have; a bigger world gets bigger cells.
const MAX_CELLS: f64 = 4.0e6;

#[derive(Debug, Clone, Default)]
pub(crate) struct Grid {
    origin: [f64; 2],
    cell_m: f64,
    nx: usize,
    ny: usize,
    /// `items[start[c]..start[c + 1]]` are the ids in cell `c = iy * nx + ix`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    /// Indexes items by their boxes `[x_min, y_min, x_max, y_max]` (id = position).
    pub(crate) fn build(boxes: &[[f64; 4]], cell_m: f64) -> Self {
        if boxes.is_empty() {
            return Self::default();
        }
        let mut bounds = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
        for b in boxes {
            bounds = [bounds[0].min(b[0]), bounds[1].min(b[1]), bounds[2].max(b[2]), bounds[3].max(b[3])];
        }
        let (width, height) = (bounds[2] - bounds[0] + 1.0, bounds[3] - bounds[1] + 1.0);
        let cell_m = cell_m.max((width * height / MAX_CELLS).sqrt());
        let origin = [bounds[0] - 0.5, bounds[1] - 0.5];
        let nx = (width / cell_m).ceil().max(1.0) as usize;
        let ny = (height / cell_m).ceil().max(1.0) as usize;
        let mut grid = Self { origin, cell_m, nx, ny, start: Vec::new(), items: Vec::new() };
        let mut counts = vec![0u32; nx * ny + 1];
        for b in boxes {
            grid.for_cells(*b, |c| counts[c] += 1);
        }
        let mut start = vec![0u32; nx * ny + 1];
        for c in 0..nx * ny {
            start[c + 1] = start[c] + counts[c];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; start[nx * ny] as usize];
        for (id, b) in boxes.iter().enumerate() {
            grid.for_cells(*b, |c| {
                items[fill[c] as usize] = id as u32;
                fill[c] += 1;
            });
        }
        grid.start = start;
        grid.items = items;
        grid
    }

    fn cell_of(&self, x: f64, y: f64) -> (usize, usize) {
        let ix = ((x - self.origin[0]) / self.cell_m).floor().clamp(0.0, (self.nx - 1) as f64) as usize;
        let iy = ((y - self.origin[1]) / self.cell_m).floor().clamp(0.0, (self.ny - 1) as f64) as usize;
        (ix, iy)
    }

    fn for_cells(&self, b: [f64; 4], mut f: impl FnMut(usize)) {
        let (x0, y0) = self.cell_of(b[0], b[1]);
        let (x1, y1) = self.cell_of(b[2], b[3]);
        for iy in y0..=y1 {
            for ix in x0..=x1 {
                f(iy * self.nx + ix);
            }
        }
    }

    fn cell(&self, c: usize) -> &[u32] {
        match (self.start.get(c), self.start.get(c + 1)) {
            (Some(&a), Some(&b)) => self.items.get(a as usize..b as usize).unwrap_or(&[]),
            _ => &[],
        }
    }

    /// Calls `f` with the ids of every cell touching the box (ids may repeat across cells).
    pub(crate) fn visit_box(&self, b: [f64; 4], f: &mut dyn FnMut(&[u32])) {
        if self.nx == 0 {
            return;
        }
        let (gx1, gy1) = (self.origin[0] + self.nx as f64 * self.cell_m, self.origin[1] + self.ny as f64 * self.cell_m);
        if b[2] < self.origin[0] || b[3] < self.origin[1] || b[0] > gx1 || b[1] > gy1 {
            return;
        }
        self.for_cells(b, |c| f(self.cell(c)));
    }

    /// Walks the cells crossed by `origin + t dir`, `0 <= t <= max_t`, nearest
    /// first, calling `f(ids, t_exit)`; stops when `f` returns false.
    pub(crate) fn walk_ray(&self, origin: [f64; 2], dir: [f64; 2], max_t: f64, f: &mut dyn FnMut(&[u32], f64) -> bool) {
        if self.nx == 0 {
            return;
        }
        let size = [self.nx as f64 * self.cell_m, self.ny as f64 * self.cell_m];
        // Clip the ray to the grid box (slab method).
        let (mut t0, mut t1) = (0.0f64, max_t);
        for k in 0..2 {
            let lo = self.origin[k];
            if dir[k].abs() < 1e-15 {
                if origin[k] < lo || origin[k] > lo + size[k] {
                    return;
                }
            } else {
                let (a, b) = ((lo - origin[k]) / dir[k], (lo + size[k] - origin[k]) / dir[k]);
                t0 = t0.max(a.min(b));
                t1 = t1.min(a.max(b));
            }
        }
        if t0 > t1 {
            return;
        }
        let entry = [origin[0] + t0 * dir[0], origin[1] + t0 * dir[1]];
        let (mut ix, mut iy) = self.cell_of(entry[0], entry[1]);
        let step = [if dir[0] >= 0.0 { 1i64 } else { -1 }, if dir[1] >= 0.0 { 1i64 } else { -1 }];
        let boundary =
            |i: usize, k: usize| self.origin[k] + (i as f64 + if step[k] > 0 { 1.0 } else { 0.0 }) * self.cell_m;
        let next_t = |i: usize, k: usize| {
            if dir[k].abs() < 1e-15 { f64::INFINITY } else { (boundary(i, k) - origin[k]) / dir[k] }
        };
        let delta = [self.cell_m / dir[0].abs().max(1e-15), self.cell_m / dir[1].abs().max(1e-15)];
        let mut t_max = [next_t(ix, 0), next_t(iy, 1)];
        loop {
            let exit = t_max[0].min(t_max[1]).min(t1);
            if !f(self.cell(iy * self.nx + ix), exit) || exit >= t1 {
                return;
            }
            let k = usize::from(t_max[1] < t_max[0]);
            let index = if k == 0 { &mut ix } else { &mut iy };
            let limit = if k == 0 { self.nx } else { self.ny };
            let next = *index as i64 + step[k];
            if next < 0 || next >= limit as i64 {
                return;
            }
            *index = next as usize;
            t_max[k] += delta[k];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_visits_the_cells_it_crosses_in_order() {
        // Items 0..5 each in its own cell along x, 10 m cells.
        let boxes: Vec<[f64; 4]> = (0..5).map(|i| [i as f64 * 10.0 + 5.0, 5.0, i as f64 * 10.0 + 5.0, 5.0]).collect();
        let grid = Grid::build(&boxes, 10.0);
        let mut seen = Vec::new();
        grid.walk_ray([0.0, 5.0], [1.0, 0.0], 1000.0, &mut |ids, _| {
            seen.extend_from_slice(ids);
            true
        });
        assert_eq!(seen, vec![0, 1, 2, 3, 4]);
        let mut backwards = Vec::new();
        grid.walk_ray([60.0, 5.0], [-1.0, 0.0], 31.0, &mut |ids, _| {
            backwards.extend_from_slice(ids);
            true
        });
        assert_eq!(backwards, vec![4, 3, 2]);
    }
}
