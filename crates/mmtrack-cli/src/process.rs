//! `mmtrack process <pipeline>`: run an algorithm on a recording, write tables.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, bail};
use clap::{Args, Subcommand};
use mmtrack_core::{OdometryEstimate, OdometryTiming, PolarScan, StampedPose, path_length_m};
use mmtrack_io::recording::PoseStream;
use mmtrack_io::recording::RecordingItem;
use mmtrack_io::table::{GroundTruthPose, RunInfo, TableWriteSummary, write_table};
use mmtrack_io::{Overwrite, RecordingEvent, RecordingMetadata, RecordingReader};
use mmtrack_odometry::{OdometryConfig, RadarOdometry};

use crate::progress;
use crate::run_id::{OutputArgs, run_id_of};
use crate::threads::ThreadsArg;

#[path = "process_mpc.rs"]
mod process_mpc;

#[derive(Args)]
pub struct ProcessArgs {
    #[command(subcommand)]
    pipeline: Pipeline,
}

#[derive(Subcommand)]
enum Pipeline {
    /// Radar odometry (Fast-CFEAR / CFEAR) on the recording's radar scans.
    ///
    /// Writes, under the output directory, `odometry/sequence=<id>/part-0.parquet`
    /// (one pose per scan with registration diagnostics), `odometry_timing/...`
    /// (time per stage; not deterministic, so kept apart) and, when the
    /// recording has ground truth, `ground_truth/...`. Then run
    /// `mmtrack analyze <out>` for drift and error metrics, or
    /// `mmtrack export --format tum <out>` for evo / pyboreas / the KITTI devkit.
    #[command(verbatim_doc_comment)]
    Odometry(OdometryArgs),
    /// Multipath-component detection and tracking (Mahler et al. 2017) on the recording's CIR snapshots.
    ///
    /// Writes, under the output directory, per sequence partition:
    /// `mpc_detections` (one row per detected MPC), `mpc_tracks` (short-term
    /// tracks within a set), `mpc_long_term` (full-lifetime tracks related
    /// across sets, with their confidence class chi), `mpc_sets` (per-set
    /// counts and channel gains), with `--gmphd` `mpc_tracks_gmphd` (the
    /// GM-PHD baseline on the same detections), and when the recording has
    /// them `mpc_truth` and `ground_truth_tx` / `ground_truth_rx`.
    /// Several TX/RX links: each is its own partition `<sequence>-tx<T>-rx<R>`
    /// unless `--link T:R` picks one. Then run `mmtrack analyze <out>`.
    #[command(verbatim_doc_comment)]
    Mpc(process_mpc::MpcArgs),
    /// Beam trackers: sweep trackers on measured beam sweeps, or SPEBT on a recording with ground truth.
    ///
    /// Sweep trackers (window, gnss-window, last-full-sweep, gnss-map) on
    /// recordings of measured beam sweeps (e.g. from `mmtrack ingest beams`)
    /// write `beam_sweeps_tracked/sequence=<id>/part-0.parquet` per
    /// recording: per sweep and tracker the chosen and best beam, beams
    /// measured, re-initialisation and received-power loss. The GNSS policies
    /// (gnss-window, gnss-map) fit the beam map leave-one-pass-out over the
    /// recordings of each site given together (at least two). Then run
    /// `mmtrack analyze <out>`.
    /// `--tracker spebt` simulates the SPEBT link along a recording's ground
    /// truth and tracks it with poses from `--odometry <tables>` (from
    /// `mmtrack process odometry`) or from the ground truth plus the
    /// pose-error model; it writes `spebt_per_slot` and `spebt_summary`.
    #[command(verbatim_doc_comment)]
    Beam(crate::beam::process::BeamArgs),
    /// 5G mmWave SLAM (Kim et al. 2018) on the recording's per-epoch path measurements.
    ///
    /// Runs the particle belief-propagation SLAM filter over /slam/paths (from
    /// `mmtrack simulate slam`) and writes per sequence partition: `slam_ue`
    /// (UE estimate per epoch, beside the truth when the recording has it),
    /// `slam_map` (every map source after every epoch: bs, va, sp or
    /// unconfirmed, position, spread, confirmation), `slam_associations` (the
    /// source each path was given, beside its true source) and
    /// `slam_true_sources`. Unusable paths are skipped and counted, or refused
    /// with --strict. Then run `mmtrack analyze <out>`.
    #[command(verbatim_doc_comment)]
    Slam(crate::slam::process::SlamArgs),
    /// Many sequences at once: every `mmtrack process` command line of a manifest as its own task.
    ///
    /// The manifest (TOML) lists `[[task]]` tables, each with `args`: a
    /// `mmtrack process` command line without `mmtrack process` and `-o`,
    /// e.g. `args = ["odometry", "runs/a.mcap", "--preset", "cfear"]`.
    /// Every task writes its sequence partitions into the same `-o`
    /// directory and runs as an independent task on the thread pool; the
    /// tables do not depend on the order or the thread count. A failed task
    /// is reported and the others finish (exit 1). A task's `--run-id ID`
    /// puts its tables under `<output>/run=<ID>/`, so several runs of one
    /// sequence fit in one manifest. `--print-commands` prints
    /// the per-sequence command lines, one cluster job each (see
    /// examples/ray_process.py).
    #[command(verbatim_doc_comment)]
    Manifest(crate::process_manifest::ManifestArgs),
}

