//! `mmtrack demo`: the whole chain on embedded data, no files needed.
//!
//! The demo calls the libraries as those commands do, printing before each
//! step the `mmtrack` command line that does the same (copy any of them to
//! run it again):
//!
//! 1. radar: simulate the embedded demo drive as an Oxford-layout folder,
//!    ingest it, run radar odometry (`cfear`);
//! 2. multipath: simulate a short stretch (40 sets) of the embedded convoy
//!    sounder scenario and detect and track its multipath components
//!    (GM-PHD baseline included);
//! 3. beam: SPEBT beam tracking along the radar drive, driven by the
//!    odometry of step 1;
//! 4. SLAM: simulate a short stretch ([`DEMO_SLAM_EPOCHS`] epochs) of the 5G
//!    mmWave SLAM world of Kim et al. 2018 and run the SLAM filter on it
//!    ([`DEMO_SLAM_PARTICLES`] particles);
//! 5. analyze every table together: trajectory metrics, MPC statistics,
//!    SPEBT accuracy, SLAM metrics, plots, `report.md` and `report.html`;
//! 6. compare runs: radar odometry with both presets (`cfear`,
//!    `fast-cfear`) as two named runs (`--run-id`), analyzed side by side.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::Args;
use mmtrack_analysis::analyze::{AnalyzeOptions, analyze};
use mmtrack_analysis::mpc::MpcOptions;
use mmtrack_analysis::trajectory::{DriftOptions, FirstFrameStep};
use mmtrack_ingest::oxford::{self, OxfordFolder, OxfordOptions};
use mmtrack_io::recording::cartesian::CartesianGrid;
use mmtrack_io::{Overwrite, RecordingOptions};
use mmtrack_process::beam::spebt::{SpebtOptions, process_spebt};
use mmtrack_process::output::OutputOptions;
use mmtrack_process::simulate::radar::{RadarLayout, RadarSimulation, simulate_radar};
use mmtrack_process::simulate::slam::{SlamSimulation, simulate_slam};
use mmtrack_process::simulate::sounder::{SounderSimulation, simulate_sounder};
use mmtrack_process::slam::{SlamOptions, process_slam};
use mmtrack_process::{mpc, odometry};

use crate::inspect;
use crate::progress::IndicatifProgress;

/// The demo radar scenario, embedded so the demo runs from any directory.
pub const DEMO_SCENARIO: &str = include_str!("../../../data/demo/radar-scenario.toml");
/// The sounder scenario the demo cuts to [`DEMO_SOUNDER_SETS`] sets.
pub const DEMO_SOUNDER_SCENARIO: &str = include_str!("../../../data/sounder/convoy-tunnel.toml");
/// Sets of the sounder scenario the demo simulates (0.4 s of driving).
pub const DEMO_SOUNDER_SETS: usize = 40;
/// Epochs of the SLAM world the demo simulates (6 s of the paper's lap).
pub const DEMO_SLAM_EPOCHS: usize = 30;
/// UE particles of the demo's SLAM run (the paper's 2000 take longer).
pub const DEMO_SLAM_PARTICLES: usize = 500;
/// Sequence id of the demo radar data (the folder name, as for real Oxford data).
pub const DEMO_SEQUENCE: &str = "oxford-demo";

#[derive(Args)]
pub struct DemoArgs {
    /// Output directory; the demo replaces its own previous outputs there
    /// (`-o` as on every other command; `--out` still works).
    #[arg(short = 'o', long = "output", visible_alias = "out", value_name = "DIR", default_value = "out/demo")]
    out: PathBuf,
}

/// Prints the command line of a step (unless `quiet`).
fn announce(words: &[&str], quiet: bool) {
    if !quiet {
        println!("\n$ mmtrack {}", words.join(" "));
    }
}

/// `path` as a command-line word for the printed lines (lossy for a path
/// that is not UTF-8: the line is for reading, the call takes the path).
fn word(path: &Path) -> String {
    path.to_string_lossy().into_owned()
}

/// The odometry of `preset` on the demo recording, into `tables` (under
/// `run=<run_id>` when given).
fn odometry_step(
    recording: &Path,
    tables: &Path,
    preset: &str,
    run_id: Option<&str>,
    quiet: bool,
) -> anyhow::Result<()> {
    let mut words = vec!["process", "odometry", recording.to_str().unwrap_or("?"), "-o"];
    let tables_word = word(tables);
    words.extend([tables_word.as_str(), "--preset", preset]);
    if let Some(id) = run_id {
        words.extend(["--run-id", id]);
    }
    words.push("--force");
    announce(&words, quiet);
    let config = odometry::effective_config(preset, None)?;
    let options = OutputOptions { run_id: run_id.map(str::to_string), force: true, ..OutputOptions::default() };
    let done =
        odometry::process_odometry(recording, tables, preset, &config, &options, &IndicatifProgress::new(quiet))?;
    if !quiet {
        crate::process::print_odometry(&done.run, preset, &done.written);
    }
    Ok(())
}

