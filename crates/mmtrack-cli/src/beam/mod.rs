//! The beam-tracking pipeline's commands: `process beam` and `reproduce
//! spebt` (the SPEBT beam tracking of Liu et al. 2024). The Shaham and
//! Zoechmann experiments are in `mmtrack_reproduce`.

pub mod reproduce_spebt;
mod spebt_odometry;
mod spebt_output;
mod spebt_report;
