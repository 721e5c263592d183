//! Beam-tracking scenarios: links whose geometry changes as a vehicle moves,
//! measured one pilot at a time through the beams a tracker chooses.
//!
//! - [`overpass`]: the vehicle-to-infrastructure overpass link of Shaham et
//!   al. 2020 (base station on an overpass, vehicle on the road below);
//! - [`overtaking`]: the half- and full-overtaking manoeuvres of Zoechmann et
//!   al. 2019 (60 GHz UCA codebook scans and Doppler between two cars), and
//!   [`overtaking_paths`]: their wall-reflected paths by the image method;
//! - [`spebt_link`]: the SPEBT link of Liu et al. 2024 along any trajectory,
//!   with the paper's pose-error model.

pub mod overpass;
pub mod overtaking;
pub mod overtaking_paths;
pub mod spebt_link;
