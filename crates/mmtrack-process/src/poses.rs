//! A recording's own trajectories as tables (`mmtrack process poses`): the
//! estimate on `/estimate/pose` (someone else's odometry or SLAM, put there
//! by `mmtrack ingest ros2`, `ingest poses --estimate` or `export --format
//! mcap`) as the `poses` table, and the ground truth on
//! `/ground_truth/pose` as `ground_truth`. `mmtrack analyze` scores a
//! `poses` table against its `ground_truth` exactly as it scores our own
//! radar odometry (drift per length, RPE, ATE), so an external estimate and
//! ours can be compared side by side (`--run-id`).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, bail};
use mmtrack_core::progress::Progress;
use mmtrack_core::{StampedPose, path_length_m};
use mmtrack_io::recording::RecordingItem;
use mmtrack_io::recording::{PoseStream, TimeBase};
use mmtrack_io::table::{Frame, GroundTruthPose, RunInfo, TableWriteSummary};
use mmtrack_io::{RecordingEvent, RecordingMetadata, RecordingReader};

use crate::output::{OutputOptions, run_id_of};

/// Every table `process poses` may write.
pub const TABLES: [&str; 2] = ["poses", "ground_truth"];

/// The trajectories of one recording.
pub struct RecordingPoses {
    /// `/estimate/pose`, in time order.
    pub estimate: Vec<StampedPose>,
    /// `/ground_truth/pose`, in time order (may be empty).
    pub ground_truth: Vec<StampedPose>,
    /// The recording's sequence id.
    pub sequence_id: String,
    /// What the recording's `t_ns` counts from.
    pub time_base: TimeBase,
    /// The recording's other metadata keys (its word on the frames).
    pub recording_extra: BTreeMap<String, String>,
}

impl RecordingPoses {
    /// One line for a terminal: pose counts, time spans and path lengths.
    #[must_use]
    pub fn summary(&self) -> String {
        let span = |p: &[StampedPose]| match (p.first(), p.last()) {
            (Some(a), Some(b)) => format!("{:.1} s, {:.1} m", (b.t_ns - a.t_ns) as f64 * 1e-9, path_length_m(p)),
            _ => "none".to_string(),
        };
        format!(
            "poses: estimate {} ({}), ground truth {} ({})",
            self.estimate.len(),
            span(&self.estimate),
            self.ground_truth.len(),
            span(&self.ground_truth)
        )
    }
}

/// The frame of a recording's ground truth as its tables state it (the
/// recording's `extra` metadata names its origin).
pub(crate) fn ground_truth_frame(recording_extra: &BTreeMap<String, String>) -> Frame {
    Frame::of_recording(
        "ground_truth",
        "the world frame of the recording's ground truth (/ground_truth/pose)",
        recording_extra,
    )
}

/// Adds `pose` (of `topic`) to `poses`, refusing a time that
/// does not increase: the trajectory metrics interpolate between poses.
pub(crate) fn push_in_order(poses: &mut Vec<StampedPose>, pose: StampedPose, topic: &str) -> anyhow::Result<()> {
    if let Some(last) = poses.last()
        && pose.t_ns <= last.t_ns
    {
        bail!(
            "{topic}: pose {} (counted from 0) has t_ns {} at or before the previous pose's {}: poses must be in \
             strictly increasing time",
            poses.len(),
            pose.t_ns,
            last.t_ns
        );
    }
    poses.push(pose);
    Ok(())
}

