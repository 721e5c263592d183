//! The sounder pulse of a recording, kept in its metadata so a detector
//! reading the recording uses the pulse the CIRs were measured (or
//! simulated) with.

use mmtrack_core::Complex64;

/// Metadata key of the pulse spectrum: `P[k]` in FFT order as
/// whitespace-separated `re im` pairs, each written with Rust's shortest
/// round-trip formatting (bit-exact back).
pub const PULSE_SPECTRUM_KEY: &str = "sounder.pulse_spectrum";

/// Encodes a pulse spectrum for [`PULSE_SPECTRUM_KEY`].
#[must_use]
pub fn encode_pulse_spectrum(spectrum: &[Complex64]) -> String {
    let mut out = String::with_capacity(spectrum.len() * 48);
    for (k, p) in spectrum.iter().enumerate() {
        if k > 0 {
            out.push(' ');
        }
        out.push_str(&format!("{:?} {:?}", p.re, p.im));
    }
    out
}

/// Decodes [`encode_pulse_spectrum`]; `None` for an odd count or a value
/// that is not a finite number.
#[must_use]
pub fn decode_pulse_spectrum(text: &str) -> Option<Vec<Complex64>> {
    let values: Vec<f64> = text.split_whitespace().map(str::parse).collect::<Result<_, _>>().ok()?;
    if values.is_empty() || !values.len().is_multiple_of(2) || values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some(values.chunks_exact(2).map(|c| Complex64::new(c[0], c[1])).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectra_round_trip_bit_exactly() {
        let spectrum = vec![Complex64::new(-0.0, 5e-324), Complex64::new(1.0 / 3.0, -2.5e17), Complex64::new(1.0, 0.0)];
        let back = decode_pulse_spectrum(&encode_pulse_spectrum(&spectrum)).unwrap();
        let bits = |v: &[Complex64]| v.iter().flat_map(|c| [c.re.to_bits(), c.im.to_bits()]).collect::<Vec<_>>();
        assert_eq!(bits(&back), bits(&spectrum));
        assert!(decode_pulse_spectrum("1 2 3").is_none());
        assert!(decode_pulse_spectrum("1 NaN").is_none());
        assert!(decode_pulse_spectrum("").is_none());
    }
}
