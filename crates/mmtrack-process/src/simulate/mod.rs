//! The scenario simulators (`mmtrack_sim`) written as recordings in the
//! canonical format, with ground truth: radar scans ([`radar`], also as an
//! Oxford-layout folder), channel-sounder CIRs ([`sounder`]) and 5G mmWave
//! SLAM path measurements ([`slam`]).

pub mod radar;
pub mod slam;
pub mod sounder;
