//! `mmtrack simulate slam [--scenario <toml>] [--seed N] -o <rec.mcap>`: the
//! 5G mmWave SLAM world of Kim et al. 2018 (or one configured in TOML) as a
//! recording: per epoch the path measurements (`/slam/paths`), the true UE
//! state and path origins (`/slam/ue_truth`) and the UE's pose
//! (`/ground_truth/pose`); once, the base station and the true virtual
//! anchors and scattering points (`/slam/sources`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use mmtrack_core::slam::SourceType;
use mmtrack_core::{Se2, StampedPose};
use mmtrack_io::RecordingWriter;
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase};
use mmtrack_sim::slam::{SlamRun, SlamScenario};

use crate::ingest::OutputArgs;
use crate::threads::ThreadsArg;

/// Recording metadata keys the SLAM pipeline reads back.
pub const SEED_KEY: &str = "simulator.seed";
/// The scenario as JSON (every field, defaults included).
pub const SCENARIO_JSON_KEY: &str = "slam.scenario_json";

#[derive(Args)]
pub struct SlamSimArgs {
    /// World file (TOML, the fields of the SLAM scenario: bs_m, walls, scattering_points_m, initial, epochs,
    /// detection_probability, clutter_per_epoch, ...); omitted fields keep the paper's values. Default: the
    /// paper's circular road (BS, 4 walls, 10 random SPs, 100 epochs of 0.2 s).
    #[arg(long, value_name = "SCENARIO.toml")]
    scenario: Option<PathBuf>,
    /// Seed of the world (random SPs), the trajectory and the noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Number of epochs (overrides the scenario's).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    epochs: Option<u64>,
    #[command(flatten)]
    pub threads: ThreadsArg,
    #[command(flatten)]
    output: OutputArgs,
}

/// Parses and checks a SLAM world file.
pub fn load_slam_scenario(path: &Path) -> anyhow::Result<SlamScenario> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    let scenario: SlamScenario = toml::from_str(&text).with_context(|| path.display().to_string())?;
    scenario.validate().with_context(|| path.display().to_string())?;
    Ok(scenario)
}

fn metadata(args: &SlamSimArgs, scenario: &SlamScenario) -> anyhow::Result<RecordingMetadata> {
    let source = args.scenario.as_ref().map_or_else(|| "paper".to_string(), |p| p.display().to_string());
    let extra = BTreeMap::from([
        (SEED_KEY.to_string(), args.seed.to_string()),
        ("simulator.scenario".to_string(), source.clone()),
        (SCENARIO_JSON_KEY.to_string(), serde_json::to_string(scenario)?),
    ]);
    Ok(RecordingMetadata {
        sequence_id: args
            .output
            .output
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "simulated".into()),
        source: format!("simulate slam:{source}"),
        time_base: TimeBase::ScenarioStart,
        extra,
    })
}

/// Writes a realised run: the sources at the first epoch's time, then per
/// epoch the paths, the truth and the ground-truth pose.
pub fn write_run(writer: &mut RecordingWriter, run: &SlamRun) -> anyhow::Result<()> {
    let t0_ns = run.epochs.first().map_or(0, |e| e.t_ns);
    let world = &run.world;
    writer.write_slam_source(t0_ns, SourceType::BaseStation, 0, world.bs_m)?;
    for (i, va) in world.virtual_anchors_m.iter().enumerate() {
        writer.write_slam_source(t0_ns, SourceType::VirtualAnchor, i, *va)?;
    }
    for (i, sp) in world.scattering_points_m.iter().enumerate() {
        writer.write_slam_source(t0_ns, SourceType::ScatteringPoint, i, *sp)?;
    }
    for (epoch, truth) in run.epochs.iter().zip(&run.truth) {
        writer.write_slam_paths(epoch)?;
        writer.write_slam_ue_truth(epoch.t_ns, &truth.ue, &truth.origins)?;
        let ue = &truth.ue;
        let pose = StampedPose {
            t_ns: epoch.t_ns,
            parent_from_child: Se2::new(ue.position_m[0], ue.position_m[1], ue.heading_rad),
        };
        writer.write_pose(PoseStream::GroundTruth, &pose, "world", "ue")?;
    }
    Ok(())
}

pub fn run_slam(args: &SlamSimArgs, quiet: bool) -> anyhow::Result<()> {
    let mut scenario = match &args.scenario {
        Some(path) => load_slam_scenario(path)?,
        None => SlamScenario::default(),
    };
    if let Some(n) = args.epochs {
        scenario.epochs = usize::try_from(n).context("--epochs")?;
    }
    let run = scenario.realise(args.seed, 0).with_context(|| {
        args.scenario.as_ref().map_or_else(|| "the paper's scenario".to_string(), |p| p.display().to_string())
    })?;
    let output = &args.output;
    let mut writer = RecordingWriter::create(&output.output, &metadata(args, &scenario)?, &output.recording_options())?;
    write_run(&mut writer, &run)?;
    writer.finish()?;
    if !quiet {
        let paths: usize = run.epochs.iter().map(|e| e.paths.len()).sum();
        println!(
            "{}: {} epochs, {paths} paths; BS, {} virtual anchors, {} scattering points",
            output.output.display(),
            run.epochs.len(),
            run.world.virtual_anchors_m.len(),
            run.world.scattering_points_m.len()
        );
    }
    Ok(())
}
