//! Antenna arrays and beam codebooks: the response vectors, beamforming gains
//! and beamwidths that every beam tracker and beam simulator shares.
//!
//! # Directions
//! A uniform linear array (ULA) sees a direction only through its *direction
//! cosine* `u = cos(theta)`, where `theta` is the angle from the array axis
//! (Shaham et al. 2020, eq. (1); Liu et al. 2024 write the same with the angle
//! from broadside, `u = sin(theta_broadside)`). Every ULA function here takes
//! `u`; [`u_from_axis_angle`] and [`u_from_broadside_angle`] convert.
//!
//! # Conventions
//! Element `n` (`n = 0..N-1`, spacing `d` in wavelengths) of the response is
//!
//! ```text
//! a(u)[n] = exp(-j 2 pi d n u) / sqrt(N)                      (Shaham eq. (1)-(4))
//! ```
//!
//! and a beam steered to `u_s` uses the same vector as weights, `w = a(u_s)`.
//! The array factor is `w^H a(u) = (1/N) sum_n exp(-j 2 pi d n (u - u_s))`,
//! equal to 1 on the beam's axis, and the beamforming gain is its squared
//! magnitude.

use crate::Complex64;
use crate::error::{CoreError, ensure_finite};

/// A uniform linear array of `element_count` isotropic elements spaced
/// `spacing_wavelengths` apart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniformLinearArray {
    element_count: usize,
    spacing_wavelengths: f64,
}

impl UniformLinearArray {
    /// Checks and builds an array.
    ///
    /// # Errors
    /// [`CoreError::OutOfRange`] for no elements or a spacing that is not
    /// positive and finite.
    pub fn new(element_count: usize, spacing_wavelengths: f64) -> Result<Self, CoreError> {
        if element_count == 0 {
            return Err(CoreError::OutOfRange { field: "element_count", value: 0.0, expected: "at least one element" });
        }
        ensure_finite("spacing_wavelengths", spacing_wavelengths)?;
        if spacing_wavelengths <= 0.0 {
            return Err(CoreError::OutOfRange {
                field: "spacing_wavelengths",
                value: spacing_wavelengths,
                expected: "a positive spacing",
            });
        }
        Ok(Self { element_count, spacing_wavelengths })
    }

    /// The usual array: `element_count` elements half a wavelength apart.
    ///
    /// # Errors
    /// As [`UniformLinearArray::new`].
    pub fn half_wavelength(element_count: usize) -> Result<Self, CoreError> {
        Self::new(element_count, 0.5)
    }

    /// Number of elements `N`.
    #[must_use]
    pub fn element_count(&self) -> usize {
        self.element_count
    }

    /// Element spacing `d` in wavelengths.
    #[must_use]
    pub fn spacing_wavelengths(&self) -> f64 {
        self.spacing_wavelengths
    }

