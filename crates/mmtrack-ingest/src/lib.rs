//! # mmtrack-ingest
//!
//! Adapters from the formats users have to mmtrack's canonical recording
//! (`mmtrack-io`). Each adapter parses bytes into core types (pure functions,
//! tested on bytes) and streams them into a [`mmtrack_io::RecordingWriter`] so
//! memory stays flat however long the sequence. Ingest never modifies its
//! input and decodes no more than it must: radar PNGs are carried unchanged.
//!
//! It depends on `mmtrack-core` and `mmtrack-io` only, never on algorithms, and
//! does not print: long operations report through a progress callback.
//!
//! Sources so far: Navtech polar scan folders of Oxford Radar RobotCar
//! ([`oxford`], with ground truth, GPS and INS), Boreas ([`boreas`], with the
//! Applanix poses) and MulRan ([`mulran`], with its global poses); ROS 2 bags
//! ([`ros2`]); trajectory files ([`poses`]); NMEA 0183 logs ([`nmea`]);
//! channel-sounder CIR/CFR files ([`cir`]); measured beam sweeps with both
//! units' positions ([`beams`]: DeepSense 6G 60 GHz).

pub mod beams;
pub mod boreas;
pub mod cdr;
pub mod cir;
mod csv;
mod error;
pub mod flags;
pub mod mulran;
pub mod nmea;
pub mod oxford;
pub mod poses;
pub mod ros2;
pub mod ros2_image;
pub mod scan_folder;
pub mod sweep;
pub mod target;

pub use error::IngestError;

/// Progress of a long ingest: `done` of `total` items (scans, lines, ...).
/// `Send`: folder ingests decode on the rayon pool and report from it.
pub type Progress<'a> = &'a mut (dyn FnMut(u64, u64) + Send);
