//! The labelled GM-PHD filter of `mmtrack-filter` ([`mmtrack_filter::GmPhdFilter`]
//! with [`mmtrack_filter::ConstantVelocity`] in one axis, a position
//! measurement and the baseline's change gate), written for this model's two
//! state dimensions on stack arrays.
//!
//! The state is `x = [d, d_dot]` (m, m/s) and the measurement the scalar
//! `z = d + e`, so every mean is a `[f64; 2]`, every covariance a
//! `[[f64; 2]; 2]`, the innovation covariance `S` a number. The generic filter
//! keeps these in faer's heap matrices: about 25 allocations per component and
//! step (prediction, the update's prepared quantities, each posterior, the
//! missed-detection copy, the merge's factor, the extraction's copy), which on
//! about 13 detections per snapshot cost more than the arithmetic.
//!
//! Every quantity is formed with the same floating-point operations in the
//! same order as the generic filter (`mmtrack_filter`'s `kalman.rs`,
//! `linalg.rs`, `gmphd/update.rs`, `gmphd/reduce.rs`, `gmphd/extract.rs`), so
//! the tracks are the same number for number; the integration test
//! `gmphd_generic` checks that on drawn sparse and dense detections, and the
//! unit tests below check prediction and the prepared update bit for bit. In particular:
//! - products are sums from `0.0` in index order, added to their destination
//!   (`linalg::mul_add`);
//! - the Cholesky factor of `S` is faer's, `l = s * (1 / sqrt(s))`, and
//!   `S^-1 b` is faer's two triangular solves, `(b * (1 / l)) * (1 / l)`;
//! - the merge test factorises each covariance with faer itself (on the stack).
//!
//! # Equations (B.-N. Vo and W.-K. Ma, IEEE TSP 54(11), 2006)
//! - Table I, steps 1-3 (prediction): `w <- p_S w`, `m <- F m`,
//!   `P <- F P F^T + Q`, with `F = [[1, dt], [0, 1]]` and the white-acceleration
//!   `Q = sigma^2 [[dt^4/4, dt^3/2], [dt^3/2, dt^2]]`; births appended with
//!   fresh labels.
//! - Table I, step 4 (update): `eta = H m`, `S = H P H^T + R`,
//!   `K = P H^T S^-1`, `P+ = (I - K H) P (I - K H)^T + K R K^T` (Joseph form),
//!   `w_i(z) = p_D w_i q_i(z) / (kappa + p_D sum_l w_l q_l(z))` in the log
//!   domain, `q_i(z) = N(z; eta_i, S_i)`, `m_i(z) = m_i + K_i (z - eta_i)`.
//! - Table II (pruning and merging) and Table III (state extraction) with the
//!   labelling rule of `mmtrack_filter::gmphd`.

use std::collections::BTreeMap;

use mmtrack_filter::gmphd::MAX_COPIES_PER_COMPONENT;
use mmtrack_filter::{FilterError, Label};

use super::small::{Cov, Mean};
use super::small::{
    checked_spd, cholesky_2x2, col, dot_add, log_sum_exp, mahalanobis_squared_2, mul_add, mul_transpose_add, pivot,
    row, symmetrise,
};

/// One weighted Gaussian of the intensity, with its label (as
/// [`mmtrack_filter::gmphd::Component`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Component {
    pub label: Label,
    pub weight: f64,
    pub mean: Mean,
    pub cov: Cov,
    /// Index of the measurement that produced it in the last update.
    pub measurement: Option<usize>,
}

/// An extracted state (as [`mmtrack_filter::gmphd::Estimate`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Estimate {
    pub label: Label,
    pub mean: Mean,
    pub measurement: Option<usize>,
}

/// The parameters of the baseline's filter (Mahler et al. 2017, Table I).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Params {
    /// White-acceleration standard deviation, m/s^2.
    pub sigma_process_mps2: f64,
    /// Measurement noise variance `R`, m^2.
    pub r_m2: f64,
    pub p_survival: f64,
    pub p_detection: f64,
    /// `kappa`, per metre.
    pub clutter_intensity_per_m: f64,
    pub truncation_threshold: f64,
    pub merge_threshold: f64,
    pub max_components: usize,
    pub extraction_threshold: f64,
}

