//! # mmtrack-sim
//!
//! Scenario simulators that produce mmtrack data in memory, with ground truth,
//! so every pipeline runs identically on simulated and real data. Seeded and
//! deterministic: the same scenario and seed give the same bytes, whatever
//! the number of threads.
//!
//! Depends on `mmtrack-core` only, reads no files and prints nothing:
//! scenarios arrive as deserialised structs, trajectories as
//! `Vec<StampedPose>`, and scans leave as core types for the caller to write.
//!
//! ## Radar ([`radar`])
//!
//! A Navtech CTS350-X-like spinning radar in a 2D world of extended
//! reflectors, calibrated against real Oxford Radar RobotCar scans (the
//! model and the numbers are in the [`radar`] module docs).
//!
//! ```
//! use mmtrack_sim::radar::{ConstantTurn, GeneratorConfig, RadarSimulator, ScanLimits, Sensor, SimOptions, Trajectory, World, generate_world};
//!
//! // A trajectory: constant turn here; `Trajectory::from_poses(ground_truth)` for a real drive.
//! let trajectory = Trajectory::constant_turn(ConstantTurn { speed_mps: 8.0, yaw_rate_radps: 0.05 }, 0, 2.0)?;
//! // A world: a procedural street along it (plus any explicit `ReflectorSpec`s).
//! let world = World::new(&generate_world(&GeneratorConfig::default(), &trajectory, 7)?)?;
//! let sensor = Sensor { bins: 500, ..Sensor::default() };
//! let options = SimOptions { seed: 7, limits: ScanLimits { max_scans: Some(2), max_distance_m: None } };
//! // Scans stream one by one: a 2 km drive never sits in memory.
//! for (scan, world_from_vehicle) in RadarSimulator::new(&world, &sensor, &trajectory, options)? {
//!     assert_eq!(scan.power.len(), 400 * 500);
//!     assert_eq!(scan.header.t_ns, world_from_vehicle.t_ns);
//! }
//! # Ok::<(), mmtrack_sim::SimError>(())
//! ```
//!
//! ## Channel sounder ([`sounder`])
//!
//! A wideband sounder (5.7 GHz, 1 GHz, sets of snapshots) observing the
//! artificial two-MPC channel of Mahler et al. 2017 ([`sounder::artificial_channel`])
//! or a two-car convoy through a curved tunnel or on a highway
//! ([`sounder::ConvoySimulator`]), with the true MPCs and both cars' poses.
//!
//! ## Beam links ([`beam`])
//!
//! Links measured one pilot at a time through the beams a tracker chooses:
//! the overpass link of Shaham et al. 2020 ([`beam::overpass`]).
//!
//! The radar pieces:
//!
//! - [`radar::Scenario`]: the TOML scenario (sensor, `[motion]`,
//!   `[generator]`, `[[reflectors]]`, seed, cuts), with
//!   [`radar::Scenario::validate`], [`radar::Scenario::motion_trajectory`],
//!   [`radar::Scenario::build_world`] and [`radar::simulate_scenario`] for
//!   small in-memory runs.
//! - [`radar::Trajectory`]: constant turn or stamped poses (linear in x, y,
//!   shortest-arc yaw); [`radar::scan_stamps`] plans the sweeps, cut by
//!   [`radar::ScanLimits`] (first N scans or N metres).
//! - [`radar::generate_world`]: seeded building fronts, junction gaps, open
//!   stretches, parked cars, poles, trees and clutter along any trajectory,
//!   never within `clearance_m` of the path.
//! - [`radar::World`]: compiled reflectors in uniform grids; a beam visits
//!   only the cells it crosses, so cost does not grow with world size.
//! - [`radar::RadarSimulator`]: `Iterator<Item = (PolarScan, StampedPose)>`,
//!   rendering one sweep per thread of the current rayon pool at a time
//!   (per-sweep randomness from `(seed, sweep index)`), or any single sweep
//!   with `render(index)`.
//!
//! Speed (release build, this project's 2-core machine, Oxford-size sweeps of
//! 400 x 3768 in the default generated city, `cargo run --release -p
//! mmtrack-sim --example radar_speed`): 340 scans/s on 2 threads, 193 on one;
//! the CLI writes an Oxford PNG folder of 400 such scans in 3.7 s.

pub mod beam;
mod error;
pub mod radar;
pub mod slam;
pub mod sounder;

pub use error::SimError;

/// Where a simulated clock starts unless the scenario's `start_t_ns` says
/// otherwise: 2023-11-14 22:13:20 UTC (UNIX time 1 700 000 000 s), in
/// nanoseconds since the UNIX epoch. A stated date, not when anything was
/// measured: viewers that show dates (Foxglove) place a simulated recording
/// there rather than at 1970-01-01, and `t_ns` keeps nanosecond steps
/// (scenario times are differences from this start).
pub const DEFAULT_START_T_NS: i64 = 1_700_000_000_000_000_000;
