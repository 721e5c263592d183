//! Small dense helpers on faer for the 3-, 4- and 5-dimensional Gaussians of
//! the filter (source beliefs, UE summaries, path likelihoods). They run per
//! source or per path, never per particle; the per-particle loops work on
//! plain arrays prepared from them.

use faer::Mat;
use faer::linalg::solvers::DenseSolveCore;

/// `A B`.
pub(crate) fn mul(a: &Mat<f64>, b: &Mat<f64>) -> Mat<f64> {
    a * b
}

/// `A P A^T`.
pub(crate) fn sandwich(a: &Mat<f64>, p: &Mat<f64>) -> Mat<f64> {
    a * p * a.transpose()
}

/// `(M + M^T) / 2`.
pub(crate) fn symmetrise(m: &Mat<f64>) -> Mat<f64> {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| 0.5 * (m[(i, j)] + m[(j, i)]))
}

/// Inverse and `ln det` of a symmetric positive definite matrix (faer's
/// `L L^T`); `None` when it is not positive definite.
pub(crate) fn spd_inverse(m: &Mat<f64>) -> Option<(Mat<f64>, f64)> {
    let llt = symmetrise(m).llt(faer::Side::Lower).ok()?;
    let l = llt.L();
    let log_det = 2.0 * (0..l.nrows()).map(|i| l[(i, i)].ln()).sum::<f64>();
    Some((symmetrise(&llt.inverse()), log_det))
}

/// The lower Cholesky factor of a symmetric positive semi-definite matrix,
/// with `eps` added to the diagonal; `None` when even that fails.
pub(crate) fn cholesky_lower(m: &Mat<f64>, eps: f64) -> Option<Mat<f64>> {
    let n = m.nrows();
    let reg = Mat::from_fn(n, n, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]) + if i == j { eps } else { 0.0 });
    let llt = reg.llt(faer::Side::Lower).ok()?;
    Some(llt.L().to_owned())
}

/// A column from a slice.
pub(crate) fn col(v: &[f64]) -> Mat<f64> {
    Mat::from_fn(v.len(), 1, |i, _| v[i])
}

/// A 3x3 array from a matrix.
pub(crate) fn to3(m: &Mat<f64>) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))
}

/// A matrix from a 3x3 array.
pub(crate) fn from3(a: &[[f64; 3]; 3]) -> Mat<f64> {
    Mat::from_fn(3, 3, |i, j| a[i][j])
}

/// A 5x5 array from a matrix.
pub(crate) fn to5(m: &Mat<f64>) -> [[f64; 5]; 5] {
    std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_and_log_det_by_hand() {
        // [[4, 2], [2, 3]]: det 8, inverse [[3, -2], [-2, 4]] / 8.
        let m = Mat::from_fn(2, 2, |i, j| [[4.0, 2.0], [2.0, 3.0]][i][j]);
        let (inv, log_det) = spd_inverse(&m).unwrap();
        assert!((log_det - 8f64.ln()).abs() < 1e-12);
        assert!((inv[(0, 0)] - 3.0 / 8.0).abs() < 1e-12);
        assert!((inv[(0, 1)] + 2.0 / 8.0).abs() < 1e-12);
        assert!(spd_inverse(&Mat::from_fn(2, 2, |i, j| if i == j { -1.0 } else { 0.0 })).is_none());
        let l = cholesky_lower(&m, 0.0).unwrap();
        assert!((l[(0, 0)] - 2.0).abs() < 1e-12 && (l[(1, 0)] - 1.0).abs() < 1e-12 && l[(0, 1)] == 0.0);
    }
}
