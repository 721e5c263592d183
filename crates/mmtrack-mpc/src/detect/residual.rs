//! The residual correlation of search and subtract on the tap grid, with the
//! blocked delay ranges and the strongest unblocked tap of each block of 64
//! taps kept up to date, so finding the next peak reads `U / 64` maxima.

use mmtrack_core::Complex64;

/// Taps per block of the running maxima.
const BLOCK_TAPS: usize = 64;

/// Residual correlation `c[n]` and blocked taps.
pub(super) struct Residual {
    correlation: Vec<Complex64>,
    blocked: Vec<bool>,
    /// Per block: `|c|^2` and tap of its strongest unblocked tap (`None`
    /// when the whole block is blocked).
    best: Vec<Option<(f64, usize)>>,
}

impl Residual {
    pub(super) fn new(correlation: Vec<Complex64>) -> Self {
        let taps = correlation.len();
        let mut residual =
            Self { correlation, blocked: vec![false; taps], best: vec![None; taps.div_ceil(BLOCK_TAPS)] };
        residual.rescan(0, taps);
        residual
    }

    pub(super) fn correlation_mut(&mut self) -> &mut [Complex64] {
        &mut self.correlation
    }

    pub(super) fn correlation(&self) -> &[Complex64] {
        &self.correlation
    }

    /// The strongest unblocked tap.
    pub(super) fn strongest(&self) -> Option<usize> {
        self.best
            .iter()
            .flatten()
            .fold(None, |best: Option<(f64, usize)>, &(p, n)| match best {
                Some((q, _)) if q >= p => best,
                _ => Some((p, n)),
            })
            .map(|(_, n)| n)
    }

    /// Marks the taps within `half_width_taps` of `delay_taps` (circularly)
    /// as blocked; returns the first tap and the count marked.
    pub(super) fn block(&mut self, delay_taps: f64, half_width_taps: f64) -> (usize, usize) {
        let taps = self.blocked.len() as i64;
        let first = (delay_taps - half_width_taps).ceil() as i64;
        let last = ((delay_taps + half_width_taps).floor() as i64).min(first + taps - 1);
        for n in first..=last {
            self.blocked[n.rem_euclid(taps) as usize] = true;
        }
        (first.rem_euclid(taps) as usize, (last - first + 1).max(0) as usize)
    }

    /// Whether the circular tap range `outer` (first, count) holds `inner`.
    pub(super) fn covers(&self, outer: (usize, usize), inner: (usize, usize)) -> bool {
        let offset = (inner.0 + self.correlation.len() - outer.0) % self.correlation.len();
        outer.1 >= self.correlation.len() || offset + inner.1 <= outer.1
    }

    /// Recomputes the block maxima of the blocks holding taps
    /// `first .. first + count` (circularly).
    pub(super) fn rescan(&mut self, first: usize, count: usize) {
        if count == 0 {
            return;
        }
        let blocks = self.best.len();
        let (first_block, last_block) = (first / BLOCK_TAPS, (first + count - 1) / BLOCK_TAPS);
        for b in first_block..=last_block.min(first_block + blocks - 1) {
            let b = b % blocks;
            let start = b * BLOCK_TAPS;
            let end = (start + BLOCK_TAPS).min(self.correlation.len());
            // The first unblocked tap of the largest `|c|^2` (never negative:
            // a blocked tap's -1 is never chosen).
            let (mut best_power, mut best_tap) = (-1.0, start);
            for (n, (c, blocked)) in self.correlation[start..end].iter().zip(&self.blocked[start..end]).enumerate() {
                let p = if *blocked { -1.0 } else { c.norm_sqr() };
                if p > best_power {
                    (best_power, best_tap) = (p, start + n);
                }
            }
            self.best[b] = (best_power >= 0.0).then_some((best_power, best_tap));
        }
    }
}
