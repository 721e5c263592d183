//! The small dense linear algebra of the crate, on faer: the Cholesky factor
//! that every SPD check, Gaussian density and Kalman gain goes through,
//! symmetrisation, and the squared Mahalanobis distance.
//!
//! The matrices are tiny (state dimension 2 to 6, measurement dimension 1 to
//! 3) and the GM-PHD calls these helpers per component and per (component,
//! measurement) pair, so they keep heap allocations out where faer allows:
//! the factorisation's scratch space lives on the stack, and a factorisation
//! done only to check definiteness works on a stack copy. (Every small faer
//! `Mat` is a 64-byte-aligned heap allocation; in the MPC GM-PHD baseline,
//! allocation was a quarter of the instructions before these measures.)

use std::mem::MaybeUninit;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt;
use faer::linalg::matmul::matmul;
use faer::{Accum, Col, ColRef, Mat, MatMut, MatRef, Par};

use crate::error::{FilterError, ensure_shape};

/// Largest dimension whose definiteness check factorises a stack copy.
const MAX_STACK_DIM: usize = 8;

/// Runs `f` with a faer scratch stack that can hold `req`: 512 bytes on the
/// stack (enough for the factorisation scratch of matrices up to dimension
/// 56), a heap buffer beyond.
fn with_scratch<R>(req: StackReq, f: impl FnOnce(&mut MemStack) -> R) -> R {
    let mut inline = [MaybeUninit::<u8>::uninit(); 512];
    let stack = MemStack::new(&mut inline);
    if stack.can_hold(req) {
        return f(stack);
    }
    f(MemStack::new(&mut MemBuffer::new(req)))
}

/// faer's `L L^T` factorisation of the square `a` in place: reads the lower
/// triangle, writes `L` there (the strict upper triangle is left as it was).
/// `false` when a pivot is not positive (NaN included).
fn factor_in_place(a: MatMut<'_, f64>) -> bool {
    let req = llt::factor::cholesky_in_place_scratch::<f64>(a.nrows(), Par::Seq, Default::default());
    with_scratch(req, |stack| {
        llt::factor::cholesky_in_place(a, Default::default(), Par::Seq, stack, Default::default()).is_ok()
    })
}

/// Whether the square, symmetric `a` is positive definite, i.e. its
/// Cholesky factorisation succeeds (every pivot positive). Up to dimension
/// [`MAX_STACK_DIM`] the factorisation works on a stack copy.
pub(crate) fn is_positive_definite(a: &Mat<f64>) -> bool {
    let n = a.nrows();
    if n <= MAX_STACK_DIM {
        let mut buffer = [0.0; MAX_STACK_DIM * MAX_STACK_DIM];
        let mut copy = MatMut::from_column_major_slice_mut(&mut buffer[..n * n], n, n);
        copy.copy_from(a);
        factor_in_place(copy)
    } else {
        factor_in_place(a.clone().as_mut())
    }
}

/// The Cholesky factor `L` of a symmetric positive definite `S = L L^T`
/// (faer's `L L^T` factorisation of the lower triangle of `S`).
#[derive(Debug, Clone)]
pub(crate) struct Cholesky {
    /// Lower triangular, zeros above the diagonal.
    l: Mat<f64>,
}

impl Cholesky {
    /// Factorises the square `s`.
    ///
    /// # Errors
    /// [`FilterError::DimensionMismatch`] if `s` is not square,
    /// [`FilterError::NotPositiveDefinite`] when a pivot is not positive.
    pub(crate) fn new(what: &'static str, s: &Mat<f64>) -> Result<Self, FilterError> {
        let n = s.nrows();
        ensure_shape(what, s, n, n)?;
        let mut l = s.clone();
        if !factor_in_place(l.as_mut()) {
            return Err(FilterError::NotPositiveDefinite { what });
        }
        for j in 1..n {
            for i in 0..j {
                l[(i, j)] = 0.0;
            }
        }
        Ok(Self { l })
    }

    /// Replaces `b` (`n x k`) by `S^-1 b`: two triangular solves with faer.
    pub(crate) fn solve_in_place(&self, b: MatMut<'_, f64>) {
        let req = llt::solve::solve_in_place_scratch::<f64>(self.l.nrows(), b.ncols(), Par::Seq);
        with_scratch(req, |stack| llt::solve::solve_in_place(self.l.as_ref(), b, Par::Seq, stack));
    }

    /// `ln det S = 2 sum ln L_ii`.
    pub(crate) fn log_det(&self) -> f64 {
        2.0 * self.l.diagonal().column_vector().iter().map(|d| d.ln()).sum::<f64>()
    }

    /// `v^T S^-1 v`: solve `L y = v` by forward substitution, return `|y|^2`.
    /// `y` is scratch space (resized to `v`), so a caller in a loop allocates
    /// nothing. `v` must have the dimension of `S` (every caller has checked
    /// it).
    ///
    /// The substitution is written out over faer's factor rather than calling
    /// `faer::linalg::triangular_solve` and `squared_norm_l2`: it runs once per
    /// (component, measurement) pair of every GM-PHD update and once per pair
    /// of components in every merge, on vectors of one or two elements, where
    /// faer's SIMD dispatch and blocked/pairwise-sum kernels cost more than
    /// the arithmetic. Measured on the MPC GM-PHD baseline (1-D delay
    /// measurements, sets of 6 snapshots with ~140 detections each): the whole
    /// filter executed 1.46 times the instructions with faer's kernels here
    /// (callgrind). The order of operations is the textbook one,
    /// `y_i = (v_i - sum_{k<i} L_ik y_k) / L_ii`, summed in index order.
    pub(crate) fn mahalanobis_squared(&self, v: ColRef<'_, f64>, y: &mut Col<f64>) -> f64 {
        let l = self.l.as_ref();
        if y.nrows() != v.nrows() {
            y.resize_with(v.nrows(), |_| 0.0);
        }
        let mut d2 = 0.0;
        for i in 0..v.nrows() {
            let mut r = v[i];
            for k in 0..i {
                r -= l[(i, k)] * y[k];
            }
            let yi = r / l[(i, i)];
            y[i] = yi;
            d2 += yi * yi;
        }
        d2
    }
}

