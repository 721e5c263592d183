//! The proposed recursive tracker of Zoechmann et al. 2019, Sec. IV.
//!
//! The state is the *initial* state `x^i` (fixed reference: the first
//! epoch), refined by one pair of equations per epoch (8), (12)-(13):
//!
//! ```text
//! y_k = [0, nu_k]^T = A_k x^i + n_k,   A_k = [a_B^T; a_D^T]                   (13)
//! x^_k = x^_(k-1) + P_k A_k^T H_k (y_k - A_k x^_(k-1))                      (15)
//! H_k  = I (RLS),   (I + A_k P_k A_k^T)^-1 (H-infinity)                     (16)
//! P_k^-1 = P_(k-1)^-1 + A_k^T A_k (RLS),
//!          P_(k-1)^-1 + (1 - gamma^-2) A_k^T A_k (H-infinity)               (19)
//! ```
//!
//! with `x^_0 = 0` and `gamma = 2` (Sec. IV). The information matrix
//! `P^-1` is updated (19) and inverted (3x3 Cholesky) rather than `P`
//! through (17)-(18): the paper's remark, and it keeps `P` symmetric
//! positive definite by construction (a sum of a positive definite start and
//! positive semi-definite terms; for H-infinity `1 - gamma^-2 > 0` needs
//! `gamma > 1`, checked).
//!
//! The filter starts in H-infinity mode and hands over to RLS once three
//! distinct azimuths have been measured (the regression matrix is rank
//! deficient while the azimuth does not change, Sec. IV): the epoch that
//! brings the third distinct azimuth is the first RLS epoch. RLS continues
//! from the H-infinity state and information matrix. While the azimuth never
//! changes, `b = 0`: the first column of every `A_k` is zero, the range
//! `r_i` is unobserved and stays at its start value 0 (its information stays
//! at the prior's), every quantity stays finite, and [`GeometricTracker::mode`]
//! reports "not converged".
//!
//! The initial information `P_0^-1 = c I` (default `c = 1`) is the unit
//! weight of the initial error in the H-infinity criterion (14); the paper
//! gives no other value.
//!
//! # Where the printed equations are ambiguous
//! (18) prints the indefinite block `-gamma I` where the information form
//! (19) implies `-gamma^2 I`; (19) is implemented. (16) is used as printed,
//! with `P_k` (after the update).

// Index loops read like the formulas on these 3x3 arrays.
#![allow(clippy::needless_range_loop)]

use super::linalg::{Sym3, add_outer, cholesky, cholesky_inverse, dot, mul};
use super::{
    DopplerBearing, GeometricError, PolarState, RangeEstimator, bearing_row, check_config, check_time,
    check_wavelength, doppler_row,
};

/// Parameters of [`GeometricTracker`]; the defaults are the paper's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeometricTrackerConfig {
    /// Carrier wavelength `lambda`, metres (60 GHz: 4.997 mm).
    pub wavelength_m: f64,
    /// H-infinity level `gamma` (2), must exceed 1.
    pub gamma: f64,
    /// `c` of the initial information `P_0^-1 = c I` (1).
    pub initial_information: f64,
    /// Distinct azimuths after which RLS takes over (3); 0 runs RLS from
    /// the start.
    pub distinct_azimuths_for_rls: usize,
}

impl Default for GeometricTrackerConfig {
    fn default() -> Self {
        Self { wavelength_m: 299_792_458.0 / 60e9, gamma: 2.0, initial_information: 1.0, distinct_azimuths_for_rls: 3 }
    }
}

impl GeometricTrackerConfig {
    /// Checks every field.
    ///
    /// # Errors
    /// [`GeometricError::BadConfig`] naming the field.
    pub fn validate(&self) -> Result<(), GeometricError> {
        check_wavelength(self.wavelength_m)?;
        check_config("gamma", self.gamma, self.gamma > 1.0, "a level above 1 (1 - gamma^-2 > 0)")?;
        check_config(
            "initial_information",
            self.initial_information,
            self.initial_information > 0.0,
            "a positive weight",
        )
    }
}

/// Which recursion the tracker runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FilterMode {
    /// H-infinity: fewer than the configured distinct azimuths so far ("not
    /// converged").
    HInfinity,
    /// Recursive least squares (converged).
    Rls,
}

/// The proposed tracker (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct GeometricTracker {
    config: GeometricTrackerConfig,
    /// Reference epoch `(t_i, phi^_i)`, set by the first observation.
    reference: Option<(f64, f64)>,
    x: [f64; 3],
    information: Sym3,
    /// Distinct measured azimuths so far (at most the configured number).
    distinct: Vec<f64>,
    mode: FilterMode,
    epochs: usize,
    last: Option<DopplerBearing>,
    handover_t_s: Option<f64>,
}

impl GeometricTracker {
    /// A tracker at `x^_0 = 0`, `P_0^-1 = c I`.
    ///
    /// # Errors
    /// [`GeometricError::BadConfig`] for an invalid config.
    pub fn new(config: GeometricTrackerConfig) -> Result<Self, GeometricError> {
        config.validate()?;
        let c = config.initial_information;
        let mode = if config.distinct_azimuths_for_rls == 0 { FilterMode::Rls } else { FilterMode::HInfinity };
        Ok(Self {
            config,
            reference: None,
            x: [0.0; 3],
            information: [[c, 0.0, 0.0], [0.0, c, 0.0], [0.0, 0.0, c]],
            distinct: Vec::with_capacity(config.distinct_azimuths_for_rls),
            mode,
            epochs: 0,
            last: None,
            handover_t_s: None,
        })
    }

