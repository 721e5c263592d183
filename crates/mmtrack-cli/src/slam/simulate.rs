//! `mmtrack simulate slam [--scenario <toml>] [--seed N] -o <rec.mcap>`: the
//! 5G mmWave SLAM world of Kim et al. 2018 (or one configured in TOML) as a
//! recording: per epoch the path measurements (`/slam/paths`), the true UE
//! state and path origins (`/slam/ue_truth`) and the UE's pose
//! (`/ground_truth/pose`); once, the base station and the true virtual
//! anchors and scattering points (`/slam/sources`).

use std::path::PathBuf;

use clap::Args;
use mmtrack_process::simulate::slam::{SlamSimulation, simulate_slam};

use crate::ingest::OutputArgs;
use crate::threads::ThreadsArg;

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

pub fn run_slam(args: &SlamSimArgs, quiet: bool) -> anyhow::Result<()> {
    let simulation = SlamSimulation {
        scenario: args.scenario.clone(),
        seed: args.seed,
        epochs: args.epochs,
        output: args.output.output.clone(),
        recording: args.output.recording_options()?,
    };
    let done = simulate_slam(&simulation)?;
    if !quiet {
        println!(
            "{}: {} epochs, {} paths; BS, {} virtual anchors, {} scattering points",
            args.output.output.display(),
            done.epochs,
            done.paths,
            done.virtual_anchors,
            done.scattering_points
        );
    }
    Ok(())
}
