//! Global-nearest-neighbour data association, eq. (3)-(7): the paths (rows)
//! are paired with map sources or with a "new source" column each, so as to
//! maximise `sum log S_lm`, by the Kuhn-Munkres solver of `mmtrack-filter`.
//!
//! `S = [S^D, P_N I]`: the `P_N I` block is [`solve_with_unassigned`]'s
//! per-row unassigned cost `-log P_N` (a row left unpaired is a path from a
//! new source), and a pair outside the gate is forbidden (`+inf` cost).

use faer::Mat;
use mmtrack_filter::FilterError;
use mmtrack_filter::assignment::solve_with_unassigned;

/// The source (column) of each path (row), `None` for a new source, given
/// `log S^D` (`-inf` for a pair that is not allowed) and `log P_N`.
///
/// # Errors
/// [`FilterError::NotFinite`] for a NaN entry or a non-finite `log P_N`.
pub fn associate(log_s: &[Vec<f64>], columns: usize, log_new: f64) -> Result<Vec<Option<usize>>, FilterError> {
    let rows = log_s.len();
    if rows == 0 {
        return Ok(Vec::new());
    }
    let cost = Mat::from_fn(rows, columns, |l, m| {
        let v = log_s[l].get(m).copied().unwrap_or(f64::NEG_INFINITY);
        if v == f64::NEG_INFINITY { f64::INFINITY } else { -v }
    });
    if columns == 0 {
        return Ok(vec![None; rows]);
    }
    Ok(solve_with_unassigned(&cost, -log_new)?.row_to_col)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// The best objective (7a) over every assignment, by enumeration.
    fn brute_force(log_s: &[Vec<f64>], columns: usize, log_new: f64) -> f64 {
        fn go(l: usize, used: &mut Vec<bool>, log_s: &[Vec<f64>], log_new: f64) -> f64 {
            if l == log_s.len() {
                return 0.0;
            }
            let mut best = log_new + go(l + 1, used, log_s, log_new);
            for m in 0..used.len() {
                if !used[m] && log_s[l][m] > f64::NEG_INFINITY {
                    used[m] = true;
                    best = best.max(log_s[l][m] + go(l + 1, used, log_s, log_new));
                    used[m] = false;
                }
            }
            best
        }
        go(0, &mut vec![false; columns], log_s, log_new)
    }

    fn objective(log_s: &[Vec<f64>], a: &[Option<usize>], log_new: f64) -> f64 {
        a.iter().enumerate().map(|(l, m)| m.map_or(log_new, |m| log_s[l][m])).sum()
    }

    #[test]
    fn kuhn_munkres_matches_brute_force_on_small_matrices() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        for trial in 0..300 {
            let rows = 1 + trial % 5;
            let columns = trial % 6;
            let log_s: Vec<Vec<f64>> = (0..rows)
                .map(|_| {
                    (0..columns)
                        .map(|_| {
                            if rng.random::<f64>() < 0.2 {
                                f64::NEG_INFINITY
                            } else {
                                20.0 * rng.random::<f64>() - 10.0
                            }
                        })
                        .collect()
                })
                .collect();
            let log_new = 6.0 * rng.random::<f64>() - 3.0;
            let a = associate(&log_s, columns, log_new).unwrap();
            // One path per source (7d), every path somewhere (7c).
            let mut seen = vec![false; columns];
            for m in a.iter().flatten() {
                assert!(!seen[*m], "column {m} used twice");
                seen[*m] = true;
                assert!(log_s.iter().zip(&a).all(|(row, c)| c.is_none_or(|c| row[c] > f64::NEG_INFINITY)));
            }
            let best = brute_force(&log_s, columns, log_new);
            let got = objective(&log_s, &a, log_new);
            assert!((got - best).abs() < 1e-9, "trial {trial}: {got} vs brute force {best}");
        }
    }

    #[test]
    fn a_far_source_loses_to_a_new_one() {
        // One path, one source with log S = -50 against log P_N = -7: new source.
        assert_eq!(associate(&[vec![-50.0]], 1, -7.0).unwrap(), vec![None]);
        assert_eq!(associate(&[vec![5.0], vec![4.0]], 1, -7.0).unwrap(), vec![Some(0), None]);
        assert!(associate(&[vec![f64::NAN]], 1, -7.0).is_err());
    }
}
