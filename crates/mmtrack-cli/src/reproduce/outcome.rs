//! What every `mmtrack reproduce <experiment>` does with the library's
//! [`Outcome`]: print the report and exit 1 when a paper target is missed
//! (the README block is rewritten by the library call,
//! [`mmtrack_reproduce::request::run_experiment`]).

use std::path::Path;
use std::process::ExitCode;

use mmtrack_reproduce::Outcome;

/// Prints the report and where the outputs are (unless `quiet`), and gives
/// the exit code: 1 when a paper target was missed.
pub fn finish(outcome: &Outcome, output_dir: &Path, quiet: bool) -> ExitCode {
    if !quiet {
        print!("{}", outcome.report);
        println!("\noutputs: {}", output_dir.display());
    }
    if outcome.targets_met() { ExitCode::SUCCESS } else { ExitCode::FAILURE }
}
