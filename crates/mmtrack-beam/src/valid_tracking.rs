//! The valid-tracking metric of Shaham et al. 2020 (Sec. IV-B, after Va et
//! al. 2016): over Monte Carlo runs, the RMS angle error per block
//! `sqrt(E[|phi[k] - phi_bar[k]|^2])`, and the number of blocks before it
//! first exceeds half the beamwidth.

/// Accumulates squared errors per block over runs, in the order they are
/// added (so a sum over runs added in run order is deterministic).
#[derive(Debug, Clone, PartialEq)]
pub struct RmsPerBlock {
    sum_squared: Vec<f64>,
    runs: usize,
}

impl RmsPerBlock {
    /// An empty accumulator for `blocks` blocks.
    #[must_use]
    pub fn new(blocks: usize) -> Self {
        Self { sum_squared: vec![0.0; blocks], runs: 0 }
    }

    /// Adds one run's errors (radians; block `k` at index `k`); values
    /// beyond the accumulator's length are ignored.
    pub fn add_run(&mut self, errors_rad: &[f64]) {
        for (sum, e) in self.sum_squared.iter_mut().zip(errors_rad) {
            *sum += e * e;
        }
        self.runs += 1;
    }

    /// Adds another accumulator's runs (same block count; extra blocks of
    /// `other` are ignored). Merging partial sums in a fixed order keeps a
    /// parallel Monte Carlo run deterministic.
    pub fn merge(&mut self, other: &RmsPerBlock) {
        for (sum, s) in self.sum_squared.iter_mut().zip(&other.sum_squared) {
            *sum += s;
        }
        self.runs += other.runs;
    }

    /// Runs added.
    #[must_use]
    pub fn runs(&self) -> usize {
        self.runs
    }

    /// RMS error per block, radians (NaN before any run).
    #[must_use]
    pub fn rms_rad(&self) -> Vec<f64> {
        self.sum_squared.iter().map(|s| (s / self.runs as f64).sqrt()).collect()
    }
}

/// Blocks of valid tracking: the index of the first block whose RMS error
/// exceeds `threshold_rad` (blocks `1..` are the tracked ones; block 0 is
/// the channel estimate), or `None` when it never does.
#[must_use]
pub fn valid_tracking_blocks(rms_rad: &[f64], threshold_rad: f64) -> Option<usize> {
    rms_rad.iter().position(|&e| e.is_nan() || e > threshold_rad)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rms_and_first_crossing() {
        let mut acc = RmsPerBlock::new(4);
        acc.add_run(&[0.0, 1.0, 2.0, 3.0]);
        acc.add_run(&[0.0, -1.0, 0.0, 5.0]);
        let rms = acc.rms_rad();
        assert_eq!(rms, vec![0.0, 1.0, 2f64.sqrt(), 17f64.sqrt()]);
        assert_eq!(valid_tracking_blocks(&rms, 1.2), Some(2));
        assert_eq!(valid_tracking_blocks(&rms, 10.0), None);
        // A NaN error (a diverged run) ends valid tracking.
        assert_eq!(valid_tracking_blocks(&[0.1, f64::NAN], 1.0), Some(1));
    }
}
