//! `mmtrack process <pipeline>`: run an algorithm on a recording, write tables.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Subcommand};

#[derive(Args)]
pub struct ProcessArgs {
    #[command(subcommand)]
    pipeline: Pipeline,
}

#[derive(Subcommand)]
enum Pipeline {
    /// Radar odometry (Fast-CFEAR / CFEAR) on the recording's radar scans.
    Odometry(OdometryArgs),
    /// Multipath-component detection and tracking (issue #5).
    Mpc {
        /// Arguments.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
}

#[derive(Args)]
pub struct OdometryArgs {
    /// Recording with radar scans (from `mmtrack ingest` or `mmtrack simulate`).
    recording: PathBuf,
    /// Output table directory.
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(args: &ProcessArgs, _quiet: bool) -> anyhow::Result<ExitCode> {
    match &args.pipeline {
        Pipeline::Odometry(_) => crate::not_built("process odometry", 4),
        Pipeline::Mpc { .. } => crate::not_built("process mpc", 5),
    }
}
