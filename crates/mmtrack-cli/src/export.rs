//! `mmtrack export`: trajectory tables as standard text (TUM, KITTI, Boreas)
//! for evo, the KITTI devkit and pyboreas (the formats are in
//! `mmtrack_analysis::export`), or as poses in a copy of the recording for
//! Foxglove (`--format mcap`, [`mmtrack_io::recording::copy_with_estimate`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use mmtrack_analysis::export::{ExportFormat, export_sequence};
use mmtrack_analysis::pipeline::{inventory, read_trajectories};
use mmtrack_core::{OdometryEstimate, Se2, StampedPose};
use mmtrack_io::recording::{EstimateToAdd, METADATA_NAME, RawReader, RecordingMetadata, copy_with_estimate};
use mmtrack_io::table::{SLAM_MAP, SLAM_UE, SlamMapRow, SlamUeRow, read_table, table_path};
use mmtrack_io::table_kv::read_key_value_metadata;
use mmtrack_io::{Durability, Overwrite, RecordingOptions};

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    /// `t_s x y z qx qy qz qw` per pose, each trajectory at its own times and in its own frame (evo `tum`).
    Tum,
    /// 12 numbers of the 3x4 world_from_vehicle per line, estimate and ground truth associated frame by frame and
    /// starting at the identity, plus `<seq>.times.txt` (KITTI devkit, evo `kitti`).
    Kitti,
    /// pyboreas odometry benchmark: `t_us` + 3x4 vehicle_from_world, `boreas/estimate/<seq>.txt`.
    Boreas,
    /// A copy of `--recording` with the estimate added as poses (`/estimate/pose`, `/viz/estimate`, and
    /// `world -> estimate` on `/tf`) for Foxglove, from the odometry table or a SLAM run's UE estimate; a SLAM
    /// run's map after each epoch as markers on `/viz/slam_estimate`. `-o` is the new recording's path.
    Mcap,
}

#[derive(Args)]
#[command(
    long_about = "Writes the estimate (table `odometry`) and, when present, the ground truth (table `ground_truth`) of \
each sequence as text files that evo, the KITTI odometry devkit and pyboreas read. Numbers are written at full \
precision (shortest round-trip) and times as exact decimals. Files: <seq>.estimate.<fmt>.txt and \
<seq>.ground_truth.<fmt>.txt (KITTI also <seq>.times.txt; Boreas boreas/{estimate,ground_truth}/<seq>.txt). \
With --format mcap: a copy of --recording (never modified) plus the estimate of its sequence as poses (table \
odometry, or slam_ue of `process slam` with the map of slam_map as 3D markers), written to -o atomically.",
    after_help = "Examples: mmtrack export --format kitti out/tables -o out/kitti && evo_ape kitti \
out/kitti/seq.ground_truth.kitti.txt out/kitti/seq.estimate.kitti.txt\n\
mmtrack export --format mcap out/tables --recording rec.mcap -o rec.estimate.mcap   (then open it in Foxglove)"
)]
pub struct ExportArgs {
    /// Output format.
    #[arg(long, value_enum)]
    format: Format,
    /// Table directory written by `mmtrack process`.
    tables: PathBuf,
    /// Output directory (text formats) or recording (`--format mcap`).
    #[arg(short, long, value_name = "DIR or OUT.mcap")]
    output: PathBuf,
    /// The recording the tables came from (`--format mcap` only): copied, with the estimate added.
    #[arg(long, value_name = "RECORDING.mcap", required_if_eq("format", "mcap"))]
    recording: Option<PathBuf>,
    /// Export only this sequence (default: every sequence with an estimate: an odometry or poses table).
    #[arg(long, value_name = "ID")]
    sequence: Option<String>,
    /// Replace existing files.
    #[arg(long)]
    force: bool,
}

