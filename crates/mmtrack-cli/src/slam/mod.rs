//! The 5G mmWave SLAM pipeline's commands: `simulate slam` (the world of
//! Kim et al. 2018 into a recording), `process slam` (the filter on a
//! recording, into tables) and `bench slam` (time per epoch); the paper's
//! experiment is `mmtrack_reproduce::kim`. `analyze` measures `process
//! slam`'s tables with `mmtrack_analysis::slam`.

pub mod bench;
pub mod simulate;
