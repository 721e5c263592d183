//! `mmtrack simulate radar`: the radar simulator's scans (`mmtrack_sim::radar`)
//! streamed into a recording with ground truth or an Oxford-layout folder.

use std::path::{Path, PathBuf};

use anyhow::Context;
use mmtrack_core::progress::Progress;
use mmtrack_ingest::oxford::{self, NavtechLayout};
use mmtrack_ingest::poses::{self, Plane};
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase};
use mmtrack_io::{Overwrite, RecordingOptions, RecordingWriter, check_replaceable_dir};
use mmtrack_sim::radar::{RadarSimulator, Scenario, Trajectory};

pub use mmtrack_ingest::poses::TrajectoryFormat;

/// A trajectory file to drive along.
#[derive(Debug, Clone)]
pub struct TrajectoryFile {
    /// The file.
    pub path: PathBuf,
    /// Its format.
    pub format: TrajectoryFormat,
    /// KITTI: the times file (decimal seconds per line).
    pub times: Option<PathBuf>,
    /// KITTI: nanoseconds added to every time.
    pub t0_ns: i64,
}

/// Where the simulated scans go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RadarLayout {
    /// A canonical MCAP recording with the ground truth as a pose stream.
    Recording,
    /// An Oxford Radar RobotCar folder (radar/*.png, radar.timestamps, gt/radar_odometry.csv).
    Oxford,
}

/// One `simulate radar` run.
#[derive(Debug, Clone)]
pub struct RadarSimulation {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    /// Drive along this instead of the scenario's `[motion]`.
    pub trajectory: Option<TrajectoryFile>,
    /// At most this many scans (overrides the scenario's).
    pub max_scans: Option<usize>,
    /// Stop after this many metres of path (overrides the scenario's).
    pub max_distance_m: Option<f64>,
    /// Recording or Oxford folder.
    pub layout: RadarLayout,
    /// The recording or folder to write.
    pub output: PathBuf,
    /// How the recording is written (overwrite, compression, views); for the
    /// folder only `overwrite` counts.
    pub recording: RecordingOptions,
}

/// What [`simulate_radar`] wrote.
#[derive(Debug, Clone, Copy)]
pub struct RadarSimulated {
    /// Scans written.
    pub scans: usize,
    /// Surfaces in the world.
    pub surfaces: usize,
    /// Point targets in the world.
    pub points: usize,
}

/// Parses a radar scenario file.
///
/// # Errors
/// The file cannot be read, parsed or checked, naming it.
pub fn load_scenario(path: &Path) -> anyhow::Result<Scenario> {
    let text = mmtrack_io::paths::read_config_text(path)?;
    parse_scenario(&text).with_context(|| format!("{}", path.display()))
}

/// Parses and checks radar scenario text.
///
/// # Errors
/// TOML errors and the scenario's own checks.
pub fn parse_scenario(text: &str) -> anyhow::Result<Scenario> {
    let scenario: Scenario = toml::from_str(text)?;
    scenario.validate()?;
    Ok(scenario)
}

/// Streams `simulator`'s scans into an Oxford folder at `dir` (replaced
/// atomically: built beside it, then renamed). An existing `dir` is replaced
/// only with [`Overwrite::Replace`] and only when it holds nothing but what this writes
/// ([`is_oxford_output_entry`]); anything else is refused by name before any
/// scan is rendered.
///
/// # Errors
/// An existing `dir` without [`Overwrite::Replace`], a `dir` holding other files, or a file
/// that cannot be written.
pub fn write_oxford_streaming(
    scenario: &Scenario,
    simulator: RadarSimulator<'_>,
    time_base: TimeBase,
    dir: &Path,
    overwrite: Overwrite,
    progress: &dyn Progress,
) -> anyhow::Result<()> {
    check_replaceable_dir(dir, "mmtrack simulate radar --format oxford", &is_oxford_output_entry, overwrite)?;
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).with_context(|| parent.display().to_string())?;
    let staging = mmtrack_io::staging_dir(parent, ".simulate-")?;
    let layout = NavtechLayout {
        range_resolution_m: scenario.sensor.range_resolution_m,
        expected_bins: Some(scenario.sensor.bins),
        ..oxford::OXFORD
    };
    let radar_dir = staging.path().join("radar");
    mmtrack_io::create_output_dirs(&radar_dir).with_context(|| radar_dir.display().to_string())?;
    let mut truth = Vec::new();
    let mut timestamps = String::new();
    for (scan, pose) in simulator {
        let t_us = scan.header.t_ns / 1000;
        let path = radar_dir.join(format!("{t_us}.png"));
        let png = oxford::encode_scan_png(&scan, &layout).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        std::fs::write(&path, png).with_context(|| path.display().to_string())?;
        timestamps.push_str(&format!("{t_us} 1\n"));
        truth.push(pose);
        progress.advance(1);
        progress.check_cancelled()?;
    }
    // The ingest crate's writer produces gt/radar_odometry.csv (its frame conventions);
    // radar.timestamps is rewritten after it with the scans streamed above.
    oxford::write_oxford_folder(staging.path(), &[], &truth, &layout)?;
    let path = staging.path().join("radar.timestamps");
    std::fs::write(&path, timestamps).with_context(|| path.display().to_string())?;
    // So that `ingest oxford` records the simulator's time base, not UNIX dates.
    let path = staging.path().join(oxford::SIMULATION_MARKER);
    std::fs::write(&path, oxford::simulation_marker_text(time_base)).with_context(|| path.display().to_string())?;
    // The old folder (checked above to hold only our own files) moves aside
    // into a staging name first, so `dir` is never missing while a finished
    // output exists, and is removed after the new one is in place.
    let replaced = if dir.exists() {
        let aside = mmtrack_io::staging_dir(parent, ".simulate-")?;
        std::fs::rename(dir, aside.path().join("old")).with_context(|| dir.display().to_string())?;
        Some(aside)
    } else {
        None
    };
    if let Err(error) = std::fs::rename(staging.path(), dir) {
        if let Some(aside) = &replaced {
            // Put the old output back; the new one goes with `staging`.
            let _ = std::fs::rename(aside.path().join("old"), dir);
        }
        return Err(error).with_context(|| dir.display().to_string());
    }
    let _ = staging.keep();
    drop(replaced);
    Ok(())
}

