//! Uniform circular arrays (UCA) and their phase-quantised beam codebooks.
//!
//! A UCA of `N` isotropic elements on a circle of radius `R` (in
//! wavelengths), element `n` at the angle `theta_n = 2 pi n / N`, sees a plane
//! wave from azimuth `phi` through the normalised response
//!
//! ```text
//! a(phi)[n] = exp(j 2 pi R cos(phi - theta_n)) / sqrt(N)
//! ```
//!
//! A beam steered to `psi` conjugates the phase progression; with analog
//! `b`-bit phase shifters every weight phase is rounded to the nearest
//! multiple of `2 pi / 2^b`:
//!
//! ```text
//! w(psi)[n] = exp(j Q_b(2 pi R cos(psi - theta_n))) / sqrt(N)
//! ```
//!
//! and the beamforming gain is `|w(psi)^H a(phi)|^2` (1 on the beam axis
//! without quantisation). Zoechmann et al. 2019, Sec. II: `N = 64`, 4-bit
//! phase shifters, 128 beams spaced by half the `2 pi / N` (about 6 deg)
//! half-power beamwidth (their Fig. 1). The radius they print, `N/2 * lambda/2`
//! = 16 wavelengths, gives a 1.3 deg beam with -7.6 dB sidelobes, not 6 deg;
//! the simulator chooses the radius (see `mmtrack_sim::beam::overtaking`).
//!
//! Rotating a beam by one element spacing (`2 pi / N`) permutes its weights
//! exactly, quantised or not: with `B = 2N` beams, every even beam is a
//! rotation of beam 0 and every odd beam one of beam 1
//! ([`UcaCodebook::pattern_class`]).
//!
//! The ULA API lives in [`crate::array`]; this module adds the circular array
//! without changing it.

use crate::Complex64;
use crate::error::{CoreError, ensure_finite};

/// A uniform circular array of `element_count` isotropic elements on a
/// circle of radius `radius_wavelengths`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniformCircularArray {
    element_count: usize,
    radius_wavelengths: f64,
}

impl UniformCircularArray {
    /// Checks and builds an array.
    ///
    /// # Errors
    /// [`CoreError::OutOfRange`] for no elements or a radius that is not
    /// positive and finite.
    pub fn new(element_count: usize, radius_wavelengths: f64) -> Result<Self, CoreError> {
        if element_count == 0 {
            return Err(CoreError::OutOfRange { field: "element_count", value: 0.0, expected: "at least one element" });
        }
        ensure_finite("radius_wavelengths", radius_wavelengths)?;
        if radius_wavelengths <= 0.0 {
            return Err(CoreError::OutOfRange {
                field: "radius_wavelengths",
                value: radius_wavelengths,
                expected: "a positive radius",
            });
        }
        Ok(Self { element_count, radius_wavelengths })
    }

    /// Number of elements `N`.
    #[must_use]
    pub fn element_count(&self) -> usize {
        self.element_count
    }

    /// Radius `R` in wavelengths.
    #[must_use]
    pub fn radius_wavelengths(&self) -> f64 {
        self.radius_wavelengths
    }

    /// Phase `2 pi R cos(phi - theta_n)` of element `n` for azimuth `phi`.
    fn phase(&self, n: usize, azimuth_rad: f64) -> f64 {
        let theta = std::f64::consts::TAU * n as f64 / self.element_count as f64;
        std::f64::consts::TAU * self.radius_wavelengths * (azimuth_rad - theta).cos()
    }

    /// The normalised response `a(phi)` (module docs), `|a| = 1`.
    #[must_use]
    pub fn response(&self, azimuth_rad: f64) -> Vec<Complex64> {
        let scale = 1.0 / (self.element_count as f64).sqrt();
        (0..self.element_count).map(|n| Complex64::from_polar(scale, self.phase(n, azimuth_rad))).collect()
    }

    /// Beam weights `w(psi)` steered to `steer_rad` with phases rounded to
    /// `phase_bits` bits (0: unquantised).
    ///
    /// # Errors
    /// [`CoreError::OutOfRange`] for a non-finite steering angle or more than
    /// 16 bits.
    pub fn weights(&self, steer_rad: f64, phase_bits: u32) -> Result<Vec<Complex64>, CoreError> {
        ensure_finite("steer_rad", steer_rad)?;
        if phase_bits > 16 {
            return Err(CoreError::OutOfRange {
                field: "phase_bits",
                value: f64::from(phase_bits),
                expected: "at most 16 bits (0: unquantised)",
            });
        }
        let scale = 1.0 / (self.element_count as f64).sqrt();
        let step = std::f64::consts::TAU / f64::from(1u32 << phase_bits);
        Ok((0..self.element_count)
            .map(|n| {
                let phase = self.phase(n, steer_rad);
                let phase = if phase_bits == 0 { phase } else { (phase / step).round() * step };
                Complex64::from_polar(scale, phase)
            })
            .collect())
    }

