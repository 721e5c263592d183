//! What every `mmtrack reproduce <experiment>` does with the library's
//! [`Outcome`]: rewrite the README block when asked, print the report, and
//! exit 1 when a paper target is missed.

use std::process::ExitCode;

use mmtrack_reproduce::{Outcome, RunOptions};

/// Writes the outcome's README block into `options.readme` (when given),
/// prints the report and where the outputs are (unless `quiet`), and gives
/// the exit code: 1 when a paper target was missed.
pub fn finish(outcome: &Outcome, options: &RunOptions, quiet: bool) -> anyhow::Result<ExitCode> {
    if let Some(readme) = &options.readme {
        crate::readme_block::replace_block(readme, outcome.readme.name, &outcome.readme.body)?;
    }
    if !quiet {
        print!("{}", outcome.report);
        println!("\noutputs: {}", options.output_dir.display());
    }
    Ok(if outcome.targets_met() { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
