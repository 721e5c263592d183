//! `mmtrack reproduce kim`: the arguments of
//! [`mmtrack_reproduce::kim::run`] (5G mmWave vehicular SLAM, Kim et al.
//! 2018).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::{RunOptions, kim};

use super::outcome::{finish, tier};
use crate::progress::IndicatifProgress;
use crate::threads::ThreadsArg;

#[derive(Args)]
pub struct KimArgs {
    /// Output directory (tables/, SVG figures, reproduce.md, metrics.json).
    #[arg(short, long, default_value = "out/reproduce/kim")]
    output: PathBuf,
    /// Replace a previous run's output directory.
    #[arg(long)]
    force: bool,
    /// Experiment file (TOML; default: the embedded data/reproduce/kim.toml).
    #[arg(long, value_name = "EXPERIMENT.toml")]
    experiment: Option<PathBuf>,
    /// Monte Carlo runs per row (default: the experiment's, 20).
    #[arg(long)]
    runs: Option<u64>,
    /// UE particles (default: the filter's, 2000).
    #[arg(long)]
    particles: Option<usize>,
    /// The CI version: the experiment's quick_runs runs with quick_particles
    /// particles, checked with quick_tolerance.
    #[arg(long)]
    quick: bool,
    /// Replace the block `<!-- reproduce-kim:begin -->` ... `end` in this
    /// file with the summary (checked before the run).
    #[arg(long, value_name = "README.md")]
    readme: Option<PathBuf>,
    #[command(flatten)]
    threads: ThreadsArg,
}

pub fn run(args: &KimArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    kim::check_start(&args.output, args.force, args.readme.as_deref())?;
    let config = kim::Config::load(args.experiment.as_deref())?;
    let options = RunOptions {
        tier: tier(args.quick),
        runs: args.runs,
        output_dir: args.output.clone(),
        readme: args.readme.clone(),
    };
    let progress = IndicatifProgress::new(quiet);
    let outcome = args.threads.install(|| kim::run(&config, args.particles, &options, &progress))??;
    finish(&outcome, args.readme.as_deref(), &args.output, quiet)
}
