//! 3x3 symmetric algebra on stack arrays (module docs of [`super`]: why not
//! faer in the hot path), with faer's self-adjoint eigendecomposition as the
//! rank-deficient fallback.

// Index loops read like the formulas on these 3x3 arrays.
#![allow(clippy::needless_range_loop)]

use faer::{Mat, Side};

/// A symmetric 3x3 matrix, row-major (both triangles stored).
pub(crate) type Sym3 = [[f64; 3]; 3];

/// Pivots (and eigenvalues) below this share of the largest diagonal entry
/// (largest eigenvalue) count as zero: the accumulated normal equations are
/// exact to a few ulps of their largest entry, and a genuinely observed
/// direction is many orders above that (the smallest change of azimuth the
/// codebook resolves, 2.8 deg, gives `sin^2 b ~ 2.4e-3` per epoch against
/// `t^2 <= 16` s^2 and `1 / lambda^2 = 4e4`).
pub(crate) const RELATIVE_PIVOT_TOLERANCE: f64 = 1e-12;

/// `m += w a a^T`.
pub(crate) fn add_outer(m: &mut Sym3, a: &[f64; 3], w: f64) {
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] += w * a[i] * a[j];
        }
    }
}

/// `m v`.
pub(crate) fn mul(m: &Sym3, v: &[f64; 3]) -> [f64; 3] {
    [dot(&m[0], v), dot(&m[1], v), dot(&m[2], v)]
}

