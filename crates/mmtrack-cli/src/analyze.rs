//! `mmtrack analyze`: metrics, result tables and plots from process outputs.
//! (Being built for issue #4; see that issue for the scope.)

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

#[derive(Args)]
pub struct AnalyzeArgs {
    /// Table directory written by `mmtrack process` (any number of sequences).
    tables: PathBuf,
}

pub fn run(_args: &AnalyzeArgs, _quiet: bool) -> anyhow::Result<ExitCode> {
    crate::not_built("analyze", 4)
}
