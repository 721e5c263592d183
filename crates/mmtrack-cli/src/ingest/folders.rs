//! The folder and bag kinds of `mmtrack ingest` (Navtech scan folders of
//! Oxford, Boreas and MulRan, ROS 2 bags, DeepSense beam arrays): each opens
//! its input, runs the ingest under a progress bar and prints a summary.

use std::path::Path;
use std::process::ExitCode;

use clap::{Args, ValueEnum};
use mmtrack_ingest::beams::{DeepsenseOptions, ingest_deepsense};
use mmtrack_ingest::boreas::{BoreasFolder, BoreasOptions, ingest_boreas};
use mmtrack_ingest::flags;
use mmtrack_ingest::mulran::{MulranFolder, MulranOptions, ingest_mulran};
use mmtrack_ingest::oxford::{self, OxfordFolder, OxfordOptions};
use mmtrack_ingest::ros2::{self, Ros2Topics};
use mmtrack_ingest::sweep::SweepTiming;

use super::{OutputArgs, RadarViewArgs};
use crate::progress;

/// Which azimuth of a sweep an image stamp marks.
#[derive(Clone, Copy, ValueEnum)]
pub enum StampAtArg {
    /// The first azimuth is at the stamp.
    Start,
    /// The last azimuth is at the stamp (a sweep is stamped once received).
    End,
}

/// Timing of polar images that carry one stamp per sweep.
#[derive(Args, Clone)]
pub struct SweepArgs {
    /// Which azimuth the image stamp marks; the others are spread evenly over the scan period.
    #[arg(long, value_enum, default_value_t = StampAtArg::End)]
    stamp_at: StampAtArg,
    /// Scan period in seconds (Navtech at 4 Hz: 0.25).
    #[arg(long, default_value_t = 0.25)]
    scan_period_s: f64,
}

impl SweepArgs {
    pub(super) fn timing(&self) -> anyhow::Result<SweepTiming> {
        let stamp_at = match self.stamp_at {
            StampAtArg::Start => "start",
            StampAtArg::End => "end",
        };
        flags::sweep_timing(stamp_at, self.scan_period_s).map_err(crate::usage)
    }
}

/// Checks that a length flag is a positive, finite number of metres
/// ([`flags::positive_metres`]).
pub(super) fn positive_metres(flag: &str, value: f64) -> anyhow::Result<()> {
    flags::positive_metres(flag, value).map(|_| ()).map_err(crate::usage)
}

