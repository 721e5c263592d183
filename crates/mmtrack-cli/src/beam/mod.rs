//! The beam-tracking pipeline's commands: `reproduce shaham` (the valid-tracking
//! experiment of Shaham et al. 2020) and `reproduce spebt` (the SPEBT beam
//! tracking of Liu et al. 2024) and `reproduce zoechmann` (geometric
//! Doppler-bearing tracking of Zoechmann et al. 2019).

pub mod reproduce_shaham;
pub mod reproduce_spebt;
pub mod reproduce_zoechmann;
mod shaham_report;
mod spebt_odometry;
mod spebt_output;
mod spebt_report;
mod zoechmann_nlos;
mod zoechmann_report;
