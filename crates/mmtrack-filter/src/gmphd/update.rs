//! GM-PHD update, Vo & Ma 2006 Table I step 4:
//!
//! ```text
//! missed:    w <- (1 - p_D) w,        (m, P) unchanged
//! detected:  w_i(z) = p_D w_i q_i(z) / (kappa + p_D sum_l w_l q_l(z))
//!            m_i(z) = m_i + K_i (z - H m_i),  P_i(z) = P_i+   (z-independent)
//!            q_i(z) = N(z; H m_i, S_i),       S_i = H P_i H^T + R
//! ```
//!
//! A (component, measurement) pair refused by the gate has `q_i(z) = 0`.
//! Components whose updated weight is exactly 0 (gated out, or a likelihood
//! that underflows) are not created: Table II would discard them at once for
//! any truncation threshold `T >= 0`, so the result is the same.
//!
//! Weights are computed in the log domain (log-sum-exp over `ln kappa` and the
//! `ln(p_D w_l q_l(z))`), so a very peaked likelihood cannot overflow and distant
//! ones cannot make `0 / 0`. If `kappa = 0` and no component explains `z` at
//! all, `z` updates nothing (rather than dividing by zero).

use std::collections::BTreeMap;

use faer::{Col, ColRef};

use super::{Component, GmPhdParams};
use crate::error::{FilterError, ensure_finite_vector, ensure_len};
use crate::gating::{Gate, GateCandidate};
use crate::kalman::KalmanUpdater;
use crate::label::Label;

/// How strongly one label was associated with one measurement in an update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Association {
    /// The label.
    pub label: Label,
    /// Index of the measurement.
    pub measurement: usize,
    /// Sum of the updated weights `w_i(z)` of the label's components for this
    /// measurement (in `[0, 1]`).
    pub weight: f64,
}

/// What an update found, for callers that build births or attach measurement
/// attributes to tracks.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct UpdateReport {
    /// For each measurement, `sum_i w_i(z)`: the expected number of targets it
    /// detected, in `[0, 1)` (or `[0, 1]` with `kappa = 0`). A value near 0
    /// means no existing component explains it (a birth candidate).
    pub measurement_weights: Vec<f64>,
    /// Label-measurement association weights, sorted by label then measurement;
    /// pairs with weight 0 are left out.
    pub associations: Vec<Association>,
}

impl UpdateReport {
    /// The measurement with the largest association weight for `label`, if any
    /// (ties: the lowest measurement index).
    #[must_use]
    pub fn best_measurement(&self, label: Label) -> Option<(usize, f64)> {
        let start = self.associations.partition_point(|a| a.label < label);
        self.associations[start..].iter().take_while(|a| a.label == label).fold(
            None,
            |best: Option<(usize, f64)>, a| match best {
                Some((_, w)) if w >= a.weight => best,
                _ => Some((a.measurement, a.weight)),
            },
        )
    }
}

/// Checks every measurement's dimension and finiteness.
pub(crate) fn check_measurements(measurements: &[Col<f64>], dim: usize) -> Result<(), FilterError> {
    for (index, z) in measurements.iter().enumerate() {
        let wrap = |e: FilterError| FilterError::Measurement { index, source: Box::new(e) };
        ensure_len("measurement", z, dim).map_err(wrap)?;
        ensure_finite_vector("measurement", z).map_err(wrap)?;
    }
    Ok(())
}

/// Returns the updated mixture and the report; `predicted` is not modified.
pub(crate) fn update<G: Gate>(
    predicted: &[Component],
    measurements: &[Col<f64>],
    updater: &KalmanUpdater,
    params: &GmPhdParams,
    gate: &G,
) -> Result<(Vec<Component>, UpdateReport), FilterError> {
    check_measurements(measurements, updater.model.measurement_dim())?;
    let prepared = predicted.iter().map(|c| updater.prepare(&c.density)).collect::<Result<Vec<_>, _>>()?;
    let p_d = params.p_detection;

    let mut out: Vec<Component> = predicted
        .iter()
        .filter(|c| (1.0 - p_d) * c.weight > 0.0)
        .map(|c| Component {
            label: c.label,
            weight: (1.0 - p_d) * c.weight,
            density: c.density.clone(),
            measurement: None,
        })
        .collect();
    let mut measurement_weights = Vec::with_capacity(measurements.len());
    let mut assoc: BTreeMap<(Label, usize), f64> = BTreeMap::new();

    // Working space of the (component, measurement) loop, which otherwise
    // would allocate two vectors per pair: the innovation, copied into the
    // terms only for pairs that pass the gate, and the triangular solve's.
    let dim = updater.model.measurement_dim();
    let mut nu = Col::zeros(dim);
    let mut solve_scratch = Col::zeros(dim);
    // (component index, ln(p_D w q)) of the pairs that pass the gate, and
    // their innovations, `dim` values each, reused from one measurement to
    // the next.
    let mut terms: Vec<(usize, f64)> = Vec::new();
    let mut innovations: Vec<f64> = Vec::new();
    for (j, z) in measurements.iter().enumerate() {
        terms.clear();
        innovations.clear();
        for (i, (c, prep)) in predicted.iter().zip(&prepared).enumerate() {
            let eta = prep.predicted_measurement();
            for r in 0..dim {
                nu[r] = z[r] - eta[r];
            }
            let mahalanobis_squared = prep.mahalanobis_squared_of_innovation(&nu, &mut solve_scratch);
            let candidate = GateCandidate {
                label: c.label,
                prior: &c.density,
                measurement_index: j,
                measurement: z,
                innovation: &nu,
                mahalanobis_squared,
            };
            if !gate.admits(&candidate) {
                continue;
            }
            let log_numerator = (p_d * c.weight).ln() + prep.log_likelihood_from_mahalanobis(mahalanobis_squared);
            if log_numerator > f64::NEG_INFINITY {
                terms.push((i, log_numerator));
                innovations.extend(nu.iter());
            }
        }
        // ln(kappa + sum exp(ln numerator)) by log-sum-exp: no overflow for
        // very peaked likelihoods, no underflow to 0/0 for distant ones.
        let log_kappa = params.clutter_intensity.ln();
        let log_denominator = log_sum_exp(std::iter::once(log_kappa).chain(terms.iter().map(|t| t.1)));
        let mut total = 0.0;
        if log_denominator > f64::NEG_INFINITY {
            for (t, &(i, log_numerator)) in terms.iter().enumerate() {
                let nu = ColRef::from_slice(&innovations[t * dim..(t + 1) * dim]);
                let weight = (log_numerator - log_denominator).exp();
                if weight <= 0.0 {
                    continue;
                }
                let label = predicted[i].label;
                out.push(Component {
                    label,
                    weight,
                    density: prepared[i].posterior_of_innovation(nu)?,
                    measurement: Some(j),
                });
                *assoc.entry((label, j)).or_insert(0.0) += weight;
                total += weight;
            }
        }
        measurement_weights.push(total);
    }
    let associations =
        assoc.into_iter().map(|((label, measurement), weight)| Association { label, measurement, weight }).collect();
    Ok((out, UpdateReport { measurement_weights, associations }))
}

/// `ln sum_i exp(x_i)`, `-inf` for an empty or all `-inf` input.
fn log_sum_exp(xs: impl Iterator<Item = f64> + Clone) -> f64 {
    let max = xs.clone().fold(f64::NEG_INFINITY, f64::max);
    if max == f64::NEG_INFINITY {
        return max;
    }
    max + xs.map(|x| (x - max).exp()).sum::<f64>().ln()
}
