//! Radar odometry (Fast-CFEAR / CFEAR, `mmtrack_odometry`) on a recording's
//! radar scans, written as the `odometry`, `odometry_timing` and
//! `ground_truth` tables (`mmtrack process odometry`).

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, bail};
use mmtrack_core::progress::Progress;
use mmtrack_core::{OdometryEstimate, OdometryTiming, PolarScan, StampedPose, path_length_m};
use mmtrack_io::recording::PoseStream;
use mmtrack_io::recording::TimeBase;
use mmtrack_io::table::{Frame, GroundTruthPose, RunInfo, TableWriteSummary};
use mmtrack_io::{RecordingEvent, RecordingMetadata};
use mmtrack_odometry::{OdometryConfig, RadarOdometry};

use crate::events::for_each_event;
use crate::output::{OutputOptions, RunDir, run_id_of};

/// The effective configuration: the preset with the TOML file's fields on top.
///
/// # Errors
/// An unknown preset; the file cannot be read, is not TOML, names an unknown
/// parameter or gives a bad value (naming the file).
pub fn effective_config(preset: &str, overrides: Option<&Path>) -> anyhow::Result<OdometryConfig> {
    let base = OdometryConfig::preset(preset).with_context(|| format!("unknown preset '{preset}'"))?;
    let Some(path) = overrides else { return Ok(base) };
    let text = mmtrack_io::paths::read_config_text(path)?;
    let changes: toml::Table = toml::from_str(&text).with_context(|| format!("{}: not valid TOML", path.display()))?;
    let mut merged = toml::Table::try_from(&base)?;
    for (key, value) in changes {
        if !merged.contains_key(&key) {
            let known: Vec<&String> = merged.keys().collect();
            bail!("{}: unknown odometry parameter '{key}'; known: {known:?}", path.display());
        }
        merged.insert(key, value);
    }
    let config: OdometryConfig =
        merged.try_into().with_context(|| format!("{}: a value has the wrong type", path.display()))?;
    config.validate().with_context(|| path.display().to_string())?;
    Ok(config)
}

/// What the odometry run produced.
pub struct OdometryRun {
    /// One estimate per scan.
    pub estimates: Vec<OdometryEstimate>,
    /// Stage timings per scan.
    pub timings: Vec<OdometryTiming>,
    /// Ground truth from the recording (may be empty).
    pub ground_truth: Vec<StampedPose>,
    /// The recording's sequence id.
    pub sequence_id: String,
    /// What the recording's `t_ns` counts from.
    pub time_base: TimeBase,
    /// The recording's other metadata keys (its word on the ground truth's
    /// frame and origin, [`Frame::of_recording`]).
    pub recording_extra: BTreeMap<String, String>,
    /// Wall-clock seconds for reading, decoding and processing.
    pub elapsed_s: f64,
}

/// Reads the recording and decodes its scans on the current rayon pool while
/// the odometry runs on the previous ones ([`for_each_event`]); progress in
/// bytes read.
///
/// # Errors
/// A bad record (naming the file and record), a scan the odometry refuses,
/// no recording metadata or no radar scans.
pub fn run_odometry(recording: &Path, config: OdometryConfig, progress: &dyn Progress) -> anyhow::Result<OdometryRun> {
    let started = Instant::now();
    let mut odometry = RadarOdometry::new(config)?;
    let total_bytes = std::fs::metadata(recording).map(|m| m.len()).unwrap_or(0);
    progress.start("odometry", total_bytes, "bytes");
    let mut estimates = Vec::new();
    let mut timings = Vec::new();
    let mut ground_truth = Vec::new();
    let metadata = for_each_event(recording, |event, bytes_read| {
        progress.set_position(bytes_read);
        progress.check_cancelled()?;
        match event {
            RecordingEvent::RadarScan(scan) => {
                let result = process_scan(&mut odometry, &scan, estimates.len())?;
                estimates.push(result.estimate);
                timings.push(result.timing);
            }
            RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } => {
                crate::poses::push_in_order(&mut ground_truth, pose, PoseStream::GroundTruth.topic())?
            }
            _ => {}
        }
        Ok(())
    })?;
    progress.finish();
    let RecordingMetadata { sequence_id, time_base, extra: recording_extra, .. } = metadata
        .as_ref()
        .and_then(RecordingMetadata::from_map)
        .with_context(|| format!("{}: no mmtrack recording metadata (sequence id)", recording.display()))?;
    if estimates.is_empty() {
        bail!("{}: the recording has no radar scans (topic /radar/image); nothing written", recording.display());
    }
    Ok(OdometryRun {
        estimates,
        timings,
        ground_truth,
        sequence_id,
        time_base,
        recording_extra,
        elapsed_s: started.elapsed().as_secs_f64(),
    })
}

