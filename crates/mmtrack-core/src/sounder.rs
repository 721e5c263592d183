//! The channel-sounder signal model shared by the sounder simulator and the MPC
//! detector, so both speak exactly the same convention.
//!
//! A sounder with `U` taps spaced `T_b` apart (bandwidth `B = 1 / T_b`)
//! measures the transfer function on `U` frequency bins `f_k = s_k / (U T_b)`,
//! where `s_k` is the signed bin index in FFT order (`0, 1, .., -2, -1`). The
//! CIR is the inverse DFT of the transfer function,
//!
//! `h[n] = (1/U) sum_k H[k] exp(+j 2 pi k n / U)`,
//!
//! so a path of complex amplitude `alpha` at delay `tau` (relative to tap 0)
//! seen through a pulse spectrum `P[k]` contributes
//! `H[k] = alpha P[k] exp(-j 2 pi f_k tau)` (Mahler et al. 2017, eqs. (2)-(4));
//! with a flat pulse (`P = 1`) and an on-grid delay `tau = n0 T_b`, the CIR is
//! exactly `alpha` at tap `n0` and zero elsewhere. Off-grid delays spread over
//! the neighbouring taps as a periodic sinc.
//!
//! The Kaiser window of eq. (10) is applied in band order (lowest frequency
//! first), i.e. band position `u = s_k + U/2`.

use num_complex::Complex64;
use rustfft::FftPlanner;

use crate::error::CoreError;

/// Frequency grid of a sounder: `taps` bins, `tap_spacing_s` between CIR taps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SounderBand {
    taps: usize,
    tap_spacing_s: f64,
}

impl SounderBand {
    /// A band of `taps` bins (>= 2) with CIR taps `tap_spacing_s` (> 0) apart.
    pub fn new(taps: usize, tap_spacing_s: f64) -> Result<Self, CoreError> {
        if taps < 2 {
            return Err(CoreError::OutOfRange { field: "taps", value: taps as f64, expected: "at least 2 taps" });
        }
        if !(tap_spacing_s.is_finite() && tap_spacing_s > 0.0) {
            return Err(CoreError::OutOfRange {
                field: "tap_spacing_s",
                value: tap_spacing_s,
                expected: "a finite positive tap spacing",
            });
        }
        Ok(Self { taps, tap_spacing_s })
    }

    /// Number of taps (= frequency bins), `U`.
    #[must_use]
    pub fn taps(&self) -> usize {
        self.taps
    }

    /// Delay between taps, seconds (`T_b = 1 / B`).
    #[must_use]
    pub fn tap_spacing_s(&self) -> f64 {
        self.tap_spacing_s
    }

    /// Bandwidth, hertz (`B = 1 / T_b`).
    #[must_use]
    pub fn bandwidth_hz(&self) -> f64 {
        1.0 / self.tap_spacing_s
    }

    /// Signed bin index `s_k` of FFT bin `k` (`0, 1, .., -2, -1`).
    #[must_use]
    pub fn signed_bin(&self, k: usize) -> i64 {
        let half = self.taps.div_ceil(2);
        if k < half { k as i64 } else { k as i64 - self.taps as i64 }
    }

    /// Baseband frequency of FFT bin `k`, hertz: `f_k = s_k / (U T_b)`.
    #[must_use]
    pub fn frequency_hz(&self, k: usize) -> f64 {
        self.signed_bin(k) as f64 / (self.taps as f64 * self.tap_spacing_s)
    }

    /// Position of FFT bin `k` in the band, lowest frequency first (`u = s_k + U/2`).
    #[must_use]
    pub fn band_position(&self, k: usize) -> usize {
        (self.signed_bin(k) + (self.taps / 2) as i64) as usize
    }

    /// The Kaiser window of eq. (10) with shape `beta`, one weight per FFT bin
    /// (applied in band order):
    ///
    /// `z[u] = I0(beta sqrt(1 - (2u/(U-1) - 1)^2)) / I0(beta)`.
    ///
    /// Eq. (10) writes `beta = pi a` with `a = 6`, but the paper's own pulse
    /// width (2.47 ns at -10 dB for 1 GHz) is what `beta = 6` gives (2.50 ns for
    /// a flat band; `beta = 6 pi` gives 4.25 ns): the authors evidently used
    /// MATLAB's `kaiser(U, 6)`, whose parameter is `beta`.
    ///
    /// # References
    /// Mahler et al. 2017, eq. (10); Kaiser and Schafer 1980.
    #[must_use]
    pub fn kaiser_window(&self, beta: f64) -> Vec<f64> {
        let u_max = (self.taps - 1) as f64;
        let norm = bessel_i0(beta);
        (0..self.taps)
            .map(|k| {
                let x = 2.0 * self.band_position(k) as f64 / u_max - 1.0;
                bessel_i0(beta * (1.0 - x * x).max(0.0).sqrt()) / norm
            })
            .collect()
    }

