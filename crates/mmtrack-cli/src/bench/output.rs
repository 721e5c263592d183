//! What every `bench` subcommand does with its table: print it, write it
//! into the README block, and turn a missed target into the exit code.

use std::path::Path;
use std::process::ExitCode;

use mmtrack_reproduce::readme_block::replace_block;

/// The table of one benchmark run and where it goes.
pub struct Finish<'a> {
    /// The Markdown table (also the README block's body).
    pub text: &'a str,
    /// Print `text` (off with `--quiet`, or when something else is printed).
    pub print: bool,
    /// README file and block to replace with `text`.
    pub readme: Option<(&'a Path, &'a str)>,
    /// `--check`: exit 1 when the target is missed.
    pub check: bool,
    pub target_met: bool,
}

/// Prints, writes the README block, and gives the exit code.
pub fn finish(done: &Finish<'_>) -> anyhow::Result<ExitCode> {
    if done.print {
        print!("{}", done.text);
    }
    if let Some((readme, block)) = done.readme {
        replace_block(readme, block, done.text)?;
    }
    Ok(if done.check && !done.target_met { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}
