//! # mmtrack-process
//!
//! Every mmtrack pipeline as a library call: a recording (path) and a
//! configuration in, Parquet tables out through `mmtrack-io`, progress
//! through [`mmtrack_core::progress::Progress`]. No clap, no terminal: the
//! `mmtrack` binary and the Python package are thin front ends over these
//! calls, and tests call them directly.
//!
//! - [`odometry`]: radar odometry (Fast-CFEAR / CFEAR) → `odometry`,
//!   `odometry_timing`, `ground_truth`;
//! - [`poses`]: a recording's own estimate and ground truth → `poses`,
//!   `ground_truth` (an external odometry scored like ours);
//! - [`mpc`]: CLEAN detection, short- and long-term MPC tracking and the
//!   GM-PHD baseline (Mahler et al. 2017) → `mpc_*`;
//! - [`beam`]: the beam-sweep trackers, SPEBT (Liu et al. 2024) and
//!   geometric Doppler-bearing tracking (Zoechmann et al. 2019);
//! - [`slam`]: 5G mmWave SLAM (Kim et al. 2018) → `slam_*`;
//! - [`simulate`]: the scenario simulators written as recordings;
//! - [`manifest`]: many sequences, each an independent task;
//! - [`output`]: where a pipeline writes (`--run-id`, `--force`,
//!   `--sequence`), shared by all;
//! - [`provenance`]: the input files a run records (canonical path, size,
//!   CRC-32);
//! - [`events`]: a recording read as a stream, scans decoded ahead in
//!   parallel;
//! - [`threads`]: the worker pool of a call (`--threads`).
//!
//! Every pipeline runs on the caller's rayon pool (the thread count never
//! changes a table), refuses existing tables before any work unless forced,
//! and records its full configuration and its inputs ([`provenance`]) in
//! the tables' metadata.

pub mod beam;
pub mod events;
pub mod manifest;
pub mod mpc;
pub mod odometry;
pub mod output;
pub mod poses;
pub mod provenance;
pub mod raw;
pub mod simulate;
pub mod slam;
pub mod threads;
