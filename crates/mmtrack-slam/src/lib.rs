//! # mmtrack-slam
//!
//! 5G mmWave vehicular SLAM after Kim, Wymeersch, Garcia, Seco-Granados and
//! Kim, "5G mmWave Vehicular Tracking", Asilomar 2018: from per-epoch sets of
//! path measurements (TOA, DOA and DOD azimuth and elevation, eq. (2)) it
//! tracks the UE state `[x, y, z, heading, speed, turn rate, clock bias]`
//! and maps the sources of the paths: the known base station, virtual
//! anchors (VA, one per reflecting wall) and scattering points (SP).
//!
//! Pure computation on in-memory types (`mmtrack-core`'s
//! [`mmtrack_core::slam`]); no files, no printing. It sits in the `process`
//! and `reproduce` stages of the data flow.
//!
//! ## One epoch ([`SlamFilter::step`])
//!
//! 1. **Prediction**, eq. (1): each UE particle moves by the constant
//!    turn-rate velocity model; speed, turn rate and clock bias take the
//!    process noise `Q`.
//! 2. **Association**, eq. (3)-(7): `log S_lm` for every (path, source) pair,
//!    with eq. (5)'s integral over the UE and the source belief done by
//!    linearisation at the predicted mean (`S = Sigma + H_s P_s H_s^T +
//!    H_m P_m H_m^T`), unconfirmed sources as the mixture (4) of their VA and
//!    SP hypotheses, "new source" columns `P_N I`, solved by Kuhn-Munkres
//!    ([`association::associate`]).
//! 3. **UE belief update** (Sec. IV-D): the messages of the paths from the
//!    BS and confirmed sources (the source belief integrated out) multiply
//!    the particle weights. At the first epoch the particles are drawn from
//!    the LOS message (step 1 of the paper's schedule).
//! 4. **Source updates**: a confirmed source takes the message from the UE
//!    (its posterior, Gaussian) by an iterated EKF; an unconfirmed source
//!    gets both hypotheses from the path and the UE particles (the SP /
//!    incidence point and the VA of eq. (12), Sec. IV-A).
//! 5. **Map maintenance** (Sec. III-D): footnote 3's fixed-point test
//!    promotes an unconfirmed source to VA or SP, close confirmed sources
//!    are merged, unconfirmed sources not seen for a few epochs forgotten.
//!
//! ## Where this differs from the paper, and why
//!
//! - The paper splits the UE into position, heading and clock-bias variables,
//!   which makes its factor graph loopy; it runs 10 message-passing
//!   iterations. Here the particles carry the joint UE state, so with one
//!   path per source per epoch the graph of an epoch is a tree (the UE in the
//!   middle, one factor per path, each linking it to one source) and one
//!   pass of messages is exact. The `iterations` budget (10) is spent where
//!   the approximation still needs it: up to 10 tempering stages of the UE
//!   update (progressive correction: the likelihood is taken in steps that
//!   keep half the particles effective, with a regularised resampling in
//!   between, so 2000 particles survive a 0.1 m / 10 mrad likelihood) and up
//!   to 10 relinearisations of each source's EKF.
//! - The 1-step smoother of Sec. IV-E is implicit: each particle carries its
//!   speed and turn rate through the prediction, so weighting by the epoch-k
//!   measurements weights `(v_{k-1}, omega_{k-1})` (step 2 of the smoother)
//!   and the process noise carries them to `(v_k, omega_k)` (step 4).
//! - `P_D = 1` makes eq. (3)'s `P_D / (1 - P_D)` infinite; the filter uses
//!   `detection_probability` (0.99 by default).
//! - A confirmed source's covariance is kept at least as large as the error
//!   the UE's current uncertainty induces in it
//!   ([`SlamConfig::ue_error_floor`]): message passing treats the slowly
//!   varying UE error as independent from epoch to epoch, and without the
//!   floor the map grew overconfident and held the UE to its early errors.
//!   A confirmed source's EKF takes the predicted UE belief as its message,
//!   so a path is not counted twice within an epoch.
//! - The UE initialises from the shortest path of an epoch only (a
//!   reflected or scattered path is longer than the line of sight), within
//!   a tighter gate ([`SlamConfig::initialisation_gate`]); until then the
//!   filter only predicts and maps nothing.
//!
//! Particles live in structure-of-arrays chunks of 256. An epoch is one
//! parallel region: a team of the calling thread and one helper per other
//! thread of the rayon pool runs the per-particle phases (prediction,
//! likelihood, weights, moments, resampling and jitter), the association's
//! per-source predictions and the paths' source updates, the calling
//! thread alone the serial steps in between
//! (`team`). Every random draw comes from a stream seeded by `(seed, epoch,
//! stage, chunk)`, and every sum over the particles that reaches the output
//! is taken per chunk, in particle order inside the chunk, in the pass that
//! computes its terms, then the chunks' partial sums are added in chunk
//! order. Chunks do not depend on the team, so a run is identical for any
//! thread count (to the bit; it is not the bits of a loop over all
//! particles in one chain of adds).

pub mod association;
mod config;
mod error;
mod filter;
mod map;
mod model;
mod particles;
mod small;
mod team;

pub use association::associate;
pub use config::SlamConfig;
pub use error::SlamError;
pub use filter::{Decision, EpochReport, PathAssociation, SlamFilter, UeEstimate};
pub use map::{Gauss3, MapSource, SourceStatus};
