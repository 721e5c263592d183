//! Where an ingest writes: a new recording, or a copy of an existing one with
//! more channels added (written beside the output and renamed over it, so a
//! failure leaves the original untouched).

use std::collections::BTreeMap;
use std::path::Path;

use mmtrack_io::recording::{METADATA_NAME, RawReader, RecordingMetadata, TimeBase};
use mmtrack_io::{RecordingOptions, RecordingWriter};

use crate::IngestError;

/// Opens the writer for `out`. Without `extend`, a new recording with
/// `source` whose time base follows `first_t_ns`, the first time the source
/// gives: UNIX time, or [`TimeBase::Relative`] when it lies before
/// 2000-01-01 (a log without dates, e.g. KITTI times from 0, CIRs without a
/// `t0_ns`, a receiver's counter); with `extend`, a copy of that recording
/// whose metadata gains `extra` (its time base is kept). Fails when the
/// existing recording already has one of `new_topics`.
pub fn open_writer(
    out: &Path,
    extend: Option<&Path>,
    source: &str,
    mut extra: BTreeMap<String, String>,
    first_t_ns: Option<i64>,
    new_topics: &[&str],
    recording: &RecordingOptions,
) -> Result<RecordingWriter, IngestError> {
    let Some(existing) = extend else {
        let time_base = first_t_ns.map_or(TimeBase::UnixEpoch, |t| TimeBase::unix_or(t, TimeBase::Relative));
        if time_base == TimeBase::Relative {
            extra.entry("time.note".into()).or_insert_with(|| {
                format!(
                    "times as the source gives them; the first is {} ns, before 2000-01-01, so they are not UNIX time",
                    first_t_ns.unwrap_or_default()
                )
            });
        }
        let metadata = RecordingMetadata {
            sequence_id: out.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "sequence".into()),
            source: source.to_string(),
            time_base,
            extra,
        };
        return Ok(RecordingWriter::create(out, &metadata, recording)?);
    };
    let mut reader = RawReader::open(existing)?;
    let mut pending = Vec::new();
    // Our writers put the metadata record before the messages.
    while reader.metadata().is_empty() {
        match reader.next_message()? {
            Some(message) => pending.push(message),
            None => break,
        }
    }
    let mut metadata = reader.metadata().get(METADATA_NAME).and_then(RecordingMetadata::from_map).ok_or_else(|| {
        IngestError::BadLayout {
            path: existing.to_path_buf(),
            detail: "not an mmtrack recording (no mmtrack.recording metadata)".into(),
        }
    })?;
    metadata.extra.extend(extra);
    let mut writer = RecordingWriter::create(out, &metadata, recording)?;
    let mut pending = pending.into_iter();
    loop {
        let message = match pending.next() {
            Some(m) => m,
            None => match reader.next_message()? {
                Some(m) => m,
                None => break,
            },
        };
        if new_topics.contains(&message.channel.topic.as_str()) {
            return Err(IngestError::BadLayout {
                path: existing.to_path_buf(),
                detail: format!("already has {}; write to a new recording instead", message.channel.topic),
            });
        }
        writer.copy_message(&message)?;
    }
    Ok(writer)
}
