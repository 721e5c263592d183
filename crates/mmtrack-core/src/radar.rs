use crate::error::{CoreError, ensure_finite, ensure_len};

/// Timing and geometry of one azimuth (one row) of a polar radar scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AzimuthSample {
    /// Time at which this azimuth was measured, nanoseconds. Spinning radars
    /// take about 250 ms per turn, so motion compensation needs this per row.
    pub t_ns: i64,
    /// Azimuth angle of the row, radians in [0, 2 pi), clockwise from the
    /// sensor's forward axis as the sensor reports it (Navtech encoders count
    /// clockwise seen from above).
    pub azimuth_rad: f64,
    /// False when the sensor flagged the row as invalid (Oxford/Boreas valid
    /// byte != 255); such rows carry no usable power.
    pub valid: bool,
}

/// Timing and geometry of one sweep of a spinning radar, without its power:
/// what a recording stores beside the power image.
///
/// Range of bin `k` is `range_offset_m + k * range_resolution_m` (bin centre as
/// the dataset defines it).
#[derive(Debug, Clone, PartialEq)]
pub struct PolarScanHeader {
    /// Scan timestamp, nanoseconds, as the dataset stamps the scan (Oxford and
    /// Boreas: the file name, also listed in `radar.timestamps`).
    pub t_ns: i64,
    /// Range bin size, metres per bin.
    pub range_resolution_m: f64,
    /// Range of bin 0, metres (Boreas: -0.31 m; Oxford: 0).
    pub range_offset_m: f64,
    /// Number of range bins per azimuth row.
    pub bins_per_azimuth: usize,
    /// Per-row time, angle and validity.
    pub azimuths: Vec<AzimuthSample>,
}

impl PolarScanHeader {
    /// Checks that the resolution is positive and finite and the angles finite.
    pub fn validate(&self) -> Result<(), CoreError> {
        ensure_finite("range_resolution_m", self.range_resolution_m)?;
        ensure_finite("range_offset_m", self.range_offset_m)?;
        if self.range_resolution_m <= 0.0 {
            return Err(CoreError::OutOfRange {
                field: "range_resolution_m",
                value: self.range_resolution_m,
                expected: "a positive bin size",
            });
        }
        for a in &self.azimuths {
            ensure_finite("azimuth_rad", a.azimuth_rad)?;
        }
        Ok(())
    }

    /// Range of bin `bin` in metres.
    #[must_use]
    pub fn range_m(&self, bin: usize) -> f64 {
        self.range_offset_m + bin as f64 * self.range_resolution_m
    }

    /// Checks that azimuth times increase strictly, as a sweep's must.
    pub fn check_azimuth_times(&self) -> Result<(), CoreError> {
        for (index, w) in self.azimuths.windows(2).enumerate() {
            if w[1].t_ns <= w[0].t_ns {
                return Err(CoreError::NonMonotonicTime {
                    what: "azimuth timestamps",
                    index: index + 1,
                    previous_t_ns: w[0].t_ns,
                    t_ns: w[1].t_ns,
                });
            }
        }
        Ok(())
    }
}

/// One sweep of a spinning radar in polar form: `header.azimuths.len()` rows of
/// `header.bins_per_azimuth` range bins of 8-bit power.
#[derive(Debug, Clone, PartialEq)]
pub struct PolarScan {
    /// Timing and geometry.
    pub header: PolarScanHeader,
    /// Raw power counts (0-255), row-major: `power[a * bins_per_azimuth + k]`.
    pub power: Vec<u8>,
}

impl PolarScan {
    /// Builds a scan, checking the header and that the power buffer matches
    /// the declared shape.
    pub fn new(header: PolarScanHeader, power: Vec<u8>) -> Result<Self, CoreError> {
        header.validate()?;
        ensure_len("polar scan power", header.azimuths.len() * header.bins_per_azimuth, power.len())?;
        Ok(Self { header, power })
    }

    /// The power row of azimuth `index`, or `None` past the last row.
    #[must_use]
    pub fn row(&self, index: usize) -> Option<&[u8]> {
        let bins = self.header.bins_per_azimuth;
        let start = index.checked_mul(bins)?;
        self.power.get(start..start + bins)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn azimuths(n: usize) -> Vec<AzimuthSample> {
        (0..n).map(|i| AzimuthSample { t_ns: i as i64 * 1000, azimuth_rad: i as f64 * 0.1, valid: true }).collect()
    }

    fn header(n: usize, bins: usize, resolution_m: f64, offset_m: f64) -> PolarScanHeader {
        PolarScanHeader {
            t_ns: 0,
            range_resolution_m: resolution_m,
            range_offset_m: offset_m,
            bins_per_azimuth: bins,
            azimuths: azimuths(n),
        }
    }

    #[test]
    fn shape_is_checked() {
        let err = PolarScan::new(header(3, 5, 0.04, 0.0), vec![0; 14]).unwrap_err();
        assert_eq!(err, CoreError::ShapeMismatch { what: "polar scan power", expected: 15, found: 14 });
    }

    #[test]
    fn rows_and_ranges() {
        let power: Vec<u8> = (0..15).collect();
        let scan = PolarScan::new(header(3, 5, 0.5, -0.25), power).unwrap();
        assert_eq!(scan.row(1), Some(&[5, 6, 7, 8, 9][..]));
        assert_eq!(scan.row(3), None);
        assert_eq!(scan.header.range_m(2), 0.75);
    }

    #[test]
    fn non_monotonic_azimuth_time_is_reported() {
        let mut h = header(4, 1, 0.5, 0.0);
        h.azimuths[2].t_ns = h.azimuths[1].t_ns;
        assert!(matches!(h.check_azimuth_times(), Err(CoreError::NonMonotonicTime { index: 2, .. })));
    }

    #[test]
    fn bad_resolution_is_rejected() {
        assert!(PolarScan::new(header(1, 1, 0.0, 0.0), vec![0]).is_err());
        assert!(PolarScan::new(header(1, 1, f64::NAN, 0.0), vec![0]).is_err());
    }
}
