//! Multipath-component detection and tracking
//! (Mahler et al. 2017) on the CIR snapshots of a recording, written as
//! Parquet tables (`mmtrack process mpc`).
//!
//! The recording is read as a stream: snapshots are grouped by link (TX, RX
//! antenna) and by `set_index`, and each complete set goes to that link's
//! [`MpcPipeline`]. Only the current set of each link is held as CIRs; the
//! results (detections, tracks) are kept until the end and then written, one
//! table file each, atomically.
//!
//! Links: a recording with one link writes the partition `<sequence>`; with
//! several, each link is its own partition `<sequence>-tx<T>-rx<R>` (its own
//! long-term tracking, since MPCs of different antenna pairs are different
//! paths), unless [`MpcOptions::link`] picks one, which is then written as
//! `<sequence>`.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, bail};
use mmtrack_core::sounder::SounderBand;
use mmtrack_core::{CirSnapshot, MpcDetection, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth, StampedPose};
use mmtrack_io::recording::pulse::{PULSE_SPECTRUM_KEY, decode_pulse_spectrum};
use mmtrack_io::recording::{PoseStream, RecordingItem, TimeBase};
use mmtrack_io::table::Frame;
use mmtrack_io::table::{
    GmPhdTrack, GroundTruthRxPose, GroundTruthTxPose, MpcSnapshotStats, RunInfo, TableWriteSummary,
};
use mmtrack_io::{Overwrite, RecordingEvent, RecordingMetadata, RecordingReader};
use mmtrack_mpc::{MpcConfig, MpcPipeline, SnapshotDetections, SounderPulse};

use mmtrack_core::progress::Progress;
use mmtrack_io::table::{
    GROUND_TRUTH_RX, GROUND_TRUTH_TX, MPC_DETECTIONS, MPC_LONG_TERM, MPC_SETS, MPC_SNAPSHOTS, MPC_TRACKS,
    MPC_TRACKS_GMPHD, MPC_TRUTH,
};

use crate::output::{OutputOptions, RunDir, RunTables, exists_error};

/// Every table `process mpc` may write.
pub const TABLES: [&str; 9] = [
    MPC_DETECTIONS.name,
    MPC_TRACKS.name,
    MPC_TRACKS_GMPHD.name,
    MPC_LONG_TERM.name,
    MPC_SETS.name,
    MPC_SNAPSHOTS.name,
    MPC_TRUTH.name,
    GROUND_TRUTH_TX.name,
    GROUND_TRUTH_RX.name,
];

/// The options of [`process_mpc`] besides the configuration.
#[derive(Clone, Debug, Default)]
pub struct MpcOptions {
    /// Sounder pulse: `flat` (the band's flat spectrum), or a `.npy` file
    /// holding a back-to-back calibration CIR; `None`: the pulse spectrum in
    /// the recording's metadata (`sounder.pulse_spectrum`), else flat.
    pub pulse: Option<String>,
    /// Only this link (TX, RX antenna indices), written as the sequence itself.
    pub link: Option<(u32, u32)>,
    /// Where the tables go.
    pub output: OutputOptions,
}

/// `TX:RX` antenna indices (`--link`).
///
/// # Errors
/// Anything else, quoting the text (a usage error: exit status 2).
pub fn parse_link(text: &str) -> anyhow::Result<(u32, u32)> {
    let parse = || -> Option<(u32, u32)> {
        let (tx, rx) = text.split_once(':')?;
        Some((tx.trim().parse().ok()?, rx.trim().parse().ok()?))
    };
    parse().ok_or_else(|| {
        let message = format!("--link '{text}': expected TX:RX antenna indices, e.g. 0:1");
        mmtrack_core::error::UsageError::new(message).into()
    })
}

