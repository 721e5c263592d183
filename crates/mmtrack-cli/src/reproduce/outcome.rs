//! What every `mmtrack reproduce <experiment>` does with the library's
//! [`Outcome`]: print a short summary (the claims and where the report is;
//! the full report is `reproduce.md`) and exit 1 when a paper target is
//! missed, saying so on stderr also with `--quiet` (the README block is
//! rewritten by the library call,
//! [`mmtrack_reproduce::request::run_experiment`]).

use std::path::Path;
use std::process::ExitCode;

use mmtrack_reproduce::Outcome;
use mmtrack_reproduce::model::verdict_rows;

/// The summary printed after a run: how many of the paper's claims were
/// met, one row per claim, and where the full report and outputs are.
fn summary(outcome: &Outcome, output_dir: &Path) -> String {
    let counted = outcome.verdicts.iter().filter(|v| !v.claim.informational);
    let (met, total) = counted.fold((0, 0), |(met, total), v| (met + usize::from(v.met), total + 1));
    format!(
        "reproduce {}: {met} of {total} paper claims met\n\n| claim | paper | measured | verdict |\n|---|---|---|---|\n{}\n\
         report: {}\noutputs: {}\n",
        outcome.experiment,
        verdict_rows(&outcome.verdicts),
        output_dir.join("reproduce.md").display(),
        output_dir.display()
    )
}

/// The line on stderr when a run exits 1 for a missed paper target (an
/// error exits 1 too, with its own `error:` line).
fn missed_line(outcome: &Outcome, output_dir: &Path) -> Option<String> {
    let missed = outcome.verdicts.iter().filter(|v| !v.met && !v.claim.informational).count();
    (missed > 0).then(|| {
        format!(
            "reproduce {}: {missed} paper claim(s) missed (exit 1; the run itself succeeded); see {}",
            outcome.experiment,
            output_dir.join("reproduce.md").display()
        )
    })
}

/// Prints the summary (unless `quiet`) and gives the exit code: 1 when a
/// paper target was missed, with one line on stderr saying so.
pub fn finish(outcome: &Outcome, output_dir: &Path, quiet: bool) -> ExitCode {
    if !quiet {
        print!("{}", summary(outcome, output_dir));
    }
    match missed_line(outcome, output_dir) {
        Some(line) => {
            eprintln!("{line}");
            ExitCode::FAILURE
        }
        None => ExitCode::SUCCESS,
    }
}

#[cfg(test)]
mod tests {
    use mmtrack_reproduce::model::{Claim, ReadmeBlock, Rule, Verdict};

    use super::*;

    fn outcome(verdicts: Vec<Verdict>) -> Outcome {
        let readme = ReadmeBlock { name: "x", body: String::new() };
        Outcome { experiment: "x", metrics: vec![], verdicts, files: vec![], report: "| long |\n".repeat(200), readme }
    }

    /// Before: the whole report went to stdout, and a missed target with
    /// `-q` exited 1 without a word.
    #[test]
    fn the_summary_counts_the_claims_and_a_miss_is_said_on_stderr() {
        let claim = |what: &str| Claim::new(what, "m", Some(1.0), "1 m", Rule::AtMost { bound: 1.0 });
        let met = Verdict::judged(claim("a"), Some(0.5), "0.5 m");
        let missed = Verdict::judged(claim("b"), Some(2.0), "2.0 m");
        let ours = Verdict::judged(claim("c").informational(), Some(2.0), "2.0 m");
        let dir = Path::new("out/x");
        let mixed = outcome(vec![met.clone(), missed, ours.clone()]);
        let text = summary(&mixed, dir);
        assert!(text.starts_with("reproduce x: 1 of 2 paper claims met\n"), "{text}");
        assert!(text.contains("| b | 1 m | 2.0 m | **missed** |") && !text.contains("| long |"), "{text}");
        assert!(text.contains("report: out/x/reproduce.md\noutputs: out/x\n"), "{text}");
        let line = missed_line(&mixed, dir).unwrap();
        assert!(line.contains("1 paper claim(s) missed") && line.contains("out/x/reproduce.md"), "{line}");
        assert_eq!(missed_line(&outcome(vec![met, ours]), dir), None);
    }
}
