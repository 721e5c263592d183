//! # mmtrack-sim
//!
//! Scenario simulators that produce mmtrack data in memory, with ground truth,
//! so every pipeline runs identically on simulated and real data. Seeded and
//! deterministic: the same scenario and seed give the same bytes.
//!
//! Depends on `mmtrack-core` only and reads no files: scenarios arrive as
//! deserialised structs, output leaves as core types for the caller to write.
//!
//! So far: [`radar`], a spinning-radar renderer for small fixtures (point and
//! wall reflectors, per-azimuth motion, range spread, receiver noise). The full
//! simulator of issue #4 (occlusion by extended objects, speckle, multipath
//! ghosts, real trajectories) extends it.

pub mod radar;
