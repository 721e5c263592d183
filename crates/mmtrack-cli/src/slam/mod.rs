//! The 5G mmWave SLAM pipeline's commands: `reproduce kim` (the vehicular
//! SLAM experiment of Kim et al. 2018) and `bench slam` (time per epoch).

pub mod bench;
pub mod evaluate;
mod kim_report;
pub mod process;
pub mod reproduce_kim;
pub mod simulate;