/// `a . b`.
pub(crate) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a x b`.
fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Lower Cholesky factor of the symmetric `m`, `None` when a pivot is not
/// above [`RELATIVE_PIVOT_TOLERANCE`] times the largest diagonal entry (or
/// NaN).
pub(crate) fn cholesky(m: &Sym3) -> Option<Sym3> {
    let scale = m[0][0].max(m[1][1]).max(m[2][2]);
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    let floor = RELATIVE_PIVOT_TOLERANCE * scale;
    let mut l = [[0.0; 3]; 3];
    for j in 0..3 {
        let mut d = m[j][j];
        for k in 0..j {
            d -= l[j][k] * l[j][k];
        }
        if d.is_nan() || d <= floor {
            return None;
        }
        let ljj = d.sqrt();
        l[j][j] = ljj;
        for i in j + 1..3 {
            let mut s = m[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            l[i][j] = s / ljj;
        }
    }
    Some(l)
}

/// `m^-1 b` from the Cholesky factor `l` of `m`.
pub(crate) fn cholesky_solve(l: &Sym3, b: &[f64; 3]) -> [f64; 3] {
    let mut y = [0.0; 3];
    for i in 0..3 {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i][k] * y[k];
        }
        y[i] = s / l[i][i];
    }
    let mut x = [0.0; 3];
    for i in (0..3).rev() {
        let mut s = y[i];
        for k in i + 1..3 {
            s -= l[k][i] * x[k];
        }
        x[i] = s / l[i][i];
    }
    x
}

/// `m^-1` from the Cholesky factor `l` of `m` (symmetric by construction).
pub(crate) fn cholesky_inverse(l: &Sym3) -> Sym3 {
    let mut inv = [[0.0; 3]; 3];
    for j in 0..3 {
        let mut e = [0.0; 3];
        e[j] = 1.0;
        let col = cholesky_solve(l, &e);
        for i in 0..3 {
            inv[i][j] = col[i];
        }
    }
    for i in 0..3 {
        for j in 0..i {
            let mean = 0.5 * (inv[i][j] + inv[j][i]);
            inv[i][j] = mean;
            inv[j][i] = mean;
        }
    }
    inv
}

/// The minimum-norm least-squares solution of `m x = b` for a symmetric
/// positive semi-definite `m`: a Cholesky solve when every pivot is clear of
/// zero, otherwise the pseudo-inverse from faer's eigendecomposition
/// (eigenvalues below [`RELATIVE_PIVOT_TOLERANCE`] times the largest are
/// dropped). All zeros for a zero `m`; `None` when faer fails or the result
/// is not finite.
pub(crate) fn min_norm_solve(m: &Sym3, b: &[f64; 3]) -> Option<[f64; 3]> {
    if let Some(l) = cholesky(m) {
        let x = cholesky_solve(&l, b);
        return x.iter().all(|v| v.is_finite()).then_some(x);
    }
    let mut x = [0.0; 3];
    for (vector, value) in eigen(m)? {
        if value > 0.0 {
            let c = dot(&vector, b) / value;
            for i in 0..3 {
                x[i] += c * vector[i];
            }
        }
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Eigenvectors of the symmetric `m` with their eigenvalues, those below
/// [`RELATIVE_PIVOT_TOLERANCE`] times the largest set to 0 (faer).
pub(crate) fn eigen(m: &Sym3) -> Option<Vec<([f64; 3], f64)>> {
    let mat = Mat::from_fn(3, 3, |i, j| m[i][j]);
    let evd = mat.self_adjoint_eigen(Side::Lower).ok()?;
    let values: Vec<f64> = (0..3).map(|i| evd.S().column_vector()[i]).collect();
    let largest = values.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    if !largest.is_finite() {
        return None;
    }
    Some(
        (0..3)
            .map(|i| {
                let u = evd.U();
                let value = if values[i] > RELATIVE_PIVOT_TOLERANCE * largest { values[i] } else { 0.0 };
                ([u[(0, i)], u[(1, i)], u[(2, i)]], value)
            })
            .collect(),
    )
}

/// An orthonormal basis of the null space of the symmetric positive
/// semi-definite `g`: for rank 2 (the common case) the normalised largest
/// cross product of two of its rows; otherwise faer's eigenvectors with
/// (relatively) zero eigenvalues. Empty for a full-rank `g`; `None` when faer
/// fails.
pub(crate) fn null_basis(g: &Sym3) -> Option<Vec<[f64; 3]>> {
    let norm = g.iter().flatten().fold(0.0_f64, |a, v| a.max(v.abs()));
    if norm == 0.0 {
        return Some(vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    }
    if !norm.is_finite() {
        return None;
    }
    let candidates = [cross(&g[0], &g[1]), cross(&g[0], &g[2]), cross(&g[1], &g[2])];
    let best = candidates.iter().max_by(|a, b| dot(a, a).total_cmp(&dot(b, b)))?;
    let length = dot(best, best).sqrt();
    // Rank 2 exactly when two rows are independent (cross product clear of
    // zero) and g is singular (its determinant, g_0 . (g_1 x g_2), is zero to
    // the same relative tolerance).
    let determinant = dot(&g[0], &candidates[2]).abs();
    if length > 1e-9 * norm * norm && determinant <= 1e-9 * norm * length {
        return Some(vec![[best[0] / length, best[1] / length, best[2] / length]]);
    }
    Some(eigen(g)?.into_iter().filter(|(_, value)| *value == 0.0).map(|(vector, _)| vector).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cholesky_solve_and_inverse() {
        let m = [[4.0, 2.0, 0.0], [2.0, 10.0, 1.0], [0.0, 1.0, 3.0]];
        let l = cholesky(&m).unwrap();
        let x = cholesky_solve(&l, &[1.0, 2.0, 3.0]);
        let back = mul(&m, &x);
        for i in 0..3 {
            assert!((back[i] - [1.0, 2.0, 3.0][i]).abs() < 1e-14);
        }
        let inv = cholesky_inverse(&l);
        let e0 = mul(&m, &[inv[0][0], inv[1][0], inv[2][0]]);
        assert!((e0[0] - 1.0).abs() < 1e-14 && e0[1].abs() < 1e-14 && e0[2].abs() < 1e-14);
        assert!(cholesky(&[[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]).is_none());
        assert!(cholesky(&[[f64::NAN; 3]; 3]).is_none());
    }

    #[test]
    fn minimum_norm_solution_of_a_singular_system() {
        // The first variable unobserved: x0 = 0, the rest solved.
        let m = [[0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 4.0]];
        let x = min_norm_solve(&m, &[0.0, 2.0, 8.0]).unwrap();
        assert!(x[0].abs() < 1e-14 && (x[1] - 1.0).abs() < 1e-14 && (x[2] - 2.0).abs() < 1e-14, "{x:?}");
        assert_eq!(min_norm_solve(&[[0.0; 3]; 3], &[1.0, 2.0, 3.0]), Some([0.0; 3]));
    }

    #[test]
    fn null_spaces_of_rank_two_one_and_zero() {
        // g = A^T A with rows orthogonal to n = [1, 2, 3].
        let rows = [[2.0, -1.0, 0.0], [3.0, 0.0, -1.0], [0.0, 3.0, -2.0]];
        let mut g = [[0.0; 3]; 3];
        for r in &rows {
            add_outer(&mut g, r, 1.0);
        }
        let basis = null_basis(&g).unwrap();
        assert_eq!(basis.len(), 1);
        let n = basis[0];
        let scale = n[0];
        assert!((n[1] / scale - 2.0).abs() < 1e-12 && (n[2] / scale - 3.0).abs() < 1e-12, "{n:?}");
        let mut one = [[0.0; 3]; 3];
        add_outer(&mut one, &[1.0, 1.0, 0.0], 1.0);
        assert_eq!(null_basis(&one).unwrap().len(), 2);
        assert_eq!(null_basis(&[[0.0; 3]; 3]).unwrap().len(), 3);
        assert!(null_basis(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]).unwrap().is_empty());
    }
}