/// The change gate of the module docs of `gmphd`: the innovation (m) and the
/// power change (dB) against the component label's last power.
pub(super) struct ChangeGate<'a> {
    pub max_innovation_m: f64,
    pub max_magnitude_change_db: f64,
    pub last_power_db: &'a BTreeMap<Label, f64>,
    pub powers_db: &'a [f64],
}

/// The filter state.
#[derive(Debug, Clone)]
pub(super) struct Filter {
    params: Params,
    mixture: Vec<Component>,
    next_label: u64,
    // Working space reused from step to step.
    prepared: Vec<Prepared>,
    scratch: Vec<Component>,
}

/// The measurement-independent part of the update of one component
/// (`kalman::PreparedUpdate`).
#[derive(Debug, Clone, Copy)]
struct Prepared {
    /// `eta = H m`.
    eta: f64,
    /// Cholesky factor of `S`.
    l: f64,
    /// `ln det S`.
    log_det_s: f64,
    /// `K`.
    gain: Mean,
    /// `P+`.
    posterior_cov: Cov,
}

impl Filter {
    /// An empty filter.
    pub(super) fn new(params: Params) -> Self {
        Self { params, mixture: Vec::new(), next_label: 0, prepared: Vec::new(), scratch: Vec::new() }
    }

    /// The current mixture.
    pub(super) fn mixture(&self) -> &[Component] {
        &self.mixture
    }

    /// `N(F m, F P F^T + Q)`, checked as `Gaussian::new` checks
    /// (`kalman::predict_with`).
    fn predict_one(mean: &Mean, cov: &Cov, f: &Cov, q: &Cov) -> Result<(Mean, Cov), FilterError> {
        let m = [dot_add(0.0, row(f, 0), *mean), dot_add(0.0, row(f, 1), *mean)];
        let fp = mul_add([[0.0; 2]; 2], f, cov);
        let p = symmetrise(mul_transpose_add(*q, &fp, f));
        check_mean(&m)?;
        Ok((m, checked_spd("Gaussian covariance", p)?))
    }

    /// Birth densities `N([d, 0], diag(var_d, var_rate))` predicted over
    /// `dt_s` (the baseline's birth model), for each path length `d` (m).
    pub(super) fn births(&self, d_m: &[f64], birth_cov: &Cov, dt_s: f64) -> Result<Vec<(Mean, Cov)>, FilterError> {
        let mut out = Vec::with_capacity(d_m.len());
        let mut fq = None;
        for &d in d_m {
            let mean = [d, 0.0];
            check_mean(&mean)?;
            let cov = checked_spd("Gaussian covariance", *birth_cov)?;
            let (f, q) = match &fq {
                Some(fq) => fq,
                None => fq.insert(transition(self.params.sigma_process_mps2, dt_s)?),
            };
            out.push(Self::predict_one(&mean, &cov, f, q)?);
        }
        Ok(out)
    }

    /// Prediction (Table I, steps 1-3), then the births with weight
    /// `birth_weight` and fresh labels, returned in order.
    pub(super) fn predict(
        &mut self,
        dt_s: f64,
        births: &[(Mean, Cov)],
        birth_weight: f64,
    ) -> Result<Vec<Label>, FilterError> {
        let mut fq = None;
        self.scratch.clear();
        for c in &self.mixture {
            let (f, q) = match &fq {
                Some(fq) => fq,
                None => fq.insert(transition(self.params.sigma_process_mps2, dt_s)?),
            };
            let (mean, cov) = Self::predict_one(&c.mean, &c.cov, f, q)?;
            self.scratch.push(Component {
                label: c.label,
                weight: self.params.p_survival * c.weight,
                mean,
                cov,
                measurement: None,
            });
        }
        std::mem::swap(&mut self.mixture, &mut self.scratch);
        let mut labels = Vec::with_capacity(births.len());
        for &(mean, cov) in births {
            let label = Label(self.next_label);
            self.next_label += 1;
            labels.push(label);
            self.mixture.push(Component { label, weight: birth_weight, mean, cov, measurement: None });
        }
        Ok(labels)
    }

