//! A recording's measurements as tables (`mmtrack process raw`): the radar
//! scans, CIR snapshots, GNSS fixes and ground truth of a recording, one row
//! per message, for notebooks and SQL engines that read Parquet but not MCAP
//! (pandas, polars, DuckDB). No algorithm runs; the values are the
//! recording's, bit for bit.
//!
//! Radar scans and CIR snapshots are written as they are read, in batches,
//! so memory stays bounded whatever the recording's length (the table
//! writer flushes a row group every [`mmtrack_io::table::ROW_GROUP_BYTES`]).

use std::path::Path;

use anyhow::{Context, bail};
use mmtrack_core::progress::Progress;
use mmtrack_core::{CirSnapshot, GnssFix, PolarScan, StampedPose};
use mmtrack_io::recording::PoseStream;
use mmtrack_io::table::{GroundTruthPose, RunInfo, TableRow, TableWriteSummary, TableWriter};
use mmtrack_io::{RecordingEvent, RecordingMetadata};

use crate::events::for_each_event;
use crate::output::{OutputOptions, RunTables, recording_metadata, run_id_of};

/// Every table `process raw` may write.
pub const TABLES: [&str; 4] = ["radar_scans", "cir_snapshots", "gnss_fixes", "ground_truth"];

/// Radar scans per write (about 1.5 MB each for an Oxford scan).
const SCANS_PER_BATCH: usize = 8;
/// CIR snapshots per write.
const CIRS_PER_BATCH: usize = 1024;

/// Rows written per table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RawCounts {
    /// `radar_scans` rows.
    pub radar_scans: u64,
    /// `cir_snapshots` rows.
    pub cir_snapshots: u64,
    /// `gnss_fixes` rows (the vehicle's fixes, `/gnss/fix`).
    pub gnss_fixes: u64,
    /// `ground_truth` rows.
    pub ground_truth: u64,
}

/// What `process raw` wrote.
#[derive(Debug)]
pub struct RawOutput {
    /// The sequence partition written.
    pub sequence: String,
    /// Rows per table.
    pub counts: RawCounts,
    /// The table files.
    pub written: Vec<TableWriteSummary>,
}

impl RawOutput {
    /// One line for a terminal.
    #[must_use]
    pub fn summary(&self) -> String {
        let c = &self.counts;
        format!(
            "raw ({}): {} radar scans, {} CIR snapshots, {} GNSS fixes, {} ground-truth poses",
            self.sequence, c.radar_scans, c.cir_snapshots, c.gnss_fixes, c.ground_truth
        )
    }
}

/// Rows of one table buffered for the next write, and its writer once
/// the first row came.
struct Batched<T> {
    rows: Vec<T>,
    per_batch: usize,
    writer: Option<TableWriter>,
}

impl<T: TableRow> Batched<T> {
    fn new(per_batch: usize) -> Self {
        Self { rows: Vec::new(), per_batch, writer: None }
    }

    fn push(&mut self, row: T, tables: &mut RunTables, sequence: &str, run: &RunInfo) -> anyhow::Result<()> {
        self.rows.push(row);
        if self.rows.len() >= self.per_batch {
            self.flush(tables, sequence, run)?;
        }
        Ok(())
    }

    fn flush(&mut self, tables: &mut RunTables, sequence: &str, run: &RunInfo) -> anyhow::Result<()> {
        if self.rows.is_empty() {
            return Ok(());
        }
        let writer = match &mut self.writer {
            Some(writer) => writer,
            None => self.writer.insert(tables.writer(T::SPEC, sequence, run)?),
        };
        writer.write(&self.rows)?;
        self.rows.clear();
        Ok(())
    }

    /// Writes what is left and hands the table to the run (nothing when no
    /// row came); returns the rows written.
    fn finish(mut self, tables: &mut RunTables, sequence: &str, run: &RunInfo) -> anyhow::Result<u64> {
        self.flush(tables, sequence, run)?;
        let Some(writer) = self.writer else { return Ok(0) };
        let rows = writer.rows();
        tables.add(writer)?;
        Ok(rows)
    }
}

