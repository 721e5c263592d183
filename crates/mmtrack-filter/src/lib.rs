//! # mmtrack-filter
//!
//! Estimation building blocks shared by the trackers (MPC, beam, SLAM): Kalman
//! predict/update, gating, assignment, the GM-PHD filter and the OSPA/GOSPA
//! metrics. Pure computation on in-memory types: no files, no printing.
//!
//! It sits in the *process* stage of the data flow (`recording -> process ->
//! tables`): the algorithm crates (`mmtrack-mpc`, `mmtrack-beam`,
//! `mmtrack-slam`) assemble their trackers from the roles here, Stone Soup
//! style, and `mmtrack-analysis` scores them with [`metrics`].
//!
//! - [`Gaussian`]: a validated mean/covariance pair (every covariance in the
//!   crate is checked symmetric positive definite on construction);
//! - [`models`]: constant-velocity motion in any number of axes, fixed linear
//!   transitions, linear measurements;
//! - [`kalman`]: the predictor and updater roles, with an explicit
//!   [`CovarianceUpdate`] (Joseph form by default);
//! - [`ekf`]: the extended Kalman filter for nonlinear models with analytic
//!   Jacobians (and a finite-difference check for them);
//! - [`gating`]: the gate role ([`Gate`]) and the Mahalanobis gate;
//! - [`assignment`]: Kuhn-Munkres on real costs, with forbidden pairs;
//! - [`gmphd`]: the labelled GM-PHD filter of Vo & Ma 2006;
//! - [`metrics`]: OSPA and GOSPA.
//!
//! Vectors and matrices are [`faer`] `Col<f64>`/`Mat<f64>` (faer is the
//! workspace's one linear-algebra crate, re-exported here as [`faer`]) so one
//! code path serves every state dimension; factorisations are faer's `L L^T`
//! (Cholesky). Shapes are checked at run time before any faer call (faer
//! panics on mismatched shapes), so a mismatch is a [`FilterError`], never a
//! panic.

pub mod assignment;
pub mod ekf;
mod error;
pub mod gating;
mod gaussian;
pub mod gmphd;
pub mod kalman;
mod label;
mod linalg;
pub mod metrics;
pub mod models;

pub use ekf::{ExtendedKalmanUpdater, NonlinearMeasurement, numerical_jacobian, predict_linearised};
pub use error::FilterError;
/// The linear-algebra crate of the public API, so dependants need not pin it.
pub use faer;
pub use gating::{Gate, GateCandidate, MahalanobisGate, NoGate};
pub use gaussian::{Gaussian, SYMMETRY_TOLERANCE};
pub use gmphd::{GmPhdFilter, GmPhdParams};
pub use kalman::{CovarianceUpdate, KalmanPredictor, KalmanUpdater, PreparedUpdate};
pub use label::Label;
pub use models::{ConstantVelocity, FixedTransition, LinearMeasurement, TransitionModel};
