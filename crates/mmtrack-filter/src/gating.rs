//! Gating: which measurement may update which prediction.
//!
//! The gate role is a small trait, [`Gate`], consulted for every
//! (component, measurement) pair before the pair's likelihood is computed. A
//! pair the gate rejects contributes nothing (its likelihood is taken as 0),
//! which is how the GM-PHD baseline of Mahler et al. 2017 applies its "maximum
//! delay / magnitude change" limits.

use faer::Col;

use crate::error::{FilterError, ensure_positive};
use crate::gaussian::Gaussian;
use crate::label::Label;

/// One (prediction, measurement) pair put to a [`Gate`].
#[derive(Debug, Clone, Copy)]
pub struct GateCandidate<'a> {
    /// Label of the predicted component.
    pub label: Label,
    /// The predicted component's density.
    pub prior: &'a Gaussian,
    /// Index of the measurement in the step's measurement set.
    pub measurement_index: usize,
    /// The measurement `z`.
    pub measurement: &'a Col<f64>,
    /// Innovation `z - H m`.
    pub innovation: &'a Col<f64>,
    /// Squared Mahalanobis distance `nu^T S^-1 nu`.
    pub mahalanobis_squared: f64,
}

/// The gating role.
pub trait Gate {
    /// Whether the measurement may update the prediction.
    fn admits(&self, candidate: &GateCandidate<'_>) -> bool;
}

/// Admits every pair (the plain GM-PHD of Vo & Ma 2006).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct NoGate;

impl Gate for NoGate {
    fn admits(&self, _candidate: &GateCandidate<'_>) -> bool {
        true
    }
}

/// Ellipsoidal gate: admits `nu^T S^-1 nu <= threshold`.
///
/// Under the model the statistic is chi-square with `m` (measurement
/// dimension) degrees of freedom; the 0.99 quantiles are 6.635 (m = 1), 9.210
/// (m = 2), 11.345 (m = 3), so those thresholds keep 99 % of true pairs.
///
/// # References
/// Y. Bar-Shalom, X. R. Li, T. Kirubarajan, *Estimation with Applications to
/// Tracking and Navigation*, 2001, Sec. 5.4.2 (validation region).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MahalanobisGate {
    threshold: f64,
}

impl MahalanobisGate {
    /// A gate at squared distance `threshold > 0`.
    ///
    /// # Errors
    /// [`FilterError::InvalidParameter`] for a non-positive or non-finite threshold.
    pub fn new(threshold: f64) -> Result<Self, FilterError> {
        ensure_positive("gate threshold (squared Mahalanobis distance)", threshold)?;
        Ok(Self { threshold })
    }

    /// The threshold on the squared distance.
    #[must_use]
    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    /// Whether a squared distance falls inside the gate (NaN never does).
    #[must_use]
    pub fn admits_distance(&self, mahalanobis_squared: f64) -> bool {
        mahalanobis_squared <= self.threshold
    }
}

impl Gate for MahalanobisGate {
    fn admits(&self, candidate: &GateCandidate<'_>) -> bool {
        self.admits_distance(candidate.mahalanobis_squared)
    }
}

/// Both gates must admit.
impl<A: Gate, B: Gate> Gate for (A, B) {
    fn admits(&self, candidate: &GateCandidate<'_>) -> bool {
        self.0.admits(candidate) && self.1.admits(candidate)
    }
}