/// Largest dimension multiplied by [`mul_add`]'s plain loops rather than
/// faer's matmul.
const SMALL_DIM: usize = 4;

/// `dst + alpha A B`, written into `dst`. Up to [`SMALL_DIM`] rows, columns
/// and inner dimension it is plain loops (`s = sum_k a_ik b_kj` in order of
/// `k`, then `dst_ij + alpha s`): faer's matmul, built for large matrices,
/// spends more on dispatch than on the arithmetic of a 2 x 2 product, and
/// the GM-PHD multiplies several per component and step. Larger products
/// go to faer.
pub(crate) fn mul_add(mut dst: MatMut<'_, f64>, alpha: f64, a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    let small = a.nrows() <= SMALL_DIM && a.ncols() <= SMALL_DIM && b.ncols() <= SMALL_DIM;
    if !small {
        matmul(dst, Accum::Add, a, b, alpha, Par::Seq);
        return;
    }
    for j in 0..b.ncols() {
        for i in 0..a.nrows() {
            let mut s = 0.0;
            for k in 0..a.ncols() {
                s += a[(i, k)] * b[(k, j)];
            }
            dst[(i, j)] += alpha * s;
        }
    }
}

/// `A B` (see [`mul_add`]).
pub(crate) fn mul(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::zeros(a.nrows(), b.ncols());
    mul_add(out.as_mut(), 1.0, a, b);
    out
}

/// `A x` (see [`mul_add`]).
pub(crate) fn mul_col(a: MatRef<'_, f64>, x: ColRef<'_, f64>) -> Col<f64> {
    let mut out = Col::zeros(a.nrows());
    mul_add(out.as_mat_mut(), 1.0, a, x.as_mat());
    out
}

/// `max |P - P^T|` of a square matrix (0 for an empty one).
pub(crate) fn max_asymmetry(m: &Mat<f64>) -> f64 {
    let mut worst = 0.0_f64;
    for j in 0..m.ncols() {
        for i in 0..j {
            worst = worst.max((m[(i, j)] - m[(j, i)]).abs());
        }
    }
    worst
}

/// `(P + P^T) / 2`, in place: element `(i, j)` becomes `(p_ij + p_ji) * 0.5`,
/// the diagonal included, so the result is the same number for number as
/// forming `P + P^T` and halving it.
pub(crate) fn symmetrise(mut m: Mat<f64>) -> Mat<f64> {
    for j in 0..m.ncols() {
        for i in 0..=j {
            let mean = (m[(i, j)] + m[(j, i)]) * 0.5;
            m[(i, j)] = mean;
            m[(j, i)] = mean;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use faer::{col, mat};

    use super::*;

    #[test]
    fn factor_solve_and_mahalanobis_of_a_known_spd_matrix() {
        // S = L L^T with L = [[2, 0], [1, 3]]: S = [[4, 2], [2, 10]], det 36.
        let s = mat![[4.0, 2.0], [2.0, 10.0]];
        let chol = Cholesky::new("S", &s).expect("SPD");
        // Integers and their square roots: exact in binary.
        assert_eq!(chol.l, mat![[2.0, 0.0], [1.0, 3.0]]);
        assert!((chol.log_det() - 36.0_f64.ln()).abs() < 1e-15);
        // S x = [8, 22] for x = [1, 2]; the solve divides by 2 and 3 (1/3 is
        // inexact): a few ulps.
        let mut b = mat![[8.0], [22.0]];
        chol.solve_in_place(b.as_mut());
        assert!((b[(0, 0)] - 1.0).abs() < 1e-15 && (b[(1, 0)] - 2.0).abs() < 1e-15, "{b:?}");
        // v = L y with y = [1, 1]: v = [2, 4], |y|^2 = 2, exact.
        let mut scratch = Col::zeros(0);
        assert_eq!(chol.mahalanobis_squared(col![2.0, 4.0].as_ref(), &mut scratch), 2.0);
    }

    #[test]
    fn definiteness_on_the_stack_and_on_the_heap() {
        assert!(is_positive_definite(&mat![[4.0, 2.0], [2.0, 10.0]]));
        assert!(!is_positive_definite(&mat![[1.0, 2.0], [2.0, 1.0]]));
        assert!(!is_positive_definite(&mat![[0.0]]));
        assert!(!is_positive_definite(&mat![[f64::NAN]]));
        let n = MAX_STACK_DIM + 2;
        let big = Mat::from_fn(n, n, |i, j| if i == j { 2.0 } else { 0.5 });
        assert!(is_positive_definite(&big));
        let singular = Mat::from_fn(n, n, |_, _| 1.0);
        assert!(!is_positive_definite(&singular));
        assert!(matches!(Cholesky::new("S", &singular), Err(FilterError::NotPositiveDefinite { what: "S" })));
        assert!(matches!(Cholesky::new("S", &Mat::zeros(2, 3)), Err(FilterError::DimensionMismatch { .. })));
    }
}
