//! `mmtrack simulate radar --scenario <toml> -o <out>`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::{Args, Subcommand, ValueEnum};
use mmtrack_ingest::oxford::{self, NavtechLayout};
use mmtrack_io::RecordingWriter;
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase};
use mmtrack_sim::radar::{self, RadarScenario};

use crate::ingest::OutputArgs;

#[derive(Args)]
pub struct SimulateArgs {
    #[command(subcommand)]
    kind: Kind,
}

#[derive(Subcommand)]
enum Kind {
    /// Spinning radar in a planar scene of points and walls (see data/demo/radar-scenario.toml).
    Radar {
        /// Scenario file (TOML).
        #[arg(long, value_name = "SCENARIO.toml")]
        scenario: PathBuf,
        /// Output layout: an Oxford-style folder (to exercise ingest) or a recording.
        #[arg(long, value_enum, default_value_t = Format::Recording)]
        format: Format,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Channel sounder (not built yet: issue #5).
    Sounder {
        /// Arguments.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq)]
enum Format {
    /// A canonical MCAP recording with ground truth.
    Recording,
    /// An Oxford Radar RobotCar folder (radar/*.png, radar.timestamps, gt/radar_odometry.csv).
    Oxford,
}

/// Parses a radar scenario file.
pub fn load_scenario(path: &Path) -> anyhow::Result<RadarScenario> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    parse_scenario(&text).with_context(|| format!("{}", path.display()))
}

/// Parses radar scenario text.
pub fn parse_scenario(text: &str) -> anyhow::Result<RadarScenario> {
    Ok(toml::from_str(text)?)
}

/// Writes a simulated scenario as an Oxford folder at `dir` (replaced atomically:
/// built beside it, then renamed).
pub fn write_oxford(scenario: &RadarScenario, dir: &Path, force: bool) -> anyhow::Result<()> {
    if dir.exists() && !force {
        anyhow::bail!("{}: output already exists (pass --force to replace it)", dir.display());
    }
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).with_context(|| parent.display().to_string())?;
    let staging = tempfile::Builder::new().prefix(".simulate-").tempdir_in(parent)?;
    let (scans, truth) = radar::simulate(scenario);
    let layout = NavtechLayout {
        range_resolution_m: scenario.sensor.range_resolution_m,
        expected_bins: Some(scenario.sensor.bins),
        ..oxford::OXFORD
    };
    oxford::write_oxford_folder(staging.path(), &scans, &truth, &layout)?;
    if dir.exists() {
        std::fs::remove_dir_all(dir).with_context(|| dir.display().to_string())?;
    }
    let staged = staging.keep();
    std::fs::rename(&staged, dir).with_context(|| dir.display().to_string())?;
    Ok(())
}

pub fn run(args: SimulateArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    match args.kind {
        Kind::Radar { scenario, format, output } => {
            let parsed = load_scenario(&scenario)?;
            match format {
                Format::Oxford => write_oxford(&parsed, &output.output, output.force)?,
                Format::Recording => {
                    let (scans, truth) = radar::simulate(&parsed);
                    let metadata = RecordingMetadata {
                        sequence_id: output
                            .output
                            .file_stem()
                            .map(|s| s.to_string_lossy().into_owned())
                            .unwrap_or_else(|| "simulated".into()),
                        source: format!("simulate:{}", scenario.display()),
                        time_base: TimeBase::UnixEpoch,
                        extra: [("simulator.seed".to_string(), parsed.seed.to_string())].into(),
                    };
                    let mut writer = RecordingWriter::create(&output.output, &metadata, &output.recording_options())?;
                    for (scan, pose) in scans.iter().zip(&truth) {
                        writer.write_radar_scan(scan)?;
                        writer.write_pose(PoseStream::GroundTruth, pose, "world", "radar")?;
                    }
                    writer.finish()?;
                }
            }
            if !quiet {
                println!("{}: {} simulated scans", output.output.display(), parsed.scans);
            }
            Ok(ExitCode::SUCCESS)
        }
        Kind::Sounder { .. } => crate::not_built("simulate sounder", 5),
    }
}
