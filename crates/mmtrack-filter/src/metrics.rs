//! Distances between finite point sets: OSPA and GOSPA.
//!
//! Both use the Euclidean base distance `d(x, y) = |x - y|`, a cut-off
//! `c > 0` and an order `p >= 1`, and find the optimal pairing with the
//! Hungarian method ([`crate::assignment`]).
//!
//! **OSPA** (Schuhmacher, Vo, Vo 2008, eq. 3), for `|X| = m <= |Y| = n`:
//!
//! ```text
//! d_p^(c)(X, Y) = ( (1/n) ( min_pi sum_{i=1}^m d^(c)(x_i, y_pi(i))^p + c^p (n - m) ) )^(1/p)
//! d^(c)(x, y) = min(c, d(x, y))
//! ```
//!
//! with `d = 0` when both sets are empty; it splits as
//! `d^p = localisation^p + cardinality^p` (Sec. IV-B).
//!
//! **GOSPA** with `alpha = 2` (Rahmathullah, Garcia-Fernandez, Svensson 2017,
//! Proposition 1): with `gamma` a partial assignment of pairs at distance `< c`,
//!
//! ```text
//! d_p^(c,2)(X, Y) = ( min_gamma sum_{(i,j) in gamma} d(x_i, y_j)^p + (c^p / 2)(|X| + |Y| - 2|gamma|) )^(1/p)
//! ```
//!
//! i.e. localisation error plus `c^p / 2` per missed and per false target. It
//! equals the minimum over full assignments of `sum min(d, c)^p` plus
//! `c^p / 2 * ||X| - |Y||`, which is how it is computed; a pair at distance
//! `>= c` is reported as one missed and one false target.
//!
//! # References
//! D. Schuhmacher, B.-T. Vo, B.-N. Vo, "A consistent metric for performance
//! evaluation of multi-object filters", IEEE TSP 56(8), 2008.
//! A. S. Rahmathullah, A. F. Garcia-Fernandez, L. Svensson, "Generalized
//! optimal sub-pattern assignment metric", FUSION 2017.

use faer::{Col, Mat};

use crate::assignment::solve;
use crate::error::FilterError;

/// OSPA distance and its two parts (`distance^p = localisation^p + cardinality^p`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ospa {
    /// `d_p^(c)(X, Y)`.
    pub distance: f64,
    /// `((1/n) min sum d^(c)^p)^(1/p)`.
    pub localisation: f64,
    /// `((1/n) c^p (n - m))^(1/p)`.
    pub cardinality: f64,
}

/// GOSPA (`alpha = 2`) distance and its parts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gospa {
    /// `d_p^(c,2)(X, Y)`.
    pub distance: f64,
    /// `sum d^p` over the assigned pairs (distance `< c`).
    pub localisation_p: f64,
    /// Points of the first set (truth) left unassigned.
    pub missed: usize,
    /// Points of the second set (estimates) left unassigned.
    pub false_targets: usize,
}

fn check_parameters(c: f64, p: f64) -> Result<(), FilterError> {
    if !(c.is_finite() && c > 0.0) {
        return Err(FilterError::InvalidParameter { name: "cut-off c", value: c, expected: "finite and > 0" });
    }
    if !(p.is_finite() && p >= 1.0) {
        return Err(FilterError::InvalidParameter { name: "order p", value: p, expected: "finite and >= 1" });
    }
    Ok(())
}

/// Checks both sets share one dimension and are finite.
fn check_sets(x: &[Col<f64>], y: &[Col<f64>]) -> Result<(), FilterError> {
    let dim = x.first().or(y.first()).map(|v| v.nrows());
    for (what, set) in [("first point set", x), ("second point set", y)] {
        for (index, v) in set.iter().enumerate() {
            if let Some(expected) = dim
                && v.nrows() != expected
            {
                return Err(FilterError::PointDimension { what, index, expected, found: v.nrows() });
            }
            // Reported as (row = point index, col = coordinate).
            if let Some(k) = v.iter().position(|e| !e.is_finite()) {
                return Err(FilterError::NotFinite { what, row: index, col: k, value: v[k] });
            }
        }
    }
    Ok(())
}

/// `min(d, c)^p` for every pair, rows = the smaller set.
fn cut_cost(small: &[Col<f64>], large: &[Col<f64>], c: f64, p: f64) -> Mat<f64> {
    Mat::from_fn(small.len(), large.len(), |i, j| (&small[i] - &large[j]).norm_l2().min(c).powf(p))
}

/// OSPA distance between `x` and `y` (symmetric in its arguments).
///
/// # Errors
/// [`FilterError::InvalidParameter`] for `c <= 0` or `p < 1`;
/// [`FilterError::PointDimension`] / [`FilterError::NotFinite`] (row = point,
/// col = coordinate) for points of mixed dimension or with NaN.
pub fn ospa(x: &[Col<f64>], y: &[Col<f64>], c: f64, p: f64) -> Result<Ospa, FilterError> {
    check_parameters(c, p)?;
    check_sets(x, y)?;
    let (small, large) = if x.len() <= y.len() { (x, y) } else { (y, x) };
    let n = large.len();
    if n == 0 {
        return Ok(Ospa { distance: 0.0, localisation: 0.0, cardinality: 0.0 });
    }
    let loc_p = solve(&cut_cost(small, large, c, p))?.total_cost;
    let card_p = c.powf(p) * (n - small.len()) as f64;
    let nf = n as f64;
    Ok(Ospa {
        distance: ((loc_p + card_p) / nf).powf(1.0 / p),
        localisation: (loc_p / nf).powf(1.0 / p),
        cardinality: (card_p / nf).powf(1.0 / p),
    })
}

/// GOSPA distance (`alpha = 2`) between `truth` and `estimates`.
///
/// # Errors
/// As [`ospa`].
pub fn gospa(truth: &[Col<f64>], estimates: &[Col<f64>], c: f64, p: f64) -> Result<Gospa, FilterError> {
    check_parameters(c, p)?;
    check_sets(truth, estimates)?;
    let cost = cut_cost(truth, estimates, c, p);
    let assignment = solve(&cost)?;
    let mut localisation_p = 0.0;
    let mut assigned = 0_usize;
    for (i, j) in assignment.pairs() {
        let d = (&truth[i] - &estimates[j]).norm_l2();
        if d < c {
            localisation_p += d.powf(p);
            assigned += 1;
        }
    }
    let missed = truth.len() - assigned;
    let false_targets = estimates.len() - assigned;
    let distance = (localisation_p + c.powf(p) / 2.0 * (missed + false_targets) as f64).powf(1.0 / p);
    Ok(Gospa { distance, localisation_p, missed, false_targets })
}