    /// The array factor `w^H a(phi)` of explicit weights (as many as elements).
    #[must_use]
    pub fn array_factor(&self, weights: &[Complex64], azimuth_rad: f64) -> Complex64 {
        let scale = 1.0 / (self.element_count as f64).sqrt();
        weights
            .iter()
            .enumerate()
            .map(|(n, w)| w.conj() * Complex64::from_polar(scale, self.phase(n, azimuth_rad)))
            .sum()
    }
}

/// A codebook of `beams` beams of a UCA steered to `psi_j = 2 pi j / beams`,
/// with `phase_bits`-bit phase shifters (Zoechmann et al. 2019, Sec. II and
/// Fig. 1: 128 beams, 4 bits).
#[derive(Debug, Clone, PartialEq)]
pub struct UcaCodebook {
    array: UniformCircularArray,
    phase_bits: u32,
    weights: Vec<Vec<Complex64>>,
}

impl UcaCodebook {
    /// Builds the codebook.
    ///
    /// # Errors
    /// [`CoreError::OutOfRange`] for no beams or more than 16 phase bits.
    pub fn new(array: UniformCircularArray, beams: usize, phase_bits: u32) -> Result<Self, CoreError> {
        if beams == 0 {
            return Err(CoreError::OutOfRange { field: "beams", value: 0.0, expected: "at least one beam" });
        }
        let weights = (0..beams)
            .map(|j| array.weights(std::f64::consts::TAU * j as f64 / beams as f64, phase_bits))
            .collect::<Result<_, _>>()?;
        Ok(Self { array, phase_bits, weights })
    }

    /// The array.
    #[must_use]
    pub fn array(&self) -> &UniformCircularArray {
        &self.array
    }

    /// Phase-shifter resolution, bits (0: unquantised).
    #[must_use]
    pub fn phase_bits(&self) -> u32 {
        self.phase_bits
    }

    /// Number of beams.
    #[must_use]
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// Always false: a codebook has at least one beam.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// Steering azimuth of `beam` (taken modulo the beam count), radians in
    /// `[0, 2 pi)`.
    #[must_use]
    pub fn steer_rad(&self, beam: usize) -> f64 {
        std::f64::consts::TAU * (beam % self.len()) as f64 / self.len() as f64
    }

    /// Beam spacing `2 pi / beams`, radians.
    #[must_use]
    pub fn spacing_rad(&self) -> f64 {
        std::f64::consts::TAU / self.len() as f64
    }

    /// Weights of `beam` (taken modulo the beam count).
    #[must_use]
    pub fn weights(&self, beam: usize) -> &[Complex64] {
        &self.weights[beam % self.len()]
    }

    /// Beamforming gain `|w_j^H a(phi)|^2` of `beam` towards `azimuth_rad`.
    #[must_use]
    pub fn gain(&self, beam: usize, azimuth_rad: f64) -> f64 {
        self.array.array_factor(self.weights(beam), azimuth_rad).norm_sqr()
    }

    /// The beam of `candidates` with the largest gain towards `azimuth_rad`
    /// (the first of equals); `None` for no candidates.
    #[must_use]
    pub fn strongest_of(&self, candidates: impl IntoIterator<Item = usize>, azimuth_rad: f64) -> Option<usize> {
        let mut best: Option<(usize, f64)> = None;
        for beam in candidates {
            let g = self.gain(beam, azimuth_rad);
            if best.is_none_or(|(_, b)| g > b) {
                best = Some((beam % self.len(), g));
            }
        }
        best.map(|(beam, _)| beam)
    }

    /// Full half-power beamwidth of `beam`, radians: the distance between
    /// the two azimuths around its peak where the gain falls to half the
    /// gain at the steering azimuth (bisection inside `+/- pi / 2`).
    #[must_use]
    pub fn half_power_beamwidth_rad(&self, beam: usize) -> f64 {
        let steer = self.steer_rad(beam);
        let half = 0.5 * self.gain(beam, steer);
        let edge = |sign: f64| {
            // First step outwards below half power, then bisection.
            let step = 1e-3;
            let mut outside = step;
            while self.gain(beam, steer + sign * outside) >= half && outside < std::f64::consts::FRAC_PI_2 {
                outside += step;
            }
            let mut inside = outside - step;
            for _ in 0..60 {
                let mid = 0.5 * (inside + outside);
                if self.gain(beam, steer + sign * mid) >= half {
                    inside = mid;
                } else {
                    outside = mid;
                }
            }
            0.5 * (inside + outside)
        };
        edge(1.0) + edge(-1.0)
    }

    /// The `count` beams whose steering azimuths are circularly nearest to
    /// `azimuth_rad`, nearest first (ties: the lower index). `count` is capped
    /// at the beam count; a non-finite azimuth gives none.
    #[must_use]
    pub fn nearest_beams(&self, azimuth_rad: f64, count: usize) -> Vec<usize> {
        nearest_circular_beams(self.len(), azimuth_rad, count)
    }

    /// How many distinct patterns the codebook has up to rotation: a shift
    /// by `s` beams is a whole number of element spacings when `s` is a
    /// multiple of `c = beams / gcd(beams, elements)`, so beam `j`'s pattern is
    /// beam `(j mod c)`'s rotated by `psi_j - psi_(j mod c)` (module docs). 2
    /// for 128 beams of 64 elements.
    #[must_use]
    pub fn pattern_class(&self) -> usize {
        let (beams, elements) = (self.len(), self.array.element_count());
        beams / gcd(beams, elements)
    }
}

