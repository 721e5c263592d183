//! Where an ingest writes: a new recording, or a copy of an existing one with
//! more channels added (written beside the output and renamed over it, so a
//! failure leaves the original untouched).

use std::collections::BTreeMap;
use std::path::Path;

use mmtrack_io::recording::{METADATA_NAME, RawReader, RecordingMetadata, TimeBase};
use mmtrack_io::{RecordingOptions, RecordingWriter};

use crate::IngestError;

/// The recording an ingest writes into, and, when records are added to an
/// existing recording, what is needed to refuse records that cannot belong
/// to it.
pub struct Target {
    writer: RecordingWriter,
    existing: Option<Existing>,
    added: AddedTimes,
}

/// The existing recording of an `--add-to` and the log-time span of its
/// messages (`None` when it has none).
struct Existing {
    path: std::path::PathBuf,
    span_ns: Option<(u64, u64)>,
}

/// The times of the records added so far: how many, how many fall within
/// the existing recording's span, the first and the last.
#[derive(Default)]
struct AddedTimes {
    count: u64,
    within: u64,
    first_t_ns: Option<i64>,
    last_t_ns: Option<i64>,
}

impl Target {
    /// The writer, for the records to add; each record's time goes to
    /// [`Target::added`] too.
    pub fn writer(&mut self) -> &mut RecordingWriter {
        &mut self.writer
    }

    /// Notes the time of a record written through [`Target::writer`].
    pub fn added(&mut self, t_ns: i64) {
        let added = &mut self.added;
        added.count += 1;
        added.first_t_ns.get_or_insert(t_ns);
        added.last_t_ns = Some(t_ns);
        let span = self.existing.as_ref().and_then(|e| e.span_ns);
        if span.is_some_and(|(first, last)| u64::try_from(t_ns).is_ok_and(|t| (first..=last).contains(&t))) {
            added.within += 1;
        }
    }

    /// Completes the recording. Records added to an existing recording none
    /// of whose times falls within its time span (the first to the last log
    /// time of its messages) are refused, naming both spans, and the
    /// existing recording is left as it was: they are of another drive, or
    /// in another unit or clock, and would sit beside the recording's data
    /// without touching it (the refusal `ingest oxford` makes for ground
    /// truth outside the scans' span, see [`crate::scan_folder`]).
    pub fn finish(self, input: &Path, what: &str) -> Result<mmtrack_io::recording::WriteSummary, IngestError> {
        let added = &self.added;
        if let (Some(Existing { path, span_ns: Some((first_ns, last_ns)) }), Some(added_first), Some(added_last)) =
            (&self.existing, added.first_t_ns, added.last_t_ns)
            && added.within == 0
        {
            return Err(IngestError::BadLayout {
                path: input.to_path_buf(),
                detail: format!(
                    "none of its {} {what} falls within the time span of {} ({first_ns} to {last_ns} ns): its times \
                     run from {added_first} to {added_last} ns (another unit, clock or drive?)",
                    added.count,
                    path.display(),
                ),
            });
        }
        Ok(self.writer.finish()?)
    }
}

/// Whether a time base dates its times (UNIX time, real or a scenario's
/// stated date) or counts from a start (sim time, relative logs).
fn dated(time_base: TimeBase) -> bool {
    match time_base {
        TimeBase::UnixEpoch | TimeBase::ScenarioStart => true,
        TimeBase::SimTime | TimeBase::Relative => false,
    }
}

