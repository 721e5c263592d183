//! # mmtrack-mpc
//!
//! Multipath-component (MPC) detection and tracking in wideband channel-sounder
//! data, after Mahler et al., "Tracking of Wideband Multipath Components in a
//! Vehicular Communication Scenario", IEEE TVT 66(1), 2017 (`seeds/` has the
//! paper):
//!
//! 1. [`Detector`]: per snapshot, noise floor + 6 dB, Kaiser window on the
//!    transfer function, search and subtract against the sounder pulse with
//!    maximum-likelihood sub-tap delay and complex amplitude (Sec. III-A);
//! 2. [`short_term`]: tracks within a set of snapshots (three-point
//!    initiation, linear prediction, search tolerances, per-track Doppler;
//!    Sec. III-B);
//! 3. [`long_term`]: full-lifetime tracks related across sets by two-way delay
//!    prediction with confidence classes chi (Sec. V);
//! 4. [`MpcPipeline`]: the three above (and optionally the GM-PHD baseline of
//!    [`gmphd`]) streamed over the sets of one link, with per-set statistics.
//!
//! Pure computation on in-memory types: no files, no printing. It sits in the
//! `process` step: recording -> CIR snapshots -> detections and tracks ->
//! tables.

mod config;
pub mod detect;
mod error;
pub mod gmphd;
pub mod long_term;
mod pipeline;
mod pulse;
pub mod short_term;

pub use config::{
    CandidateGate, DelayRate, DetectionConfig, LongTermConfig, MpcConfig, NoiseFloor, ShortTermConfig,
    ShortTermPrediction,
};
pub use detect::{Detector, SnapshotDetections};
pub use error::MpcError;
pub use gmphd::{GmPhdConfig, GmPhdError, GmPhdSnapshot, track_gmphd};
pub use long_term::LongTermTracker;
pub use pipeline::{MpcPipeline, SetOutput};
pub use pulse::SounderPulse;
pub use short_term::short_term_tracks;

/// Speed of light in vacuum, m/s.
pub const SPEED_OF_LIGHT_M_PER_S: f64 = 299_792_458.0;