    /// `eta`, `S`'s factor, `K` and `P+` of one component
    /// (`kalman::prepare_linearised` with `H = [1, 0]`, `R = r`).
    fn prepare(mean: &Mean, p: &Cov, r: f64) -> Result<Prepared, FilterError> {
        const H: [f64; 2] = [1.0, 0.0];
        let eta = dot_add(0.0, H, *mean);
        if !eta.is_finite() {
            return Err(FilterError::NotFinite { what: "predicted measurement", row: 0, col: 0, value: eta });
        }
        let hp = [dot_add(0.0, H, col(p, 0)), dot_add(0.0, H, col(p, 1))];
        // S = R + H P H^T, symmetrised ((s + s) / 2, as the generic code).
        let s = dot_add(r, hp, H);
        let s = (s + s) * 0.5;
        // faer's 1 x 1 factor: the pivot's root, then the column scaled by its reciprocal.
        let l = match pivot(s) {
            Some(root) => s * root.recip(),
            None => return Err(FilterError::NotPositiveDefinite { what: "innovation covariance S" }),
        };
        // K^T = S^-1 (H P): two triangular solves by l.
        let inv = l.recip();
        let gain = [(hp[0] * inv) * inv, (hp[1] * inv) * inv];
        // I - K H.
        let mut i_kh = [[1.0, 0.0], [0.0, 1.0]];
        for j in 0..2 {
            for i in 0..2 {
                let mut s = 0.0;
                s += gain[i] * H[j];
                // -1 * s, exactly.
                i_kh[i][j] += -s;
            }
        }
        let i_kh_p = mul_add([[0.0; 2]; 2], &i_kh, p);
        let post = mul_transpose_add([[0.0; 2]; 2], &i_kh_p, &i_kh);
        // + (K R) K^T.
        let kr = [0.0 + gain[0] * r, 0.0 + gain[1] * r];
        let mut post = post;
        for j in 0..2 {
            for i in 0..2 {
                let mut s = 0.0;
                s += kr[i] * gain[j];
                post[i][j] += s;
            }
        }
        let posterior_cov = checked_spd("Gaussian covariance", symmetrise(post))?;
        Ok(Prepared { eta, l, log_det_s: 2.0 * [l.ln()].into_iter().sum::<f64>(), gain, posterior_cov })
    }

