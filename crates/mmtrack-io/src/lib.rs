//! # mmtrack-io
//!
//! mmtrack's canonical formats and nothing else:
//!
//! - [`recording`]: one MCAP file per sequence, protobuf-encoded, readable by
//!   Foxglove and the Python `mcap` package; written by [`RecordingWriter`],
//!   streamed back by [`RecordingReader`] with bounded memory;
//! - [`table`]: Parquet tables (zstd, a `units` map and the run configuration in
//!   key-value metadata, Hive layout `<table>/sequence=<id>/part-0.parquet`);
//! - [`atomic`]: every output is written to a temporary file and renamed, so a
//!   half-written file never replaces a good one.
//!
//! It depends on `mmtrack-core` only and never on algorithm crates; it does not
//! print. The documents in `schemas/` are generated from the specs here
//! ([`schema_docs`]) and a test fails when they differ.

pub mod atomic;
mod error;
pub mod paths;
mod png_gray;
pub mod proto;
pub mod recording;
pub mod schema_docs;
pub mod table;
pub mod table_kv;

pub use atomic::{
    AtomicFile, Durability, Overwrite, check_output_dir, check_output_file, check_output_is_not_input,
    check_replaceable_dir, create_output_dirs, publish_dir, staging_dir,
};
pub use error::{IoError, Result};
pub use png_gray::{Gray8Png, MAX_GRAY8_BYTES, decode_gray8};
pub use recording::{RecordingEvent, RecordingMetadata, RecordingOptions, RecordingReader, RecordingWriter};