#[derive(Args)]
pub struct OdometryArgs {
    /// Recording with radar scans (from `mmtrack ingest` or `mmtrack simulate`); not needed with `--print-config`.
    #[arg(required_unless_present = "print_config")]
    pub recording: Option<PathBuf>,
    /// Output table directory (created if missing); not needed with `--print-config`.
    #[arg(short, long, required_unless_present = "print_config")]
    pub output: Option<PathBuf>,
    /// Parameter preset: `fast-cfear` (Liu et al., SPEBT Table I: scan-to-scan) or
    /// `cfear` (CFEAR-3: keyframe submap, motion compensation, re-association).
    #[arg(long, default_value = "cfear", value_parser = clap::builder::PossibleValuesParser::new(OdometryConfig::PRESETS))]
    pub preset: String,
    /// TOML file overriding single fields of the preset (see `--print-config`).
    #[arg(long, value_name = "TOML")]
    pub config: Option<PathBuf>,
    /// Print the effective configuration (the preset with `--config` on top) as TOML and exit.
    #[arg(long)]
    pub print_config: bool,
    #[command(flatten)]
    pub output_args: OutputArgs,
    #[command(flatten)]
    pub threads: ThreadsArg,
}

pub fn run(args: &ProcessArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    match &args.pipeline {
        Pipeline::Odometry(odometry_args) => {
            odometry(odometry_args, quiet)?;
            Ok(ExitCode::SUCCESS)
        }
        Pipeline::Mpc(mpc_args) => {
            process_mpc::run(mpc_args, quiet)?;
            Ok(ExitCode::SUCCESS)
        }
        Pipeline::Beam(beam_args) => crate::beam::process::run(beam_args, quiet),
        Pipeline::Slam(slam_args) => {
            crate::slam::process::run(slam_args, quiet)?;
            Ok(ExitCode::SUCCESS)
        }
        Pipeline::Manifest(manifest_args) => crate::process_manifest::run(manifest_args, quiet),
    }
}

/// The effective configuration: the preset with the TOML file's fields on top.
fn effective_config(preset: &str, overrides: Option<&Path>) -> anyhow::Result<OdometryConfig> {
    let base = OdometryConfig::preset(preset).with_context(|| format!("unknown preset '{preset}'"))?;
    let Some(path) = overrides else { return Ok(base) };
    let text = std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display()))?;
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
    /// Wall-clock seconds for reading, decoding and processing.
    pub elapsed_s: f64,
}

