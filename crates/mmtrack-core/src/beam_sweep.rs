//! One beam sweep of a codebook: the received power of each beam that was
//! measured at one time.
//!
//! A measured codebook (e.g. the 64-beam, 90-degree codebook of a 60 GHz
//! phased array) is swept beam by beam; a tracker measures only some beams,
//! a full sweep measures all of them. The record keeps one power slot per
//! codebook beam and says which slots hold a measurement.

use crate::error::{CoreError, ensure_finite, ensure_len};

/// Received power per beam of one sweep, with which beams were measured.
///
/// Powers are linear (e.g. milliwatts, or normalised as the source gives
/// them), one slot per codebook beam in codebook order; a slot of a beam
/// that was not measured holds no information (conventionally `0.0`) and
/// [`BeamSweep::power`] returns `None` for it.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamSweep {
    t_ns: i64,
    power: Vec<f64>,
    measured: Vec<bool>,
}

impl BeamSweep {
    /// Checks and builds a sweep.
    ///
    /// # Errors
    /// - [`CoreError::OutOfRange`] for zero beams, a negative power, or no
    ///   beam measured;
    /// - [`CoreError::NotFinite`] for a NaN or infinite power;
    /// - [`CoreError::ShapeMismatch`] when `measured` and `power` differ in
    ///   length.
    pub fn new(t_ns: i64, power: Vec<f64>, measured: Vec<bool>) -> Result<Self, CoreError> {
        if power.is_empty() {
            return Err(CoreError::OutOfRange {
                field: "beam sweep beam count",
                value: 0.0,
                expected: "at least one beam",
            });
        }
        ensure_len("beam sweep measured flags (one per beam power)", power.len(), measured.len())?;
        for &p in &power {
            ensure_finite("beam sweep power (linear)", p)?;
            if p < 0.0 {
                return Err(CoreError::OutOfRange {
                    field: "beam sweep power (linear)",
                    value: p,
                    expected: "a non-negative linear power",
                });
            }
        }
        if !measured.iter().any(|&m| m) {
            return Err(CoreError::OutOfRange {
                field: "beam sweep measured beams",
                value: 0.0,
                expected: "at least one measured beam",
            });
        }
        Ok(Self { t_ns, power, measured })
    }

    /// A full sweep: every beam measured.
    ///
    /// # Errors
    /// As [`BeamSweep::new`].
    pub fn full(t_ns: i64, power: Vec<f64>) -> Result<Self, CoreError> {
        let measured = vec![true; power.len()];
        Self::new(t_ns, power, measured)
    }

    /// Sweep time, nanoseconds.
    #[must_use]
    pub fn t_ns(&self) -> i64 {
        self.t_ns
    }

    /// Number of beams of the codebook (measured or not), at least one.
    #[must_use]
    pub fn beam_count(&self) -> usize {
        self.power.len()
    }

    /// Whether `beam` was measured (false for a beam outside the codebook).
    #[must_use]
    pub fn is_measured(&self, beam: usize) -> bool {
        self.measured.get(beam).copied().unwrap_or(false)
    }

    /// Linear power of `beam`; `None` when it was not measured or is outside
    /// the codebook.
    #[must_use]
    pub fn power(&self, beam: usize) -> Option<f64> {
        if self.is_measured(beam) { self.power.get(beam).copied() } else { None }
    }

    /// Number of measured beams.
    #[must_use]
    pub fn measured_count(&self) -> usize {
        self.measured.iter().filter(|&&m| m).count()
    }

    /// Whether every beam was measured.
    #[must_use]
    pub fn is_full(&self) -> bool {
        self.measured.iter().all(|&m| m)
    }

    /// The strongest measured beam (the lowest index among equal powers).
    #[must_use]
    pub fn best_measured_beam(&self) -> usize {
        let mut best = None::<(usize, f64)>;
        for (beam, (&p, &m)) in self.power.iter().zip(&self.measured).enumerate() {
            if m && best.is_none_or(|(_, best_p)| p > best_p) {
                best = Some((beam, p));
            }
        }
        // `new` guarantees at least one measured beam.
        best.map_or(0, |(beam, _)| beam)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_sweep_reports_its_best_beam_and_counts() {
        let sweep = BeamSweep::full(5, vec![0.1, 0.4, 0.4, 0.2]).unwrap();
        assert_eq!(sweep.t_ns(), 5);
        assert_eq!(sweep.beam_count(), 4);
        assert_eq!(sweep.measured_count(), 4);
        assert!(sweep.is_full());
        // Ties go to the lower index.
        assert_eq!(sweep.best_measured_beam(), 1);
        assert_eq!(sweep.power(3), Some(0.2));
        assert_eq!(sweep.power(4), None);
    }

    #[test]
    fn partial_sweep_hides_unmeasured_beams() {
        let sweep = BeamSweep::new(0, vec![0.0, 0.3, 9.0], vec![true, true, false]).unwrap();
        assert_eq!(sweep.measured_count(), 2);
        assert!(!sweep.is_full());
        assert_eq!(sweep.power(2), None, "unmeasured");
        assert_eq!(sweep.best_measured_beam(), 1, "the unmeasured 9.0 does not count");
    }

    #[test]
    fn bad_sweeps_are_errors() {
        assert!(matches!(BeamSweep::full(0, vec![]), Err(CoreError::OutOfRange { .. })), "zero beams");
        assert!(matches!(BeamSweep::full(0, vec![0.1, f64::NAN]), Err(CoreError::NotFinite { .. })), "NaN power");
        assert!(
            matches!(BeamSweep::full(0, vec![0.1, f64::INFINITY]), Err(CoreError::NotFinite { .. })),
            "infinite power"
        );
        assert!(
            matches!(BeamSweep::full(0, vec![0.1, -1e-3]), Err(CoreError::OutOfRange { value, .. }) if value == -1e-3),
            "negative power"
        );
        assert_eq!(
            BeamSweep::new(0, vec![0.1, 0.2], vec![true]),
            Err(CoreError::ShapeMismatch {
                what: "beam sweep measured flags (one per beam power)",
                expected: 2,
                found: 1
            }),
            "mismatched lengths"
        );
        assert!(
            matches!(BeamSweep::new(0, vec![0.1], vec![false]), Err(CoreError::OutOfRange { .. })),
            "nothing measured"
        );
    }
}