/// The default configuration with the TOML file's fields on top, table by
/// table: `[long_term]` with only `delay_gate_s` changes that one field. A
/// table that names a `method` (the noise floor's) replaces the default's
/// table, since its other fields depend on the method. Unknown fields are
/// refused by name when the result is read back.
///
/// # Errors
/// The file cannot be read, is not TOML or not a valid configuration.
pub fn effective_config(path: Option<&Path>) -> anyhow::Result<MpcConfig> {
    let Some(path) = path else { return Ok(MpcConfig::default()) };
    let text = mmtrack_io::paths::read_config_text(path)?;
    let changes: toml::Table = toml::from_str(&text).with_context(|| format!("{}: not valid TOML", path.display()))?;
    let mut merged = toml::Table::try_from(MpcConfig::default())?;
    merge_tables(&mut merged, changes);
    let config: MpcConfig =
        merged.try_into().with_context(|| format!("{}: not a valid MPC configuration", path.display()))?;
    config.validate().with_context(|| path.display().to_string())?;
    Ok(config)
}

/// `changes` on top of `base`, recursing into tables present in both.
fn merge_tables(base: &mut toml::Table, changes: toml::Table) {
    for (key, value) in changes {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(inner)), toml::Value::Table(more)) if !more.contains_key("method") => {
                merge_tables(inner, more);
            }
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

/// What one link accumulates.
struct LinkRun {
    pipeline: MpcPipeline,
    current_set: Option<u64>,
    /// Snapshots of the set being read.
    pending: Vec<CirSnapshot>,
    /// Complete sets not yet processed.
    complete: Vec<Vec<CirSnapshot>>,
    detections: Vec<MpcDetection>,
    tracks: Vec<MpcTrack>,
    gmphd_tracks: Vec<MpcTrack>,
    long_term: Vec<MpcLongTermEntry>,
    sets: Vec<MpcSetStats>,
    /// Per snapshot: what detection found, and the receiver's first-path hint.
    snapshots: Vec<MpcSnapshotStats>,
}

impl LinkRun {
    /// Ends the set being read; processes the complete sets once there are
    /// enough of them, or all of them with `all`.
    fn end_set(&mut self, all: bool) -> anyhow::Result<()> {
        if !self.pending.is_empty() {
            self.complete.push(std::mem::take(&mut self.pending));
        }
        if self.complete.is_empty()
            || (!all && self.complete.len() < MpcPipeline::SETS_PER_THREAD * rayon::current_num_threads())
        {
            return Ok(());
        }
        let (first, last) = (self.complete[0][0].set_index, self.complete[self.complete.len() - 1][0].set_index);
        let outputs = self.pipeline.push_sets(&self.complete).with_context(|| format!("sets {first}..={last}"))?;
        for (set, out) in self.complete.iter().zip(outputs) {
            for (cir, found) in set.iter().zip(out.per_snapshot) {
                self.snapshots.push(snapshot_stats(cir, &found));
                self.detections.extend(found.detections);
            }
            self.tracks.extend(out.short_term_tracks);
            if let Some(tracks) = out.gmphd_tracks {
                self.gmphd_tracks.extend(tracks);
            }
            self.long_term.extend(out.long_term_entries);
            self.sets.push(out.stats);
        }
        self.complete.clear();
        Ok(())
    }
}

/// The `mpc_snapshots` row of one detected snapshot.
fn snapshot_stats(cir: &CirSnapshot, found: &SnapshotDetections) -> MpcSnapshotStats {
    MpcSnapshotStats {
        t_ns: cir.t_ns,
        set_index: cir.set_index,
        snapshot_index: cir.snapshot_index,
        detections: u32::try_from(found.detections.len()).unwrap_or(u32::MAX),
        skipped: found.skipped.is_some(),
        noise_floor_db: found.noise_floor_db,
        channel_gain_db: found.channel_gain_db,
        detected_gain_db: found.detected_gain_db,
        first_path_hint_s: cir.first_path_hint_s,
    }
}

/// Everything read and computed.
struct MpcRun {
    sequence_id: String,
    /// The recording's time base and metadata (for the tables' `time_base` and `frame`).
    time_base: TimeBase,
    metadata: BTreeMap<String, String>,
    links: BTreeMap<(u32, u32), LinkRun>,
    truth: Vec<MpcTruth>,
    tx: Vec<StampedPose>,
    rx: Vec<StampedPose>,
    snapshots: u64,
}