    /// The recursion in use: H-infinity means "not converged".
    #[must_use]
    pub fn mode(&self) -> FilterMode {
        self.mode
    }

    /// Whether RLS has taken over (three distinct azimuths seen).
    #[must_use]
    pub fn converged(&self) -> bool {
        self.mode == FilterMode::Rls
    }

    /// Time of the first RLS epoch, seconds; `None` while not converged.
    #[must_use]
    pub fn handover_t_s(&self) -> Option<f64> {
        self.handover_t_s
    }

    /// Epochs processed.
    #[must_use]
    pub fn epochs(&self) -> usize {
        self.epochs
    }

    /// The information matrix `P^-1` (19).
    #[must_use]
    pub fn information(&self) -> [[f64; 3]; 3] {
        self.information
    }

    /// Distinct azimuths measured so far (capped at the handover count).
    #[must_use]
    pub fn distinct_azimuths(&self) -> usize {
        self.distinct.len()
    }

    /// The regression pair `(A_k, y_k)` (13) of an observation against the
    /// reference `(t_i, phi_i)`.
    #[must_use]
    pub fn regression(
        observation: &DopplerBearing,
        reference: (f64, f64),
        wavelength_m: f64,
    ) -> ([[f64; 3]; 2], [f64; 2]) {
        let b = mmtrack_core::wrap_angle_rad(observation.azimuth_rad - reference.1);
        let t = observation.t_s - reference.0;
        ([bearing_row(b, t), doppler_row(b, wavelength_m)], [0.0, observation.doppler_hz])
    }
}

impl RangeEstimator for GeometricTracker {
    fn update(&mut self, observation: &DopplerBearing) -> Result<(), GeometricError> {
        let epoch = self.epochs;
        observation.check(epoch)?;
        check_time(epoch, observation.t_s, self.last.map(|l| l.t_s))?;
        let reference = self.reference.unwrap_or((observation.t_s, observation.azimuth_rad));
        let (mut mode, mut handover_t_s, mut new_azimuth) = (self.mode, self.handover_t_s, false);
        if mode == FilterMode::HInfinity
            && !self.distinct.contains(&observation.azimuth_rad)
            && self.distinct.len() < self.config.distinct_azimuths_for_rls
        {
            new_azimuth = true;
            if self.distinct.len() + 1 >= self.config.distinct_azimuths_for_rls {
                mode = FilterMode::Rls;
                handover_t_s = Some(observation.t_s);
            }
        }
        let (a, y) = Self::regression(observation, reference, self.config.wavelength_m);
        let weight = match mode {
            FilterMode::Rls => 1.0,
            FilterMode::HInfinity => 1.0 - self.config.gamma.powi(-2),
        };
        let mut information = self.information;
        for row in &a {
            add_outer(&mut information, row, weight);
        }
        let numerical = |detail| GeometricError::Numerical { epoch, detail };
        let p = cholesky_inverse(&cholesky(&information).ok_or(numerical("P^-1 not positive definite"))?);
        let residual = [y[0] - dot(&a[0], &self.x), y[1] - dot(&a[1], &self.x)];
        // Gain applied to the residual: H_k (16) times it.
        let weighted = match mode {
            FilterMode::Rls => residual,
            FilterMode::HInfinity => {
                // S = I + A P A^T (2x2, symmetric positive definite).
                let pa = [mul(&p, &a[0]), mul(&p, &a[1])];
                let s00 = 1.0 + dot(&a[0], &pa[0]);
                let s01 = dot(&a[0], &pa[1]);
                let s11 = 1.0 + dot(&a[1], &pa[1]);
                let det = s00 * s11 - s01 * s01;
                if !(det > 0.0 && det.is_finite()) {
                    return Err(numerical("I + A P A^T not positive definite"));
                }
                [(s11 * residual[0] - s01 * residual[1]) / det, (s00 * residual[1] - s01 * residual[0]) / det]
            }
        };
        // x += P A^T weighted.
        let at_w = [
            a[0][0] * weighted[0] + a[1][0] * weighted[1],
            a[0][1] * weighted[0] + a[1][1] * weighted[1],
            a[0][2] * weighted[0] + a[1][2] * weighted[1],
        ];
        let step = mul(&p, &at_w);
        let x = [self.x[0] + step[0], self.x[1] + step[1], self.x[2] + step[2]];
        if !x.iter().all(|v| v.is_finite()) {
            return Err(numerical("state not finite"));
        }
        self.x = x;
        self.information = information;
        self.reference = Some(reference);
        if new_azimuth {
            self.distinct.push(observation.azimuth_rad);
        }
        self.mode = mode;
        self.handover_t_s = handover_t_s;
        self.last = Some(*observation);
        self.epochs += 1;
        Ok(())
    }

    fn state(&self) -> Option<PolarState> {
        self.reference.map(|(t_ref_s, azimuth_ref_rad)| PolarState { t_ref_s, azimuth_ref_rad, x: self.x })
    }

    fn range_now_m(&self) -> Option<f64> {
        Some(self.state()?.range_m(self.last?.t_s))
    }
}
