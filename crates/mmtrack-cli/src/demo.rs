//! `mmtrack demo`: the whole chain on embedded data, no files needed.
//!
//! The demo runs the same commands a user types, printed before each runs
//! (copy any of them to run it again):
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

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::Args;

use crate::inspect;

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
    /// Output directory; the demo replaces its own previous outputs there.
    #[arg(long, default_value = "out/demo")]
    out: PathBuf,
}

/// Runs one `mmtrack` command line, printing it first.
fn step(args: &[String], quiet: bool) -> anyhow::Result<()> {
    if !quiet {
        println!("\n$ mmtrack {}", args.join(" "));
    }
    let mut words = args.to_vec();
    if quiet {
        words.push("--quiet".into());
    }
    let code = crate::run_words(&words).with_context(|| format!("demo step `mmtrack {}`", args.join(" ")))?;
    if code != ExitCode::SUCCESS {
        bail!("demo step `mmtrack {}` failed", args.join(" "));
    }
    Ok(())
}

/// `words` as owned arguments.
fn line(words: &[&str]) -> Vec<String> {
    words.iter().map(|w| (*w).to_string()).collect()
}

pub fn run(args: &DemoArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let out = &args.out;
    let input = out.join("input");
    std::fs::create_dir_all(&input).with_context(|| input.display().to_string())?;
    let radar_scenario = input.join("radar-scenario.toml");
    let sounder_scenario = input.join("sounder-scenario.toml");
    std::fs::write(&radar_scenario, DEMO_SCENARIO).with_context(|| radar_scenario.display().to_string())?;
    std::fs::write(&sounder_scenario, DEMO_SOUNDER_SCENARIO).with_context(|| sounder_scenario.display().to_string())?;
    let folder = crate::path_word(&input.join(DEMO_SEQUENCE))?;
    let recording = crate::path_word(&out.join("recording.mcap"))?;
    let sounder = crate::path_word(&out.join("sounder.mcap"))?;
    let slam = crate::path_word(&out.join("slam.mcap"))?;
    let (slam_epochs, slam_particles) = (DEMO_SLAM_EPOCHS.to_string(), DEMO_SLAM_PARTICLES.to_string());
    let tables = crate::path_word(&out.join("tables"))?;
    let analysis = crate::path_word(&out.join("analysis"))?;
    let runs = crate::path_word(&out.join("runs"))?;
    let compare = crate::path_word(&out.join("compare"))?;
    let sets = DEMO_SOUNDER_SETS.to_string();
    let radar_scenario = crate::path_word(&radar_scenario)?;
    let sounder_scenario = crate::path_word(&sounder_scenario)?;

    if !quiet {
        println!(
            "mmtrack demo: radar odometry, multipath tracking, SPEBT beam tracking and 5G mmWave SLAM on simulated data"
        );
    }
    // The demo drive is 14 m: KITTI segments scaled down from the devkit's
    // 100..800 m, a first frame at every scan.
    let kitti = ["--segment-lengths-m", "4,8,12", "--step-frames", "1"];
    let steps: [Vec<String>; 12] = [
        line(&["simulate", "radar", "--scenario", &radar_scenario, "--format", "oxford", "-o", &folder, "--force"]),
        line(&["ingest", "oxford", &folder, "-o", &recording, "--bins", "auto", "--force"]),
        line(&["process", "odometry", &recording, "-o", &tables, "--preset", "cfear", "--force"]),
        line(&["simulate", "sounder", "--scenario", &sounder_scenario, "--sets", &sets, "-o", &sounder, "--force"]),
        line(&["process", "mpc", &sounder, "-o", &tables, "--gmphd", "--force"]),
        line(&["process", "beam", &recording, "--tracker", "spebt", "--odometry", &tables, "-o", &tables, "--force"]),
        line(&["simulate", "slam", "--epochs", &slam_epochs, "-o", &slam, "--force"]),
        line(&["process", "slam", &slam, "-o", &tables, "--particles", &slam_particles, "--force"]),
        line(&[&["analyze", &tables, "-o", &analysis][..], &kitti, &["--force"]].concat()),
        line(&["process", "odometry", &recording, "-o", &runs, "--preset", "cfear", "--run-id", "cfear", "--force"]),
        line(&[
            "process",
            "odometry",
            &recording,
            "-o",
            &runs,
            "--preset",
            "fast-cfear",
            "--run-id",
            "fast-cfear",
            "--force",
        ]),
        line(&[&["analyze", &runs, "-o", &compare][..], &kitti, &["--force"]].concat()),
    ];
    for args in &steps {
        step(args, quiet)?;
    }

    if !quiet {
        println!();
        inspect::run(&inspect::InspectArgs::new(PathBuf::from(&recording)), quiet)?;
        println!("\nOutputs:");
        println!("  input folder (Oxford layout): {folder}");
        println!("  radar recording (Foxglove):    {recording}");
        println!("  sounder recording:             {sounder}");
        println!("  SLAM recording:                {slam}");
        println!("  tables (Parquet, Hive layout): {tables}");
        println!("  analysis (metrics, plots):     {analysis}");
        println!("  report (open in a browser):    {analysis}/report.html (and report.md)");
        println!("  runs cfear and fast-cfear:     {runs}/run=<id>/ (tables), side by side in {compare}/report.html");
    }
    Ok(ExitCode::SUCCESS)
}
