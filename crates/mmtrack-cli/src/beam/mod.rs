//! The beam-tracking pipeline's commands: `reproduce shaham` (the valid-tracking
//! experiment of Shaham et al. 2020).

pub mod process;
pub mod reproduce_shaham;
mod shaham_report;
