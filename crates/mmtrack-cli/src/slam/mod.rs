//! The 5G mmWave SLAM pipeline's commands: `simulate slam` (the world of
//! Kim et al. 2018 into a recording), `process slam` (the filter on a
//! recording, into tables), `reproduce kim` (the paper's experiment) and
//! `bench slam` (time per epoch). `analyze` measures `process slam`'s tables
//! with `mmtrack_analysis::slam`.

pub mod bench;
pub mod evaluate;
mod kim_report;
pub mod reproduce_kim;
pub mod simulate;
