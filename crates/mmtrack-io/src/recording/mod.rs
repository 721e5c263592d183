//! Canonical MCAP recordings: one file per sequence.
//!
//! Channels are protobuf-encoded. Canonical data uses mmtrack's own schemas
//! ([`crate::proto`]) so that every value round-trips bit-exactly; alongside,
//! the writer adds Foxglove well-known views (`/viz/...`: `foxglove.PoseInFrame`,
//! `foxglove.LocationFix`) so the file opens in Foxglove with poses in the 3D
//! panel and fixes on the map. Radar power is stored once, as a Foxglove image
//! (`foxglove.RawImage` mono8, or `foxglove.CompressedImage` carrying the
//! dataset's PNG bytes unchanged), paired by MCAP sequence number with an
//! `mmtrack.RadarScanMeta` message holding the per-azimuth times and angles.
//!
//! The channel table lives in [`channels`] and is what `schemas/` documents.

pub mod channels;
pub mod pulse;
mod reader;
mod writer;

pub use channels::{BEAM_SITE_KEY, CHANNELS, ChannelSpec, PoseStream};
pub use reader::{
    ChannelInfo, ChannelSummary, EncodedScan, RawMessage, RawReader, RecordingEvent, RecordingItem, RecordingReader,
    RecordingSummary, inspect_recording, inspect_recording_with_progress,
};
pub use writer::{Compression, RecordingMetadata, RecordingOptions, RecordingWriter, TimeBase, WriteSummary};

/// Name of the MCAP metadata record that holds [`RecordingMetadata`].
pub const METADATA_NAME: &str = "mmtrack.recording";
