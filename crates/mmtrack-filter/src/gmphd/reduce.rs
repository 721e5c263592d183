//! Pruning and merging of the mixture, Vo & Ma 2006 Table II.
//!
//! ```text
//! I = { i : w_i > T }                                   (truncation)
//! repeat while I is not empty:
//!     j = argmax_{i in I} w_i
//!     L = { i in I : (m_i - m_j)^T P_i^-1 (m_i - m_j) <= U }
//!     w~ = sum_{i in L} w_i
//!     m~ = (1 / w~) sum_{i in L} w_i m_i
//!     P~ = (1 / w~) sum_{i in L} w_i (P_i + (m~ - m_i)(m~ - m_i)^T)
//!     I = I \ L
//! keep the J_max components of largest weight
//! ```
//!
//! Choices where the paper leaves room, all explicit:
//! - the truncated weight is *not* redistributed over the survivors (Table II
//!   does not; Stone Soup does), so `sum w` may drop by at most the pruned mass;
//! - ties in `argmax` go to the component that comes first in the mixture,
//!   which makes the result deterministic;
//! - the merged component takes the label (and the measurement provenance) of
//!   `j`, the heaviest member;
//! - `P~` is a weighted sum of SPD matrices plus positive semi-definite outer
//!   products, hence SPD; it is symmetrised against round-off.

use faer::{Col, Mat, Scale, unzip, zip};

use super::Component;
use crate::error::{FilterError, ensure_in_range, ensure_len};
use crate::gaussian::Gaussian;
use crate::linalg::{Cholesky, symmetrise};

/// The pruning-and-merging role.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MixtureReducer {
    truncation_threshold: f64,
    merge_threshold: f64,
    max_components: usize,
}

/// What one reduction did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReductionReport {
    /// Components discarded for `w <= T`.
    pub truncated: usize,
    /// Components absorbed into a heavier one.
    pub merged: usize,
    /// Components dropped by the `J_max` cap.
    pub capped: usize,
}

impl MixtureReducer {
    /// Truncation threshold `T >= 0`, merge threshold `U >= 0` (a squared
    /// Mahalanobis distance), at most `J_max >= 1` components.
    ///
    /// # Errors
    /// [`FilterError::InvalidParameter`] naming the bad parameter.
    pub fn new(truncation_threshold: f64, merge_threshold: f64, max_components: usize) -> Result<Self, FilterError> {
        ensure_in_range("truncation_threshold", truncation_threshold, 0.0, f64::MAX, "finite and >= 0")?;
        ensure_in_range("merge_threshold", merge_threshold, 0.0, f64::MAX, "finite and >= 0")?;
        if max_components == 0 {
            return Err(FilterError::InvalidParameter {
                name: "max_components",
                value: 0.0,
                expected: "at least one component",
            });
        }
        Ok(Self { truncation_threshold, merge_threshold, max_components })
    }

    /// Truncation threshold `T`.
    #[must_use]
    pub fn truncation_threshold(&self) -> f64 {
        self.truncation_threshold
    }

    /// Merge threshold `U`.
    #[must_use]
    pub fn merge_threshold(&self) -> f64 {
        self.merge_threshold
    }

    /// `J_max`.
    #[must_use]
    pub fn max_components(&self) -> usize {
        self.max_components
    }

    /// Reduces `mixture` (see the module docs); the result is in the order the
    /// merge groups were formed (descending leader weight).
    ///
    /// # Errors
    /// [`FilterError::DimensionMismatch`] if the kept components do not share
    /// one state dimension; [`FilterError::NotPositiveDefinite`] if a component
    /// covariance cannot be factorised.
    pub fn reduce(&self, mixture: &[Component]) -> Result<(Vec<Component>, ReductionReport), FilterError> {
        let kept: Vec<&Component> = mixture.iter().filter(|c| c.weight > self.truncation_threshold).collect();
        let n = kept.first().map_or(0, |c| c.density.dim());
        for c in &kept {
            ensure_len("component mean (state dimension of the first kept component)", c.density.mean(), n)?;
        }
        let mut report = ReductionReport { truncated: mixture.len() - kept.len(), ..ReductionReport::default() };
        let chols = kept
            .iter()
            .map(|c| Cholesky::new("component covariance", c.density.cov()))
            .collect::<Result<Vec<_>, _>>()?;
        let mut remaining: Vec<usize> = (0..kept.len()).collect();
        // Working space of the Mahalanobis tests.
        let (mut d, mut scratch) = (Col::zeros(n), Col::zeros(n));
        let mut out = Vec::new();
        while !remaining.is_empty() {
            // argmax with ties to the earliest: strict `>` keeps the first.
            let mut j = remaining[0];
            for &i in &remaining[1..] {
                if kept[i].weight > kept[j].weight {
                    j = i;
                }
            }
            let mj = kept[j].density.mean();
            let (group, rest): (Vec<usize>, Vec<usize>) = remaining.iter().partition(|&&i| {
                if i == j {
                    return true;
                }
                let mi = kept[i].density.mean();
                for r in 0..n {
                    d[r] = mi[r] - mj[r];
                }
                chols[i].mahalanobis_squared(d.as_ref(), &mut scratch) <= self.merge_threshold
            });
            remaining = rest;
            report.merged += group.len() - 1;
            out.push(merge_group(&kept, &group, j)?);
        }
        if out.len() > self.max_components {
            // Stable sort keeps the merge order among equal weights.
            out.sort_by(|a, b| b.weight.total_cmp(&a.weight));
            report.capped = out.len() - self.max_components;
            out.truncate(self.max_components);
        }
        Ok((out, report))
    }
}

/// Moment-matched merge of `group` (indices into `kept`), labelled as `leader`.
fn merge_group(kept: &[&Component], group: &[usize], leader: usize) -> Result<Component, FilterError> {
    if let [only] = group {
        return Ok(kept[*only].clone());
    }
    let n = kept[leader].density.dim();
    let w_total: f64 = group.iter().map(|&i| kept[i].weight).sum();
    let mut mean = Col::<f64>::zeros(n);
    for &i in group {
        mean += kept[i].density.mean() * Scale(kept[i].weight);
    }
    // Divided, not multiplied by the reciprocal: the equation as written.
    zip!(&mut mean).for_each(|unzip!(x)| *x /= w_total);
    let mut cov = Mat::<f64>::zeros(n, n);
    for &i in group {
        let d = &mean - kept[i].density.mean();
        cov += (kept[i].density.cov() + &d * d.transpose()) * Scale(kept[i].weight);
    }
    zip!(&mut cov).for_each(|unzip!(x)| *x /= w_total);
    Ok(Component {
        label: kept[leader].label,
        weight: w_total,
        density: Gaussian::new(mean, symmetrise(cov))?,
        measurement: kept[leader].measurement,
    })
}