pub fn run(args: &ExportArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let overwrite = if args.force { Overwrite::Replace } else { Overwrite::Refuse };
    if !args.tables.is_dir() {
        bail!("{}: not a directory (expected a table directory written by `mmtrack process`)", args.tables.display());
    }
    if let Format::Mcap = args.format {
        return export_mcap(args, overwrite, quiet);
    }
    if args.recording.is_some() {
        return Err(crate::usage("--recording is only used with --format mcap"));
    }
    let mut inputs = read_trajectories(&args.tables)?;
    if inputs.is_empty() {
        bail!("{}: no estimate to export (found {})", args.tables.display(), inventory(&args.tables)?.describe());
    }
    if let Some(wanted) = &args.sequence {
        let available: Vec<String> = inputs.keys().cloned().collect();
        inputs.retain(|s, _| s == wanted);
        if inputs.is_empty() {
            bail!(
                "sequence {wanted}: no odometry or poses table in {} (sequences: {})",
                args.tables.display(),
                available.join(", ")
            );
        }
    }
    let format = match args.format {
        Format::Tum => ExportFormat::Tum,
        Format::Kitti => ExportFormat::Kitti,
        Format::Boreas => ExportFormat::Boreas,
        Format::Mcap => return export_mcap(args, overwrite, quiet),
    };
    for (sequence, input) in &inputs {
        let files = export_sequence(&args.output, sequence, input, format, overwrite)
            .with_context(|| format!("sequence {sequence}"))?;
        if !quiet {
            for f in files {
                println!("{sequence}: {} ({} lines): {}", f.what, f.lines, f.path.display());
            }
            if input.ground_truth.is_none() {
                println!("{sequence}: no ground_truth table; estimate only");
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The recording's `mmtrack.recording` metadata (writers put it first).
fn recording_metadata(path: &Path) -> anyhow::Result<RecordingMetadata> {
    let mut reader = RawReader::open(path)?;
    while reader.metadata().is_empty() && reader.next_message()?.is_some() {}
    reader
        .metadata()
        .get(METADATA_NAME)
        .and_then(RecordingMetadata::from_map)
        .with_context(|| format!("{}: not an mmtrack recording (no mmtrack.recording metadata)", path.display()))
}

/// `--format mcap`: the recording plus the estimate of its sequence: the
/// `odometry` table, or a SLAM run's `slam_ue` and `slam_map` tables.
fn export_mcap(args: &ExportArgs, overwrite: Overwrite, quiet: bool) -> anyhow::Result<ExitCode> {
    let Some(recording) = &args.recording else {
        return Err(crate::usage("--format mcap needs --recording <RECORDING.mcap>"));
    };
    // An output that is the recording is refused by the copy itself ("never modified").
    mmtrack_io::check_output_file(&args.output)?;
    let metadata = recording_metadata(recording)?;
    let sequence = args.sequence.clone().unwrap_or_else(|| metadata.sequence_id.clone());
    let odometry = table_path(&args.tables, "odometry", &sequence)?;
    let slam_ue = table_path(&args.tables, SLAM_UE.name, &sequence)?;
    let (table, poses, slam_map, parent_frame) = if odometry.is_file() {
        let rows: Vec<OdometryEstimate> = read_table(&odometry)?;
        let poses: Vec<StampedPose> =
            rows.iter().map(|e| StampedPose { t_ns: e.t_ns, parent_from_child: e.world_from_vehicle }).collect();
        // Tables in the ground truth's frame share the recording's `world`; older
        // tables, and runs without ground truth, start at the first scan's pose.
        let run_config = read_key_value_metadata(&odometry)?.remove("mmtrack.run_config").unwrap_or_default();
        let world = serde_json::from_str::<serde_json::Value>(&run_config)
            .ok()
            .and_then(|c| c["frame"]["world"].as_str().map(str::to_string))
            .unwrap_or_else(|| "first_scan".to_string());
        let parent_frame = if world == "ground_truth" { "world" } else { "odometry_first_scan" };
        (odometry, poses, Vec::new(), parent_frame)
    } else if slam_ue.is_file() {
        // A SLAM run is in the recording's world frame. The UE poses from
        // its initialisation on (before it the estimate is the prior), and
        // the map after every epoch.
        let rows: Vec<SlamUeRow> = read_table(&slam_ue)?;
        let poses: Vec<StampedPose> = rows
            .iter()
            .filter(|r| r.initialised)
            .map(|r| StampedPose { t_ns: r.t_ns, parent_from_child: Se2::new(r.x_m, r.y_m, r.heading_rad) })
            .collect();
        let map = table_path(&args.tables, SLAM_MAP.name, &sequence)?;
        let slam_map: Vec<SlamMapRow> = if map.is_file() { read_table(&map)? } else { Vec::new() };
        (slam_ue, poses, slam_map, "world")
    } else {
        bail!(
            "{}: no odometry or slam_ue table of sequence {sequence} (the recording's; pick another with --sequence; \
             found {})",
            odometry.display(),
            inventory(&args.tables)?.describe()
        );
    };
    let estimate = EstimateToAdd {
        poses: &poses,
        parent_frame,
        slam_map: &slam_map,
        metadata: BTreeMap::from([
            ("estimate.source".to_string(), table.display().to_string()),
            ("estimate.frame".to_string(), parent_frame.to_string()),
        ]),
    };
    let options = RecordingOptions { overwrite, durability: Durability::Fsync, ..RecordingOptions::default() };
    let summary = copy_with_estimate(recording, &args.output, &estimate, &options)?;
    if !quiet {
        let maps = if slam_map.is_empty() {
            String::new()
        } else {
            let epochs: std::collections::BTreeSet<u64> = slam_map.iter().map(|r| r.epoch).collect();
            format!(" and {} SLAM maps", epochs.len())
        };
        println!(
            "{sequence}: {} estimate poses{maps} added to a copy of {}: {} ({:.1} MB)",
            poses.len(),
            recording.display(),
            summary.path.display(),
            summary.file_bytes as f64 / 1e6
        );
    }
    Ok(ExitCode::SUCCESS)
}
