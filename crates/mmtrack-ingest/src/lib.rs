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
//! Sources so far: Oxford Radar RobotCar folders ([`oxford`]) with their
//! ground truth and GPS, ROS 2 bags ([`ros2`]), trajectory files ([`poses`])
//! and NMEA 0183 logs ([`nmea`]).

pub mod cir;
mod csv;
mod error;
pub mod nmea;
pub mod oxford;
pub mod poses;
pub mod ros2;
pub mod target;

pub use error::IngestError;

/// Progress of a long ingest: `done` of `total` items (scans, lines, ...).
pub type Progress<'a> = &'a mut dyn FnMut(u64, u64);