/// Writes the recording's radar scans, CIR snapshots, GNSS fixes and ground
/// truth as the tables `radar_scans`, `cir_snapshots`, `gnss_fixes` and
/// `ground_truth` (those it has), partitioned by its sequence id.
///
/// # Errors
/// A recording without mmtrack metadata or without any of these messages
/// (nothing is written then), an existing table without `--force`, or a
/// bad record (nothing is published).
pub fn process_raw(
    recording: &Path,
    output: &Path,
    options: &OutputOptions,
    progress: &dyn Progress,
) -> anyhow::Result<RawOutput> {
    let out = options.resolve(output)?;
    let Some(RecordingMetadata { sequence_id, time_base, extra, .. }) = recording_metadata(recording)? else {
        bail!("{}: no mmtrack recording metadata (sequence id); nothing written", recording.display());
    };
    let sequence = options.sequence_or(&sequence_id);
    out.refuse_existing(&TABLES, &sequence)?;
    let config_json = serde_json::json!({
        "command": "process raw",
        "recording": crate::provenance::canonical(recording),
        "inputs": crate::provenance::input_files(&[recording])?,
        "run_id": run_id_of(&out.path),
        "mmtrack_version": env!("CARGO_PKG_VERSION"),
    })
    .to_string();
    let run = RunInfo::new(config_json, time_base);

    let mut tables = out.tables();
    let mut scans: Batched<PolarScan> = Batched::new(SCANS_PER_BATCH);
    let mut cirs: Batched<CirSnapshot> = Batched::new(CIRS_PER_BATCH);
    let mut fixes: Vec<GnssFix> = Vec::new();
    let mut truth: Vec<StampedPose> = Vec::new();
    let total_bytes = std::fs::metadata(recording).map(|m| m.len()).unwrap_or(0);
    progress.start("raw", total_bytes, "bytes");
    for_each_event(recording, |event, bytes_read| {
        progress.set_position(bytes_read);
        progress.check_cancelled()?;
        match event {
            RecordingEvent::RadarScan(scan) => scans.push(scan, &mut tables, &sequence, &run)?,
            RecordingEvent::Cir(cir) => cirs.push(cir, &mut tables, &sequence, &run)?,
            RecordingEvent::Gnss(fix) => fixes.push(fix),
            RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } => {
                crate::poses::push_in_order(&mut truth, pose, PoseStream::GroundTruth.topic())
                    .with_context(|| recording.display().to_string())?
            }
            _ => {}
        }
        Ok(())
    })?;
    progress.finish();
    let counts = RawCounts {
        radar_scans: scans.finish(&mut tables, &sequence, &run)?,
        cir_snapshots: cirs.finish(&mut tables, &sequence, &run)?,
        gnss_fixes: fixes.len() as u64,
        ground_truth: truth.len() as u64,
    };
    if counts == RawCounts::default() {
        bail!(
            "{}: the recording has no radar scans, CIR snapshots, GNSS fixes or ground truth; nothing written",
            recording.display()
        );
    }
    if !fixes.is_empty() {
        tables.write(&sequence, &fixes, &run)?;
    }
    if !truth.is_empty() {
        let frame = crate::poses::ground_truth_frame(&extra);
        let truth: Vec<GroundTruthPose> = truth.into_iter().map(GroundTruthPose).collect();
        tables.write(&sequence, &truth, &RunInfo { frame: Some(frame), ..run.clone() })?;
    }
    let written = tables.publish()?;
    Ok(RawOutput { sequence, counts, written })
}

#[cfg(test)]
mod tests {
    use super::*;
    use mmtrack_io::table::{CIR_SNAPSHOTS, RADAR_SCANS};

    #[test]
    fn the_tables_named_are_the_ones_declared() {
        assert_eq!(TABLES, [RADAR_SCANS.name, CIR_SNAPSHOTS.name, mmtrack_io::table::GNSS_FIXES.name, "ground_truth"]);
        assert_eq!(TABLES[3], mmtrack_io::table::GROUND_TRUTH.name);
    }
}
