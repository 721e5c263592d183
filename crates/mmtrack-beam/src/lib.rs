//! # mmtrack-beam
//!
//! Beam trackers for mmWave links to moving vehicles: each keeps a state of
//! the link, points the beams for the next pilot from its prediction, and
//! updates from the pilot it receives.
//!
//! - [`PositionVelocityEkf`]: Shaham et al. 2020, state `[d, v, Re alpha,
//!   Im alpha]` on the overpass link, linear motion, Jacobian (31);
//! - [`AngleEkf`]: the angle-state baseline of Va et al. 2016, state `[AoA,
//!   AoD, Re alpha, Im alpha]` with additive angle noise;
//! - [`SpebtEkf`]: the SPEBT beam tracker of Liu et al. 2024, state
//!   `[|alpha|, AoD, AoA]` driven by estimated vehicle poses (Proposition 2),
//!   measured by the pilot's power, re-initialised on large deviations;
//! - [`geometric`]: geometric Doppler-bearing tracking of Zoechmann et al.
//!   2019 (recursive H-infinity/RLS on the initial state, the Ho-Chan batch
//!   baseline, two genie bounds, beam selection with measurement counting);
//! - [`PilotTracker`]: the predict / update roles every such tracker plays,
//!   so experiments drive them alike; [`OpenLoop`] runs one's predictor
//!   without its updates (the open-loop baseline);
//! - [`valid_tracking`]: the paper's metric, blocks until the RMS angle error
//!   over Monte Carlo runs exceeds half the beamwidth;
//! - [`sweep`]: beam-sweep trackers for measured codebooks (a window around
//!   the predicted beam, from the beams alone or driven by the car's GNSS
//!   through a fitted beam map), their baselines and accounting.
//!
//! It sits in the *process* stage: pure computation on in-memory types (no
//! files, no printing); `mmtrack-sim` provides links to run on and
//! `mmtrack-reproduce` wires the experiments. Depends on `mmtrack-core` (arrays)
//! and `mmtrack-filter` (the EKF) only.

mod angle_ekf;
mod error;
pub mod geometric;
mod link;
mod position_velocity_ekf;
pub mod spebt;
pub mod sweep;
pub mod valid_tracking;

pub use angle_ekf::{AngleEkf, AngleEkfConfig};
pub use error::BeamError;
pub use link::{BeamPair, OpenLoop, PilotTracker};
pub use position_velocity_ekf::{PositionVelocityEkf, PositionVelocityEkfConfig, ProcessModel};
pub use spebt::{Deviation, SpebtConfig, SpebtEkf, SpebtState};