impl OdometryRun {
    /// Two lines for a terminal: scans, low-confidence ones and path
    /// lengths; throughput and the mean time of each stage.
    #[must_use]
    pub fn summary(&self, preset: &str) -> [String; 2] {
        let n = self.estimates.len();
        let low = self.estimates.iter().filter(|e| e.low_confidence).count();
        let path: Vec<StampedPose> = self
            .estimates
            .iter()
            .map(|e| StampedPose { t_ns: e.t_ns, parent_from_child: e.world_from_vehicle })
            .collect();
        let mean_ms = |f: fn(&OdometryTiming) -> f64| self.timings.iter().map(f).sum::<f64>() / n.max(1) as f64 * 1e3;
        let truth = if self.ground_truth.is_empty() {
            String::new()
        } else {
            format!(" (ground truth {:.1} m)", path_length_m(&self.ground_truth))
        };
        [
            format!(
                "odometry ({preset}): {n} scans, {low} low-confidence, estimated path {:.1} m{truth}",
                path_length_m(&path)
            ),
            format!(
                "  {:.1} scans/s end to end; per scan: filter {:.2} ms, surface points {:.2} ms, registration {:.2} ms",
                n as f64 / self.elapsed_s,
                mean_ms(|t| t.filter_s),
                mean_ms(|t| t.surface_s),
                mean_ms(|t| t.register_s)
            ),
        ]
    }
}

fn process_scan(
    odometry: &mut RadarOdometry,
    scan: &PolarScan,
    index: usize,
) -> anyhow::Result<mmtrack_odometry::ScanOdometry> {
    odometry.process(scan).with_context(|| format!("radar scan {index} (t_ns {})", scan.header.t_ns))
}

/// What [`process_odometry`] did: the run and the tables written.
pub struct OdometryOutput {
    /// The estimates, timings and ground truth.
    pub run: OdometryRun,
    /// The sequence partition written.
    pub sequence: String,
    /// Each table written, with its row count.
    pub written: Vec<TableWriteSummary>,
}

/// `mmtrack process odometry`: runs `config` (of `preset`, recorded in the
/// tables' metadata) on the radar scans of `recording` and writes the
/// tables under `output` ([`OutputOptions::resolve`]). Existing tables are
/// refused before any work unless `options.force`.
///
/// # Errors
/// A bad run id, an existing table, a bad recording ([`run_odometry`]) or a
/// table that cannot be written.
pub fn process_odometry(
    recording: &Path,
    output: &Path,
    preset: &str,
    config: &OdometryConfig,
    options: &OutputOptions,
    progress: &dyn Progress,
) -> anyhow::Result<OdometryOutput> {
    let out = options.resolve(output)?;
    // Check the outputs before the work, so a refusal costs nothing.
    if let Some(sequence) = options.sequence_hint(recording) {
        out.refuse_existing(&TABLES, &sequence)?;
    }
    let run = run_odometry(recording, config.clone(), progress).with_context(|| format!("{}", recording.display()))?;
    let sequence = options.sequence_or(&run.sequence_id);
    out.refuse_existing(&TABLES, &sequence)?;
    let written = write_outputs(&out, &sequence, &run, config, preset, recording)?;
    Ok(OdometryOutput { run, sequence, written })
}

/// Every table `process odometry` may write.
pub const TABLES: [&str; 3] = ["odometry", "odometry_timing", "ground_truth"];