    /// Update with the path lengths `zs` (m) of one snapshot (Table I, step
    /// 4) through `gate`; returns `sum_i w_i(z)` for each measurement.
    pub(super) fn update(&mut self, zs: &[f64], gate: &ChangeGate<'_>) -> Result<Vec<f64>, FilterError> {
        for (index, &z) in zs.iter().enumerate() {
            if !z.is_finite() {
                return Err(FilterError::Measurement {
                    index,
                    source: Box::new(FilterError::NotFinite { what: "measurement", row: 0, col: 0, value: z }),
                });
            }
        }
        let (r, p_d) = (self.params.r_m2, self.params.p_detection);
        self.prepared.clear();
        for c in &self.mixture {
            self.prepared.push(Self::prepare(&c.mean, &c.cov, r)?);
        }
        let predicted = &self.mixture;
        let out = &mut self.scratch;
        out.clear();
        out.extend(predicted.iter().filter(|c| (1.0 - p_d) * c.weight > 0.0).map(|c| Component {
            weight: (1.0 - p_d) * c.weight,
            measurement: None,
            ..*c
        }));
        // Per component: ln(p_D w) and the label's last power.
        let log_pdw: Vec<f64> = predicted.iter().map(|c| (p_d * c.weight).ln()).collect();
        let last_power: Vec<Option<f64>> =
            predicted.iter().map(|c| gate.last_power_db.get(&c.label).copied()).collect();
        let log_two_pi = 1.0 * (2.0 * std::f64::consts::PI).ln();
        let log_kappa = self.params.clutter_intensity_per_m.ln();
        let mut measurement_weights = Vec::with_capacity(zs.len());
        // (component, ln(p_D w q), innovation) of the pairs that pass the gate.
        let mut terms: Vec<(usize, f64, f64)> = Vec::new();
        for (j, &z) in zs.iter().enumerate() {
            terms.clear();
            let power_now = gate.powers_db.get(j).copied();
            for (i, prep) in self.prepared.iter().enumerate() {
                let nu = z - prep.eta;
                // The delay part of the gate first: it needs neither the
                // distance nor the label's power.
                let delay_ok = nu.abs() <= gate.max_innovation_m;
                if !delay_ok {
                    continue;
                }
                let magnitude_ok = match (last_power[i], power_now) {
                    (Some(last), Some(now)) => (now - last).abs() <= gate.max_magnitude_change_db,
                    _ => true,
                };
                if !magnitude_ok {
                    continue;
                }
                let y = nu / prep.l;
                let d2 = 0.0 + y * y;
                let log_numerator = log_pdw[i] + -0.5 * (log_two_pi + prep.log_det_s + d2);
                if log_numerator > f64::NEG_INFINITY {
                    terms.push((i, log_numerator, nu));
                }
            }
            let log_denominator = log_sum_exp(std::iter::once(log_kappa).chain(terms.iter().map(|t| t.1)));
            let mut total = 0.0;
            if log_denominator > f64::NEG_INFINITY {
                for &(i, log_numerator, nu) in &terms {
                    let weight = (log_numerator - log_denominator).exp();
                    if weight <= 0.0 {
                        continue;
                    }
                    let prep = &self.prepared[i];
                    let m = predicted[i].mean;
                    let mean = [m[0] + (0.0 + prep.gain[0] * nu), m[1] + (0.0 + prep.gain[1] * nu)];
                    check_mean(&mean)?;
                    out.push(Component {
                        label: predicted[i].label,
                        weight,
                        mean,
                        cov: prep.posterior_cov,
                        measurement: Some(j),
                    });
                    total += weight;
                }
            }
            measurement_weights.push(total);
        }
        std::mem::swap(&mut self.mixture, &mut self.scratch);
        Ok(measurement_weights)
    }

    /// Pruning and merging (Table II, `reduce.rs`): truncation at `T`,
    /// groups within squared Mahalanobis distance `U` of the heaviest
    /// remaining component (ties to the earliest), moment-matched, then the
    /// `J_max` heaviest.
    pub(super) fn reduce(&mut self) -> Result<(), FilterError> {
        let (t, u) = (self.params.truncation_threshold, self.params.merge_threshold);
        let kept: Vec<Component> = self.mixture.iter().filter(|c| c.weight > t).copied().collect();
        let chols = kept
            .iter()
            .map(|c| cholesky_2x2(&c.cov).ok_or(FilterError::NotPositiveDefinite { what: "component covariance" }))
            .collect::<Result<Vec<_>, _>>()?;
        let mut remaining: Vec<usize> = (0..kept.len()).collect();
        let (mut group, mut rest) = (Vec::new(), Vec::new());
        let out = &mut self.scratch;
        out.clear();
        while !remaining.is_empty() {
            let mut j = remaining[0];
            for &i in &remaining[1..] {
                if kept[i].weight > kept[j].weight {
                    j = i;
                }
            }
            let mj = kept[j].mean;
            group.clear();
            rest.clear();
            for &i in &remaining {
                let mi = kept[i].mean;
                if i == j || mahalanobis_squared_2(&chols[i], [mi[0] - mj[0], mi[1] - mj[1]]) <= u {
                    group.push(i);
                } else {
                    rest.push(i);
                }
            }
            std::mem::swap(&mut remaining, &mut rest);
            out.push(merge_group(&kept, &group, j)?);
        }
        if out.len() > self.params.max_components {
            out.sort_by(|a, b| b.weight.total_cmp(&a.weight));
            out.truncate(self.params.max_components);
        }
        std::mem::swap(&mut self.mixture, &mut self.scratch);
        Ok(())
    }