/// Whether `relative` (a path inside an Oxford output folder) is something
/// [`write_oxford_streaming`] writes: `radar/` with `<t_us>.png` scans,
/// `radar.timestamps`, `gt/` with `radar_odometry.csv`, the simulation marker.
fn is_oxford_output_entry(relative: &Path, is_dir: bool) -> bool {
    let parts: Vec<&str> = relative.iter().filter_map(|c| c.to_str()).collect();
    match parts.as_slice() {
        ["radar" | "gt"] => is_dir,
        ["radar.timestamps"] | [oxford::SIMULATION_MARKER] => !is_dir,
        ["radar", scan] => {
            !is_dir && scan.strip_suffix(".png").is_some_and(|t| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit()))
        }
        ["gt", "radar_odometry.csv"] => !is_dir,
        _ => false,
    }
}

fn write_recording(
    sim: &RadarSimulation,
    scenario: &Scenario,
    simulator: RadarSimulator<'_>,
    progress: &dyn Progress,
) -> anyhow::Result<()> {
    let mut extra = std::collections::BTreeMap::from([
        ("simulator.seed".to_string(), scenario.seed.to_string()),
        ("simulator.scenario".to_string(), mmtrack_io::paths::canonical(&sim.scenario)),
        ("radar.model".to_string(), "simulated Navtech CTS350-X-like".to_string()),
    ]);
    if let Some(t) = &sim.trajectory {
        extra.insert("simulator.trajectory".to_string(), mmtrack_io::paths::canonical(&t.path));
    }
    // Scan times are the trajectory's: a real drive's UNIX times when
    // `--trajectory` brings one, else the scenario's clock from its stated
    // `start_t_ns`.
    let mut simulator = simulator.peekable();
    let first_t_ns = simulator.peek().map_or(0, |(scan, _)| scan.header.t_ns);
    let time_base = if sim.trajectory.is_some() {
        TimeBase::unix_or(first_t_ns, TimeBase::ScenarioStart)
    } else {
        TimeBase::ScenarioStart
    };
    let metadata = RecordingMetadata {
        sequence_id: sim
            .output
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "simulated".into()),
        source: format!("simulate:{}", mmtrack_io::paths::canonical(&sim.scenario)),
        time_base,
        extra,
    };
    let mut writer = RecordingWriter::create(&sim.output, &metadata, &sim.recording)?;
    for (scan, pose) in simulator {
        writer.write_radar_scan(&scan)?;
        writer.write_pose(PoseStream::GroundTruth, &pose, "world")?;
        progress.advance(1);
        progress.check_cancelled()?;
    }
    writer.finish()?;
    Ok(())
}

/// `mmtrack simulate radar`: renders the scenario's scans along its motion
/// (or the trajectory file) into a recording or an Oxford folder.
///
/// # Errors
/// A bad scenario or trajectory, an existing output without overwrite, or
/// a file that cannot be written.
pub fn simulate_radar(args: &RadarSimulation, progress: &dyn Progress) -> anyhow::Result<RadarSimulated> {
    if args.max_scans == Some(0) {
        let message =
            "--max-scans 0: expected at least 1 scan (an empty recording is not a simulation; nothing was done)";
        return Err(mmtrack_core::error::UsageError::new(message).into());
    }
    let mut scenario = load_scenario(&args.scenario)?;
    if args.max_scans.is_some() {
        scenario.max_scans = args.max_scans;
    }
    if args.max_distance_m.is_some() {
        scenario.max_distance_m = args.max_distance_m;
    }
    let trajectory = match &args.trajectory {
        Some(file) => {
            let poses = poses::read_trajectory(&file.path, file.format, file.times.as_deref(), file.t0_ns, Plane::Xy)?;
            Trajectory::from_poses(poses).with_context(|| file.path.display().to_string())?
        }
        None => scenario.motion_trajectory().with_context(|| args.scenario.display().to_string())?,
    };
    let world = scenario.build_world(&trajectory).with_context(|| args.scenario.display().to_string())?;
    let options = scenario.options();
    let trajectory_source = args.trajectory.as_ref().map_or(&args.scenario, |t| &t.path);
    let simulator = RadarSimulator::new(&world, &scenario.sensor, &trajectory, options)
        .with_context(|| trajectory_source.display().to_string())?;
    let total = simulator.len();
    progress.start("simulate radar", total as u64, "scans");
    match args.layout {
        RadarLayout::Oxford => {
            // As a recording's: a real drive's UNIX times with --trajectory, else the scenario's clock.
            let time_base = if args.trajectory.is_some() {
                TimeBase::unix_or(trajectory.start_t_ns(), TimeBase::ScenarioStart)
            } else {
                TimeBase::ScenarioStart
            };
            write_oxford_streaming(&scenario, simulator, time_base, &args.output, args.recording.overwrite, progress)?;
        }
        RadarLayout::Recording => write_recording(args, &scenario, simulator, progress)?,
    }
    progress.finish();
    Ok(RadarSimulated { scans: total, surfaces: world.segment_count(), points: world.point_count() })
}
