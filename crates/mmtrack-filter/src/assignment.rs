//! Optimal assignment (Kuhn-Munkres / Hungarian method) on real-valued costs.
//!
//! [`solve`] finds the one-to-one pairing of rows and columns of a rectangular
//! cost matrix that pairs `min(rows, cols)` of them at minimum total cost.
//! [`solve_with_unassigned`] lets every row stay unpaired at a fixed cost and
//! accepts `+inf` for forbidden (gated-out) pairs, which is what a
//! global-nearest-neighbour associator and the GOSPA metric need.
//!
//! The algorithm is the shortest-augmenting-path form of the Hungarian method
//! with row/column potentials (one Dijkstra-like pass per row), `O(n^2 m)` for
//! `n <= m`.
//!
//! Why our own and not `pathfinding::kuhn_munkres`: that function requires
//! `Ord` weights, so `f64` costs (log-likelihoods, distances) would have to be
//! scaled and rounded to integers, a hidden numerical choice that changes
//! near-ties; it also maximises, needs rows <= columns and has no notion of a
//! forbidden pair. The version here works on `f64` directly and is about sixty
//! lines.
//!
//! # References
//! H. W. Kuhn, "The Hungarian method for the assignment problem", Naval Research
//! Logistics Quarterly 2, 1955; J. Munkres, "Algorithms for the assignment and
//! transportation problems", J. SIAM 5(1), 1957; R. Jonker and A. Volgenant,
//! "A shortest augmenting path algorithm for dense and sparse linear assignment
//! problems", Computing 38, 1987 (the potentials/augmenting-path form).

use faer::{Mat, MatRef};

use crate::error::FilterError;

/// An optimal assignment.
#[derive(Debug, Clone, PartialEq)]
pub struct Assignment {
    /// For each row, the column it is paired with, if any.
    pub row_to_col: Vec<Option<usize>>,
    /// Total cost: the sum of the paired costs (plus, for
    /// [`solve_with_unassigned`], the unassigned cost of every unpaired row).
    pub total_cost: f64,
}

impl Assignment {
    /// The `(row, col)` pairs in row order.
    pub fn pairs(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.row_to_col.iter().enumerate().filter_map(|(r, c)| c.map(|c| (r, c)))
    }
}

/// Minimum-cost assignment pairing `min(rows, cols)` rows and columns.
///
/// # Errors
/// [`FilterError::NotFinite`] if a cost is NaN or infinite.
pub fn solve(cost: &Mat<f64>) -> Result<Assignment, FilterError> {
    crate::error::ensure_finite_matrix("assignment cost matrix", cost)?;
    let (n, m) = (cost.nrows(), cost.ncols());
    if n == 0 || m == 0 {
        return Ok(Assignment { row_to_col: vec![None; n], total_cost: 0.0 });
    }
    let row_to_col = if n <= m {
        hungarian(cost.as_ref())?.into_iter().map(Some).collect::<Vec<_>>()
    } else {
        // Solve the transpose (columns as rows) and invert the pairing.
        let col_to_row = hungarian(cost.transpose())?;
        let mut row_to_col = vec![None; n];
        for (c, r) in col_to_row.into_iter().enumerate() {
            if let Some(slot) = row_to_col.get_mut(r) {
                *slot = Some(c);
            }
        }
        row_to_col
    };
    let total_cost = row_to_col.iter().enumerate().filter_map(|(r, c)| c.map(|c| cost[(r, c)])).sum();
    Ok(Assignment { row_to_col, total_cost })
}

/// Minimum-cost assignment where each row may stay unpaired at
/// `unassigned_cost` and each column may stay unpaired for free.
///
/// `+inf` marks a forbidden pair. Pairs costing more than `unassigned_cost` are
/// never chosen (leaving the row unpaired is cheaper), so a gate of distance
/// `g` is `unassigned_cost = g`. Solved as an `n x (m + n)` problem whose `n`
/// extra columns all cost `unassigned_cost`.
///
/// # Errors
/// [`FilterError::NotFinite`] for a NaN or `-inf` cost, or a non-finite
/// `unassigned_cost`.
pub fn solve_with_unassigned(cost: &Mat<f64>, unassigned_cost: f64) -> Result<Assignment, FilterError> {
    if !unassigned_cost.is_finite() {
        return Err(FilterError::NotFinite { what: "unassigned cost", row: 0, col: 0, value: unassigned_cost });
    }
    let (n, m) = (cost.nrows(), cost.ncols());
    // Column-major order, as `ensure_finite_matrix`.
    for col in 0..m {
        if let Some(row) = cost.col(col).iter().position(|c| c.is_nan() || *c == f64::NEG_INFINITY) {
            return Err(FilterError::NotFinite { what: "assignment cost matrix", row, col, value: cost[(row, col)] });
        }
    }
    // Any value above the unassigned cost is never used by an optimum.
    let forbidden = unassigned_cost + unassigned_cost.abs().max(1.0);
    let augmented = Mat::from_fn(n, m + n, |r, c| {
        if c < m {
            let v = cost[(r, c)];
            if v.is_finite() { v.min(forbidden) } else { forbidden }
        } else {
            unassigned_cost
        }
    });
    if n == 0 {
        return Ok(Assignment { row_to_col: Vec::new(), total_cost: 0.0 });
    }
    let cols = hungarian(augmented.as_ref())?;
    let mut total_cost = 0.0;
    let row_to_col = cols
        .into_iter()
        .enumerate()
        .map(|(r, c)| {
            let real = c < m && cost[(r, c)] <= unassigned_cost;
            total_cost += if real { cost[(r, c)] } else { unassigned_cost };
            real.then_some(c)
        })
        .collect();
    Ok(Assignment { row_to_col, total_cost })
}

