//! The 5G mmWave SLAM pipeline's commands: `simulate slam` (the world of
//! Kim et al. 2018 into a recording), `process slam` (the filter on a
//! recording, into tables); `bench slam` (time per epoch) is
//! `mmtrack_reproduce::bench::slam`, the paper's experiment
//! `mmtrack_reproduce::kim`. `analyze` measures `process slam`'s tables
//! with `mmtrack_analysis::slam`.

pub mod simulate;
