//! A wideband channel sounder (the HHI sounder of Mahler et al. 2017:
//! 5.7 GHz, 1 GHz, sets of snapshots) observing either the paper's
//! artificial two-MPC channel or a two-car convoy through a curved tunnel or
//! on a highway, with the true multipath components (MPCs) as ground truth.
//!
//! # Signal model
//!
//! Shared with the MPC detector through [`mmtrack_core::sounder`]: a path of
//! complex amplitude `alpha` at delay `tau` after tap 0, seen through the
//! pulse spectrum `P[k]`, adds `alpha P[k] exp(-j 2 pi f_k tau)` to the
//! transfer function; the CIR is its inverse DFT (`1/U` normalised), so an
//! on-grid path through a flat pulse is exactly `alpha` at one tap. Powers
//! are `20 log10 |alpha|` on this tap scale. The noise floor is complex white
//! Gaussian noise of mean power `noise_floor_db` per CIR tap, added after
//! the inverse DFT. The pulse ([`PulseModel`]) is flat or measured-like
//! (raised-cosine band edges and a small amplitude/phase ripple), normalised
//! so an on-grid path still peaks at `alpha`; the spectrum used is exposed
//! ([`PulseModel::spectrum`], [`ConvoySimulator::pulse_spectrum`]) so the
//! detector can be given the same pulse or a flat model of it.
//!
//! A path's amplitude carries the carrier phase of its length,
//! `alpha = |alpha| exp(j (phi - 2 pi f_c tau))`, with a static seeded
//! `phi` per path, so the snapshot-to-snapshot phase rotation is the
//! Doppler `nu = -f_c d tau / dt` recorded in the truth.
//!
//! # Artificial channel ([`artificial_channel`])
//!
//! Mahler et al., Sec. IV-A, Fig. 3: two equal-power MPCs approaching in
//! delay over `N` continuous snapshots plus the noise floor
//! ([`ArtificialChannelConfig`]); a cheap pure function of the config and a
//! seed for the Monte Carlo sweeps of `reproduce mpc-artificial`.
//!
//! # Convoy ([`ConvoySimulator`])
//!
//! Sec. II-B: the transmitter car drives ahead of the receiver car (75..110
//! m apart, 42..52 km/h) through a curved tunnel (or on a highway). The
//! plane geometry, evaluated at every snapshot's time:
//!
//! - the road is a straight line or an arc of signed radius `R`; a lane at
//!   lateral offset `y` is the arc of radius `R - y`, and positions along it
//!   are lane arc lengths. The two cars' speeds swing smoothly within their
//!   ranges (`v(t) = v_mid + v_half sin(2 pi t / T + phi)`, seeded phase);
//! - tunnel walls are polylines of vertices on the arcs at `+-half_width_m`
//!   (wall 0 left, wall 1 right), `wall_segment_m` apart;
//! - paths, each kept when its every leg is clear of all wall segments
//!   (visibility), and with its length `L`, delay `tau = L / c`, Doppler
//!   `-f_c (dL/dt) / c` and power from free-space loss
//!   `g lambda / (4 pi L)` (`g` = `system_gain_db`):
//!   - the LOS;
//!   - single wall bounces by the image method per wall segment (the
//!     specular point of each segment clamped to it, the shortest over the
//!     wall's segments), `wall_reflection_loss_db` per bounce;
//!   - wall-to-wall double bounces (both orders), found by alternating
//!     the single-bounce solution of each reflection point (exact to
//!     machine precision on segment interiors; within 0.3 mm of path when
//!     a reflection point sits on a polyline vertex);
//!   - traffic cars (oncoming and same-direction, Poisson per km plus
//!     explicit ones) as point reflectors with the bistatic radar equation
//!     `g lambda sqrt(sigma) / ((4 pi)^(3/2) d1 d2)`; they appear and
//!     disappear as the walls hide them and as their delay enters and
//!     leaves the window;
//!   - diffuse components: Poisson scatterers on the walls (roadside on a
//!     highway), each `relative_power_db` below a specular bounce of the
//!     same length times a Rayleigh draw and `cos(incidence) cos(departure)`,
//!     random static phase; visibility per set, delay per snapshot. They are
//!     rendered but listed in the truth only with `diffuse.in_truth`.
//!
//!   Because reflection points are stationary points of the path length
//!   (Fermat), `dL/dt` is exact from the end legs:
//!   `v_tx . u(P1 -> TX) + v_rx . u(Pn -> RX)` (plus the car's velocity for
//!   traffic).
//!
//! **Delay axis.** `delay_offset_s` (default 200 ns, i.e. 60 m) is fixed for
//! the whole run, as with synchronised sounder clocks: truth `delay_s` is the
//! absolute propagation delay `L / c`, on the same axis as the taps (tap `k`
//! at `delay_offset_s + k / B`). Paths are rendered only when their delay
//! lies in `[guard_taps, U - noise_tail_taps]` taps after tap 0: with 512
//! taps that is 204..648 ns, 61..194 m of path, which holds the LOS of
//! 75..110 m and its wall bounces. Paths outside are dropped (they would
//! wrap around the circular CIR), and the last `noise_tail_taps` stay
//! path-free for the detector's noise-floor estimate.
//!
//! **Truth.** [`mmtrack_core::MpcTruth`] per snapshot for every rendered
//! specular path at least `truth_min_power_db` strong; `path_id` is stable
//! for a path while it exists ([`PathKind`]: LOS 0, single bounce off wall
//! `w` 100 + w, double bounce starting on wall `w` 200 + w, traffic car `i`
//! 1000 + i; diffuse scatterer `j`, with `diffuse.in_truth`, 1 000 000 + j).
//!
//! **Sets.** Snapshot `n` of set `m` is at
//! `start_t_ns + m * set_interval_s + n * snapshot_interval_s` (paper: 6
//! snapshots 0.717 ms apart, a set every 10 ms, 1666 sets). Both cars'
//! `world_from_vehicle` poses are given per set.
//!
//! Everything random comes from the seed through stateless hashes of
//! `(seed, stream, set, snapshot)`, so output is identical for any thread
//! count.
//!
//! Speed (release build, this project's 2-core machine, `cargo run --release
//! -p mmtrack-sim --example sounder_convoy 1666 1`): the paper's 1666 sets
//! (9996 CIRs of 512 taps, about 110 paths each, most of them diffuse) in
//! 2.7 s on one thread; summing the path phasors is most of it.
//!
//! # References
//! Mahler, Keusgen, Tufvesson, Zemen, Caire, "Tracking of wideband
//! multipath components in a vehicular communication scenario", IEEE TVT
//! 2017, Secs. II, III-A (eqs. 2-4) and IV-A.

