//! `mmtrack simulate radar --scenario <toml> [--trajectory <file>] -o <out>`:
//! reads the scenario (and a trajectory file), streams the simulator's scans
//! into a recording with ground truth or an Oxford-layout folder.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Subcommand, ValueEnum};
use mmtrack_process::simulate::radar::{RadarLayout, RadarSimulation, TrajectoryFile, simulate_radar};

use crate::ingest::{OutputArgs, PoseFormat, RadarViewArgs};
use crate::progress::IndicatifProgress;
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
    #[command(flatten)]
    radar_view: RadarViewArgs,
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq)]
enum Format {
    /// A canonical MCAP recording with the ground truth as a pose stream.
    Recording,
    /// An Oxford Radar RobotCar folder (radar/*.png, radar.timestamps, gt/radar_odometry.csv).
    Oxford,
}

fn run_radar(args: &RadarArgs, quiet: bool) -> anyhow::Result<()> {
    let simulation = RadarSimulation {
        scenario: args.scenario.clone(),
        trajectory: args.trajectory.as_ref().map(|path| TrajectoryFile {
            path: path.clone(),
            format: args.trajectory_format.trajectory_format(),
            times: args.times.clone(),
            t0_ns: args.t0_ns,
        }),
        max_scans: args.max_scans,
        max_distance_m: args.max_distance_m,
        layout: match args.format {
            Format::Recording => RadarLayout::Recording,
            Format::Oxford => RadarLayout::Oxford,
        },
        output: args.output.output.clone(),
        recording: args.output.radar_recording_options(&args.radar_view)?,
    };
    let done = simulate_radar(&simulation, &IndicatifProgress::new(quiet))?;
    if !quiet {
        println!(
            "{}: {} simulated scans ({} surfaces, {} point targets in the world)",
            args.output.output.display(),
            done.scans,
            done.surfaces,
            done.points
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
