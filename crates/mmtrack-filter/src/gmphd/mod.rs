//! The Gaussian-mixture probability hypothesis density (GM-PHD) filter of
//! Vo & Ma 2006, with labels so that the extracted states form tracks.
//!
//! The PHD (intensity) `v(x)` of the multi-target state is a weighted sum of
//! Gaussians, `v(x) = sum_i w_i N(x; m_i, P_i)`; its integral `sum_i w_i` is the
//! expected number of targets. One step of the filter is
//!
//! 1. **prediction** (Table I, steps 1-3): every component survives with
//!    probability `p_S` and moves with the linear-Gaussian motion model,
//!    `w <- p_S w`, `(m, P) <- (F m, F P F^T + Q)`; the birth intensity
//!    `gamma_k(x) = sum_b w_b N(x; m_b, P_b)`, supplied by the caller at every
//!    step (so it may be built from the previous measurements: measurement-
//!    driven birth), is appended as is;
//! 2. **update** (Table I, step 4): with detection probability `p_D`, clutter
//!    intensity `kappa` and measurements `Z`,
//!    `v(x) = (1 - p_D) v_pred(x) + sum_{z in Z} sum_i w_i(z) N(x; m_i(z), P_i)`,
//!    `w_i(z) = p_D w_i q_i(z) / (kappa(z) + p_D sum_l w_l q_l(z))`,
//!    `q_i(z) = N(z; H m_i, H P_i H^T + R)` ([`GmPhdFilter::update`]);
//! 3. **pruning and merging** (Table II) with truncation threshold `T`, merge
//!    threshold `U` and at most `J_max` components ([`MixtureReducer`]);
//! 4. **state extraction** (Table III) of the components above a weight
//!    threshold ([`StateExtractor`]).
//!
//! The roles (predictor, updater, gate, reducer, extractor) are separate values
//! held by [`GmPhdFilter`], as in Stone Soup's `PointProcessMultiTargetTracker`.
//!
//! # Labelling rule
//! Every component carries a [`Label`]:
//! - a component inherits its parent's label through prediction and update
//!   (the missed-detection copy and every measurement-updated copy);
//! - birth components get fresh labels when they enter the mixture;
//! - on merging, the merged component takes the label of the heaviest member
//!   (the one that started the merge group, Table II's `j = argmax w`);
//! - on extraction, if two extracted components share a label, the heavier
//!   keeps it and the other receives a fresh label, written back into the
//!   mixture so that it continues as its own track.
//!
//! Extracted states with the same label at successive steps form a track.
//!
//! # References
//! B.-N. Vo and W.-K. Ma, "The Gaussian mixture probability hypothesis density
//! filter", IEEE Trans. Signal Processing 54(11), 4091-4104, 2006: Table I
//! (prediction and update), Table II (pruning and merging), Table III (state
//! extraction). The labelling follows D. E. Clark, K. Panta, B.-N. Vo, "The
//! GM-PHD filter multiple target tracker", FUSION 2006 (tags carried by
//! components) as realised in Stone Soup.

mod extract;
mod reduce;
mod update;

pub use extract::{Estimate, MAX_COPIES_PER_COMPONENT, StateExtractor};
pub use reduce::{MixtureReducer, ReductionReport};
pub use update::{Association, UpdateReport};

use crate::error::{FilterError, ensure_in_range, ensure_len};
use crate::gating::Gate;
use crate::gaussian::Gaussian;
use crate::kalman::{KalmanPredictor, KalmanUpdater};
use crate::label::Label;
use crate::models::TransitionModel;
use faer::Col;

/// One weighted Gaussian of the intensity, with its label.
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    /// Label of the lineage.
    pub label: Label,
    /// Weight `w >= 0` (expected number of targets the component stands for).
    pub weight: f64,
    /// The Gaussian `N(m, P)`.
    pub density: Gaussian,
    /// Index (in the last update's measurement set) of the measurement that
    /// produced this component; `None` for predicted, birth and
    /// missed-detection components. Merging keeps the heaviest member's.
    pub measurement: Option<usize>,
}