mod artificial;
mod convoy;
mod geometry;
mod pulse;
mod render;
mod scenario;
mod simulator;

pub use artificial::{ArtificialChannelConfig, artificial_channel};
pub use convoy::{ConvoyConfig, ConvoyVehicles, DiffuseConfig, RoadConfig, RoadKind, TrafficCar, TrafficConfig};
pub use pulse::{PulseModel, SounderConfig};
pub use scenario::SounderScenario;
pub use simulator::{ConvoySimulator, SounderSet};

/// Speed of light in vacuum, metres per second (exact, SI).
pub const SPEED_OF_LIGHT_MPS: f64 = 299_792_458.0;

/// What kind of propagation path a convoy `path_id` names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum PathKind {
    /// Line of sight, id 0.
    Los,
    /// One wall bounce, id `100 + wall` (wall 0 left, 1 right).
    SingleBounce,
    /// Two wall bounces, id `200 + first wall`.
    DoubleBounce,
    /// A traffic car, id `1000 + car index`.
    Traffic,
    /// A diffuse scatterer, id `1_000_000 + scatterer index` (listed only
    /// with `diffuse.in_truth`).
    Diffuse,
}

impl PathKind {
    /// Also the traffic base, for readers of path ids.
    pub const TRAFFIC_BASE: u64 = 1000;

    /// The first diffuse scatterer id.
    pub const DIFFUSE_BASE: u64 = 1_000_000;

    /// The first id of this kind.
    #[must_use]
    pub fn base(self) -> u64 {
        match self {
            Self::Los => 0,
            Self::SingleBounce => 100,
            Self::DoubleBounce => 200,
            Self::Traffic => Self::TRAFFIC_BASE,
            Self::Diffuse => Self::DIFFUSE_BASE,
        }
    }

    /// The kind of a convoy path id, `None` for ids no convoy path uses.
    #[must_use]
    pub fn of(path_id: u64) -> Option<Self> {
        match path_id {
            0 => Some(Self::Los),
            100..=199 => Some(Self::SingleBounce),
            200..=299 => Some(Self::DoubleBounce),
            1000..Self::DIFFUSE_BASE => Some(Self::Traffic),
            Self::DIFFUSE_BASE.. => Some(Self::Diffuse),
            _ => None,
        }
    }
}
