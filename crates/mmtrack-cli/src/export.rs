//! `mmtrack export`: trajectory tables as standard text (TUM, KITTI).
//! (Being built for issue #4.)

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

#[derive(Args)]
pub struct ExportArgs {
    /// Table directory written by `mmtrack process`.
    tables: PathBuf,
}

pub fn run(_args: &ExportArgs, _quiet: bool) -> anyhow::Result<ExitCode> {
    crate::not_built("export", 4)
}