/// An unlabelled weighted Gaussian: a term of the birth intensity.
#[derive(Debug, Clone, PartialEq)]
pub struct WeightedGaussian {
    /// Weight `w_b >= 0` (expected number of births the term stands for).
    pub weight: f64,
    /// The Gaussian `N(m_b, P_b)`, already at the time of the step.
    pub density: Gaussian,
}

/// The scalar parameters of the multi-target model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GmPhdParams {
    /// Survival probability `p_S` in `[0, 1]` (Vo & Ma eq. 19).
    pub p_survival: f64,
    /// Detection probability `p_D` in `[0, 1]` (Vo & Ma eq. 20).
    pub p_detection: f64,
    /// Clutter intensity `kappa >= 0`, uniform over the measurement space, in
    /// expected false measurements per unit measurement volume (Vo & Ma eq. 21
    /// with a constant `kappa(z)`).
    pub clutter_intensity: f64,
}

impl GmPhdParams {
    /// Checks the ranges.
    ///
    /// # Errors
    /// [`FilterError::InvalidParameter`] naming the bad parameter.
    pub fn validate(&self) -> Result<(), FilterError> {
        ensure_in_range("p_survival", self.p_survival, 0.0, 1.0, "a probability in [0, 1]")?;
        ensure_in_range("p_detection", self.p_detection, 0.0, 1.0, "a probability in [0, 1]")?;
        ensure_in_range("clutter_intensity", self.clutter_intensity, 0.0, f64::MAX, "finite and >= 0")
    }
}

/// What one call of [`GmPhdFilter::step`] produced.
#[derive(Debug, Clone, PartialEq)]
pub struct StepReport {
    /// Labels given to the birth terms, in their order.
    pub birth_labels: Vec<Label>,
    /// Measurement-to-label association weights of the update.
    pub update: UpdateReport,
    /// What pruning and merging did.
    pub reduction: ReductionReport,
    /// Extracted states, sorted by label.
    pub estimates: Vec<Estimate>,
}

/// A labelled GM-PHD filter for a linear-Gaussian motion model `T`.
#[derive(Debug, Clone)]
pub struct GmPhdFilter<T> {
    predictor: KalmanPredictor<T>,
    updater: KalmanUpdater,
    params: GmPhdParams,
    reducer: MixtureReducer,
    extractor: StateExtractor,
    mixture: Vec<Component>,
    next_label: u64,
}

impl<T: TransitionModel> GmPhdFilter<T> {
    /// An empty filter (no components) assembled from its roles.
    ///
    /// # Errors
    /// [`FilterError::InvalidParameter`] for bad parameters,
    /// [`FilterError::DimensionMismatch`] if the motion and measurement models
    /// disagree on the state dimension.
    pub fn new(
        predictor: KalmanPredictor<T>,
        updater: KalmanUpdater,
        params: GmPhdParams,
        reducer: MixtureReducer,
        extractor: StateExtractor,
    ) -> Result<Self, FilterError> {
        params.validate()?;
        let n = predictor.model.state_dim();
        if updater.model.state_dim() != n {
            return Err(FilterError::DimensionMismatch {
                what: "measurement matrix H (columns = motion model state dimension)",
                expected_rows: updater.model.measurement_dim(),
                expected_cols: n,
                found_rows: updater.model.measurement_dim(),
                found_cols: updater.model.state_dim(),
            });
        }
        Ok(Self { predictor, updater, params, reducer, extractor, mixture: Vec::new(), next_label: 0 })
    }

    /// The current mixture.
    #[must_use]
    pub fn mixture(&self) -> &[Component] {
        &self.mixture
    }

    /// State dimension.
    #[must_use]
    pub fn state_dim(&self) -> usize {
        self.predictor.model.state_dim()
    }

    /// Expected number of targets `N = sum_i w_i` (Vo & Ma, eq. 13 / Table III).
    #[must_use]
    pub fn expected_cardinality(&self) -> f64 {
        self.mixture.iter().map(|c| c.weight).sum()
    }

    /// The model parameters.
    #[must_use]
    pub fn params(&self) -> &GmPhdParams {
        &self.params
    }

    /// The updater role (its measurement model is what births are built against).
    #[must_use]
    pub fn updater(&self) -> &KalmanUpdater {
        &self.updater
    }

    /// The predictor role.
    #[must_use]
    pub fn predictor(&self) -> &KalmanPredictor<T> {
        &self.predictor
    }

