//! `mmtrack simulate radar --scenario <toml> [--trajectory <file>] -o <out>`:
//! reads the scenario (and a trajectory file), streams the simulator's scans
//! into a recording with ground truth or an Oxford-layout folder.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::{Args, Subcommand, ValueEnum};
use mmtrack_core::StampedPose;
use mmtrack_ingest::oxford::{self, NavtechLayout};
use mmtrack_ingest::poses::{self, Plane};
use mmtrack_io::RecordingWriter;
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase};
use mmtrack_sim::radar::{RadarSimulator, Scenario, Trajectory};

use crate::ingest::{OutputArgs, PoseFormat};
use crate::threads::ThreadsArg;

#[derive(Args)]
pub struct SimulateArgs {
    #[command(subcommand)]
    kind: Kind,
}

#[derive(Subcommand)]
enum Kind {
    /// Navtech-like spinning radar driving through a 2D world (see data/demo/radar-scenario.toml).
    ///
    /// The world is the scenario's [[reflectors]] plus, with a [generator] table, a procedural
    /// street scene (buildings, junctions, parked cars, poles, trees, clutter) laid along the
    /// trajectory. The trajectory is the scenario's [motion] (constant turn) or a file given
    /// with --trajectory (e.g. Oxford gt/radar_odometry.csv). One scan every sweep period over
    /// the trajectory's span, cut by --max-scans / --max-distance-m. Same scenario, trajectory
    /// and seed give identical bytes.
    Radar(Box<RadarArgs>),
    /// Wideband channel sounder with true MPCs (see data/sounder/*.toml).
    ///
    /// The scenario holds a seed and one channel: [artificial] (Mahler et al. 2017, Sec. IV-A:
    /// two equal-power MPCs approaching in delay over continuous snapshots, plus a noise floor) or
    /// [convoy] (Sec. II: two cars in convoy through a curved tunnel or on a highway; LOS, wall
    /// bounces, traffic, diffuse scattering and noise; sets of snapshots). The recording carries
    /// the CIRs (/channel/cir), the true MPCs (/channel/mpc_truth), both cars' poses per set
    /// (/ground_truth/tx, /ground_truth/rx) and the pulse spectrum in its metadata. Same scenario
    /// and seed give identical bytes.
    Sounder(Box<crate::simulate_sounder::SounderArgs>),
    /// 5G mmWave SLAM world (Kim et al. 2018): per-epoch path measurements with ground truth.
    ///
    /// Without --scenario the paper's world: a base station at (0, 0, 40) m, four walls (virtual
    /// anchors), 10 random scattering points visible within 50 m, the UE on a circular road
    /// (radius 70.73 m, 22.22 m/s) for 100 epochs of 0.2 s. A TOML world changes any field (other
    /// roads, walls, explicit scattering points, detection probability, clutter). The recording
    /// carries the paths of each epoch (/slam/paths: TOA, DOA and DOD azimuth and elevation), the
    /// true UE state and path origins (/slam/ue_truth), the UE pose (/ground_truth/pose) and the
    /// base station and true sources (/slam/sources). Same world and seed give identical bytes.
    Slam(Box<crate::slam::simulate::SlamSimArgs>),
}