/// Hungarian method for `n <= m` finite costs; returns the column of each row.
fn hungarian(a: MatRef<'_, f64>) -> Result<Vec<usize>, FilterError> {
    let (n, m) = (a.nrows(), a.ncols());
    // 1-based rows/columns; index 0 is the virtual source. p[j]: row paired with
    // column j (0 = none); way[j]: previous column on the augmenting path.
    let mut u = vec![0.0_f64; n + 1];
    let mut v = vec![0.0_f64; m + 1];
    let mut p = vec![0_usize; m + 1];
    let mut way = vec![0_usize; m + 1];
    for i in 1..=n {
        p[0] = i;
        let mut j0 = 0_usize;
        let mut minv = vec![f64::INFINITY; m + 1];
        let mut used = vec![false; m + 1];
        loop {
            used[j0] = true;
            let i0 = p[j0];
            let mut delta = f64::INFINITY;
            let mut j1 = 0_usize;
            for j in 1..=m {
                if !used[j] {
                    let cur = a[(i0 - 1, j - 1)] - u[i0] - v[j];
                    if cur < minv[j] {
                        minv[j] = cur;
                        way[j] = j0;
                    }
                    if minv[j] < delta {
                        delta = minv[j];
                        j1 = j;
                    }
                }
            }
            if j1 == 0 {
                // Only reachable with non-finite reduced costs (overflow).
                return Err(FilterError::InvalidParameter {
                    name: "assignment cost matrix",
                    value: delta,
                    expected: "costs whose differences are finite",
                });
            }
            for j in 0..=m {
                if used[j] {
                    u[p[j]] += delta;
                    v[j] -= delta;
                } else {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
            if p[j0] == 0 {
                break;
            }
        }
        loop {
            let j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
            if j0 == 0 {
                break;
            }
        }
    }
    let mut row_to_col = vec![0_usize; n];
    for (j, &row) in p.iter().enumerate().skip(1) {
        if row > 0 {
            row_to_col[row - 1] = j - 1;
        }
    }
    Ok(row_to_col)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force over all injections rows -> columns (n <= m).
    fn brute(cost: MatRef<'_, f64>) -> f64 {
        fn rec(cost: MatRef<'_, f64>, r: usize, used: &mut Vec<bool>) -> f64 {
            if r == cost.nrows() {
                return 0.0;
            }
            let mut best = f64::INFINITY;
            for c in 0..cost.ncols() {
                if !used[c] {
                    used[c] = true;
                    best = best.min(cost[(r, c)] + rec(cost, r + 1, used));
                    used[c] = false;
                }
            }
            best
        }
        rec(cost, 0, &mut vec![false; cost.ncols()])
    }

    #[test]
    fn matches_brute_force_on_small_matrices() {
        // Deterministic pseudo-random costs (LCG), including negatives.
        let mut s: u64 = 12345;
        let mut next = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 33) as f64 / (1u64 << 31) as f64) * 20.0 - 5.0
        };
        for (n, m) in [(1, 1), (2, 3), (3, 3), (4, 4), (3, 5), (5, 5), (5, 3)] {
            let c = Mat::from_fn(n, m, |_, _| next());
            let a = solve(&c).expect("finite");
            let best = if n <= m { brute(c.as_ref()) } else { brute(c.transpose()) };
            // Sums of <= 5 terms of magnitude <= 15: round-off well below 1e-9.
            assert!((a.total_cost - best).abs() < 1e-9, "{n}x{m}: {} vs {best}", a.total_cost);
            assert_eq!(a.pairs().count(), n.min(m));
        }
    }
}