/// Ingests one Boreas folder, with a progress bar.
pub(super) fn boreas_folder(
    input: &Path,
    output: &OutputArgs,
    radar_view: &RadarViewArgs,
    options: &BoreasOptions,
    quiet: bool,
) -> anyhow::Result<ExitCode> {
    let recording = output.radar_recording_options(radar_view)?;
    let folder = BoreasFolder::open(input)?;
    let bar = progress::bar(folder.scans.len() as u64, "ingest boreas", "scans", quiet);
    let report = ingest_boreas(&folder, &output.output, options, &recording, &mut |done, _| {
        bar.set_position(done);
    });
    bar.finish_and_clear();
    let report = report?;
    if !quiet {
        println!(
            "{}: {} scans ({} m range bins: {}), {} ground-truth poses, {} GNSS fixes ({:.1} MB)",
            report.output.path.display(),
            report.scans,
            report.range_resolution_m,
            report.range_resolution_source,
            report.ground_truth_poses,
            report.gnss_fixes,
            report.output.file_bytes as f64 / 1e6
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// Ingests one MulRan folder, with a progress bar.
pub(super) fn mulran_folder(
    input: &Path,
    output: &OutputArgs,
    radar_view: &RadarViewArgs,
    options: &MulranOptions,
    quiet: bool,
) -> anyhow::Result<ExitCode> {
    let recording = output.radar_recording_options(radar_view)?;
    let folder = MulranFolder::open(input)?;
    let bar = progress::bar(folder.scans.len() as u64, "ingest mulran", "scans", quiet);
    let report = ingest_mulran(&folder, &output.output, options, &recording, &mut |done, _| {
        bar.set_position(done);
    });
    bar.finish_and_clear();
    let report = report?;
    if !quiet {
        println!(
            "{}: {} scans (azimuth times: file time at the sweep's {}), {} ground-truth poses, {} GNSS fixes ({:.1} MB)",
            report.output.path.display(),
            report.scans,
            options.timing.stamp_at.name(),
            report.ground_truth_poses,
            report.gnss_fixes,
            report.output.file_bytes as f64 / 1e6
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// Ingests one Oxford folder, with a progress bar.
pub fn oxford_folder(
    input: &Path,
    output: &OutputArgs,
    radar_view: &RadarViewArgs,
    options: &OxfordOptions,
    quiet: bool,
) -> anyhow::Result<ExitCode> {
    let recording = output.radar_recording_options(radar_view)?;
    let folder = OxfordFolder::open(input)?;
    let bar = progress::bar(folder.scans.len() as u64, "ingest oxford", "scans", quiet);
    let report = oxford::ingest_oxford(&folder, &output.output, options, &recording, &mut |done, _| {
        bar.set_position(done);
    })?;
    bar.finish_and_clear();
    if !quiet {
        println!(
            "{}: {} scans, {} ground-truth poses, {} GNSS fixes{} ({:.1} MB)",
            report.output.path.display(),
            report.scans,
            report.ground_truth_poses,
            report.gnss_fixes,
            if report.skipped_invalid_scans > 0 {
                format!(", {} scans skipped (flagged invalid in radar.timestamps)", report.skipped_invalid_scans)
            } else {
                String::new()
            } + &report
                .ins_used_as
                .as_ref()
                .map(|used| {
                    format!(
                        "; gps/ins.csv used as {used} ({} rows not INS_SOLUTION_GOOD skipped)",
                        report.ins_rows_not_good
                    )
                })
                .unwrap_or_default(),
            report.output.file_bytes as f64 / 1e6
        );
        if let Some(warning) = unlisted_warning(&folder.root, &report.unlisted_pngs) {
            eprintln!("{warning}");
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// How many PNGs of `radar/` were skipped because `radar.timestamps` does not
/// list them, with the first few names (escaped); `None` when there were none.
fn unlisted_warning(root: &Path, unlisted: &[std::path::PathBuf]) -> Option<String> {
    const SHOWN: usize = 3;
    let names: Vec<String> = unlisted
        .iter()
        .take(SHOWN)
        .map(|p| {
            let name = p.file_name().unwrap_or(p.as_os_str());
            mmtrack_core::error::printable(name.as_encoded_bytes()).into_owned()
        })
        .collect();
    (!unlisted.is_empty()).then(|| {
        format!(
            "warning: {}: {} PNGs in radar/ are not listed in radar.timestamps and were skipped: {}{}",
            root.display(),
            unlisted.len(),
            names.join(", "),
            if unlisted.len() > SHOWN { ", ..." } else { "" }
        )
    })
}

/// Ingests the chosen topics of a ROS 2 bag, with a progress bar.
pub(super) fn ros2_bag(
    input: &Path,
    output: &OutputArgs,
    radar_view: &RadarViewArgs,
    topics: &Ros2Topics,
    quiet: bool,
) -> anyhow::Result<ExitCode> {
    let recording = output.radar_recording_options(radar_view)?;
    let bar = progress::bytes_bar(std::fs::metadata(input).map_or(0, |m| m.len()), "ingest ros2", quiet);
    let report = ros2::ingest_ros2(input, &output.output, topics, &recording, &mut |done, total| {
        bar.set_length(total);
        bar.set_position(done);
    });
    bar.finish_and_clear();
    let report = report?;
    if !quiet {
        println!("{}", report.summary());
    }
    Ok(ExitCode::SUCCESS)
}

/// Where `ingest beams` writes: a directory of recordings, one per pass.
#[derive(Args, Clone)]
pub struct RecordingDirArgs {
    /// Output directory; one recording per pass is written into it (created if missing).
    #[arg(short, long, value_name = "DIR")]
    pub output: std::path::PathBuf,
    /// Replace existing recordings of the same passes (each atomically, once complete).
    #[arg(long)]
    pub force: bool,
    /// Omit the Foxglove display channels (/viz/...).
    #[arg(long)]
    pub no_foxglove_views: bool,
    /// Skip the fsync before each final rename.
    #[arg(long)]
    pub no_sync: bool,
}

impl RecordingDirArgs {
    /// The writer's options ([`mmtrack_io::recording::RecordingFlags`]; beam
    /// recordings have no radar view).
    fn recording_options(&self) -> anyhow::Result<mmtrack_io::RecordingOptions> {
        let flags = mmtrack_io::recording::RecordingFlags {
            force: self.force,
            no_foxglove_views: self.no_foxglove_views,
            no_radar_cartesian: true,
            no_sync: self.no_sync,
            ..Default::default()
        };
        flags.options().map_err(crate::usage)
    }
}

pub(super) fn deepsense_folder(
    input: &Path,
    output: &RecordingDirArgs,
    options: &DeepsenseOptions,
    quiet: bool,
) -> anyhow::Result<ExitCode> {
    let bar = progress::bar(0, "ingest beams", "sweeps", quiet);
    let written = ingest_deepsense(input, &output.output, options, &output.recording_options()?, &mut |done, total| {
        bar.set_length(total);
        bar.set_position(done);
    });
    bar.finish_and_clear();
    let written = written?;
    if !quiet {
        let mut scenarios: Vec<u32> = written.iter().map(|w| w.scenario).collect();
        scenarios.dedup();
        for scenario in scenarios {
            let passes: Vec<_> = written.iter().filter(|w| w.scenario == scenario).collect();
            let (Some(first), Some(last)) = (passes.first(), passes.last()) else { continue };
            println!(
                "scenario {scenario}: {} passes, {} sweeps of {} beams, {} car positions -> {} .. {} ({:.1} MB)",
                passes.len(),
                passes.iter().map(|w| w.sweeps).sum::<usize>(),
                first.beams,
                if first.calibrated { "calibrated" } else { "raw" },
                first.output.path.display(),
                last.output.path.display(),
                passes.iter().map(|w| w.output.file_bytes).sum::<u64>() as f64 / 1e6
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
