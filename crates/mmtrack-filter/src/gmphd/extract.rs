//! Multi-target state extraction, Vo & Ma 2006 Table III, with labels.
//!
//! Table III emits the mean of every component with `w_i > 0.5`,
//! `round(w_i)` times. Here the threshold is a parameter (Mahler et al. 2017,
//! Table I, use 0.2), and a component above it is emitted
//! `max(1, round(w_i))` times: with a threshold below 0.5, plain `round`
//! would emit nothing for `threshold < w_i < 0.5` and make the threshold
//! meaningless.
//!
//! Labels (see the parent module): extracted components that share a label
//! are ordered by weight (ties: mixture order); the heaviest keeps the label,
//! every other one gets a fresh label, written back into the mixture so that
//! it continues as its own track. The 2nd, 3rd, ... copies of one component
//! (`round(w_i) >= 2`: several targets under one Gaussian) also get fresh
//! labels, but these cannot be written back (the component has one label) and
//! so last one step.

use std::collections::BTreeMap;

use super::Component;
use crate::error::{FilterError, ensure_in_range};
use crate::gaussian::Gaussian;
use crate::label::Label;

/// Upper bound on the copies one component yields (`round(w)` beyond it
/// would only come from a nonsensical birth weight; it keeps memory bounded).
pub const MAX_COPIES_PER_COMPONENT: usize = 1024;

/// One extracted target state.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Track label.
    pub label: Label,
    /// Weight of the component it came from.
    pub weight: f64,
    /// The component's Gaussian (mean = the state estimate).
    pub density: Gaussian,
    /// The measurement that produced the component (see
    /// [`Component::measurement`]): after merging, the one with the largest
    /// association weight among the merged members.
    pub measurement: Option<usize>,
}

/// The state-extraction role.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateExtractor {
    weight_threshold: f64,
}

impl StateExtractor {
    /// Extracts components with `w > weight_threshold` (`>= 0`, finite).
    ///
    /// # Errors
    /// [`FilterError::InvalidParameter`] for a negative or non-finite threshold.
    pub fn new(weight_threshold: f64) -> Result<Self, FilterError> {
        ensure_in_range("extraction weight threshold", weight_threshold, 0.0, f64::MAX, "finite and >= 0")?;
        Ok(Self { weight_threshold })
    }

    /// The weight threshold.
    #[must_use]
    pub fn weight_threshold(&self) -> f64 {
        self.weight_threshold
    }

    /// Extracts the estimates of `mixture`, relabelling duplicates in place;
    /// `fresh` hands out new labels. Estimates are sorted by label.
    pub fn extract(&self, mixture: &mut [Component], fresh: &mut dyn FnMut() -> Label) -> Vec<Estimate> {
        // Extracted component indices grouped by label, in mixture order.
        let mut by_label: BTreeMap<Label, Vec<usize>> = BTreeMap::new();
        for (i, c) in mixture.iter().enumerate() {
            if c.weight > self.weight_threshold {
                by_label.entry(c.label).or_default().push(i);
            }
        }
        let mut estimates = Vec::new();
        for (_, mut members) in by_label {
            // Stable: equal weights keep mixture order.
            members.sort_by(|&a, &b| mixture[b].weight.total_cmp(&mixture[a].weight));
            for (rank, &i) in members.iter().enumerate() {
                if rank > 0 {
                    mixture[i].label = fresh();
                }
                let c = &mixture[i];
                let copies = (c.weight.round().min(MAX_COPIES_PER_COMPONENT as f64) as usize).max(1);
                estimates.push(Estimate {
                    label: c.label,
                    weight: c.weight,
                    density: c.density.clone(),
                    measurement: c.measurement,
                });
                for _ in 1..copies {
                    estimates.push(Estimate {
                        label: fresh(),
                        weight: c.weight,
                        density: c.density.clone(),
                        measurement: c.measurement,
                    });
                }
            }
        }
        estimates.sort_by_key(|e| e.label);
        estimates
    }
}