#[derive(Args)]
struct RadarArgs {
    /// Scenario file (TOML): seed, [sensor], [motion], [generator], [[reflectors]].
    #[arg(long, value_name = "SCENARIO.toml")]
    scenario: PathBuf,
    /// Drive along this trajectory instead of the scenario's [motion].
    #[arg(long, value_name = "FILE")]
    trajectory: Option<PathBuf>,
    /// Format of --trajectory.
    #[arg(long, value_enum, default_value_t = PoseFormat::Oxford, requires = "trajectory")]
    trajectory_format: PoseFormat,
    /// KITTI trajectories: the times file (decimal seconds per line).
    #[arg(long, value_name = "times.txt", requires = "trajectory")]
    times: Option<PathBuf>,
    /// KITTI trajectories: nanoseconds added to every time of --times.
    #[arg(long, default_value_t = 0, requires = "times")]
    t0_ns: i64,
    /// Render at most this many scans (overrides the scenario's max_scans).
    #[arg(long, value_name = "N")]
    max_scans: Option<usize>,
    /// Stop after this many metres of path (overrides the scenario's max_distance_m).
    #[arg(long, value_name = "METRES")]
    max_distance_m: Option<f64>,
    #[command(flatten)]
    threads: ThreadsArg,
    /// Output layout: a recording with ground truth, or an Oxford-style folder (to exercise ingest).
    #[arg(long, value_enum, default_value_t = Format::Recording)]
    format: Format,
    #[command(flatten)]
    output: OutputArgs,
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq)]
enum Format {
    /// A canonical MCAP recording with the ground truth as a pose stream.
    Recording,
    /// An Oxford Radar RobotCar folder (radar/*.png, radar.timestamps, gt/radar_odometry.csv).
    Oxford,
}

/// Parses a radar scenario file.
pub fn load_scenario(path: &Path) -> anyhow::Result<Scenario> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    parse_scenario(&text).with_context(|| format!("{}", path.display()))
}

/// Parses and checks radar scenario text.
pub fn parse_scenario(text: &str) -> anyhow::Result<Scenario> {
    let scenario: Scenario = toml::from_str(text)?;
    scenario.validate()?;
    Ok(scenario)
}

/// Reads a trajectory file as `world_from_vehicle` poses.
pub fn read_trajectory(
    path: &Path,
    format: PoseFormat,
    times: Option<&Path>,
    t0_ns: i64,
) -> anyhow::Result<Vec<StampedPose>> {
    let poses = match format {
        PoseFormat::Oxford => oxford::odometry::read_radar_odometry(path)?,
        PoseFormat::Tum => poses::parse_tum(path, &poses::read_text(path)?, Plane::Xy)?,
        PoseFormat::Kitti => {
            let times_path = times.context("KITTI pose files carry no time: give --times <times.txt>")?;
            let times = poses::parse_times(times_path, &poses::read_text(times_path)?, t0_ns)?;
            poses::parse_kitti(path, &poses::read_text(path)?, &times, Plane::Xy)?
        }
    };
    Ok(poses)
}

/// Streams `simulator`'s scans into an Oxford folder at `dir` (replaced
/// atomically: built beside it, then renamed).
pub fn write_oxford_streaming(
    scenario: &Scenario,
    simulator: RadarSimulator<'_>,
    dir: &Path,
    force: bool,
    tick: &dyn Fn(),
) -> anyhow::Result<()> {
    if dir.exists() && !force {
        anyhow::bail!("{}: output already exists (pass --force to replace it)", dir.display());
    }
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).with_context(|| parent.display().to_string())?;
    let staging = mmtrack_io::staging_dir(parent, ".simulate-")?;
    let layout = NavtechLayout {
        range_resolution_m: scenario.sensor.range_resolution_m,
        expected_bins: Some(scenario.sensor.bins),
        ..oxford::OXFORD
    };
    let radar_dir = staging.path().join("radar");
    std::fs::create_dir_all(&radar_dir).with_context(|| radar_dir.display().to_string())?;
    let mut truth = Vec::new();
    let mut timestamps = String::new();
    for (scan, pose) in simulator {
        let t_us = scan.header.t_ns / 1000;
        let path = radar_dir.join(format!("{t_us}.png"));
        let png = oxford::encode_scan_png(&scan, &layout).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        std::fs::write(&path, png).with_context(|| path.display().to_string())?;
        timestamps.push_str(&format!("{t_us} 1\n"));
        truth.push(pose);
        tick();
    }
    // The ingest crate's writer produces gt/radar_odometry.csv (its frame conventions);
    // radar.timestamps is rewritten after it with the scans streamed above.
    oxford::write_oxford_folder(staging.path(), &[], &truth, &layout)?;
    let path = staging.path().join("radar.timestamps");
    std::fs::write(&path, timestamps).with_context(|| path.display().to_string())?;
    if dir.exists() {
        std::fs::remove_dir_all(dir).with_context(|| dir.display().to_string())?;
    }
    let staged = staging.keep();
    std::fs::rename(&staged, dir).with_context(|| dir.display().to_string())?;
    Ok(())
}

