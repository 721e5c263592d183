//! Beam selection and measurement accounting (Zoechmann et al. 2019, Sec.
//! VI): the receiver scans the whole codebook for the first 10 epochs; after
//! that it projects the azimuth to the next epoch (11) and measures only the
//! 3 codebook beams nearest to it, "a factor 128 / 3 = 43" fewer
//! measurements per epoch. [`BeamCount`] counts what was measured, so the
//! saving is measured rather than assumed.

use mmtrack_core::array_uca::nearest_circular_beams;

/// Which beams to measure at an epoch.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BeamSelection {
    /// Every beam of the codebook.
    FullScan,
    /// Only these beams (nearest the projected azimuth first).
    Window(Vec<usize>),
}

/// The schedule of Sec. VI over a circular codebook of `beams` beams steered
/// to `2 pi j / beams`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BeamSchedule {
    /// Beams of the codebook (128).
    pub beams: usize,
    /// Epochs scanned in full before projecting (10).
    pub full_scan_epochs: usize,
    /// Beams measured around the projected azimuth afterwards (3).
    pub window_beams: usize,
}

impl BeamSchedule {
    /// The paper's schedule for a codebook of `beams` beams: 10 full scans,
    /// then 3 beams.
    #[must_use]
    pub fn paper(beams: usize) -> Self {
        Self { beams, full_scan_epochs: 10, window_beams: 3 }
    }

    /// The beams to measure at `epoch` (0-based) given the azimuth the
    /// tracker projects to that epoch; a full scan during the first
    /// `full_scan_epochs` epochs or without a finite projection.
    #[must_use]
    pub fn select(&self, epoch: usize, projected_azimuth_rad: Option<f64>) -> BeamSelection {
        match projected_azimuth_rad {
            Some(azimuth) if epoch >= self.full_scan_epochs && azimuth.is_finite() && self.window_beams > 0 => {
                BeamSelection::Window(nearest_circular_beams(self.beams, azimuth, self.window_beams))
            }
            _ => BeamSelection::FullScan,
        }
    }
}

/// Beam measurements counted over epochs (and summed over runs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BeamCount {
    /// Epochs counted.
    pub epochs: u64,
    /// Epochs with a full scan.
    pub full_scans: u64,
    /// Beams measured.
    pub measured: u64,
    /// Beams a full scan at every epoch would have measured.
    pub full_scan_equivalent: u64,
}

impl BeamCount {
    /// Counts one epoch's selection over a codebook of `beams` beams.
    pub fn add(&mut self, selection: &BeamSelection, beams: usize) {
        self.epochs += 1;
        self.full_scan_equivalent += beams as u64;
        match selection {
            BeamSelection::FullScan => {
                self.full_scans += 1;
                self.measured += beams as u64;
            }
            BeamSelection::Window(window) => self.measured += window.len() as u64,
        }
    }

    /// Adds another count.
    pub fn merge(&mut self, other: &BeamCount) {
        self.epochs += other.epochs;
        self.full_scans += other.full_scans;
        self.measured += other.measured;
        self.full_scan_equivalent += other.full_scan_equivalent;
    }

    /// Full-scan measurements over measured ones (the saving factor); `None`
    /// before anything was measured.
    #[must_use]
    pub fn saving(&self) -> Option<f64> {
        (self.measured > 0).then(|| self.full_scan_equivalent as f64 / self.measured as f64)
    }

    /// The saving over the epochs after the full scans: beams per full scan
    /// over beams measured per windowed epoch; `None` without windowed epochs.
    #[must_use]
    pub fn windowed_saving(&self, beams: usize) -> Option<f64> {
        let windowed = self.epochs - self.full_scans;
        let measured = self.measured - self.full_scans * beams as u64;
        (windowed > 0 && measured > 0).then(|| (windowed * beams as u64) as f64 / measured as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ten_full_scans_then_three_beams() {
        let schedule = BeamSchedule::paper(128);
        let spacing = std::f64::consts::TAU / 128.0;
        let mut count = BeamCount::default();
        for epoch in 0..100 {
            let selection = schedule.select(epoch, Some(10.2 * spacing));
            if epoch < 10 {
                assert_eq!(selection, BeamSelection::FullScan);
            } else {
                assert_eq!(selection, BeamSelection::Window(vec![10, 11, 9]));
            }
            count.add(&selection, 128);
        }
        // 10 x 128 + 90 x 3 = 1550 of 12800: 8.26 over the run, 128 / 3
        // = 42.7 after the full scans.
        assert_eq!(count.measured, 1550);
        assert!((count.saving().unwrap() - 12800.0 / 1550.0).abs() < 1e-12);
        assert!((count.windowed_saving(128).unwrap() - 128.0 / 3.0).abs() < 1e-12);
        assert_eq!(schedule.select(50, None), BeamSelection::FullScan);
        assert_eq!(schedule.select(50, Some(f64::NAN)), BeamSelection::FullScan);
        assert_eq!(BeamCount::default().saving(), None);
    }
}