    /// State extraction (Table III, `extract.rs`) of the components above
    /// the threshold, `max(1, round(w))` copies each; duplicate labels are
    /// resolved as the generic extractor does. Sorted by label.
    pub(super) fn extract(&mut self) -> Vec<Estimate> {
        let mut by_label: BTreeMap<Label, Vec<usize>> = BTreeMap::new();
        for (i, c) in self.mixture.iter().enumerate() {
            if c.weight > self.params.extraction_threshold {
                by_label.entry(c.label).or_default().push(i);
            }
        }
        let mut estimates = Vec::new();
        for (_, mut members) in by_label {
            members.sort_by(|&a, &b| self.mixture[b].weight.total_cmp(&self.mixture[a].weight));
            for (rank, &i) in members.iter().enumerate() {
                if rank > 0 {
                    self.mixture[i].label = Label(self.next_label);
                    self.next_label += 1;
                }
                let c = self.mixture[i];
                let copies = (c.weight.round().min(MAX_COPIES_PER_COMPONENT as f64) as usize).max(1);
                estimates.push(Estimate { label: c.label, mean: c.mean, measurement: c.measurement });
                for _ in 1..copies {
                    let label = Label(self.next_label);
                    self.next_label += 1;
                    estimates.push(Estimate { label, mean: c.mean, measurement: c.measurement });
                }
            }
        }
        estimates.sort_by_key(|e| e.label);
        estimates
    }
}

/// `(F, Q)` of the constant-velocity model over `dt_s` with white
/// acceleration of standard deviation `sigma_mps2` (`ConstantVelocity::matrices`).
fn transition(sigma_mps2: f64, dt_s: f64) -> Result<(Cov, Cov), FilterError> {
    if !(dt_s.is_finite() && dt_s >= 0.0) {
        return Err(FilterError::InvalidParameter { name: "dt_s", value: dt_s, expected: "finite and >= 0" });
    }
    let s2 = sigma_mps2 * sigma_mps2;
    let q01 = s2 * dt_s.powi(3) / 2.0;
    Ok(([[1.0, dt_s], [0.0, 1.0]], [[s2 * dt_s.powi(4) / 4.0, q01], [q01, s2 * dt_s * dt_s]]))
}

/// A mean must be finite (`Gaussian::new`'s check).
fn check_mean(m: &Mean) -> Result<(), FilterError> {
    match m.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(row) => Err(FilterError::NotFinite { what: "Gaussian mean", row, col: 0, value: m[row] }),
    }
}

/// Moment-matched merge of `group` (indices into `kept`), labelled as
/// `leader` (`reduce::merge_group`).
fn merge_group(kept: &[Component], group: &[usize], leader: usize) -> Result<Component, FilterError> {
    if let [only] = group {
        return Ok(kept[*only]);
    }
    let w_total: f64 = group.iter().map(|&i| kept[i].weight).sum();
    let mut mean = [0.0; 2];
    for &i in group {
        for (r, m) in mean.iter_mut().enumerate() {
            *m += kept[i].mean[r] * kept[i].weight;
        }
    }
    for m in &mut mean {
        *m /= w_total;
    }
    let mut cov = [[0.0; 2]; 2];
    for &i in group {
        let d = [mean[0] - kept[i].mean[0], mean[1] - kept[i].mean[1]];
        for c in 0..2 {
            for r in 0..2 {
                cov[r][c] += (kept[i].cov[r][c] + d[r] * d[c]) * kept[i].weight;
            }
        }
    }
    for x in cov.iter_mut().flatten() {
        *x /= w_total;
    }
    check_mean(&mean)?;
    Ok(Component {
        label: kept[leader].label,
        weight: w_total,
        mean,
        cov: checked_spd("Gaussian covariance", symmetrise(cov))?,
        measurement: kept[leader].measurement,
    })
}

#[cfg(test)]
mod tests {
    use mmtrack_filter::faer::{Col, Mat};
    use mmtrack_filter::{ConstantVelocity, Gaussian, KalmanPredictor, KalmanUpdater, LinearMeasurement};

    use super::*;
    use crate::gmphd::small::is_positive_definite;