/// Writes the tables; they appear together or not at all
/// ([`RunDir::tables`]).
///
/// # Errors
/// A table that cannot be written (or exists, without `force`).
pub fn write_outputs(
    out: &RunDir,
    sequence: &str,
    run: &OdometryRun,
    config: &OdometryConfig,
    preset: &str,
    recording: &Path,
) -> anyhow::Result<Vec<TableWriteSummary>> {
    let (estimates, frame) = in_ground_truth_frame(&run.estimates, &run.ground_truth);
    let truth_frame = Frame::of_recording(
        "ground_truth",
        "the world frame of the recording's ground truth (/ground_truth/pose); odometry is moved into it at the run \
         config's frame.anchor_t_ns",
        &run.recording_extra,
    );
    let table_frame = match frame["world"].as_str() {
        Some("ground_truth") => truth_frame.clone(),
        _ => Frame::new(
            "first_scan",
            "the vehicle's pose at the first radar scan (the recording has no ground truth at the scan times)",
        ),
    };
    let info = RunInfo {
        config_json: serde_json::json!({
            "command": "process odometry",
            "recording": crate::provenance::canonical(recording),
            "inputs": crate::provenance::input_files(&[recording])?,
            "preset": preset,
            "odometry": config,
            "frame": frame,
            "run_id": run_id_of(&out.path),
            "mmtrack_version": env!("CARGO_PKG_VERSION"),
        })
        .to_string(),
        time_base: run.time_base.into(),
        frame: Some(table_frame),
    };
    let mut tables = out.tables();
    tables.write(sequence, &estimates, &info)?;
    tables.write(sequence, &run.timings, &info)?;
    if !run.ground_truth.is_empty() {
        let truth: Vec<GroundTruthPose> = run.ground_truth.iter().cloned().map(GroundTruthPose).collect();
        // The ground truth is in its own frame, also when the odometry is not.
        tables.write(sequence, &truth, &RunInfo { frame: Some(truth_frame), ..info.clone() })?;
    }
    tables.publish()
}

/// The odometry's poses in the ground truth's frame, and the `frame` entry of
/// the run configuration saying which frame the table is in.
///
/// With ground truth covering a scan, the first estimate inside the
/// ground-truth time span is placed at the ground-truth pose of its time
/// (interpolated as `mmtrack analyze` does,
/// [`mmtrack_core::interpolate_pose`], when no pose has that
/// time) and every estimate moves with it:
/// `world_from_vehicle = truth(t_a) * estimate(t_a)^-1 * estimate`. This is
/// the anchor `analyze` uses, so its metrics do not change, while a join of
/// `odometry` and `ground_truth` on `(sequence, t_ns)` (or evo without
/// alignment flags) now compares like with like. Without ground truth the
/// frame stays the vehicle's pose at the first scan.
fn in_ground_truth_frame(
    estimates: &[OdometryEstimate],
    ground_truth: &[StampedPose],
) -> (Vec<OdometryEstimate>, serde_json::Value) {
    let span = ground_truth.first().zip(ground_truth.last()).map(|(a, b)| a.t_ns..=b.t_ns);
    let anchor = span.and_then(|span| estimates.iter().find(|e| span.contains(&e.t_ns)));
    let Some(anchor) = anchor else {
        let frame = serde_json::json!({
            "world": "first_scan",
            "meaning": "world is the vehicle's pose at the first scan (no ground truth at the scan times)",
        });
        return (estimates.to_vec(), frame);
    };
    let truth = match ground_truth.binary_search_by_key(&anchor.t_ns, |g| g.t_ns) {
        Ok(i) => ground_truth[i].parent_from_child,
        // The anchor lies strictly inside the span, so 0 < i < len.
        Err(i) => mmtrack_core::interpolate_pose(&ground_truth[i - 1], &ground_truth[i], anchor.t_ns),
    };
    let truth_from_odometry = truth * anchor.world_from_vehicle.inverse();
    let moved = estimates
        .iter()
        .map(|e| OdometryEstimate { world_from_vehicle: truth_from_odometry * e.world_from_vehicle, ..*e })
        .collect();
    let frame = serde_json::json!({
        "world": "ground_truth",
        "meaning": "the ground truth's world frame (table ground_truth, recording topic /ground_truth/pose): the \
                    estimate at anchor_t_ns sits at the ground-truth pose of that time, the others follow the odometry",
        "anchor_t_ns": anchor.t_ns,
        "ground_truth_from_odometry": [truth_from_odometry.x_m, truth_from_odometry.y_m, truth_from_odometry.yaw_rad],
    });
    (moved, frame)
}
