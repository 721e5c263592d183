//! What every `mmtrack reproduce <experiment>` does with the library's
//! [`Outcome`]: rewrite the README block when asked, print the report, and
//! exit 1 when a paper target is missed.

use std::path::Path;
use std::process::ExitCode;

use mmtrack_reproduce::{Outcome, Tier};

/// The tier of `--quick`.
pub fn tier(quick: bool) -> Tier {
    if quick { Tier::Smoke } else { Tier::Full }
}

/// Writes the outcome's README block into `readme` (when given), prints
/// the report and where the outputs are (unless `quiet`), and gives the
/// exit code: 1 when a paper target was missed.
pub fn finish(outcome: &Outcome, readme: Option<&Path>, output: &Path, quiet: bool) -> anyhow::Result<ExitCode> {
    if let Some(readme) = readme {
        crate::readme_block::replace_block(readme, outcome.readme.name, &outcome.readme.body)?;
    }
    if !quiet {
        print!("{}", outcome.report);
        println!("\noutputs: {}", output.display());
    }
    Ok(if outcome.targets_met() { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