    /// Priors of the sizes the baseline sees: path lengths up to 600 m,
    /// rates up to 100 m/s, standard deviations from 1 mm to 40 m/s,
    /// correlated.
    fn priors() -> Vec<(Mean, Cov)> {
        let mut out = Vec::new();
        let mut u = 0.5_f64;
        let mut next = || {
            u = (u * 3.987_654_321 + 0.123_456_789).fract();
            u
        };
        for _ in 0..200 {
            let (sd, sv, rho) = (1e-3 + 0.1 * next(), 1e-2 + 40.0 * next(), 1.8 * next() - 0.9);
            let cov = [[sd * sd, rho * sd * sv], [rho * sd * sv, sv * sv]];
            out.push(([600.0 * next(), 200.0 * next() - 100.0], cov));
        }
        out
    }

    fn gaussian(mean: &Mean, cov: &Cov) -> Gaussian {
        Gaussian::new(Col::from_fn(2, |i| mean[i]), Mat::from_fn(2, 2, |i, j| cov[i][j])).expect("SPD prior")
    }

    #[test]
    fn prediction_is_the_generic_predictors_bit_for_bit() {
        let sigma = 0.3;
        let predictor = KalmanPredictor::new(ConstantVelocity::new(1, sigma).expect("valid"));
        for dt_s in [0.0, 717e-6, 6.415e-3] {
            let (f, q) = transition(sigma, dt_s).expect("valid step");
            for (mean, cov) in priors() {
                let (m, p) = Filter::predict_one(&mean, &cov, &f, &q).expect("SPD");
                let want = predictor.predict(&gaussian(&mean, &cov), dt_s).expect("SPD");
                assert_eq!(m, [want.mean()[0], want.mean()[1]], "dt {dt_s}");
                assert_eq!(p, [[want.cov()[(0, 0)], want.cov()[(0, 1)]], [want.cov()[(1, 0)], want.cov()[(1, 1)]]]);
            }
        }
    }

    #[test]
    fn prepared_update_is_the_generic_updaters_bit_for_bit() {
        let sigma_m = 3e-3;
        let updater = KalmanUpdater::new(LinearMeasurement::position(1, sigma_m).expect("valid"));
        for (mean, cov) in priors() {
            let prep = Filter::prepare(&mean, &cov, sigma_m * sigma_m).expect("SPD");
            let want = updater.prepare(&gaussian(&mean, &cov)).expect("SPD");
            assert_eq!(prep.eta, want.predicted_measurement()[0]);
            assert_eq!(prep.gain, [want.gain()[(0, 0)], want.gain()[(1, 0)]]);
            let p = want.posterior_cov();
            assert_eq!(prep.posterior_cov, [[p[(0, 0)], p[(0, 1)]], [p[(1, 0)], p[(1, 1)]]]);
            // ln N(z; eta, S) at a measurement 2 mm off, through l and ln det S.
            let z = prep.eta + 2e-3;
            let y = (z - prep.eta) / prep.l;
            let log_q = -0.5 * (1.0 * (2.0 * std::f64::consts::PI).ln() + prep.log_det_s + (0.0 + y * y));
            assert_eq!(log_q, want.log_likelihood(&Col::full(1, z)).expect("finite"));
        }
    }

    #[test]
    fn merge_factor_and_definiteness() {
        // [[4, 2], [2, 10]] = L L^T with L = [[2, 0], [1, 3]]: exact in binary.
        assert_eq!(cholesky_2x2(&[[4.0, 2.0], [2.0, 10.0]]), Some([2.0, 1.0, 3.0]));
        assert_eq!(cholesky_2x2(&[[1.0, 2.0], [2.0, 1.0]]), None);
        assert!(is_positive_definite(&[[4.0, 2.0], [2.0, 10.0]]));
        assert!(!is_positive_definite(&[[1.0, 2.0], [2.0, 1.0]]));
        assert!(!is_positive_definite(&[[f64::NAN, 0.0], [0.0, 1.0]]));
        // d = L [1, 1]^T = [2, 4]: y = [1, 1], d^T P^-1 d = 2.
        assert_eq!(mahalanobis_squared_2(&[2.0, 1.0, 3.0], [2.0, 4.0]), 2.0);
        assert!(matches!(
            checked_spd("P", [[1.0, 0.5], [0.0, 1.0]]),
            Err(FilterError::NotPositiveDefinite { what: "P" })
        ));
    }
}