/// The `count` beams of a `beams`-beam circular codebook (`psi_j = 2 pi j /
/// beams`) circularly nearest to `azimuth_rad`, nearest first (ties: the lower
/// index); empty for a non-finite azimuth or no beams.
#[must_use]
pub fn nearest_circular_beams(beams: usize, azimuth_rad: f64, count: usize) -> Vec<usize> {
    if beams == 0 || !azimuth_rad.is_finite() {
        return Vec::new();
    }
    let spacing = std::f64::consts::TAU / beams as f64;
    let position = azimuth_rad.rem_euclid(std::f64::consts::TAU) / spacing;
    let below = (position.floor() as usize) % beams;
    let mut out = Vec::with_capacity(count.min(beams));
    // Walk outwards from the two beams around the azimuth.
    let (mut down, mut up) = (0usize, 1usize);
    while out.len() < count.min(beams) {
        let d_down = position - position.floor() + down as f64;
        let d_up = up as f64 - (position - position.floor());
        if d_down <= d_up {
            out.push((below + beams - down % beams) % beams);
            down += 1;
        } else {
            out.push((below + up) % beams);
            up += 1;
        }
    }
    out
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 64 elements, 4 bits, 128 beams; radius 3.42 wavelengths (a 6 deg beam).
    fn paper() -> UcaCodebook {
        UcaCodebook::new(UniformCircularArray::new(64, 3.42).unwrap(), 128, 4).unwrap()
    }

    #[test]
    fn the_papers_array_and_codebook() {
        let book = paper();
        assert_eq!(book.len(), 128);
        assert_eq!(book.pattern_class(), 2);
        // Unit-norm response; unquantised weights give gain 1 on the axis.
        let array = *book.array();
        let a = array.response(0.3);
        assert!((a.iter().map(Complex64::norm_sqr).sum::<f64>() - 1.0).abs() < 1e-12);
        let w = array.weights(0.3, 0).unwrap();
        assert!((array.array_factor(&w, 0.3).norm_sqr() - 1.0).abs() < 1e-12);
        // 4-bit quantisation: phase errors uniform in +/- pi/16 cost
        // |E exp(j e)|^2 = sinc^2(1/16) = 0.987 on average (0.06 dB); 64
        // elements give a little spread around that.
        let g0 = book.gain(0, 0.0);
        assert!((10.0 * g0.log10()).abs() < 0.3, "{g0}");
        // Half-power beamwidth 2 pi / N (5.6 deg, Sec. II) for this radius:
        // J0(2 pi R x) = 1/sqrt(2) at x = 1.126 / (2 pi 3.42) = 3.0 deg half
        // width, plus a little from the quantisation (numpy gave 6.01 deg).
        let bw = book.half_power_beamwidth_rad(0).to_degrees();
        assert!((bw - 6.0).abs() < 0.2, "{bw}");
        // The printed radius, 16 wavelengths, gives a 1.28 deg beam.
        let printed = UcaCodebook::new(UniformCircularArray::new(64, 16.0).unwrap(), 128, 4).unwrap();
        assert!((printed.half_power_beamwidth_rad(0).to_degrees() - 1.28).abs() < 0.05);
    }

    #[test]
    fn rotation_by_one_element_permutes_the_weights() {
        let book = paper();
        // Beam 2 is beam 0 rotated by 2 pi / 64, exactly (module docs).
        let d = std::f64::consts::TAU / 64.0;
        for &phi in &[0.1, 1.0, -2.5] {
            assert!((book.gain(2, phi + d) - book.gain(0, phi)).abs() < 1e-12);
            assert!((book.gain(7, phi + 3.0 * d) - book.gain(1, phi)).abs() < 1e-12);
        }
    }

    #[test]
    fn strongest_and_nearest_beams() {
        let book = paper();
        let spacing = book.spacing_rad();
        // On beam 5's axis beam 5 wins among its neighbours and over all beams.
        assert_eq!(book.strongest_of(0..128, 5.0 * spacing), Some(5));
        assert_eq!(book.strongest_of([4, 5, 6], 5.1 * spacing), Some(5));
        assert_eq!(book.strongest_of([], 0.0), None);
        assert_eq!(book.nearest_beams(5.2 * spacing, 3), vec![5, 6, 4]);
        assert_eq!(book.nearest_beams(-0.2 * spacing, 3), vec![0, 127, 1]);
        assert_eq!(book.nearest_beams(127.9 * spacing, 2), vec![0, 127]);
        assert!(book.nearest_beams(f64::NAN, 3).is_empty());
        assert_eq!(nearest_circular_beams(2, 0.1, 5).len(), 2);
        assert!(UniformCircularArray::new(0, 1.0).is_err());
        assert!(UniformCircularArray::new(4, f64::NAN).is_err());
        assert!(UcaCodebook::new(*book.array(), 0, 4).is_err());
        assert!(book.array().weights(0.0, 17).is_err());
    }
}