fn write_recording(
    args: &RadarArgs,
    scenario: &Scenario,
    simulator: RadarSimulator<'_>,
    tick: &dyn Fn(),
) -> anyhow::Result<()> {
    let output = &args.output;
    let mut extra = std::collections::BTreeMap::from([
        ("simulator.seed".to_string(), scenario.seed.to_string()),
        ("simulator.scenario".to_string(), args.scenario.display().to_string()),
        ("radar.model".to_string(), "simulated Navtech CTS350-X-like".to_string()),
    ]);
    if let Some(t) = &args.trajectory {
        extra.insert("simulator.trajectory".to_string(), t.display().to_string());
    }
    // Scan times are the trajectory's: UNIX time when a real trajectory or the
    // scenario's `start_t_ns` puts the drive at a date, scenario time from 0 otherwise.
    let mut simulator = simulator.peekable();
    let first_t_ns = simulator.peek().map_or(0, |(scan, _)| scan.header.t_ns);
    let time_base = TimeBase::unix_or(first_t_ns, TimeBase::ScenarioStart);
    let metadata = RecordingMetadata {
        sequence_id: output
            .output
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "simulated".into()),
        source: format!("simulate:{}", args.scenario.display()),
        time_base,
        extra,
    };
    let mut writer = RecordingWriter::create(&output.output, &metadata, &output.recording_options())?;
    for (scan, pose) in simulator {
        writer.write_radar_scan(&scan)?;
        writer.write_pose(PoseStream::GroundTruth, &pose, "world", "radar")?;
        tick();
    }
    writer.finish()?;
    Ok(())
}

fn run_radar(args: &RadarArgs, quiet: bool) -> anyhow::Result<()> {
    let mut scenario = load_scenario(&args.scenario)?;
    if args.max_scans.is_some() {
        scenario.max_scans = args.max_scans;
    }
    if args.max_distance_m.is_some() {
        scenario.max_distance_m = args.max_distance_m;
    }
    let trajectory = match &args.trajectory {
        Some(path) => {
            let poses = read_trajectory(path, args.trajectory_format, args.times.as_deref(), args.t0_ns)?;
            Trajectory::from_poses(poses).with_context(|| path.display().to_string())?
        }
        None => scenario.motion_trajectory().with_context(|| args.scenario.display().to_string())?,
    };
    let world = scenario.build_world(&trajectory).with_context(|| args.scenario.display().to_string())?;
    let options = scenario.options();
    let trajectory_source = args.trajectory.as_ref().unwrap_or(&args.scenario);
    let simulator = RadarSimulator::new(&world, &scenario.sensor, &trajectory, options)
        .with_context(|| trajectory_source.display().to_string())?;
    let total = simulator.len();
    let bar = crate::progress::bar(total as u64, "simulate radar", "scans", quiet);
    let tick = || bar.inc(1);
    match args.format {
        Format::Oxford => write_oxford_streaming(&scenario, simulator, &args.output.output, args.output.force, &tick)?,
        Format::Recording => write_recording(args, &scenario, simulator, &tick)?,
    }
    bar.finish_and_clear();
    if !quiet {
        println!(
            "{}: {total} simulated scans ({} surfaces, {} point targets in the world)",
            args.output.output.display(),
            world.segment_count(),
            world.point_count()
        );
    }
    Ok(())
}

pub fn run(args: SimulateArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    match args.kind {
        Kind::Radar(radar) => {
            radar.threads.install(|| run_radar(&radar, quiet))??;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Sounder(sounder) => {
            sounder.threads.install(|| crate::simulate_sounder::run_sounder(&sounder, quiet))??;
            Ok(ExitCode::SUCCESS)
        }
        Kind::Slam(slam) => {
            slam.threads.install(|| crate::slam::simulate::run_slam(&slam, quiet))??;
            Ok(ExitCode::SUCCESS)
        }
    }
}
