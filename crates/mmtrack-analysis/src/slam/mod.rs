//! 5G mmWave SLAM results on the tables of `mmtrack process slam` and of the
//! experiment of Kim et al. 2018 (`mmtrack reproduce kim`), declared in
//! `mmtrack_io::table`: the paper's metrics shared by both ([`metrics`]), the
//! per-sequence analysis of `mmtrack analyze` ([`analysis`]) and the figures
//! ([`plots`]).
//!
//! Pure data in, tables and SVG documents out; the Monte Carlo loop and the
//! filter run in the CLI.

pub mod analysis;
pub mod metrics;
pub mod plots;
