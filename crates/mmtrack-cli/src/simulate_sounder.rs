//! `mmtrack simulate sounder --scenario <toml> -o <rec.mcap>`: reads a
//! channel-sounder scenario, streams the simulator's CIR snapshots, true MPCs
//! and (convoy) both cars' poses into a recording.

use std::path::PathBuf;

use clap::Args;
use mmtrack_process::simulate::sounder::{SounderSimulation, simulate_sounder};

use crate::ingest::OutputArgs;
use crate::progress::IndicatifProgress;
use crate::threads::ThreadsArg;

#[derive(Args)]
pub struct SounderArgs {
    /// Scenario file (TOML): seed and one of [artificial] or [convoy] (see data/sounder/).
    #[arg(long, value_name = "SCENARIO.toml")]
    scenario: PathBuf,
    /// Write only the first N sets of the scenario's run (the same sets as the full run's first N).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    sets: Option<u64>,
    #[command(flatten)]
    pub threads: ThreadsArg,
    #[command(flatten)]
    output: OutputArgs,
}

pub fn run_sounder(args: &SounderArgs, quiet: bool) -> anyhow::Result<()> {
    let simulation = SounderSimulation {
        scenario: args.scenario.clone(),
        sets: args.sets,
        output: args.output.output.clone(),
        recording: args.output.recording_options()?,
    };
    let written = simulate_sounder(&simulation, &IndicatifProgress::new(quiet))?;
    if !quiet {
        println!(
            "{}: {} sets, {} CIR snapshots, {} true MPCs ({})",
            args.output.output.display(),
            written.sets,
            written.snapshots,
            written.truths,
            written.detail
        );
    }
    Ok(())
}