    /// Adds a path of amplitude `amplitude` at `delay_s` (relative to tap 0)
    /// seen through `pulse` to the transfer function `spectrum` (FFT order):
    /// `H[k] += alpha P[k] exp(-j 2 pi f_k tau)`.
    pub fn add_path(&self, spectrum: &mut [Complex64], pulse: &[Complex64], delay_s: f64, amplitude: Complex64) {
        for (k, (h, p)) in spectrum.iter_mut().zip(pulse).enumerate() {
            let phase = -2.0 * std::f64::consts::PI * self.frequency_hz(k) * delay_s;
            *h += amplitude * p * Complex64::from_polar(1.0, phase);
        }
    }
}

/// Modified Bessel function of the first kind, order zero, by its power series
/// `I0(x) = sum_m ((x/2)^m / m!)^2` (converges for all x; 1e-17 relative for
/// the arguments of a Kaiser window, |x| < 100).
#[must_use]
pub fn bessel_i0(x: f64) -> f64 {
    let quarter_x2 = x * x / 4.0;
    let mut term = 1.0;
    let mut sum = 1.0;
    for m in 1..500 {
        term *= quarter_x2 / (m as f64 * m as f64);
        sum += term;
        if term < sum * 1e-17 {
            break;
        }
    }
    sum
}

/// The CIR of a transfer function: `h[n] = (1/U) sum_k H[k] exp(+j 2 pi k n / U)`.
#[must_use]
pub fn cir_from_spectrum(spectrum: &[Complex64]) -> Vec<Complex64> {
    let mut buffer = spectrum.to_vec();
    FftPlanner::new().plan_fft_inverse(buffer.len()).process(&mut buffer);
    let scale = 1.0 / buffer.len() as f64;
    buffer.iter_mut().for_each(|x| *x *= scale);
    buffer
}

/// The transfer function of a CIR: `H[k] = sum_n h[n] exp(-j 2 pi k n / U)`.
#[must_use]
pub fn spectrum_from_cir(cir: &[Complex64]) -> Vec<Complex64> {
    let mut buffer = cir.to_vec();
    FftPlanner::new().plan_fft_forward(buffer.len()).process(&mut buffer);
    buffer
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn on_grid_path_is_one_tap() {
        let band = SounderBand::new(64, 1e-9).unwrap();
        let pulse = vec![Complex64::new(1.0, 0.0); 64];
        let mut spectrum = vec![Complex64::default(); 64];
        let alpha = Complex64::new(0.3, -0.4);
        band.add_path(&mut spectrum, &pulse, 5e-9, alpha);
        let cir = cir_from_spectrum(&spectrum);
        for (n, h) in cir.iter().enumerate() {
            let expected = if n == 5 { alpha } else { Complex64::default() };
            // 1e-12: a 64-point FFT of unit-size values rounds at ~1e-15.
            assert!((h - expected).norm() < 1e-12, "tap {n}: {h}");
        }
        let back = spectrum_from_cir(&cir);
        assert!(back.iter().zip(&spectrum).all(|(a, b)| (a - b).norm() < 1e-12));
    }

    #[test]
    fn bins_and_band_positions() {
        let band = SounderBand::new(4, 1e-9).unwrap();
        let signed: Vec<i64> = (0..4).map(|k| band.signed_bin(k)).collect();
        assert_eq!(signed, [0, 1, -2, -1]);
        let positions: Vec<usize> = (0..4).map(|k| band.band_position(k)).collect();
        assert_eq!(positions, [2, 3, 0, 1]);
        let odd = SounderBand::new(5, 1e-9).unwrap();
        let positions: Vec<usize> = (0..5).map(|k| odd.band_position(k)).collect();
        assert_eq!(positions, [2, 3, 4, 0, 1]);
        assert!((band.frequency_hz(1) - 250e6).abs() < 1e-3);
        assert!(SounderBand::new(1, 1e-9).is_err());
        assert!(SounderBand::new(8, -1e-9).is_err());
    }

    #[test]
    fn kaiser_window_is_symmetric_and_peaks_at_band_centre() {
        let band = SounderBand::new(9, 1e-9).unwrap();
        let z = band.kaiser_window(6.0);
        // Band centre u = 4 is FFT bin 0; its weight is I0(beta)/I0(beta) = 1.
        assert!((z[0] - 1.0).abs() < 1e-15);
        // Band edges u = 0 and u = 8 (bins 5 and 4) weigh 1 / I0(6).
        let edge = 1.0 / bessel_i0(6.0);
        assert!((z[4] - edge).abs() < 1e-18 && (z[5] - edge).abs() < 1e-18);
        // I0(1) = 1.2660658777520082 (Abramowitz and Stegun, Table 9.8).
        assert!((bessel_i0(1.0) - 1.266_065_877_752_008_2).abs() < 1e-15);
    }
}
