//! What every `mmtrack reproduce <experiment>` does with the library's
//! [`Outcome`]: print a short summary (the claims and where the report is;
//! the full report is `reproduce.md`) and exit 1 when a paper target is
//! missed, saying so on stderr also with `--quiet` (the README block is
//! rewritten by the library call,
//! [`mmtrack_reproduce::request::run_experiment`]).

use std::path::Path;
use std::process::ExitCode;

use mmtrack_reproduce::Outcome;

/// Prints the summary (unless `quiet`) and gives the exit code: 1 when a
/// paper target was missed, with one line on stderr saying so.
pub fn finish(outcome: &Outcome, output_dir: &Path, quiet: bool) -> ExitCode {
    if !quiet {
        print!("{}", outcome.summary(output_dir));
    }
    match outcome.missed_line(output_dir) {
        Some(line) => {
            eprintln!("{line}");
            ExitCode::FAILURE
        }
        None => ExitCode::SUCCESS,
    }
}
