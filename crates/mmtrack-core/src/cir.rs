use crate::error::{CoreError, ensure_finite};
use num_complex::Complex64;

/// One channel impulse response (CIR) snapshot from a channel sounder.
///
/// Tap `k` sits at delay `delay_offset_s + k * tap_spacing_s`. Sounders measure
/// in *sets* of closely spaced snapshots (Mahler et al. 2017: 6 snapshots
/// 0.717 ms apart, a set every 10 ms); `set_index` and `snapshot_index` keep that
/// structure. MIMO sounders give one snapshot per antenna pair (`tx_antenna`,
/// `rx_antenna`); SISO recordings use 0 for both.
///
/// Some receivers estimate the first (leading-edge) path themselves, e.g. the
/// DW1000's `HLP` register; [`CirSnapshot::first_path_hint_s`] keeps that
/// estimate on the same delay axis as the taps so algorithms can be compared
/// against it. It is a hint from the device, not ground truth.
#[derive(Debug, Clone, PartialEq)]
pub struct CirSnapshot {
    /// Measurement time, nanoseconds.
    pub t_ns: i64,
    /// Index of the set this snapshot belongs to (0-based, increasing).
    pub set_index: u64,
    /// Index of the snapshot within its set (0-based).
    pub snapshot_index: u32,
    /// Transmit antenna index (0 for SISO).
    pub tx_antenna: u32,
    /// Receive antenna index (0 for SISO).
    pub rx_antenna: u32,
    /// Carrier frequency, hertz.
    pub carrier_hz: f64,
    /// Delay between consecutive taps, seconds (1/bandwidth for a Nyquist-sampled sounder).
    pub tap_spacing_s: f64,
    /// Delay of tap 0, seconds.
    pub delay_offset_s: f64,
    /// Complex tap amplitudes (linear, unitless: the sounder's own scale).
    pub taps: Vec<Complex64>,
    /// The receiver's own first-path estimate, seconds, on the delay axis of
    /// the taps (a fractional tap index `i` is `delay_offset_s + i *
    /// tap_spacing_s`); `None` when the source gives none.
    pub first_path_hint_s: Option<f64>,
}

impl CirSnapshot {
    /// Checks the invariants: finite positive carrier and tap spacing, finite
    /// offset and first-path hint, at least one tap, all taps finite.
    pub fn validate(&self) -> Result<(), CoreError> {
        ensure_finite("carrier_hz", self.carrier_hz)?;
        ensure_finite("tap_spacing_s", self.tap_spacing_s)?;
        ensure_finite("delay_offset_s", self.delay_offset_s)?;
        if let Some(hint) = self.first_path_hint_s {
            ensure_finite("first_path_hint_s", hint)?;
        }
        if self.tap_spacing_s <= 0.0 {
            return Err(CoreError::OutOfRange {
                field: "tap_spacing_s",
                value: self.tap_spacing_s,
                expected: "a positive tap spacing",
            });
        }
        if self.carrier_hz < 0.0 {
            return Err(CoreError::OutOfRange {
                field: "carrier_hz",
                value: self.carrier_hz,
                expected: "a non-negative carrier (0 = baseband)",
            });
        }
        if self.taps.is_empty() {
            return Err(CoreError::ShapeMismatch { what: "CIR taps", expected: 1, found: 0 });
        }
        for tap in &self.taps {
            ensure_finite("tap real part", tap.re)?;
            ensure_finite("tap imaginary part", tap.im)?;
        }
        // Finite taps whose power overflows (|tap| of 1e308) made every power
        // and the noise floor infinite: zero detections, no error.
        if !self.taps.iter().map(|t| t.norm_sqr()).sum::<f64>().is_finite() {
            let largest = self.taps.iter().map(|t| t.norm()).fold(0.0, f64::max);
            return Err(CoreError::OutOfRange {
                field: "taps",
                value: largest,
                expected: "taps whose total power is finite (magnitudes below about 1e150)",
            });
        }
        Ok(())
    }

    /// Delay of tap `k`, seconds.
    #[must_use]
    pub fn delay_s(&self, k: usize) -> f64 {
        self.delay_offset_s + k as f64 * self.tap_spacing_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn snapshot() -> CirSnapshot {
        CirSnapshot {
            t_ns: 0,
            set_index: 0,
            snapshot_index: 0,
            tx_antenna: 0,
            rx_antenna: 0,
            carrier_hz: 5.7e9,
            tap_spacing_s: 1e-9,
            delay_offset_s: 0.0,
            taps: vec![Complex64::new(1.0, -1.0); 4],
            first_path_hint_s: Some(1.5e-9),
        }
    }

    #[test]
    fn valid_snapshot_passes() {
        assert_eq!(snapshot().validate(), Ok(()));
        // 1e-24 s: far below one ulp-scale error of 3 ns products.
        assert!((snapshot().delay_s(3) - 3e-9).abs() < 1e-24);
    }

    #[test]
    fn nan_tap_and_bad_spacing_fail() {
        let mut s = snapshot();
        s.taps[2].im = f64::NAN;
        assert!(matches!(s.validate(), Err(CoreError::NotFinite { field: "tap imaginary part", .. })));
        let mut s = snapshot();
        s.tap_spacing_s = -1e-9;
        assert!(matches!(s.validate(), Err(CoreError::OutOfRange { field: "tap_spacing_s", .. })));
        let mut s = snapshot();
        s.first_path_hint_s = Some(f64::INFINITY);
        assert!(matches!(s.validate(), Err(CoreError::NotFinite { field: "first_path_hint_s", .. })));
        // Finite taps whose power overflows (detection found nothing, silently).
        let mut s = snapshot();
        s.taps[1].re = 1e308;
        assert!(matches!(s.validate(), Err(CoreError::OutOfRange { field: "taps", .. })));
    }
}