fn choose_pulse(
    choice: Option<&str>,
    metadata: Option<&BTreeMap<String, String>>,
    first: &CirSnapshot,
    recording: &Path,
) -> anyhow::Result<SounderPulse> {
    let flat = || -> anyhow::Result<SounderPulse> {
        let band = SounderBand::new(first.taps.len(), first.tap_spacing_s)
            .with_context(|| format!("{}: first CIR snapshot (t_ns {})", recording.display(), first.t_ns))?;
        Ok(SounderPulse::flat(&band))
    };
    match choice {
        Some("flat") => flat(),
        Some(file) => {
            let path = Path::new(file);
            // A back-to-back CIR of this sounder: its carrier and tap spacing
            // are the recording's (the .npy holds only the taps).
            let sidecar = mmtrack_ingest::cir::CirSidecar {
                carrier_hz: Some(first.carrier_hz),
                tap_spacing: Some(mmtrack_ingest::cir::TapSpacing::Seconds(first.tap_spacing_s)),
                ..mmtrack_ingest::cir::CirSidecar::empty()
            };
            let cir = mmtrack_ingest::cir::read_cir_file(mmtrack_ingest::cir::CirFormat::Npy, path, Some(&sidecar))
                .with_context(|| format!("--pulse {}: back-to-back CIR", path.display()))?;
            let taps = cir.snapshots.first().map(|s| s.taps.clone()).with_context(|| {
                format!("--pulse {}: no CIR in the file (expected one back-to-back CIR)", path.display())
            })?;
            SounderPulse::from_back_to_back_cir(&taps).with_context(|| format!("--pulse {}", path.display()))
        }
        None => match metadata.and_then(|m| m.get(PULSE_SPECTRUM_KEY)) {
            Some(text) => {
                let spectrum = decode_pulse_spectrum(text).with_context(|| {
                    format!(
                        "{}: metadata {PULSE_SPECTRUM_KEY} is not a list of finite re/im pairs",
                        recording.display()
                    )
                })?;
                SounderPulse::from_spectrum(spectrum)
                    .with_context(|| format!("{}: metadata {PULSE_SPECTRUM_KEY}", recording.display()))
            }
            None => flat(),
        },
    }
}