pub fn run(args: &DemoArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let out = &args.out;
    let input = out.join("input");
    std::fs::create_dir_all(&input).with_context(|| input.display().to_string())?;
    let radar_scenario = input.join("radar-scenario.toml");
    let sounder_scenario = input.join("sounder-scenario.toml");
    std::fs::write(&radar_scenario, DEMO_SCENARIO).with_context(|| radar_scenario.display().to_string())?;
    std::fs::write(&sounder_scenario, DEMO_SOUNDER_SCENARIO).with_context(|| sounder_scenario.display().to_string())?;
    let folder = input.join(DEMO_SEQUENCE);
    let recording = out.join("recording.mcap");
    let sounder = out.join("sounder.mcap");
    let slam = out.join("slam.mcap");
    let tables = out.join("tables");
    let analysis = out.join("analysis");
    let runs = out.join("runs");
    let compare = out.join("compare");
    // The CLI's recording defaults: replace, and the Cartesian radar view for Foxglove.
    let replace = RecordingOptions {
        overwrite: Overwrite::Replace,
        radar_cartesian: Some(CartesianGrid::default()),
        ..RecordingOptions::default()
    };
    let (w_folder, w_recording, w_sounder, w_slam) = (word(&folder), word(&recording), word(&sounder), word(&slam));
    let (w_tables, w_analysis, w_runs, w_compare) = (word(&tables), word(&analysis), word(&runs), word(&compare));
    let force = OutputOptions { force: true, ..OutputOptions::default() };

    if !quiet {
        println!(
            "mmtrack demo: radar odometry, multipath tracking, SPEBT beam tracking and 5G mmWave SLAM on simulated data"
        );
    }
    // 1. Radar: the demo drive as an Oxford folder, ingested, odometry.
    announce(
        &["simulate", "radar", "--scenario", &word(&radar_scenario), "--format", "oxford", "-o", &w_folder, "--force"],
        quiet,
    );
    let simulation = RadarSimulation {
        scenario: radar_scenario.clone(),
        trajectory: None,
        max_scans: None,
        max_distance_m: None,
        layout: RadarLayout::Oxford,
        output: folder.clone(),
        recording: replace.clone(),
    };
    let radar = simulate_radar(&simulation, &IndicatifProgress::new(quiet))?;
    if !quiet {
        println!("{w_folder}: {} simulated scans", radar.scans);
    }
    announce(&["ingest", "oxford", &w_folder, "-o", &w_recording, "--bins", "auto", "--force"], quiet);
    let options = OxfordOptions {
        layout: oxford::NavtechLayout { expected_bins: None, ..oxford::OXFORD },
        ..OxfordOptions::default()
    };
    let report = oxford::ingest_oxford(&OxfordFolder::open(&folder)?, &recording, &options, &replace, &mut |_, _| {})?;
    if !quiet {
        println!("{w_recording}: {} scans, {} ground-truth poses", report.scans, report.ground_truth_poses);
    }
    odometry_step(&recording, &tables, "cfear", None, quiet)?;

    // 2. Multipath: a stretch of the convoy, detection and tracking.
    let sets = DEMO_SOUNDER_SETS.to_string();
    announce(
        &["simulate", "sounder", "--scenario", &word(&sounder_scenario), "--sets", &sets, "-o", &w_sounder, "--force"],
        quiet,
    );
    let simulation = SounderSimulation {
        scenario: sounder_scenario.clone(),
        sets: Some(DEMO_SOUNDER_SETS as u64),
        output: sounder.clone(),
        recording: replace.clone(),
    };
    let written = simulate_sounder(&simulation, &IndicatifProgress::new(quiet))?;
    if !quiet {
        println!("{w_sounder}: {} sets, {} CIR snapshots", written.sets, written.snapshots);
    }
    announce(&["process", "mpc", &w_sounder, "-o", &w_tables, "--gmphd", "--force"], quiet);
    let config = mmtrack_mpc::MpcConfig { run_gmphd: true, ..mpc::effective_config(None)? };
    let options = mpc::MpcOptions { output: force.clone(), ..mpc::MpcOptions::default() };
    let done = mpc::process_mpc(&sounder, &tables, &config, &options, &IndicatifProgress::new(quiet))?;
    if !quiet {
        for link in &done.links {
            println!(
                "mpc {}: {}, {}, {}",
                link.partition,
                mmtrack_core::words::counted(link.sets as u64, "set"),
                mmtrack_core::words::counted(link.detections as u64, "detection"),
                mmtrack_core::words::counted(link.tracks as u64, "track")
            );
        }
    }

    // 3. Beam: SPEBT along the radar drive, driven by its odometry.
    announce(
        &["process", "beam", &w_recording, "--tracker", "spebt", "--odometry", &w_tables, "-o", &w_tables, "--force"],
        quiet,
    );
    let options = SpebtOptions { odometry: Some(tables.clone()), ..SpebtOptions::default() };
    let done = process_spebt(
        std::slice::from_ref(&recording),
        &force.resolve(&tables)?,
        &options,
        &IndicatifProgress::new(quiet),
    )?;
    if !quiet {
        for r in &done.recordings {
            let s = &r.summary;
            println!(
                "{}: SPEBT RMSE AoD {:.3} deg, AoA {:.3} deg",
                r.sequence_id,
                s.rmse_aod_rad.to_degrees(),
                s.rmse_aoa_rad.to_degrees()
            );
        }
    }

    // 4. SLAM: a stretch of the paper's world, the filter on it.
    let (epochs, particles) = (DEMO_SLAM_EPOCHS.to_string(), DEMO_SLAM_PARTICLES.to_string());
    announce(&["simulate", "slam", "--epochs", &epochs, "-o", &w_slam, "--force"], quiet);
    let simulation = SlamSimulation {
        scenario: None,
        seed: 1,
        epochs: Some(DEMO_SLAM_EPOCHS as u64),
        output: slam.clone(),
        recording: replace.clone(),
    };
    simulate_slam(&simulation)?;
    announce(&["process", "slam", &w_slam, "-o", &w_tables, "--particles", &particles, "--force"], quiet);
    let options = SlamOptions { particles: Some(DEMO_SLAM_PARTICLES), output: force.clone(), ..SlamOptions::default() };
    let done = process_slam(&slam, &tables, &options)?;
    if !quiet {
        let (va, sp) = done.confirmed_at_end();
        println!("slam: {} epochs, {va} VAs and {sp} SPs confirmed at the end", done.tables.ue.len());
    }

    // 5. Every table analyzed together. The demo drive is 318 m: KITTI
    // segments of 50..300 m (the devkit's 100..800 m need a longer drive), a
    // first frame at every scan.
    let analyze_options = AnalyzeOptions {
        drift: DriftOptions {
            segment_lengths_m: vec![50.0, 100.0, 150.0, 200.0, 250.0, 300.0],
            step: FirstFrameStep::Frames(1),
        },
        mpc: MpcOptions::default(),
        overwrite: Overwrite::Replace,
    };
    let kitti = ["--segment-lengths-m", "50,100,150,200,250,300", "--step-frames", "1", "--force"];
    announce(&[&["analyze", &w_tables, "-o", &w_analysis][..], &kitti].concat(), quiet);
    let analyzed = analyze(std::slice::from_ref(&tables), &analysis, &analyze_options)?;
    if !quiet {
        crate::analyze::print_analyzed(&analyzed);
    }

    // 6. Both odometry presets as two named runs, side by side.
    odometry_step(&recording, &runs, "cfear", Some("cfear"), quiet)?;
    odometry_step(&recording, &runs, "fast-cfear", Some("fast-cfear"), quiet)?;
    announce(&[&["analyze", &w_runs, "-o", &w_compare][..], &kitti].concat(), quiet);
    let analyzed = analyze(std::slice::from_ref(&runs), &compare, &analyze_options)?;
    if !quiet {
        crate::analyze::print_analyzed(&analyzed);
    }

    if !quiet {
        println!();
        inspect::run(&inspect::InspectArgs::new(recording.clone()), quiet)?;
        println!("\nOutputs:");
        println!("  input folder (Oxford layout): {w_folder}");
        println!("  radar recording (Foxglove):    {w_recording}");
        println!("  sounder recording:             {w_sounder}");
        println!("  SLAM recording:                {w_slam}");
        println!("  tables (Parquet, Hive layout): {w_tables}");
        println!("  analysis (metrics, plots):     {w_analysis}");
        println!("  report (open in a browser):    {w_analysis}/report.html (and report.md)");
        println!(
            "  runs cfear and fast-cfear:     {w_runs}/run=<id>/ (tables), side by side in {w_compare}/report.html"
        );
    }
    Ok(ExitCode::SUCCESS)
}
