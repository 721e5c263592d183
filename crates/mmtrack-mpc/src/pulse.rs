//! The sounder pulse `w(tau)` of eq. (2): what one path looks like in the CIR.

use mmtrack_core::Complex64;
use mmtrack_core::sounder::{SounderBand, spectrum_from_cir};

use crate::MpcError;

/// The sounder's pulse as a transfer function `P[k]` in FFT order, one value
/// per frequency bin, normalised so that the pulse peaks at delay 0 with a
/// real value of 1: a path of amplitude `alpha` then shows as `alpha` at its
/// CIR peak (exactly, for an on-grid delay).
///
/// It is an input of the detector (Mahler et al. 2017 use a pulse measured
/// through an RF cable): [`SounderPulse::flat`] models an ideal sounder of the
/// given bandwidth; [`SounderPulse::from_back_to_back_cir`] takes a measured
/// back-to-back calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct SounderPulse {
    spectrum: Vec<Complex64>,
}

impl SounderPulse {
    /// An ideal sounder: a flat transfer function over the whole band (its
    /// CIR is a periodic sinc of the tap spacing).
    #[must_use]
    pub fn flat(band: &SounderBand) -> Self {
        Self { spectrum: vec![Complex64::new(1.0, 0.0); band.taps()] }
    }

    /// A band-limited pulse inside an oversampled band: a raised-cosine
    /// spectrum of `bandwidth_hz` (between the -6 dB points) and roll-off
    /// `rolloff` in 0..=1, zero beyond `(1 + rolloff) bandwidth / 2`. Models
    /// receivers that sample faster than their signal bandwidth, such as the
    /// DW1000 (499.2 MHz channels sampled at 998.4 MHz).
    pub fn raised_cosine(band: &SounderBand, bandwidth_hz: f64, rolloff: f64) -> Result<Self, MpcError> {
        if !(bandwidth_hz.is_finite() && bandwidth_hz > 0.0 && (0.0..=1.0).contains(&rolloff)) {
            return Err(MpcError::BadPulse {
                detail: format!(
                    "raised cosine of {bandwidth_hz} Hz, roll-off {rolloff}: expected a positive bandwidth and a roll-off in 0..=1"
                ),
            });
        }
        let half = bandwidth_hz / 2.0;
        let spectrum = (0..band.taps())
            .map(|k| {
                let f = band.frequency_hz(k).abs();
                let (inner, outer) = (half * (1.0 - rolloff), half * (1.0 + rolloff));
                let gain = if f <= inner {
                    1.0
                } else if f >= outer {
                    0.0
                } else {
                    0.5 * (1.0 + (std::f64::consts::PI * (f - inner) / (outer - inner)).cos())
                };
                Complex64::new(gain, 0.0)
            })
            .collect::<Vec<_>>();
        let peak = spectrum.iter().map(|p| p.re).sum::<f64>() / band.taps() as f64;
        Self::from_spectrum(spectrum.into_iter().map(|p| p / peak).collect())
    }

    /// A pulse given as its transfer function in FFT order, as a simulator
    /// knows it. It must be finite and not all zero; it is used as given.
    pub fn from_spectrum(spectrum: Vec<Complex64>) -> Result<Self, MpcError> {
        if spectrum.len() < 2 {
            return Err(MpcError::BadPulse { detail: format!("{} frequency bins, need at least 2", spectrum.len()) });
        }
        if let Some(k) = spectrum.iter().position(|p| !(p.re.is_finite() && p.im.is_finite())) {
            return Err(MpcError::BadPulse { detail: format!("bin {k} is not finite") });
        }
        if spectrum.iter().all(|p| p.norm_sqr() == 0.0) {
            return Err(MpcError::BadPulse { detail: "all bins are zero".into() });
        }
        Ok(Self { spectrum })
    }

    /// A pulse measured back to back (transmitter cabled to receiver): its
    /// strongest tap becomes delay 0 and its value 1.
    pub fn from_back_to_back_cir(cir: &[Complex64]) -> Result<Self, MpcError> {
        if let Some(n) = cir.iter().position(|h| !(h.re.is_finite() && h.im.is_finite())) {
            return Err(MpcError::BadPulse { detail: format!("back-to-back CIR tap {n} is not finite") });
        }
        let (peak_tap, peak) = cir
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.norm_sqr().total_cmp(&b.1.norm_sqr()))
            .ok_or_else(|| MpcError::BadPulse { detail: "empty back-to-back CIR".into() })?;
        if peak.norm_sqr() == 0.0 {
            return Err(MpcError::BadPulse { detail: "back-to-back CIR is all zero".into() });
        }
        let peak = *peak;
        let taps = cir.len();
        let spectrum = spectrum_from_cir(cir)
            .into_iter()
            .enumerate()
            .map(|(k, p)| {
                // Moving the peak from tap n_p to tap 0: multiply by exp(+j 2 pi k n_p / U).
                let turn = 2.0 * std::f64::consts::PI * ((k * peak_tap) % taps) as f64 / taps as f64;
                p * Complex64::from_polar(1.0, turn) / peak
            })
            .collect();
        Self::from_spectrum(spectrum)
    }

    /// The transfer function, FFT order.
    #[must_use]
    pub fn spectrum(&self) -> &[Complex64] {
        &self.spectrum
    }

    /// Number of frequency bins (= CIR taps).
    #[must_use]
    pub fn taps(&self) -> usize {
        self.spectrum.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mmtrack_core::sounder::cir_from_spectrum;

    #[test]
    fn back_to_back_pulse_is_moved_to_delay_zero_with_unit_peak() {
        let band = SounderBand::new(32, 1e-9).unwrap();
        let mut spectrum = vec![Complex64::default(); 32];
        band.add_path(&mut spectrum, SounderPulse::flat(&band).spectrum(), 7e-9, Complex64::new(0.0, 2.0));
        let pulse = SounderPulse::from_back_to_back_cir(&cir_from_spectrum(&spectrum)).unwrap();
        let cir = cir_from_spectrum(pulse.spectrum());
        // 1e-12: FFT round-off on unit-size values.
        assert!((cir[0] - Complex64::new(1.0, 0.0)).norm() < 1e-12);
        assert!(cir[1..].iter().all(|h| h.norm() < 1e-12));
    }

    #[test]
    fn bad_pulses_are_refused() {
        assert!(SounderPulse::from_back_to_back_cir(&[]).is_err());
        assert!(SounderPulse::from_back_to_back_cir(&[Complex64::default(); 8]).is_err());
        assert!(SounderPulse::from_back_to_back_cir(&[Complex64::new(f64::NAN, 0.0); 8]).is_err());
        assert!(SounderPulse::from_spectrum(vec![Complex64::default(); 8]).is_err());
    }
}