fn read_and_process(
    path: &Path,
    options: &MpcOptions,
    config: &MpcConfig,
    progress: &dyn Progress,
) -> anyhow::Result<MpcRun> {
    let link_filter = options.link;
    let mut reader = RecordingReader::open(path)?;
    progress.start("mpc", std::fs::metadata(path).map(|m| m.len()).unwrap_or(0), "bytes");
    let mut pulse: Option<SounderPulse> = None;
    let mut run = MpcRun {
        sequence_id: String::new(),
        time_base: TimeBase::Relative,
        metadata: BTreeMap::new(),
        links: BTreeMap::new(),
        truth: Vec::new(),
        tx: Vec::new(),
        rx: Vec::new(),
        snapshots: 0,
    };
    while let Some(item) = reader.next_item() {
        let event = match item? {
            RecordingItem::Event(event) => event,
            RecordingItem::Scan(_) => continue,
        };
        progress.set_position(reader.bytes_read());
        progress.check_cancelled()?;
        match event {
            RecordingEvent::Cir(snapshot) => {
                let key = (snapshot.tx_antenna, snapshot.rx_antenna);
                if link_filter.is_some_and(|l| l != key) {
                    continue;
                }
                let index = run.snapshots;
                run.snapshots += 1;
                let context = || {
                    format!(
                        "{}: CIR snapshot {index} (t_ns {}, set {})",
                        path.display(),
                        snapshot.t_ns,
                        snapshot.set_index
                    )
                };
                if pulse.is_none() {
                    pulse = Some(choose_pulse(options.pulse.as_deref(), reader.metadata(), &snapshot, path)?);
                }
                let link = match run.links.entry(key) {
                    std::collections::btree_map::Entry::Occupied(e) => e.into_mut(),
                    std::collections::btree_map::Entry::Vacant(e) => {
                        let pulse = pulse.as_ref().context("internal: pulse chosen above")?;
                        let pipeline =
                            MpcPipeline::new(config.clone(), pulse, snapshot.tap_spacing_s, snapshot.carrier_hz)
                                .with_context(context)?;
                        e.insert(LinkRun {
                            pipeline,
                            current_set: None,
                            pending: Vec::new(),
                            complete: Vec::new(),
                            detections: Vec::new(),
                            tracks: Vec::new(),
                            gmphd_tracks: Vec::new(),
                            long_term: Vec::new(),
                            sets: Vec::new(),
                            snapshots: Vec::new(),
                        })
                    }
                };
                match link.current_set {
                    Some(set) if snapshot.set_index < set => bail!(
                        "{}: set_index {} after set {set} on link tx{}:rx{}; snapshots must come in set order",
                        context(),
                        snapshot.set_index,
                        key.0,
                        key.1
                    ),
                    Some(set) if snapshot.set_index == set => {}
                    _ => {
                        link.end_set(false)
                            .with_context(|| format!("{}: link tx{}:rx{}", path.display(), key.0, key.1))?;
                        link.current_set = Some(snapshot.set_index);
                    }
                }
                link.pending.push(snapshot);
            }
            RecordingEvent::MpcTruth(truth) => run.truth.push(truth),
            RecordingEvent::Pose { stream: stream @ (PoseStream::GroundTruthTx | PoseStream::GroundTruthRx), pose } => {
                let poses = if stream == PoseStream::GroundTruthTx { &mut run.tx } else { &mut run.rx };
                crate::poses::push_in_order(poses, pose, stream.topic()).with_context(|| path.display().to_string())?;
            }
            _ => {}
        }
    }
    for (key, link) in &mut run.links {
        link.end_set(true).with_context(|| format!("{}: link tx{}:rx{}", path.display(), key.0, key.1))?;
    }
    progress.finish();
    let metadata = reader
        .metadata()
        .and_then(RecordingMetadata::from_map)
        .with_context(|| format!("{}: no mmtrack recording metadata (sequence id)", path.display()))?;
    run.metadata = reader.metadata().cloned().unwrap_or_default();
    run.sequence_id = metadata.sequence_id;
    run.time_base = metadata.time_base;
    if run.links.is_empty() {
        match link_filter {
            Some((tx, rx)) if run.snapshots == 0 => {
                bail!("{}: no CIR snapshot of link {tx}:{rx} (topic /channel/cir); nothing written", path.display())
            }
            _ => bail!("{}: the recording has no CIR snapshots (topic /channel/cir); nothing written", path.display()),
        }
    }
    Ok(run)
}

/// Partition name of each link.
fn partitions(run: &MpcRun, sequence: &str, picked: bool) -> Vec<((u32, u32), String)> {
    let single = picked || run.links.len() == 1;
    run.links
        .keys()
        .map(|&(tx, rx)| ((tx, rx), if single { sequence.to_string() } else { format!("{sequence}-tx{tx}-rx{rx}") }))
        .collect()
}

/// Without `--force`, refuses when any table of `sequence` (or one of its
/// link partitions) exists.
fn refuse_existing(out: &RunDir, sequence: &str) -> anyhow::Result<()> {
    if out.overwrite == Overwrite::Replace {
        return Ok(());
    }
    for table in TABLES {
        out.refuse_existing(&[table], sequence)?;
        let Ok(entries) = std::fs::read_dir(out.path.join(table)) else { continue };
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            let link_part =
                name.strip_prefix(&format!("sequence={sequence}-tx")).is_some_and(|rest| rest.contains("-rx"));
            if link_part && entry.path().join("part-0.parquet").exists() {
                return Err(exists_error(&entry.path()));
            }
        }
    }
    Ok(())
}

