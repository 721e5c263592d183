//! `mmtrack reproduce mpc-convoy`: the arguments of
//! [`mmtrack_reproduce::mpc_convoy::run`] (long-term MPC tracking in the
//! simulated tunnel convoy of Mahler et al. 2017).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::mpc_convoy;
use mmtrack_reproduce::request::{ExperimentRequest, run_experiment};

use super::outcome::finish;
use crate::progress::IndicatifProgress;

#[derive(Args)]
pub struct MpcConvoyArgs {
    /// Output directory (results.csv, reproduce.md, metrics.json).
    #[arg(short, long, default_value = "out/reproduce/mpc-convoy")]
    output: PathBuf,
    /// Replace a previous run's output directory.
    #[arg(long)]
    force: bool,
    /// The CI version: the first 300 of the 1666 sets.
    #[arg(long)]
    quick: bool,
    /// Replace the block `<!-- reproduce-mpc-convoy:begin -->` ... `end`
    /// in this file (docs/results/multipath.md) with the summary (checked
    /// before the run).
    #[arg(long, value_name = "FILE.md")]
    readme: Option<PathBuf>,
}

pub fn run(args: &MpcConvoyArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let request = ExperimentRequest {
        output_dir: Some(args.output.clone()),
        force: args.force,
        quick: args.quick,
        readme: args.readme.clone(),
        ..ExperimentRequest::default()
    };
    let outcome = run_experiment(mpc_convoy::NAME, &request, &IndicatifProgress::new(quiet))?;
    Ok(finish(&outcome, &args.output, quiet))
}