    /// The normalised response vector `a(u)` (module docs), `|a| = 1`.
    #[must_use]
    pub fn response(&self, u: f64) -> Vec<Complex64> {
        let scale = 1.0 / (self.element_count as f64).sqrt();
        let step = Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * self.spacing_wavelengths * u);
        let mut element = Complex64::new(scale, 0.0);
        (0..self.element_count)
            .map(|_| {
                let current = element;
                element *= step;
                current
            })
            .collect()
    }

    /// The array factor `w(steer_u)^H a(u)` (module docs): 1 on the beam axis.
    #[must_use]
    pub fn array_factor(&self, steer_u: f64, u: f64) -> Complex64 {
        self.array_factor_with_derivative(steer_u, u).0
    }

    /// The array factor and its derivative with respect to `u`:
    ///
    /// ```text
    /// AF(u)      = (1/N) sum_n exp(-j c n (u - u_s)),   c = 2 pi d
    /// dAF/du     = (1/N) sum_n (-j c n) exp(-j c n (u - u_s))
    /// ```
    ///
    /// (the factor of Shaham eq. (16) and, through the chain rule, of its
    /// Jacobian (31)). The phasors come from one `sin`/`cos` and a running
    /// product.
    #[must_use]
    pub fn array_factor_with_derivative(&self, steer_u: f64, u: f64) -> (Complex64, Complex64) {
        let c = 2.0 * std::f64::consts::PI * self.spacing_wavelengths;
        let step = Complex64::from_polar(1.0, -c * (u - steer_u));
        let mut phasor = Complex64::new(1.0, 0.0);
        let mut sum = Complex64::new(0.0, 0.0);
        let mut weighted = Complex64::new(0.0, 0.0);
        for n in 0..self.element_count {
            sum += phasor;
            weighted += phasor * n as f64;
            phasor *= step;
        }
        let n = self.element_count as f64;
        (sum / n, weighted * Complex64::new(0.0, -c) / n)
    }

    /// Beamforming gain `|w(steer_u)^H a(u)|^2`, 1 on the beam axis.
    #[must_use]
    pub fn gain(&self, steer_u: f64, u: f64) -> f64 {
        self.array_factor(steer_u, u).norm_sqr()
    }

    /// Half of the half-power (-3.01 dB) beamwidth in direction cosine: the
    /// smallest `delta_u > 0` with `gain(0, delta_u) = 1/2`, found by
    /// bisection inside the main lobe (`0 < delta_u < 1 / (N d)`, the first
    /// null). About `0.443 / (N d)` for large `N`.
    #[must_use]
    pub fn half_power_half_width_u(&self) -> f64 {
        let first_null_u = 1.0 / (self.element_count as f64 * self.spacing_wavelengths);
        if self.element_count == 1 {
            return f64::INFINITY;
        }
        let (mut inside, mut outside) = (0.0, first_null_u);
        for _ in 0..100 {
            let mid = 0.5 * (inside + outside);
            if self.gain(0.0, mid) >= 0.5 {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        0.5 * (inside + outside)
    }

    /// Full half-power beamwidth, radians, of a beam steered to the angle
    /// `steer_axis_angle_rad` from the array axis: the angular distance
    /// between the two half-power directions `acos(u_s -/+ delta_u)` (clamped
    /// to the visible region `|u| <= 1`).
    #[must_use]
    pub fn half_power_beamwidth_rad(&self, steer_axis_angle_rad: f64) -> f64 {
        let steer_u = steer_axis_angle_rad.cos();
        let delta_u = self.half_power_half_width_u();
        let low = (steer_u - delta_u).clamp(-1.0, 1.0).acos();
        let high = (steer_u + delta_u).clamp(-1.0, 1.0).acos();
        (low - high).abs()
    }
}

/// Direction cosine `u = cos(theta)` of an angle from the array axis.
#[must_use]
pub fn u_from_axis_angle(theta_rad: f64) -> f64 {
    theta_rad.cos()
}

/// Direction cosine `u = sin(theta)` of an angle from broadside.
#[must_use]
pub fn u_from_broadside_angle(theta_rad: f64) -> f64 {
    theta_rad.sin()
}

/// A beam codebook of a linear array: one steering direction cosine per beam,
/// beams indexed `0..len` in increasing `u`.
#[derive(Debug, Clone, PartialEq)]
pub struct Codebook {
    steer_u: Vec<f64>,
}

impl Codebook {
    /// A codebook from explicit steering direction cosines.
    ///
    /// # Errors
    /// [`CoreError::OutOfRange`] for an empty list, a `u` outside `[-1, 1]` or
    /// NaN, or directions not strictly increasing.
    pub fn new(steer_u: Vec<f64>) -> Result<Self, CoreError> {
        if steer_u.is_empty() {
            return Err(CoreError::OutOfRange { field: "codebook beams", value: 0.0, expected: "at least one beam" });
        }
        for (i, &u) in steer_u.iter().enumerate() {
            ensure_finite("codebook steer_u", u)?;
            if !(-1.0..=1.0).contains(&u) {
                return Err(CoreError::OutOfRange {
                    field: "codebook steer_u",
                    value: u,
                    expected: "a direction cosine in [-1, 1]",
                });
            }
            if i > 0 && u <= steer_u[i - 1] {
                return Err(CoreError::OutOfRange {
                    field: "codebook steer_u",
                    value: u,
                    expected: "directions in strictly increasing order",
                });
            }
        }
        Ok(Self { steer_u })
    }

    /// `beams` beams equally spaced in angle across a field of view of
    /// `fov_rad` centred on broadside (angles from broadside
    /// `-fov/2 + (i + 1/2) fov / beams`), like the 64-beam, 90-degree
    /// codebooks of measured 60 GHz arrays.
    ///
    /// # Errors
    /// [`CoreError::OutOfRange`] for no beams or a field of view outside
    /// `(0, pi]`.
    pub fn uniform_in_angle(beams: usize, fov_rad: f64) -> Result<Self, CoreError> {
        ensure_finite("fov_rad", fov_rad)?;
        if !(fov_rad > 0.0 && fov_rad <= std::f64::consts::PI) {
            return Err(CoreError::OutOfRange { field: "fov_rad", value: fov_rad, expected: "in (0, pi]" });
        }
        let step = fov_rad / beams as f64;
        Self::new((0..beams).map(|i| u_from_broadside_angle(-0.5 * fov_rad + (i as f64 + 0.5) * step)).collect())
    }

    /// The DFT codebook of an `element_count`-element array:
    /// `u_i = -1 + (2 i + 1) / N` in the visible region (orthogonal beams for
    /// half-wavelength spacing).
    ///
    /// # Errors
    /// [`CoreError::OutOfRange`] for zero elements.
    pub fn dft(element_count: usize) -> Result<Self, CoreError> {
        let n = element_count as f64;
        Self::new((0..element_count).map(|i| -1.0 + (2.0 * i as f64 + 1.0) / n).collect())
    }

    /// Number of beams.
    #[must_use]
    pub fn len(&self) -> usize {
        self.steer_u.len()
    }

    /// Always false: a codebook has at least one beam.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.steer_u.is_empty()
    }

    /// Steering direction cosines, beam order.
    #[must_use]
    pub fn steer_u(&self) -> &[f64] {
        &self.steer_u
    }

    /// The beam whose steering direction is nearest to `u`.
    #[must_use]
    pub fn nearest_beam(&self, u: f64) -> usize {
        let after = self.steer_u.partition_point(|&s| s < u);
        match after {
            0 => 0,
            n if n == self.steer_u.len() => n - 1,
            n => {
                if u - self.steer_u[n - 1] <= self.steer_u[n] - u {
                    n - 1
                } else {
                    n
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ula16() -> UniformLinearArray {
        UniformLinearArray::half_wavelength(16).unwrap()
    }

    #[test]
    fn response_is_unit_norm_and_gain_is_one_on_axis() {
        let array = ula16();
        let a = array.response(0.3);
        let norm: f64 = a.iter().map(Complex64::norm_sqr).sum();
        assert!((norm - 1.0).abs() < 1e-12);
        assert!((array.gain(0.3, 0.3) - 1.0).abs() < 1e-12);
        // w^H a from the vectors equals the closed sum.
        let w = array.response(0.1);
        let direct: Complex64 = w.iter().zip(&a).map(|(w, a)| w.conj() * a).sum();
        assert!((direct - array.array_factor(0.1, 0.3)).norm() < 1e-12);
    }

    #[test]
    fn derivative_matches_finite_differences() {
        let array = ula16();
        let h = 1e-7;
        for &(steer, u) in &[(0.0, 0.02), (-0.7, -0.65), (0.5, 0.9)] {
            let (_, d) = array.array_factor_with_derivative(steer, u);
            let numeric = (array.array_factor(steer, u + h) - array.array_factor(steer, u - h)) / (2.0 * h);
            // Central differences: error O(h^2 |AF'''|) ~ 1e-14 * 1e5, far below 1e-6.
            assert!((d - numeric).norm() < 1e-6, "{d} vs {numeric}");
        }
    }

    #[test]
    fn half_power_width_of_a_16_element_array() {
        let array = ula16();
        let delta_u = array.half_power_half_width_u();
        assert!((array.gain(0.0, delta_u) - 0.5).abs() < 1e-12);
        // The textbook 0.886 / (N d) full width: 0.1108 in u, within 0.5 %.
        assert!((2.0 * delta_u - 0.886 / 8.0).abs() < 0.005 * 0.1108, "{delta_u}");
        // At 135 degrees from the axis the beam is wider by 1 / sin(135 deg).
        let bw = array.half_power_beamwidth_rad(135f64.to_radians());
        assert!((bw - 2.0 * delta_u / 45f64.to_radians().sin()).abs() < 2e-3, "{}", bw.to_degrees());
    }

    #[test]
    fn codebooks() {
        let fov = 90f64.to_radians();
        let book = Codebook::uniform_in_angle(64, fov).unwrap();
        assert_eq!(book.len(), 64);
        assert!(book.steer_u()[0] < 0.0 && book.steer_u()[63] > 0.0);
        assert_eq!(book.nearest_beam(book.steer_u()[17] + 1e-6), 17);
        assert_eq!(book.nearest_beam(-1.0), 0);
        assert_eq!(book.nearest_beam(1.0), 63);
        let dft = Codebook::dft(16).unwrap();
        let array = ula16();
        // DFT beams of a half-wavelength array are orthogonal.
        assert!(array.gain(dft.steer_u()[3], dft.steer_u()[4]) < 1e-20);
        assert!(Codebook::new(vec![]).is_err());
        assert!(Codebook::new(vec![0.1, 0.1]).is_err());
        assert!(Codebook::new(vec![f64::NAN]).is_err());
        assert!(Codebook::uniform_in_angle(0, fov).is_err());
        assert!(UniformLinearArray::new(0, 0.5).is_err());
        assert!(UniformLinearArray::new(4, -0.5).is_err());
    }
}