/// One link's counts, for the front end's summary.
#[derive(Clone, Debug)]
pub struct LinkSummary {
    /// The partition written.
    pub partition: String,
    /// TX and RX antenna indices.
    pub link: (u32, u32),
    /// Sets processed.
    pub sets: usize,
    /// Detections over all snapshots.
    pub detections: usize,
    /// Short-term tracks.
    pub tracks: usize,
    /// Long-term entries.
    pub long_term: usize,
    /// Most snapshots a set held after skipped ones (no short-term track
    /// can be longer).
    pub most_snapshots_per_set: u64,
    /// Snapshots with detections.
    pub snapshots_with_detections: usize,
    /// Snapshots whose detections stopped at `[detection] max_mpcs`: the
    /// search (Mahler et al. 2017, Sec. III-A, repeated until the residual
    /// is below the threshold) ended on the cap, not on the threshold, so
    /// weaker paths above the threshold were left undetected.
    pub snapshots_at_max_mpcs: usize,
}

impl LinkSummary {
    /// The lines the CLI prints for the link: its counts, and why there are
    /// no short-term tracks when its sets are too short for one.
    #[must_use]
    pub fn summary(&self, min_track_length: usize) -> Vec<String> {
        use mmtrack_core::words::{counted, counted_as};
        let capped = match self.snapshots_at_max_mpcs {
            0 => String::new(),
            n => format!(" ({n} snapshots at max_mpcs)"),
        };
        let mut lines = vec![format!(
            "mpc {} (link tx{}:rx{}): {}, {}{capped}, {}, {}",
            self.partition,
            self.link.0,
            self.link.1,
            counted(self.sets as u64, "set"),
            counted(self.detections as u64, "detection"),
            counted(self.tracks as u64, "short-term track"),
            counted_as(self.long_term as u64, "long-term entry", "long-term entries")
        )];
        let most = self.most_snapshots_per_set;
        if self.tracks == 0 && self.detections > 0 && (most as usize) < min_track_length {
            lines.push(format!(
                "  no short-term tracks: sets hold at most {most} snapshot(s) and a track follows one path over at \
                 least short_term.min_track_length = {min_track_length} snapshots of one set (Mahler et al. Sec. \
                 III-B); this source gives detections and first paths only"
            ));
        }
        lines
    }
}

/// Per snapshot (set, snapshot index) with detections: how many there are
/// and how many of those reached `max_mpcs`.
fn snapshots_at_cap(detections: &[mmtrack_core::MpcDetection], max_mpcs: usize) -> (usize, usize) {
    let mut per_snapshot = std::collections::BTreeMap::<(u64, u32), usize>::new();
    for d in detections {
        *per_snapshot.entry((d.set_index, d.snapshot_index)).or_default() += 1;
    }
    (per_snapshot.len(), per_snapshot.values().filter(|&&n| n >= max_mpcs).count())
}

/// What [`process_mpc`] did.
#[derive(Clone, Debug)]
pub struct MpcOutput {
    /// Per link, in link order.
    pub links: Vec<LinkSummary>,
    /// Each table written, with its row count.
    pub written: Vec<TableWriteSummary>,
}

