//! `mmtrack simulate slam`: the 5G mmWave SLAM world of Kim et al. 2018 (or
//! one configured in TOML) as a recording: per epoch the path measurements
//! (`/slam/paths`), the true UE state and path origins (`/slam/ue_truth`)
//! and the UE's pose (`/ground_truth/pose`); once, the base station and the
//! true virtual anchors and scattering points (`/slam/sources`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Context;
use mmtrack_core::slam::SourceType;
use mmtrack_core::{Se2, StampedPose};
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase};
use mmtrack_io::{RecordingOptions, RecordingWriter};
use mmtrack_sim::slam::{SlamRun, SlamScenario};

use crate::slam::SCENARIO_JSON_KEY;

/// Recording metadata key of the simulator's seed.
pub const SEED_KEY: &str = "simulator.seed";

/// One `simulate slam` run.
#[derive(Debug, Clone)]
pub struct SlamSimulation {
    /// World file (TOML); `None`: the paper's world.
    pub scenario: Option<PathBuf>,
    /// Seed of the realisation.
    pub seed: u64,
    /// Epochs (overrides the world's).
    pub epochs: Option<u64>,
    /// The recording to write.
    pub output: PathBuf,
    /// How it is written.
    pub recording: RecordingOptions,
}

/// What [`simulate_slam`] wrote.
#[derive(Debug, Clone, Copy)]
pub struct SlamSimulated {
    /// Epochs written.
    pub epochs: usize,
    /// Paths over all epochs.
    pub paths: usize,
    /// True virtual anchors.
    pub virtual_anchors: usize,
    /// True scattering points.
    pub scattering_points: usize,
}

/// Parses and checks a SLAM world file.
///
/// # Errors
/// The file cannot be read, parsed or checked, naming it.
pub fn load_slam_scenario(path: &Path) -> anyhow::Result<SlamScenario> {
    let text = mmtrack_io::paths::read_config_text(path)?;
    let scenario: SlamScenario = toml::from_str(&text).with_context(|| path.display().to_string())?;
    scenario.validate().with_context(|| path.display().to_string())?;
    Ok(scenario)
}

fn metadata(args: &SlamSimulation, scenario: &SlamScenario) -> anyhow::Result<RecordingMetadata> {
    let source = args.scenario.as_ref().map_or_else(|| "paper".to_string(), |p| mmtrack_io::paths::canonical(p));
    let extra = BTreeMap::from([
        (SEED_KEY.to_string(), args.seed.to_string()),
        ("simulator.scenario".to_string(), source.clone()),
        (SCENARIO_JSON_KEY.to_string(), serde_json::to_string(scenario)?),
    ]);
    Ok(RecordingMetadata {
        sequence_id: args
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
///
/// # Errors
/// A message that cannot be written.
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
        writer.write_pose(PoseStream::GroundTruth, &pose, "world")?;
    }
    Ok(())
}

/// `mmtrack simulate slam`: one realisation of the world into a recording.
///
/// # Errors
/// A bad world file or epoch count, an existing output without overwrite,
/// or a write error.
pub fn simulate_slam(args: &SlamSimulation) -> anyhow::Result<SlamSimulated> {
    let mut scenario = match &args.scenario {
        Some(path) => load_slam_scenario(path)?,
        None => SlamScenario::default(),
    };
    if let Some(n) = args.epochs {
        mmtrack_core::limits::SLAM_EPOCHS.check_flag("--epochs", n, 1)?;
        scenario.epochs = usize::try_from(n).context("--epochs")?;
    }
    let run = scenario.realise(args.seed, 0).with_context(|| {
        args.scenario.as_ref().map_or_else(|| "the paper's scenario".to_string(), |p| p.display().to_string())
    })?;
    let mut writer = RecordingWriter::create(&args.output, &metadata(args, &scenario)?, &args.recording)?;
    write_run(&mut writer, &run)?;
    writer.finish()?;
    Ok(SlamSimulated {
        epochs: run.epochs.len(),
        paths: run.epochs.iter().map(|e| e.paths.len()).sum(),
        virtual_anchors: run.world.virtual_anchors_m.len(),
        scattering_points: run.world.scattering_points_m.len(),
    })
}