/// Opens the writer for `out`. Without `extend`, a new recording with
/// `source` whose time base follows `first_t_ns`, the first time the source
/// gives: UNIX time, or [`TimeBase::Relative`] when it lies before
/// 2000-01-01 (a log without dates, e.g. KITTI times from 0, CIRs without a
/// `t0_ns`, a receiver's counter); with `extend`, a copy of that recording
/// whose metadata gains `extra` (its time base is kept). Fails when the
/// existing recording already has one of `new_topics`, and when the first
/// added time is dated (UNIX time, from 2000 on) and the recording's time
/// base is not (`sim_time`, `relative`) or the other way round, naming both.
pub fn open_writer(
    out: &Path,
    extend: Option<&Path>,
    source: &str,
    mut extra: BTreeMap<String, String>,
    first_t_ns: Option<i64>,
    new_topics: &[&str],
    recording: &RecordingOptions,
) -> Result<Target, IngestError> {
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
            sequence_id: crate::scan_folder::sequence_id_of_file(out, "output")?,
            source: source.to_string(),
            time_base,
            extra,
        };
        let writer = RecordingWriter::create(out, &metadata, recording)?;
        return Ok(Target { writer, existing: None, added: AddedTimes::default() });
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
    if let Some(first_t_ns) = first_t_ns {
        let added = TimeBase::unix_or(first_t_ns, TimeBase::Relative);
        if dated(added) != dated(metadata.time_base) {
            return Err(IngestError::BadLayout {
                path: existing.to_path_buf(),
                detail: format!(
                    "time base {} ({}), but the first time of {source} is {first_t_ns} ns, {}: the times cannot be \
                     compared",
                    metadata.time_base.as_str(),
                    metadata.time_base.meaning(),
                    if dated(added) { "UNIX time (2000 or later)" } else { "not UNIX time (before 2000)" },
                ),
            });
        }
    }
    metadata.extra.extend(extra);
    let mut writer = RecordingWriter::create(out, &metadata, recording)?;
    let mut pending = pending.into_iter();
    let mut span_ns: Option<(u64, u64)> = None;
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
        span_ns = Some(span_ns.map_or((message.log_time_ns, message.log_time_ns), |(first, last)| {
            (first.min(message.log_time_ns), last.max(message.log_time_ns))
        }));
        writer.copy_message(&message)?;
    }
    let existing = Existing { path: existing.to_path_buf(), span_ns };
    Ok(Target { writer, existing: Some(existing), added: AddedTimes::default() })
}

#[cfg(test)]
mod tests {
    use mmtrack_core::{Se2, StampedPose};
    use mmtrack_io::recording::PoseStream;

    use super::*;

    fn poses(first_t_ns: i64, count: i64) -> Vec<StampedPose> {
        (0..count)
            .map(|i| StampedPose { t_ns: first_t_ns + i * 100_000_000, parent_from_child: Se2::IDENTITY })
            .collect()
    }

    /// A recording of ground truth from `first_t_ns`, ten poses 0.1 s apart.
    fn recording(dir: &Path, first_t_ns: i64) -> std::path::PathBuf {
        let out = dir.join("rec.mcap");
        let input = dir.join("gt.txt");
        crate::poses::write_poses(
            &poses(first_t_ns, 10),
            PoseStream::GroundTruth,
            &input,
            "tum:gt.txt",
            None,
            &out,
            &RecordingOptions::default(),
        )
        .unwrap();
        out
    }

    fn add(dir: &Path, existing: &Path, first_t_ns: i64) -> Result<(), IngestError> {
        let input = dir.join("est.txt");
        let out = dir.join("added.mcap");
        let added = poses(first_t_ns, 5);
        let options = RecordingOptions { overwrite: mmtrack_io::Overwrite::Replace, ..RecordingOptions::default() };
        crate::poses::write_poses(&added, PoseStream::Estimate, &input, "tum:est.txt", Some(existing), &out, &options)
            .map(|_| ())
    }

    /// Before: `--add-to` copied the recording and added the poses whatever
    /// their times: another drive's poses (or UNIX times added to a sim-time
    /// recording) made a recording that looked complete.
    #[test]
    fn added_records_outside_the_span_or_of_another_time_base_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let t0_ns = 1_700_000_000_000_000_000;
        let existing = recording(dir.path(), t0_ns);
        let before = std::fs::read(&existing).unwrap();
        add(dir.path(), &existing, t0_ns + 500_000_000).unwrap();
        // Overlapping at one end only is enough.
        add(dir.path(), &existing, t0_ns - 400_000_000).unwrap();

        let hour_ns = 3_600_000_000_000;
        let err = add(dir.path(), &existing, t0_ns + hour_ns).unwrap_err().to_string();
        let expected = format!(
            "est.txt: none of its 5 poses falls within the time span of {} ({t0_ns} to {} ns): its times run from {} to {} ns",
            existing.display(),
            t0_ns + 900_000_000,
            t0_ns + hour_ns,
            t0_ns + hour_ns + 400_000_000
        );
        assert!(err.contains(&expected), "{err}");
        assert_eq!(std::fs::read(&existing).unwrap(), before, "the recording is left as it was");

        // A recording counting from 0 (relative, like sim time) and UNIX times.
        let relative = tempfile::tempdir().unwrap();
        let existing = recording(relative.path(), 0);
        let err = add(relative.path(), &existing, t0_ns).unwrap_err().to_string();
        assert!(
            err.starts_with(&format!("{}: time base relative", existing.display()))
                && err.contains(&format!("the first time of tum:est.txt is {t0_ns} ns, UNIX time")),
            "{err}"
        );
        add(relative.path(), &existing, 200_000_000).unwrap();
    }
}
