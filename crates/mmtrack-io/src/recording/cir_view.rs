//! The display view of a channel-impulse-response recording: a delay x time
//! image (`/viz/cir`, mono8 `foxglove.RawImage`) that Foxglove's image panel
//! shows as a scrolling power-delay-profile waterfall. The snapshots on
//! `/channel/cir` stay the canonical data; nothing reads this view back.
//!
//! One row per snapshot set: the set's power delay profile, the mean of
//! `|h(tau)|^2` over its snapshots (every antenna pair), in dB. Columns are
//! delay taps, at most [`MAX_COLUMNS`]: with more taps, each column holds the
//! largest power of [`CirWaterfall::taps_per_column`] neighbouring taps (a
//! peak is never averaged away). An image is written when a set is complete,
//! holding the last [`ROWS`] sets, the newest at the bottom; its grey levels
//! span [`DYNAMIC_RANGE_DB`] below the image's strongest tap (255 = that tap,
//! 0 = that far below it or weaker). A change in tap count starts a new
//! history.

use std::collections::VecDeque;

/// Sets shown per image (rows).
pub const ROWS: usize = 64;
/// Largest image width, columns.
pub const MAX_COLUMNS: usize = 256;
/// Grey levels span this many dB below the image's strongest tap.
pub const DYNAMIC_RANGE_DB: f64 = 60.0;

/// One image of the waterfall.
#[derive(Debug, Clone, PartialEq)]
pub struct WaterfallImage {
    /// Columns.
    pub width: u32,
    /// Rows (sets shown, up to [`ROWS`]).
    pub height: u32,
    /// Grey levels, row-major.
    pub pixels: Vec<u8>,
}

/// The rows so far and the set being summed.
#[derive(Debug, Clone, Default)]
pub struct CirWaterfall {
    /// Power delay profiles of the last sets, dB per column (`-inf` for 0).
    rows: VecDeque<Vec<f64>>,
    /// Set index, snapshot count and summed `|h|^2` per tap of the set being read.
    current: Option<(u64, usize, Vec<f64>)>,
}

impl CirWaterfall {
    /// Taps per column for `taps` taps.
    #[must_use]
    pub fn taps_per_column(taps: usize) -> usize {
        taps.div_ceil(MAX_COLUMNS).max(1)
    }

    /// Adds one snapshot's `|h|^2` per tap. Returns the image of the
    /// previous set when this snapshot starts a new one.
    pub fn add(&mut self, set_index: u64, power: impl ExactSizeIterator<Item = f64>) -> Option<WaterfallImage> {
        let taps = power.len();
        let finished = match &self.current {
            Some((set, _, sum)) if *set != set_index || sum.len() != taps => self.finish_set(),
            _ => None,
        };
        let (_, count, sum) = self.current.get_or_insert_with(|| (set_index, 0, vec![0.0; taps]));
        *count += 1;
        for (s, p) in sum.iter_mut().zip(power) {
            *s += p;
        }
        finished
    }

    /// Completes the set being read (at the end of the recording); its image.
    pub fn finish_set(&mut self) -> Option<WaterfallImage> {
        let (_, count, sum) = self.current.take()?;
        let per_column = Self::taps_per_column(sum.len());
        #[allow(clippy::cast_precision_loss)]
        let row: Vec<f64> = sum
            .chunks(per_column)
            .map(|c| 10.0 * (c.iter().copied().fold(0.0, f64::max) / count as f64).log10())
            .collect();
        if self.rows.back().is_some_and(|last| last.len() != row.len()) {
            self.rows.clear();
        }
        if self.rows.len() == ROWS {
            self.rows.pop_front();
        }
        self.rows.push_back(row);
        Some(self.image())
    }

    fn image(&self) -> WaterfallImage {
        let width = self.rows.back().map_or(0, Vec::len);
        let peak_db = self.rows.iter().flatten().copied().fold(f64::NEG_INFINITY, f64::max);
        let pixels = self
            .rows
            .iter()
            .flatten()
            .map(|&db| {
                let level = (db - (peak_db - DYNAMIC_RANGE_DB)) / DYNAMIC_RANGE_DB;
                // NaN (an all-zero image) and below the range are 0.
                #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
                if level > 0.0 { (255.0 * level.min(1.0)).round() as u8 } else { 0 }
            })
            .collect();
        #[allow(clippy::cast_possible_truncation)]
        WaterfallImage { width: width as u32, height: self.rows.len() as u32, pixels }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_set_means_in_db_scaled_to_the_strongest_tap() {
        let mut w = CirWaterfall::default();
        // Set 0: two snapshots, tap 1 at |h|^2 = 1 and 3 (mean 2), tap 0 at 2e-3 (mean: 30 dB down).
        assert!(w.add(0, [2e-3, 1.0].into_iter()).is_none());
        assert!(w.add(0, [2e-3, 3.0].into_iter()).is_none());
        // Set 1 starts: set 0's image.
        let image = w.add(1, [0.0, 2e-6].into_iter()).unwrap();
        assert_eq!((image.width, image.height), (2, 1));
        // 30 dB below the peak in a 60 dB range: 127.5 -> 128.
        assert_eq!(image.pixels, [128, 255]);
        // Set 1 (60 dB down, and a zero tap) below set 0, the newest at the bottom.
        let image = w.finish_set().unwrap();
        assert_eq!((image.width, image.height), (2, 2));
        assert_eq!(image.pixels, [128, 255, 0, 0]);
        assert!(w.finish_set().is_none());
    }

    #[test]
    fn wide_profiles_keep_each_column_peak_and_history_is_bounded() {
        let taps = 1000;
        assert_eq!(CirWaterfall::taps_per_column(taps), 4);
        let mut w = CirWaterfall::default();
        let mut last = None;
        for set in 0..(ROWS as u64 + 10) {
            let power = (0..taps).map(|t| if t == 999 { 1.0 } else { 1e-9 });
            if let Some(image) = w.add(set, power) {
                last = Some(image);
            }
        }
        let image = last.unwrap();
        assert_eq!((image.width, image.height), (250, ROWS as u32));
        // Tap 999 alone in the last column of every row.
        assert!(image.pixels.chunks(250).all(|row| row[249] == 255 && row[..249].iter().all(|&v| v == 0)));
        // A new tap count starts a new history.
        w.add(1000, [1.0; 8].into_iter());
        let image = w.finish_set().unwrap();
        assert_eq!((image.width, image.height), (8, 1));
    }
}
