//! Small deterministic helpers shared by the tests.

use mmtrack_filter::faer::{Col, ColRef, Mat, MatRef};

/// Column vector from a slice.
pub fn v(xs: &[f64]) -> Col<f64> {
    ColRef::from_slice(xs).to_owned()
}

/// Row-major matrix.
pub fn m(rows: usize, cols: usize, xs: &[f64]) -> Mat<f64> {
    MatRef::from_row_major_slice(xs, rows, cols).to_owned()
}

/// Deterministic standard-normal samples (64-bit LCG + Box-Muller), so the
/// scenario tests do not depend on a random-number crate or its versions.
pub struct Normal {
    state: u64,
}

impl Normal {
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    fn uniform(&mut self) -> f64 {
        self.state = self.state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        // 53 high bits -> (0, 1).
        ((self.state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    pub fn sample(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        mmtrack_core::random::box_muller(u1, u2).0
    }
}