/// Reads the recording and decodes its scans on the current rayon pool while
/// the odometry runs on the previous ones ([`for_each_event`]).
pub fn run_odometry(recording: &Path, config: OdometryConfig, quiet: bool) -> anyhow::Result<OdometryRun> {
    let started = Instant::now();
    let mut odometry = RadarOdometry::new(config)?;
    let total_bytes = std::fs::metadata(recording).map(|m| m.len()).unwrap_or(0);
    let bar = progress::bytes_bar("odometry", quiet);
    bar.set_length(total_bytes);
    let mut estimates = Vec::new();
    let mut timings = Vec::new();
    let mut ground_truth = Vec::new();
    let metadata = for_each_event(recording, |event, bytes_read| {
        bar.set_position(bytes_read);
        match event {
            RecordingEvent::RadarScan(scan) => {
                let result = process_scan(&mut odometry, &scan, estimates.len())?;
                estimates.push(result.estimate);
                timings.push(result.timing);
            }
            RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } => ground_truth.push(pose),
            _ => {}
        }
        Ok(())
    })?;
    bar.finish_and_clear();
    let sequence_id = metadata
        .as_ref()
        .and_then(RecordingMetadata::from_map)
        .map(|m| m.sequence_id)
        .with_context(|| format!("{}: no mmtrack recording metadata (sequence id)", recording.display()))?;
    if estimates.is_empty() {
        bail!("{}: the recording has no radar scans (topic /radar/image); nothing written", recording.display());
    }
    Ok(OdometryRun { estimates, timings, ground_truth, sequence_id, elapsed_s: started.elapsed().as_secs_f64() })
}

/// Scans decoded ahead of `f`, per thread of the pool.
const SCANS_PER_THREAD: usize = 2;

/// Calls `f` with every event of the recording in file order (and the bytes
/// read so far). Radar scans are decoded on the current rayon pool, a few per
/// thread ahead of `f` ([`mmtrack_core::parallel::map_in_order`]), so
/// reading, PNG inflating and `f` overlap, order is kept and memory holds a
/// bounded number of scans. Reading stops at the first bad record. Returns the
/// recording metadata.
pub fn for_each_event(
    recording: &Path,
    mut f: impl FnMut(RecordingEvent, u64) -> anyhow::Result<()> + Send,
) -> anyhow::Result<Option<BTreeMap<String, String>>> {
    let mut reader = RecordingReader::open(recording)?;
    let mut failed = false;
    let items = std::iter::from_fn(|| {
        if failed {
            return None;
        }
        let item = reader.next_item()?;
        failed = item.is_err();
        Some((item, reader.bytes_read()))
    });
    mmtrack_core::parallel::map_in_order(
        items,
        SCANS_PER_THREAD,
        |(item, bytes_read)| {
            let event = match item {
                Ok(RecordingItem::Event(event)) => Ok(event),
                Ok(RecordingItem::Scan(scan)) => scan.decode().map(RecordingEvent::RadarScan),
                Err(e) => Err(e),
            };
            (event, bytes_read)
        },
        |(event, bytes_read)| f(event?, bytes_read),
    )?;
    Ok(reader.metadata().cloned())
}

fn process_scan(
    odometry: &mut RadarOdometry,
    scan: &PolarScan,
    index: usize,
) -> anyhow::Result<mmtrack_odometry::ScanOdometry> {
    odometry.process(scan).with_context(|| format!("radar scan {index} (t_ns {})", scan.header.t_ns))
}

