//! Small order statistics, the root mean square and special functions
//! shared by the analyses and reports.
//!
//! The quantiles take values already sorted ascending (by `f64::total_cmp`,
//! so NaN sorts last) and return `None` for no values. Two rules are in use
//! and are kept apart, since they give different values on small samples:
//!
//! - [`quantile`]: linear interpolation between the two nearest order
//!   statistics (Hyndman and Fan type 7, numpy's and R's default);
//! - [`quantile_nearest_rank`]: the smallest value with at least a share `q`
//!   of the values at or below it (type 1, no interpolation).

/// The `q` quantile of `sorted` by linear interpolation between the two
/// nearest order statistics (numpy's default): with `p = q (n - 1)`,
/// `sorted[floor p] (1 - w) + sorted[floor p + 1] w`, `w = p - floor p`.
///
/// `q` is clamped to `[0, 1]` (`q = 0` the minimum, `q = 1` the maximum);
/// `None` when `sorted` is empty. The two neighbours are always weighted,
/// also when `w = 0`, so an infinite neighbour gives `NaN`.
#[must_use]
pub fn quantile(sorted: &[f64], q: f64) -> Option<f64> {
    let last = sorted.len().checked_sub(1)?;
    let position = q.clamp(0.0, 1.0) * last as f64;
    let below = (position.floor() as usize).min(last);
    let above = (below + 1).min(last);
    let w = position - below as f64;
    Some(sorted[below] * (1.0 - w) + sorted[above] * w)
}

/// The nearest-rank `q` quantile of `sorted`: `sorted[ceil(q n) - 1]`, the
/// index clamped to the values (`q <= 1 / n` the minimum, `q = 1` the
/// maximum). `None` when `sorted` is empty.
#[must_use]
pub fn quantile_nearest_rank(sorted: &[f64], q: f64) -> Option<f64> {
    let n = sorted.len();
    (n > 0).then(|| sorted[((q * n as f64).ceil() as usize).clamp(1, n) - 1])
}

/// The median of `sorted`: the middle value, or the mean `(a + b) / 2` of the
/// two middle values for an even count. `None` when `sorted` is empty.
///
/// The same as `quantile(sorted, 0.5)` up to the last bit (`0.5 (a + b)`
/// against `0.5 a + 0.5 b`).
#[must_use]
pub fn median(sorted: &[f64]) -> Option<f64> {
    let n = sorted.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(sorted[n / 2]),
        _ => Some(0.5 * (sorted[n / 2 - 1] + sorted[n / 2])),
    }
}

/// The root mean square `sqrt(sum v^2 / n)` of `values`, summed in their
/// order; `None` for no values.
#[must_use]
pub fn rms(values: impl Iterator<Item = f64>) -> Option<f64> {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    (n > 0).then(|| (sum / n as f64).sqrt())
}

