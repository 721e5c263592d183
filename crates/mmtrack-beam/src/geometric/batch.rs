//! Direct batch solves of the geometric equations on faer: the whole stacked
//! system solved at once by a singular value decomposition (minimum-norm
//! least squares), with no recursion and no accumulated normal equations.
//! These are the references the recursive and accumulated estimators are
//! tested against, and an offline tool for a finished recording.

// Index loops read like the formulas on these 3x3 arrays.
#![allow(clippy::needless_range_loop)]

use faer::Mat;

use super::linalg::cholesky;
use super::{DopplerBearing, PolarState, bearing_row, doppler_row};

/// Singular values below this share of the largest count as zero.
const RELATIVE_SINGULAR_TOLERANCE: f64 = 1e-10;

/// The minimum-norm least-squares solution of `rows x = y` (faer SVD);
/// `None` for no rows, mismatched lengths or a failed decomposition.
#[must_use]
pub fn least_squares(rows: &[[f64; 3]], y: &[f64]) -> Option<[f64; 3]> {
    if rows.is_empty() || rows.len() != y.len() {
        return None;
    }
    let a = Mat::from_fn(rows.len(), 3, |i, j| rows[i][j]);
    let svd = a.svd().ok()?;
    let s = svd.S().column_vector();
    let largest = (0..s.nrows()).fold(0.0_f64, |m, i| m.max(s[i]));
    let mut x = [0.0; 3];
    for k in 0..s.nrows() {
        if s[k] > RELATIVE_SINGULAR_TOLERANCE * largest && s[k] > 0.0 {
            let uty: f64 = (0..rows.len()).map(|i| svd.U()[(i, k)] * y[i]).sum();
            for (j, xj) in x.iter_mut().enumerate() {
                *xj += svd.V()[(j, k)] * uty / s[k];
            }
        }
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The stacked rows of (7) against the reference `(t_ref_s, azimuth_ref_rad)`:
/// bearing rows (2) with right-hand side 0, Doppler rows (5) with `nu`.
#[must_use]
pub fn stacked_rows(
    observations: &[DopplerBearing],
    wavelength_m: f64,
    reference: (f64, f64),
) -> (Vec<[f64; 3]>, Vec<f64>) {
    let mut rows = Vec::with_capacity(2 * observations.len());
    let mut y = Vec::with_capacity(2 * observations.len());
    for o in observations {
        let b = mmtrack_core::wrap_angle_rad(o.azimuth_rad - reference.1);
        let t = o.t_s - reference.0;
        rows.push(bearing_row(b, t));
        y.push(0.0);
        rows.push(doppler_row(b, wavelength_m));
        y.push(o.doppler_hz);
    }
    (rows, y)
}

/// Least squares of (7) with the fixed reference (the first observation).
#[must_use]
pub fn fixed_reference(observations: &[DopplerBearing], wavelength_m: f64) -> Option<PolarState> {
    let first = observations.first()?;
    let reference = (first.t_s, first.azimuth_rad);
    let (rows, y) = stacked_rows(observations, wavelength_m, reference);
    Some(PolarState { t_ref_s: reference.0, azimuth_ref_rad: reference.1, x: least_squares(&rows, &y)? })
}

/// Least squares of (7) with the fixed reference and a prior: minimises
/// `(x - x0)^T W (x - x0) + sum_k |y_k - A_k x|^2` (the prior enters as the
/// rows `L^T x = L^T x0` with `W = L L^T`): what RLS from `(x0, W)` computes.
/// `None` when `W` is not positive definite.
#[must_use]
pub fn fixed_reference_with_prior(
    observations: &[DopplerBearing],
    wavelength_m: f64,
    reference: (f64, f64),
    x0: [f64; 3],
    information: [[f64; 3]; 3],
) -> Option<PolarState> {
    let l = cholesky(&information)?;
    let (mut rows, mut y) = stacked_rows(observations, wavelength_m, reference);
    for i in 0..3 {
        // Row i of L^T is column i of L.
        let row = [l[0][i], l[1][i], l[2][i]];
        y.push(row[0] * x0[0] + row[1] * x0[1] + row[2] * x0[2]);
        rows.push(row);
    }
    Some(PolarState { t_ref_s: reference.0, azimuth_ref_rad: reference.1, x: least_squares(&rows, &y)? })
}

/// The running-reference system of Ho and Chan re-solved whole at the last
/// observation (its reference).
#[must_use]
pub fn running_reference(observations: &[DopplerBearing], wavelength_m: f64) -> Option<PolarState> {
    let last = observations.last()?;
    let reference = (last.t_s, last.azimuth_rad);
    let (rows, y) = stacked_rows(observations, wavelength_m, reference);
    Some(PolarState { t_ref_s: reference.0, azimuth_ref_rad: reference.1, x: least_squares(&rows, &y)? })
}

/// The nullspace-projected solution (20)-(21) with the fixed reference: the
/// null space of the stacked `A_B` from its SVD, then least squares of the
/// Doppler rows inside it.
#[must_use]
pub fn nullspace(observations: &[DopplerBearing], wavelength_m: f64) -> Option<PolarState> {
    let first = observations.first()?;
    let reference = (first.t_s, first.azimuth_rad);
    let (rows, y) = stacked_rows(observations, wavelength_m, reference);
    let a_b = Mat::from_fn(observations.len(), 3, |i, j| rows[2 * i][j]);
    let svd = a_b.svd().ok()?;
    let s = svd.S().column_vector();
    let largest = (0..s.nrows()).fold(0.0_f64, |m, i| m.max(s[i]));
    // Columns of V beyond the rank span the null space.
    let basis: Vec<[f64; 3]> = (0..3)
        .filter(|&k| k >= s.nrows() || s[k] <= RELATIVE_SINGULAR_TOLERANCE * largest)
        .map(|k| [svd.V()[(0, k)], svd.V()[(1, k)], svd.V()[(2, k)]])
        .collect();
    let doppler: Vec<[f64; 3]> = (0..observations.len()).map(|i| rows[2 * i + 1]).collect();
    let nu: Vec<f64> = (0..observations.len()).map(|i| y[2 * i + 1]).collect();
    // A_D U c = nu, c padded to 3 columns with zeros.
    let reduced: Vec<[f64; 3]> = doppler
        .iter()
        .map(|d| {
            let mut r = [0.0; 3];
            for (k, u) in basis.iter().enumerate() {
                r[k] = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
            }
            r
        })
        .collect();
    let c = if basis.is_empty() { [0.0; 3] } else { least_squares(&reduced, &nu)? };
    let mut x = [0.0; 3];
    for (k, u) in basis.iter().enumerate() {
        for j in 0..3 {
            x[j] += c[k] * u[j];
        }
    }
    Some(PolarState { t_ref_s: reference.0, azimuth_ref_rad: reference.1, x })
}
