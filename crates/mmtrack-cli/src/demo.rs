//! `mmtrack demo`: the whole chain on embedded data, no files needed.
//!
//! Simulate the demo radar scenario as an Oxford-layout folder, ingest it into
//! a recording, write its ground truth as a Parquet table, run radar odometry
//! (the `cfear` preset) on it, compute trajectory metrics and plots against
//! the ground truth, and show where everything is.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::Args;
use mmtrack_analysis::output::write_results;
use mmtrack_analysis::pipeline::analyze_trajectory;
use mmtrack_analysis::trajectory::{DriftOptions, FirstFrameStep};
use mmtrack_core::StampedPose;
use mmtrack_ingest::oxford::{self, OxfordOptions};
use mmtrack_io::recording::PoseStream;
use mmtrack_io::table::{RunInfo, write_table};
use mmtrack_io::{Overwrite, RecordingEvent, RecordingReader};
use mmtrack_odometry::OdometryConfig;

use crate::ingest::{CompressionArg, OutputArgs};
use crate::{inspect, process, simulate};

/// The demo scenario, embedded so the demo runs from any directory.
pub const DEMO_SCENARIO: &str = include_str!("../../../data/demo/radar-scenario.toml");
/// Sequence id of the demo data (the folder name, as for real Oxford data).
pub const DEMO_SEQUENCE: &str = "oxford-demo";

#[derive(Args)]
pub struct DemoArgs {
    /// Output directory; the demo replaces its own previous outputs there.
    #[arg(long, default_value = "out/demo")]
    out: PathBuf,
}

pub fn run(args: &DemoArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let scenario = simulate::parse_scenario(DEMO_SCENARIO).context("embedded demo scenario")?;
    let input = args.out.join("input").join(DEMO_SEQUENCE);
    simulate::write_oxford(&scenario, &input, true)?;

    let recording = args.out.join("recording.mcap");
    let output = OutputArgs {
        output: recording.clone(),
        force: true,
        compression: CompressionArg::Zstd,
        zstd_level: 1,
        no_foxglove_views: false,
        no_sync: false,
    };
    let options = OxfordOptions {
        layout: oxford::NavtechLayout {
            range_resolution_m: scenario.sensor.range_resolution_m,
            expected_bins: Some(scenario.sensor.bins),
            ..oxford::OXFORD
        },
        ..OxfordOptions::default()
    };
    crate::ingest::oxford_folder(&input, &output, &options, quiet)?;

    let mut ground_truth: Vec<StampedPose> = Vec::new();
    for event in RecordingReader::open(&recording)? {
        if let RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } = event? {
            ground_truth.push(pose);
        }
    }
    let tables = args.out.join("tables");
    let run = RunInfo {
        config_json: serde_json::json!({"command": "demo", "table": "ground truth of the recording"}).to_string(),
    };
    write_table(&tables, DEMO_SEQUENCE, &ground_truth, &run, Overwrite::Replace)?;

    let preset = "cfear";
    let config = OdometryConfig::cfear();
    let odometry = process::run_odometry(&recording, config.clone(), quiet)?;
    let written =
        process::write_outputs(&tables, DEMO_SEQUENCE, &odometry, &config, preset, &recording, Overwrite::Replace)?;

    // Trajectory metrics and plots. The demo drive is 14 m, so the KITTI
    // segments are scaled down from the devkit's 100..800 m.
    let options = DriftOptions { segment_lengths_m: vec![4.0, 8.0, 12.0], step: FirstFrameStep::Frames(1) };
    let estimate: Vec<StampedPose> = odometry
        .estimates
        .iter()
        .map(|e| StampedPose { t_ns: e.t_ns, parent_from_child: e.world_from_vehicle })
        .collect();
    let result = analyze_trajectory(DEMO_SEQUENCE, &estimate, &odometry.ground_truth, &options)?;
    let info = RunInfo {
        config_json: serde_json::json!({"command": "demo", "segment_lengths_m": options.segment_lengths_m}).to_string(),
    };
    let analysis = write_results(&args.out.join("analysis"), &[result], &[], &options, &info, Overwrite::Replace)?;

    if !quiet {
        println!();
        inspect::run(&inspect::InspectArgs::new(recording.clone()), quiet)?;
        println!();
        inspect::run(&inspect::InspectArgs::new(tables.clone()), quiet)?;
        println!("\nOutputs:");
        println!("  input folder (Oxford layout): {}", input.display());
        println!("  recording (open in Foxglove):  {}", recording.display());
        println!("  tables (Parquet, Hive layout): {}", tables.display());
        let last = odometry.estimates.last().map(|e| e.world_from_vehicle);
        let truth_end = odometry
            .ground_truth
            .first()
            .zip(odometry.ground_truth.last())
            .map(|(a, b)| a.parent_from_child.inverse() * b.parent_from_child);
        if let (Some(estimate), Some(truth)) = (last, truth_end) {
            println!(
                "  radar odometry ({preset}, {} scans, {} low-confidence): end point {:.2} m from the ground truth's after {:.1} m",
                odometry.estimates.len(),
                odometry.estimates.iter().filter(|e| e.low_confidence).count(),
                (truth.inverse() * estimate).translation_norm_m(),
                truth.translation_norm_m()
            );
        }
        println!(
            "  odometry tables: {}",
            written.iter().map(|w| w.path.display().to_string()).collect::<Vec<_>>().join(", ")
        );
        println!(
            "  analysis (metrics, plots):    {} (report {})",
            analysis.out_dir.display(),
            analysis.report.display()
        );
        println!("\nNot in the demo yet: the mpc, beam and slam pipelines.");
    }
    Ok(ExitCode::SUCCESS)
}
