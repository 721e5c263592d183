//! `mmtrack export`: trajectory tables as standard text (TUM, KITTI, Boreas)
//! for evo, the KITTI devkit and pyboreas. The formats are in
//! `mmtrack_analysis::export`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use mmtrack_analysis::export::{ExportFormat, export_sequence};
use mmtrack_analysis::pipeline::{inventory, read_trajectories};
use mmtrack_io::Overwrite;

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    /// `t_s x y z qx qy qz qw` per pose, each trajectory at its own times and in its own frame (evo `tum`).
    Tum,
    /// 12 numbers of the 3x4 world_from_vehicle per line, estimate and ground truth associated frame by frame and
    /// starting at the identity, plus `<seq>.times.txt` (KITTI devkit, evo `kitti`).
    Kitti,
    /// pyboreas odometry benchmark: `t_us` + 3x4 vehicle_from_world, `boreas/estimate/<seq>.txt`.
    Boreas,
}

#[derive(Args)]
#[command(
    long_about = "Writes the estimate (table `odometry`) and, when present, the ground truth (table `ground_truth`) of \
each sequence as text files that evo, the KITTI odometry devkit and pyboreas read. Numbers are written at full \
precision (shortest round-trip) and times as exact decimals. Files: <seq>.estimate.<fmt>.txt and \
<seq>.ground_truth.<fmt>.txt (KITTI also <seq>.times.txt; Boreas boreas/{estimate,ground_truth}/<seq>.txt).",
    after_help = "Example: mmtrack export --format kitti out/tables -o out/kitti && evo_ape kitti \
out/kitti/seq.ground_truth.kitti.txt out/kitti/seq.estimate.kitti.txt"
)]
pub struct ExportArgs {
    /// Output format.
    #[arg(long, value_enum)]
    format: Format,
    /// Table directory written by `mmtrack process`.
    tables: PathBuf,
    /// Output directory.
    #[arg(short, long, value_name = "DIR")]
    output: PathBuf,
    /// Export only this sequence (default: every sequence with an odometry table).
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
    let mut inputs = read_trajectories(&args.tables)?;
    if inputs.is_empty() {
        bail!("{}: no odometry table to export (found {})", args.tables.display(), inventory(&args.tables)?.describe());
    }
    if let Some(wanted) = &args.sequence {
        let available: Vec<String> = inputs.keys().cloned().collect();
        inputs.retain(|s, _| s == wanted);
        if inputs.is_empty() {
            bail!(
                "sequence {wanted}: no odometry table in {} (sequences: {})",
                args.tables.display(),
                available.join(", ")
            );
        }
    }
    let format = match args.format {
        Format::Tum => ExportFormat::Tum,
        Format::Kitti => ExportFormat::Kitti,
        Format::Boreas => ExportFormat::Boreas,
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