/// `mmtrack process mpc`: detection and tracking with `config` on the CIR
/// snapshots of `recording`, tables under `output`. Existing tables (of the
/// sequence or of its link partitions) are refused before any work unless
/// `options.output.force`.
///
/// # Errors
/// A bad run id, an existing table, a bad recording (naming file, snapshot
/// and field), a bad pulse file, or a table that cannot be written.
pub fn process_mpc(
    recording: &Path,
    output: &Path,
    config: &MpcConfig,
    options: &MpcOptions,
    progress: &dyn Progress,
) -> anyhow::Result<MpcOutput> {
    let out = options.output.resolve(output)?;
    // Check the outputs before the work, so a refusal costs nothing.
    if let Some(sequence) = &options.output.sequence_hint(recording) {
        refuse_existing(&out, sequence)?;
    }
    let run = read_and_process(recording, options, config, progress)?;
    let sequence = options.output.sequence_or(&run.sequence_id);
    refuse_existing(&out, &sequence)?;
    let info = RunInfo {
        config_json: serde_json::json!({
            "command": "process mpc",
            "recording": crate::provenance::canonical(recording),
            "inputs": crate::provenance::input_files(&[recording])?,
            "pulse": options.pulse.as_deref().map_or_else(|| "recording metadata, else flat".into(), |p| {
                if p == "flat" { p.to_string() } else { crate::provenance::canonical(std::path::Path::new(p)) }
            }),
            "link": options.link.map(|(tx, rx)| format!("{tx}:{rx}")),
            "mpc": config,
            "run_id": out.run_id(),
            "mmtrack_version": env!("CARGO_PKG_VERSION"),
        })
        .to_string(),
        time_base: run.time_base.into(),
        frame: Some(Frame::of_recording(
            "recording_world",
            "the recording's world frame of both vehicles' ground truth (/ground_truth/tx, /ground_truth/rx): x, y \
             in metres, yaw counter-clockwise from world x",
            &run.metadata,
        )),
    };
    let mut tables = out.tables();
    let mut links = Vec::new();
    for (key, partition) in partitions(&run, &sequence, options.link.is_some()) {
        let link = &run.links[&key];
        write_link(&mut tables, &partition, link, &run, config.run_gmphd, &info)?;
        let (snapshots_with_detections, snapshots_at_max_mpcs) =
            snapshots_at_cap(&link.detections, config.detection.max_mpcs);
        links.push(LinkSummary {
            snapshots_with_detections,
            snapshots_at_max_mpcs,
            partition,
            link: key,
            sets: link.sets.len(),
            detections: link.detections.len(),
            tracks: link.tracks.len(),
            long_term: link.long_term.len(),
            most_snapshots_per_set: link
                .sets
                .iter()
                .map(|s| s.snapshots.saturating_sub(s.skipped_snapshots))
                .max()
                .unwrap_or(0)
                .into(),
        });
    }
    Ok(MpcOutput { links, written: tables.publish()? })
}

/// The records counted in a table's [`TableWriteSummary::rows`], as one
/// and as many, from the table's directory in
/// `<output>/<table>/sequence=<id>/part-0.parquet`: one record of
/// `mpc_tracks` is a whole track (one row per point).
#[must_use]
pub fn record_noun(path: &Path) -> (&'static str, &'static str) {
    let table = path.parent().and_then(Path::parent).and_then(Path::file_name).and_then(|n| n.to_str());
    match table {
        Some("mpc_detections") => ("detection", "detections"),
        Some("mpc_tracks" | "mpc_tracks_gmphd") => ("track", "tracks"),
        Some("mpc_long_term") => ("long-term entry", "long-term entries"),
        Some("mpc_sets") => ("set", "sets"),
        Some("mpc_snapshots") => ("snapshot", "snapshots"),
        Some("ground_truth_tx" | "ground_truth_rx") => ("pose", "poses"),
        _ => ("row", "rows"),
    }
}

fn write_link(
    tables: &mut RunTables,
    partition: &str,
    link: &LinkRun,
    run: &MpcRun,
    gmphd: bool,
    info: &RunInfo,
) -> anyhow::Result<()> {
    tables.write(partition, &link.detections, info)?;
    tables.write(partition, &link.tracks, info)?;
    tables.write(partition, &link.long_term, info)?;
    tables.write(partition, &link.sets, info)?;
    tables.write(partition, &link.snapshots, info)?;
    if gmphd {
        let tracks: Vec<GmPhdTrack> = link.gmphd_tracks.iter().cloned().map(GmPhdTrack).collect();
        tables.write(partition, &tracks, info)?;
    }
    if !run.truth.is_empty() {
        tables.write(partition, &run.truth, info)?;
    }
    if !run.tx.is_empty() && !run.rx.is_empty() {
        let tx: Vec<GroundTruthTxPose> = run.tx.iter().cloned().map(GroundTruthTxPose).collect();
        let rx: Vec<GroundTruthRxPose> = run.rx.iter().cloned().map(GroundTruthRxPose).collect();
        tables.write(partition, &tx, info)?;
        tables.write(partition, &rx, info)?;
    }
    Ok(())
}
