//! # mmtrack-core
//!
//! The data model every other mmtrack crate speaks, plus the small math that
//! belongs with it. It owns:
//!
//! - time: `i64` nanoseconds since the UNIX epoch (or since scenario start for
//!   simulations), always in fields named `t_ns`;
//! - [`Se2`] rigid transforms (`world_from_vehicle`) with composition and inverse;
//! - [`PolarScan`]: a spinning-radar sweep with per-azimuth time, angle and validity;
//! - [`CirSnapshot`]: one channel impulse response with its tap spacing and its
//!   position in the sounder's set/snapshot structure;
//! - [`BeamSweep`]: received power per measured beam of one codebook sweep;
//! - [`GnssFix`], [`MpcDetection`], [`MpcTrack`], [`MpcTruth`] and [`OdometryEstimate`];
//! - [`array`]: antenna array responses, beamforming gains, beamwidths and
//!   beam codebooks; [`array_uca`]: uniform circular arrays and their
//!   phase-quantised codebooks;
//! - [`progress`]: the trait long library calls report their progress through;
//! - [`parallel`]: order-keeping parallel maps on rayon, for every parallel stage;
//! - [`random`]: the seeded random streams (SplitMix64 of words into `Pcg64`)
//!   and the standard-normal, exponential and gamma draws every simulator,
//!   filter and benchmark uses, so a seed means the same draws everywhere;
//! - [`plausible`]: the bounds every reader checks values from files against
//!   (latitude, altitude, coordinates, angles, rotations, scan row times);
//! - [`stats`]: quantiles (linear and nearest-rank), median, root mean square and `erfc`;
//! - [`sounder`]: the channel-sounder signal model (frequency grid, Kaiser
//!   window, path spectra) shared by the sounder simulator and the MPC detector.
//!
//! It must not do I/O, print, or depend on any other mmtrack crate: it sits at
//! the bottom of the data flow (`ingest -> recording -> process -> tables ->
//! analyze`) and everything else depends on it.
//!
//! Units are SI and named in identifiers (`range_m`, `delay_s`, `azimuth_rad`);
//! geodetic latitude/longitude are the one exception and are named `_deg`.

pub mod array;
pub mod array_uca;
mod beam_sweep;
pub mod calendar;
mod cir;
pub mod error;
mod gnss;
pub mod limits;
mod mpc;
mod odometry;
pub mod parallel;
pub mod plausible;
mod pose;
pub mod progress;
mod radar;
pub mod random;
pub mod slam;
pub mod sounder;
pub mod stats;
pub mod words;

pub use beam_sweep::BeamSweep;
pub use cir::CirSnapshot;
pub use error::CoreError;
pub use gnss::{GnssFix, GnssFixQuality};
pub use mpc::{MpcDetection, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth, PathGeometry};
pub use num_complex::Complex64;
pub use odometry::{OdometryEstimate, OdometryTiming};
pub use pose::{Se2, StampedPose, interpolate_pose, path_length_m, wrap_angle_rad};
pub use radar::{AzimuthSample, PolarScan, PolarScanHeader};

/// Nanoseconds per second, for converting `t_ns` to seconds at the edges.
pub const NS_PER_S: i64 = 1_000_000_000;

/// Converts a nanosecond timestamp to seconds (for display and arithmetic on
/// durations; never store time as `f64`).
#[must_use]
pub fn ns_to_s(t_ns: i64) -> f64 {
    t_ns as f64 * 1e-9
}