    fn fresh_label(&mut self) -> Label {
        let l = Label(self.next_label);
        self.next_label += 1;
        l
    }

    /// Prediction (Table I, steps 1-3) over `dt_s` seconds, then appends the
    /// birth terms with fresh labels. Returns those labels in order.
    ///
    /// # Errors
    /// [`FilterError::Birth`] for a birth term of the wrong dimension or with a
    /// negative / non-finite weight (checked before anything changes); the
    /// motion model's errors for a bad `dt_s`. On error the mixture is unchanged.
    pub fn predict(&mut self, dt_s: f64, births: Vec<WeightedGaussian>) -> Result<Vec<Label>, FilterError> {
        let n = self.state_dim();
        for (index, b) in births.iter().enumerate() {
            let wrap = |e: FilterError| FilterError::Birth { index, source: Box::new(e) };
            ensure_len("birth mean", b.density.mean(), n).map_err(wrap)?;
            ensure_in_range("birth weight", b.weight, 0.0, f64::MAX, "finite and >= 0").map_err(wrap)?;
        }
        let densities = self.predictor.predict_each(self.mixture.iter().map(|c| &c.density), dt_s)?;
        let mut predicted = Vec::with_capacity(self.mixture.len() + births.len());
        for (c, density) in self.mixture.iter().zip(densities) {
            predicted.push(Component {
                label: c.label,
                weight: self.params.p_survival * c.weight,
                density,
                measurement: None,
            });
        }
        let mut labels = Vec::with_capacity(births.len());
        self.mixture = predicted;
        for b in births {
            let label = self.fresh_label();
            labels.push(label);
            self.mixture.push(Component { label, weight: b.weight, density: b.density, measurement: None });
        }
        Ok(labels)
    }

    /// Update with the measurements of one step (Table I, step 4); pairs the
    /// `gate` rejects have likelihood 0.
    ///
    /// # Errors
    /// [`FilterError::Measurement`] for a measurement of the wrong dimension or
    /// with NaN (checked before anything changes); [`FilterError::NotPositiveDefinite`]
    /// if an innovation covariance is not SPD. On error the mixture is unchanged.
    pub fn update<G: Gate>(&mut self, measurements: &[Col<f64>], gate: &G) -> Result<UpdateReport, FilterError> {
        let (mixture, report) = update::update(&self.mixture, measurements, &self.updater, &self.params, gate)?;
        self.mixture = mixture;
        Ok(report)
    }

    /// Pruning and merging (Table II).
    ///
    /// # Errors
    /// [`FilterError::NotPositiveDefinite`] if a covariance cannot be factorised
    /// (not expected for mixtures built by this filter). On error the mixture
    /// is unchanged.
    pub fn reduce(&mut self) -> Result<ReductionReport, FilterError> {
        let (mixture, report) = self.reducer.reduce(&self.mixture)?;
        self.mixture = mixture;
        Ok(report)
    }

    /// State extraction (Table III) with the labelling rule of the module docs;
    /// estimates sorted by label.
    pub fn extract(&mut self) -> Vec<Estimate> {
        let mut next = self.next_label;
        let estimates = self.extractor.extract(&mut self.mixture, &mut || {
            let l = Label(next);
            next += 1;
            l
        });
        self.next_label = next;
        estimates
    }

    /// One full step: predict over `dt_s` with `births`, update with
    /// `measurements` through `gate`, reduce, extract.
    ///
    /// # Errors
    /// As the four stages. Inputs are checked before the mixture changes.
    pub fn step<G: Gate>(
        &mut self,
        dt_s: f64,
        births: Vec<WeightedGaussian>,
        measurements: &[Col<f64>],
        gate: &G,
    ) -> Result<StepReport, FilterError> {
        update::check_measurements(measurements, self.updater.model.measurement_dim())?;
        let saved = (self.mixture.clone(), self.next_label);
        let result = (|| {
            let birth_labels = self.predict(dt_s, births)?;
            let update = self.update(measurements, gate)?;
            let reduction = self.reduce()?;
            Ok(StepReport { birth_labels, update, reduction, estimates: self.extract() })
        })();
        if result.is_err() {
            (self.mixture, self.next_label) = saved;
        }
        result
    }
}