/// Reads the estimate and the ground truth of `recording`; progress in
/// bytes read.
///
/// # Errors
/// A bad record (naming the file and record), poses out of time order
/// (naming the topic and pose), no recording metadata, or no estimate.
pub fn read_poses(recording: &Path, progress: &dyn Progress) -> anyhow::Result<RecordingPoses> {
    let total_bytes = std::fs::metadata(recording).map(|m| m.len()).unwrap_or(0);
    progress.start("poses", total_bytes, "bytes");
    let (mut estimate, mut ground_truth) = (Vec::new(), Vec::new());
    // Item by item, so radar scans are skipped undecoded (their PNGs are
    // most of a recording's bytes and none of its poses).
    let mut reader = RecordingReader::open(recording)?;
    while let Some(item) = reader.next_item() {
        progress.set_position(reader.bytes_read());
        progress.check_cancelled()?;
        match item.with_context(|| recording.display().to_string())? {
            RecordingItem::Event(RecordingEvent::Pose { stream: PoseStream::Estimate, pose }) => {
                push_in_order(&mut estimate, pose, PoseStream::Estimate.topic())
            }
            RecordingItem::Event(RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose }) => {
                push_in_order(&mut ground_truth, pose, PoseStream::GroundTruth.topic())
            }
            _ => Ok(()),
        }
        .with_context(|| recording.display().to_string())?;
    }
    let metadata = reader.metadata().cloned();
    progress.finish();
    let RecordingMetadata { sequence_id, time_base, extra: recording_extra, .. } = metadata
        .as_ref()
        .and_then(RecordingMetadata::from_map)
        .with_context(|| format!("{}: no mmtrack recording metadata (sequence id)", recording.display()))?;
    if estimate.is_empty() {
        bail!(
            "{}: the recording has no estimated poses (topic /estimate/pose; `mmtrack ingest ros2 --pose-topic` or \
             `mmtrack ingest poses --estimate` put them there); nothing written",
            recording.display()
        );
    }
    Ok(RecordingPoses { estimate, ground_truth, sequence_id, time_base, recording_extra })
}

/// What [`process_poses`] did.
pub struct PosesOutput {
    /// The poses read.
    pub poses: RecordingPoses,
    /// The sequence partition written.
    pub sequence: String,
    /// Each table written, with its row count.
    pub written: Vec<TableWriteSummary>,
}

/// `mmtrack process poses`: the recording's estimate as the `poses` table
/// and its ground truth (when it has one) as `ground_truth`, under `output`
/// ([`OutputOptions::resolve`]); both tables appear together or not at all.
/// Existing tables are refused before any work unless `options.force`.
///
/// # Errors
/// A bad run id, an existing table, a bad recording ([`read_poses`]) or a
/// table that cannot be written.
pub fn process_poses(
    recording: &Path,
    output: &Path,
    options: &OutputOptions,
    progress: &dyn Progress,
) -> anyhow::Result<PosesOutput> {
    let out = options.resolve(output)?;
    if let Some(sequence) = options.sequence_hint(recording) {
        out.refuse_existing(&TABLES, &sequence)?;
    }
    let poses = read_poses(recording, progress)?;
    let sequence = options.sequence_or(&poses.sequence_id);
    out.refuse_existing(&TABLES, &sequence)?;
    let estimate_frame = Frame::new(
        "estimate",
        "the world frame of the recording's estimate (/estimate/pose) as its source gives it; `mmtrack analyze` \
         anchors it to the ground truth before comparing",
    );
    let truth_frame = ground_truth_frame(&poses.recording_extra);
    let info = RunInfo {
        config_json: serde_json::json!({
            "command": "process poses",
            "recording": crate::provenance::canonical(recording),
            "inputs": crate::provenance::input_files(&[recording])?,
            "poses": "estimate (/estimate/pose)",
            "run_id": run_id_of(&out.path),
            "mmtrack_version": env!("CARGO_PKG_VERSION"),
        })
        .to_string(),
        time_base: poses.time_base.into(),
        frame: Some(estimate_frame),
    };
    let mut tables = out.tables();
    tables.write(&sequence, &poses.estimate, &info)?;
    if !poses.ground_truth.is_empty() {
        let truth: Vec<GroundTruthPose> = poses.ground_truth.iter().cloned().map(GroundTruthPose).collect();
        tables.write(&sequence, &truth, &RunInfo { frame: Some(truth_frame), ..info.clone() })?;
    }
    let written = tables.publish()?;
    Ok(PosesOutput { poses, sequence, written })
}

#[cfg(test)]
mod tests {
    use super::*;
    use mmtrack_core::Se2;

    #[test]
    fn a_pose_at_or_before_the_previous_one_is_refused_naming_the_topic_and_pose() {
        let pose = |t_ns| StampedPose { t_ns, parent_from_child: Se2::new(0.0, 0.0, 0.0) };
        let mut poses = Vec::new();
        push_in_order(&mut poses, pose(10), "/estimate/pose").unwrap();
        push_in_order(&mut poses, pose(20), "/estimate/pose").unwrap();
        for t_ns in [20, 5] {
            let e = push_in_order(&mut poses, pose(t_ns), "/estimate/pose").unwrap_err().to_string();
            assert!(e.starts_with(&format!(
                "/estimate/pose: pose 2 (counted from 0) has t_ns {t_ns} at or before the previous pose's 20"
            )));
        }
        assert_eq!(poses.len(), 2);
    }
}
