//! A copy of a recording with an estimated trajectory added: what
//! `mmtrack export --format mcap` writes so that Foxglove shows the estimate
//! beside the ground truth and the scans. The input is only read; the copy
//! appears atomically ([`crate::atomic`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use mmtrack_core::StampedPose;

use super::channels::{PoseStream, SLAM_ESTIMATE_VIZ_TOPIC};
use super::metadata::RecordingMetadata;
use super::writer::{RecordingOptions, RecordingWriter, WriteSummary};
use super::{METADATA_NAME, RawReader};
use crate::error::{IoError, Result};
use crate::table::SlamMapRow;

/// An estimated trajectory to add to a copy of a recording.
#[derive(Debug, Clone)]
pub struct EstimateToAdd<'a> {
    /// Poses `parent_from_estimate`, in time order.
    pub poses: &'a [StampedPose],
    /// Frame the poses are given in (`world` when they are in the ground
    /// truth's frame).
    pub parent_frame: &'a str,
    /// A SLAM run's map (rows of table `slam_map`, any order), drawn epoch
    /// by epoch on `/viz/slam_estimate`; empty for odometry.
    pub slam_map: &'a [SlamMapRow],
    /// Metadata keys added to the copy's `mmtrack.recording` record (e.g.
    /// `estimate.source`, `estimate.frame`).
    pub metadata: BTreeMap<String, String>,
}

/// Writes `output`: every message of `input` (channels, schemas, sequence
/// numbers and log times kept), then `estimate` on `/estimate/pose` (with its
/// `/viz/estimate` display copy and `world -> estimate` on `/tf`) and a SLAM
/// run's map on `/viz/slam_estimate`, one scene per epoch. The
/// recording metadata gains `estimate.metadata`. Refuses an input that already
/// has estimates, and an output that is the input.
pub fn copy_with_estimate(
    input: &Path,
    output: &Path,
    estimate: &EstimateToAdd<'_>,
    options: &RecordingOptions,
) -> Result<WriteSummary> {
    if same_file(input, output) {
        return Err(IoError::BadValue {
            path: output.to_path_buf(),
            record: "output".into(),
            field: "path",
            detail: format!("is the input recording {}; the input is never modified, write a copy", input.display()),
        });
    }
    let mut reader = RawReader::open(input)?;
    let mut pending = Vec::new();
    // Our writers put the metadata record before the messages.
    while reader.metadata().is_empty() {
        match reader.next_message()? {
            Some(message) => pending.push(message),
            None => break,
        }
    }
    let mut metadata = reader.metadata().get(METADATA_NAME).and_then(RecordingMetadata::from_map).ok_or_else(|| {
        IoError::CorruptRecording {
            path: input.to_path_buf(),
            detail: "not an mmtrack recording (no mmtrack.recording metadata)".into(),
        }
    })?;
    metadata.extra.extend(estimate.metadata.clone());
    let mut writer = RecordingWriter::create(output, &metadata, options)?;
    let mut pending = pending.into_iter();
    loop {
        let message = match pending.next() {
            Some(m) => m,
            None => match reader.next_message()? {
                Some(m) => m,
                None => break,
            },
        };
        let topic = message.channel.topic.as_str();
        if topic == PoseStream::Estimate.topic()
            || topic == PoseStream::Estimate.viz_topic()
            || topic == SLAM_ESTIMATE_VIZ_TOPIC
        {
            return Err(IoError::BadMessage {
                path: input.to_path_buf(),
                topic: topic.to_string(),
                sequence: message.sequence,
                detail: "the recording already holds an estimate; add estimates to a recording without one".into(),
            });
        }
        writer.copy_message(&message)?;
    }
    for pose in estimate.poses {
        writer.write_pose(PoseStream::Estimate, pose, estimate.parent_frame)?;
    }
    let mut by_epoch: BTreeMap<(i64, u64), Vec<SlamMapRow>> = BTreeMap::new();
    for row in estimate.slam_map {
        by_epoch.entry((row.t_ns, row.epoch)).or_default().push(row.clone());
    }
    for ((t_ns, _), mut sources) in by_epoch {
        sources.sort_by_key(|s| s.source_id);
        writer.write_slam_estimate(t_ns, &sources)?;
    }
    writer.finish()
}

/// Whether two paths name the same file (the output may not exist yet).
fn same_file(a: &Path, b: &Path) -> bool {
    let resolve = |p: &Path| -> Option<PathBuf> {
        if let Ok(p) = p.canonicalize() {
            return Some(p);
        }
        let parent = p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        Some(parent.canonicalize().ok()?.join(p.file_name()?))
    };
    matches!((resolve(a), resolve(b)), (Some(x), Some(y)) if x == y)
}
