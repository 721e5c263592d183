//! 5G mmWave SLAM results: the experiment of Kim et al. 2018 (`mmtrack
//! reproduce kim`) as result tables ([`tables`]) and figures ([`plots`]).
//!
//! Pure data in, tables and SVG documents out; the Monte Carlo loop and the
//! filter run in the CLI.

pub mod analysis;
pub mod metrics;
pub mod plots;
pub mod tables;