fn odometry(args: &OdometryArgs, quiet: bool) -> anyhow::Result<()> {
    let config = effective_config(&args.preset, args.config.as_deref())?;
    if args.print_config {
        print!("{}", toml::to_string(&config)?);
        return Ok(());
    }
    // clap requires both unless --print-config.
    let (Some(recording), Some(output)) = (&args.recording, &args.output) else {
        bail!("a recording and --output are required (unless --print-config)");
    };
    let out = args.output_args.run.resolve(output)?;
    // Check the outputs before the work, so a refusal costs nothing.
    if let Some(sequence) = args.output_args.sequence_hint(recording) {
        out.refuse_existing(&TABLES, &sequence)?;
    }
    let run = args
        .threads
        .install(|| run_odometry(recording, config.clone(), quiet))?
        .with_context(|| format!("{}", recording.display()))?;
    let sequence = args.output_args.sequence_or(&run.sequence_id);
    out.refuse_existing(&TABLES, &sequence)?;
    let written = write_outputs(&out.path, &sequence, &run, &config, &args.preset, recording, out.overwrite)?;
    if !quiet {
        print_summary(&run, &args.preset, &written);
    }
    Ok(())
}

/// Every table `process odometry` may write.
const TABLES: [&str; 3] = ["odometry", "odometry_timing", "ground_truth"];

/// Writes the tables; each appears atomically.
pub fn write_outputs(
    output: &Path,
    sequence: &str,
    run: &OdometryRun,
    config: &OdometryConfig,
    preset: &str,
    recording: &Path,
    overwrite: Overwrite,
) -> anyhow::Result<Vec<TableWriteSummary>> {
    let (estimates, frame) = in_ground_truth_frame(&run.estimates, &run.ground_truth);
    let info = RunInfo {
        config_json: serde_json::json!({
            "command": "process odometry",
            "recording": recording.display().to_string(),
            "preset": preset,
            "odometry": config,
            "frame": frame,
            "run_id": run_id_of(output),
            "mmtrack_version": env!("CARGO_PKG_VERSION"),
        })
        .to_string(),
    };
    let mut written = vec![
        write_table(output, sequence, &estimates, &info, overwrite)?,
        write_table(output, sequence, &run.timings, &info, overwrite)?,
    ];
    if !run.ground_truth.is_empty() {
        let truth: Vec<GroundTruthPose> = run.ground_truth.iter().cloned().map(GroundTruthPose).collect();
        written.push(write_table(output, sequence, &truth, &info, overwrite)?);
    }
    Ok(written)
}

/// The odometry's poses in the ground truth's frame, and the `frame` entry of
/// the run configuration saying which frame the table is in.
///
/// With ground truth covering a scan, the first estimate inside the
/// ground-truth time span is placed at the ground-truth pose of its time
/// (interpolated as `mmtrack analyze` does,
/// [`mmtrack_analysis::trajectory::interpolate_pose`], when no pose has that
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
        Err(i) => mmtrack_analysis::trajectory::interpolate_pose(&ground_truth[i - 1], &ground_truth[i], anchor.t_ns),
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

fn print_summary(run: &OdometryRun, preset: &str, written: &[TableWriteSummary]) {
    let n = run.estimates.len();
    let low = run.estimates.iter().filter(|e| e.low_confidence).count();
    let path: Vec<StampedPose> =
        run.estimates.iter().map(|e| StampedPose { t_ns: e.t_ns, parent_from_child: e.world_from_vehicle }).collect();
    let mean = |f: fn(&OdometryTiming) -> f64| run.timings.iter().map(f).sum::<f64>() / n as f64 * 1e3;
    println!(
        "odometry ({preset}): {n} scans, {low} low-confidence, estimated path {:.1} m{}",
        path_length_m(&path),
        if run.ground_truth.is_empty() {
            String::new()
        } else {
            format!(" (ground truth {:.1} m)", path_length_m(&run.ground_truth))
        }
    );
    println!(
        "  {:.1} scans/s end to end; per scan: filter {:.2} ms, surface points {:.2} ms, registration {:.2} ms",
        n as f64 / run.elapsed_s,
        mean(|t| t.filter_s),
        mean(|t| t.surface_s),
        mean(|t| t.register_s)
    );
    for w in written {
        println!("  wrote {} ({} rows)", w.path.display(), w.rows);
    }
}