/// The complementary error function `erfc(x) = 1 - erf(x)`, for any `x`,
/// to double precision (`libm::erfc`, the musl/FreeBSD implementation).
#[must_use]
pub fn erfc(x: f64) -> f64 {
    libm::erfc(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_values_have_no_quantile() {
        assert_eq!(quantile(&[], 0.5), None);
        assert_eq!(quantile_nearest_rank(&[], 0.5), None);
        assert_eq!(median(&[]), None);
    }

    #[test]
    fn one_value_is_every_quantile() {
        for q in [0.0, 0.1, 0.5, 0.9, 1.0] {
            assert_eq!(quantile(&[3.5], q), Some(3.5));
            assert_eq!(quantile_nearest_rank(&[3.5], q), Some(3.5));
        }
        assert_eq!(median(&[3.5]), Some(3.5));
    }

    #[test]
    fn zero_and_one_are_the_extremes() {
        let v = [-2.0, 1.0, 4.0, 8.0, 9.5];
        assert_eq!(quantile(&v, 0.0), Some(-2.0));
        assert_eq!(quantile(&v, 1.0), Some(9.5));
        assert_eq!(quantile_nearest_rank(&v, 0.0), Some(-2.0));
        assert_eq!(quantile_nearest_rank(&v, 1.0), Some(9.5));
        // Out of range: clamped (linear) and the clamped rank (nearest rank).
        assert_eq!(quantile(&v, -0.5), Some(-2.0));
        assert_eq!(quantile(&v, 1.5), Some(9.5));
        assert_eq!(quantile_nearest_rank(&v, -0.5), Some(-2.0));
        assert_eq!(quantile_nearest_rank(&v, 1.5), Some(9.5));
    }

    #[test]
    fn linear_interpolation_matches_numpy() {
        // numpy.quantile([1, 2, 4, 8], q) for q = 0.25, 0.5, 0.9, 1/3.
        let v = [1.0, 2.0, 4.0, 8.0];
        assert_eq!(quantile(&v, 0.25), Some(1.75));
        assert_eq!(quantile(&v, 0.5), Some(3.0));
        assert!((quantile(&v, 0.9).unwrap_or(f64::NAN) - 6.8).abs() < 1e-12);
        assert!((quantile(&v, 1.0 / 3.0).unwrap_or(f64::NAN) - 2.0).abs() < 1e-12);
        // Odd count: the middle value exactly.
        assert_eq!(quantile(&[1.0, 2.0, 40.0], 0.5), Some(2.0));
    }

    #[test]
    fn nearest_rank_takes_a_value_without_interpolation() {
        let v = [1.0, 2.0, 4.0, 8.0];
        assert_eq!(quantile_nearest_rank(&v, 0.25), Some(1.0));
        assert_eq!(quantile_nearest_rank(&v, 0.26), Some(2.0));
        assert_eq!(quantile_nearest_rank(&v, 0.5), Some(2.0));
        assert_eq!(quantile_nearest_rank(&v, 0.9), Some(8.0));
    }

    #[test]
    fn median_averages_the_middle_pair() {
        assert_eq!(median(&[1.0, 2.0, 40.0]), Some(2.0));
        assert_eq!(median(&[1.0, 2.0, 4.0, 40.0]), Some(3.0));
        assert_eq!(median(&[1.0, 2.0]), Some(1.5));
        for v in [vec![0.1, 0.7, 0.9], vec![0.1, 0.2, 0.7, 0.9], vec![-3.3, 1.1, 2.9, 5.0, 7.7, 8.1]] {
            let (m, q) = (median(&v).unwrap_or(f64::NAN), quantile(&v, 0.5).unwrap_or(f64::NAN));
            assert!((m - q).abs() <= 1e-15 * m.abs(), "{v:?}: {m} {q}");
        }
    }

    #[test]
    fn rms_of_values_and_of_none() {
        assert_eq!(rms(std::iter::empty()), None);
        assert_eq!(rms([-2.0].into_iter()), Some(2.0));
        // sqrt((1 + 4 + 4 + 16 + 25) / 5) = sqrt(10): exact inputs, one rounding in sqrt.
        assert_eq!(rms([1.0, -2.0, 2.0, 4.0, -5.0].into_iter()), Some(10f64.sqrt()));
    }

    #[test]
    fn erfc_matches_tabulated_values() {
        // Reference values: the C library's erfc (glibc, through CPython).
        assert_eq!(erfc(0.0), 1.0);
        assert!((erfc(0.5) - 0.479_500_122_186_953_5).abs() < 1e-15);
        assert!((erfc(1.25) - 0.077_099_871_743_541_77).abs() < 1e-15);
        assert!((erfc(2.0) - 0.004_677_734_981_047_265).abs() < 1e-17);
        assert!((erfc(-1.0) - 1.842_700_792_949_715).abs() < 1e-15);
        assert!((erfc(6.0) - 2.151_973_671_249_891_6e-17).abs() < 1e-30);
        assert_eq!(erfc(f64::INFINITY), 0.0);
        assert_eq!(erfc(f64::NEG_INFINITY), 2.0);
    }
}
