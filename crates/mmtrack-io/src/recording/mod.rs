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
//! For Foxglove's 3D panel the writer also puts the vehicle, sensor and
//! estimate frames on `/tf` ([`tf`]), and, when asked, each radar scan
//! resampled onto a Cartesian grid on `/radar/cartesian` ([`cartesian`]).
//!
//! The channel table lives in [`channels`] and is what `schemas/` documents.

pub mod cartesian;
pub mod channels;
pub mod cir_view;
mod copy;
mod metadata;
pub mod pulse;
mod reader;
pub mod tf;
mod writer;

pub use cartesian::{CartesianGrid, CartesianResampler};
pub use channels::{
    BEAM_SITE_KEY, CHANNELS, ChannelSpec, PoseStream, SLAM_PATHS_TOPIC, SLAM_SOURCES_TOPIC, SLAM_UE_TRUTH_TOPIC,
};
pub use copy::{EstimateToAdd, copy_with_estimate};
pub use metadata::{RecordingMetadata, TIME_BASE_MEANING_KEY, TimeBase, YEAR_2000_NS};
pub use reader::{
    ChannelInfo, ChannelSummary, EncodedScan, RawMessage, RawReader, RecordingEvent, RecordingItem, RecordingReader,
    RecordingSummary, inspect_recording, inspect_recording_with_progress,
};
pub use writer::{Compression, RecordingFlags, RecordingOptions, RecordingWriter, WriteSummary};

/// Name of the MCAP metadata record that holds [`RecordingMetadata`].
pub const METADATA_NAME: &str = "mmtrack.recording";
