//! The 2 x 2 kernels of the GM-PHD filter ([`super::filter`]) on stack
//! arrays, each formed with the same floating-point operations in the same
//! order as the generic code it stands for (`mmtrack_filter`'s `linalg.rs`,
//! `gaussian.rs`, `gmphd/update.rs`), so that the filter's tracks are the
//! generic filter's number for number.

use std::mem::MaybeUninit;

use mmtrack_filter::faer::dyn_stack::{MemBuffer, MemStack};
use mmtrack_filter::faer::linalg::cholesky::llt;
use mmtrack_filter::faer::{MatMut, Par};
use mmtrack_filter::{FilterError, SYMMETRY_TOLERANCE};

/// A mean `[d, d_dot]`.
pub(super) type Mean = [f64; 2];
/// A covariance, row-major: `p[i][j]` is element `(i, j)`.
pub(super) type Cov = [[f64; 2]; 2];

/// `dst + sum_k a_k b_k`, the sum formed from `0.0` in order of `k` and then
/// added (`linalg::mul_add` with `alpha = 1`).
#[inline]
pub(super) fn dot_add(dst: f64, a: [f64; 2], b: [f64; 2]) -> f64 {
    let mut s = 0.0;
    s += a[0] * b[0];
    s += a[1] * b[1];
    dst + s
}

/// Row `i` of `a`.
#[inline]
pub(super) fn row(a: &Cov, i: usize) -> [f64; 2] {
    a[i]
}

/// Column `j` of `a`.
#[inline]
pub(super) fn col(a: &Cov, j: usize) -> [f64; 2] {
    [a[0][j], a[1][j]]
}

/// `dst + A B` (`linalg::mul_add`, column by column).
pub(super) fn mul_add(dst: Cov, a: &Cov, b: &Cov) -> Cov {
    let mut out = dst;
    for j in 0..2 {
        for i in 0..2 {
            out[i][j] = dot_add(dst[i][j], row(a, i), col(b, j));
        }
    }
    out
}

/// `dst + A B^T` (`linalg::mul_add` with `B^T`).
pub(super) fn mul_transpose_add(dst: Cov, a: &Cov, b: &Cov) -> Cov {
    let mut out = dst;
    for j in 0..2 {
        for i in 0..2 {
            out[i][j] = dot_add(dst[i][j], row(a, i), row(b, j));
        }
    }
    out
}

/// `(P + P^T) / 2` (`linalg::symmetrise`).
#[inline]
pub(super) fn symmetrise(m: Cov) -> Cov {
    let off = (m[0][1] + m[1][0]) * 0.5;
    [[(m[0][0] + m[0][0]) * 0.5, off], [off, (m[1][1] + m[1][1]) * 0.5]]
}

/// `gaussian::checked_spd` for a 2 x 2 matrix: finite (the first bad element
/// in column-major order is named), symmetric to [`SYMMETRY_TOLERANCE`]
/// relative, positive definite; returns the symmetrised matrix.
pub(super) fn checked_spd(what: &'static str, m: Cov) -> Result<Cov, FilterError> {
    for (r, c) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        if !m[r][c].is_finite() {
            return Err(FilterError::NotFinite { what, row: r, col: c, value: m[r][c] });
        }
    }
    let scale = m.iter().flatten().fold(0.0_f64, |a, x| a.max(x.abs())).max(1.0);
    if (m[0][1] - m[1][0]).abs() > SYMMETRY_TOLERANCE * scale {
        return Err(FilterError::NotPositiveDefinite { what });
    }
    let sym = symmetrise(m);
    if !is_positive_definite(&sym) {
        return Err(FilterError::NotPositiveDefinite { what });
    }
    Ok(sym)
}

/// Whether the symmetric `m` has a Cholesky factor (both pivots positive),
/// the pivots formed as faer forms them; only the verdict is used.
pub(super) fn is_positive_definite(m: &Cov) -> bool {
    let Some(l00) = pivot(m[0][0]) else { return false };
    let l10 = m[1][0] * (1.0 / l00);
    pivot(m[1][1] - l10 * l10).is_some()
}

/// `sqrt(a)` for a positive `a` whose root is finite and non-zero.
#[inline]
pub(super) fn pivot(a: f64) -> Option<f64> {
    let positive = a > 0.0;
    let root = a.sqrt();
    (positive && root != 0.0 && root.is_finite()).then_some(root)
}

/// faer's `L L^T` factor of a 2 x 2 symmetric positive definite matrix (on
/// the stack): `[l00, l10, l11]`, `None` if a pivot is not positive. faer
/// forms the second pivot with its SIMD kernels (a fused multiply-add where
/// the CPU has one), so the factor is faer's rather than re-derived here.
pub(super) fn cholesky_2x2(m: &Cov) -> Option<[f64; 3]> {
    let mut buffer = [m[0][0], m[1][0], m[0][1], m[1][1]];
    let a = MatMut::from_column_major_slice_mut(&mut buffer, 2, 2);
    let req = llt::factor::cholesky_in_place_scratch::<f64>(2, Par::Seq, Default::default());
    // faer's scratch for a 2 x 2 factor is one aligned 2 x 1 column: a
    // 256-byte buffer on the stack holds it, a heap one if a faer version
    // ever asks for more.
    let mut inline = [MaybeUninit::<u8>::uninit(); 256];
    let mut heap;
    let mut stack = MemStack::new(&mut inline);
    if !stack.can_hold(req) {
        heap = MemBuffer::new(req);
        stack = MemStack::new(&mut heap);
    }
    llt::factor::cholesky_in_place(a, Default::default(), Par::Seq, stack, Default::default()).ok()?;
    Some([buffer[0], buffer[1], buffer[3]])
}

/// `d^T P^-1 d` from the factor `[l00, l10, l11]` of `P`
/// (`linalg::Cholesky::mahalanobis_squared`).
#[inline]
pub(super) fn mahalanobis_squared_2(l: &[f64; 3], d: Mean) -> f64 {
    let mut d2 = 0.0;
    let y0 = d[0] / l[0];
    d2 += y0 * y0;
    let y1 = (d[1] - l[1] * y0) / l[2];
    d2 += y1 * y1;
    d2
}

/// `ln sum_i exp(x_i)`, `-inf` for an empty or all `-inf` input (the
/// generic update's).
pub(super) fn log_sum_exp(xs: impl Iterator<Item = f64> + Clone) -> f64 {
    let max = xs.clone().fold(f64::NEG_INFINITY, f64::max);
    if max == f64::NEG_INFINITY {
        return max;
    }
    max + xs.map(|x| (x - max).exp()).sum::<f64>().ln()
}
