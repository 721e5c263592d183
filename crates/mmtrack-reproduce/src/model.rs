//! The one model every experiment reports in.
//!
//! Two different questions, two kinds of record (STYLE.md, detectron2):
//!
//! - "does it reproduce the paper?": a [`Claim`] of the paper (what, unit,
//!   the paper's number, the [`Rule`] it is judged by) and its [`Verdict`]
//!   (the measured value, met or not). Missed targets make the CLI exit 1.
//! - "did our numbers move?": the [`Metric`]s an experiment measured,
//!   checked against `data/reproduce/<experiment>.expected.toml` by
//!   [`crate::expectation`]. The expectations are our earlier runs, never
//!   the paper's numbers.
//!
//! A run of an experiment returns an [`Outcome`] holding both, the files it
//! wrote, its Markdown report and its README block.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::{Deserialize, Serialize};

/// How long an experiment runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tier {
    /// The CI version (the CLI's `--quick`, `reproduce --all --smoke`):
    /// fewer runs or points, checked against the smoke expectations.
    Smoke,
    /// The run the results pages (docs/results/) come from.
    Full,
}

impl Tier {
    /// `true` for [`Tier::Smoke`].
    #[must_use]
    pub fn is_smoke(self) -> bool {
        self == Self::Smoke
    }
}

/// Where and how long one experiment runs.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Smoke or full.
    pub tier: Tier,
    /// Monte Carlo runs, replacing the tier's count of the experiment file.
    pub runs: Option<u64>,
    /// The output directory; an earlier output there is replaced (the
    /// caller checks first that it may be, e.g. with
    /// [`crate::common::check_start`]).
    pub output_dir: PathBuf,
    /// The README the caller will write [`Outcome::readme`] into, if any:
    /// links from the block to the figures are relative to it. The run
    /// does not write it.
    pub readme: Option<PathBuf>,
}

impl RunOptions {
    /// `tier` into `output_dir`, the experiment's own run count, no README.
    #[must_use]
    pub fn new(tier: Tier, output_dir: impl Into<PathBuf>) -> Self {
        Self { tier, runs: None, output_dir: output_dir.into(), readme: None }
    }
}

/// File name of an experiment's measured metrics, beside its report.
pub const METRICS_FILE: &str = "metrics.json";

/// One number an experiment measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Metric {
    /// Stable name, the key of the expectation file.
    pub key: String,
    /// Measured value (finite).
    pub value: f64,
    /// Unit, for display ("blocks", "deg", "%", "ns").
    pub unit: String,
    /// The paper's number, where it gives one.
    pub paper: Option<f64>,
}

impl Metric {
    /// A metric.
    pub fn new(key: impl Into<String>, value: f64, unit: &str, paper: Option<f64>) -> Self {
        Self { key: key.into(), value, unit: unit.to_string(), paper }
    }
}

/// Writes `metrics` as `dir/metrics.json`.
///
/// # Errors
/// A metric that is not finite (named), or the file cannot be written.
pub fn write_metrics(dir: &Path, metrics: &[Metric]) -> anyhow::Result<()> {
    if let Some(bad) = metrics.iter().find(|m| !m.value.is_finite()) {
        bail!("metric `{}` is {}; expected a finite value", bad.key, bad.value);
    }
    let path = dir.join(METRICS_FILE);
    let text = serde_json::to_string_pretty(metrics).context("metrics as JSON")?;
    std::fs::write(&path, text + "\n").with_context(|| path.display().to_string())
}

/// How a claim is judged against the measured value.
#[derive(Debug, Clone, PartialEq)]
pub enum Rule {
    /// Strictly below `bound`.
    Below {
        /// The bound, in the claim's unit.
        bound: f64,
    },
    /// At most `bound`.
    AtMost {
        /// The bound, in the claim's unit.
        bound: f64,
    },
    /// At least `bound`.
    AtLeast {
        /// The bound, in the claim's unit.
        bound: f64,
    },
    /// `|measured - target| <= tolerance`.
    Within {
        /// The value aimed at, in the claim's unit.
        target: f64,
        /// Largest accepted deviation, in the claim's unit (absolute).
        tolerance: f64,
    },
    /// A relation between several measured values (an ordering), which the
    /// experiment checks itself; `description` says which.
    Ordering {
        /// The relation, in words ("nullspace <= error-free <= proposed < Ho-Chan").
        description: String,
    },
    /// A numeric rule on the measured value that counts only when a further
    /// condition holds, which the experiment checks itself and passes to
    /// [`Verdict::judged_given`]; `condition` says which, and the summary
    /// prints both ("within 42.67 +- 2.13 x, given the window holds the
    /// strongest beam in >= 90 % of epochs").
    Given {
        /// The rule on the measured value.
        rule: Box<Rule>,
        /// The further condition, in words.
        condition: String,
    },
}

impl Rule {
    /// Whether `measured` satisfies a numeric rule (`None` for
    /// [`Rule::Ordering`], which the experiment decides, and for
    /// [`Rule::Given`], whose condition only the experiment knows).
    #[must_use]
    pub fn holds(&self, measured: f64) -> Option<bool> {
        Some(match *self {
            Self::Below { bound } => measured < bound,
            Self::AtMost { bound } => measured <= bound,
            Self::AtLeast { bound } => measured >= bound,
            Self::Within { target, tolerance } => (measured - target).abs() <= tolerance,
            Self::Ordering { .. } | Self::Given { .. } => return None,
        })
    }
}

impl Rule {
    /// The rule as the summary prints it, in `unit` ("< 6.56 %",
    /// "within 15.00 +- 2.25 blocks", or the ordering's words).
    #[must_use]
    pub fn describe(&self, unit: &str) -> String {
        let unit = if unit.is_empty() { String::new() } else { format!(" {unit}") };
        match self {
            Self::Below { bound } => format!("< {}{unit}", short_number(*bound)),
            Self::AtMost { bound } => format!("<= {}{unit}", short_number(*bound)),
            Self::AtLeast { bound } => format!(">= {}{unit}", short_number(*bound)),
            Self::Within { target, tolerance } => {
                format!("within {} +- {}{unit}", short_number(*target), short_number(*tolerance))
            }
            Self::Ordering { description } => description.clone(),
            Self::Given { rule, condition } => format!("{}, given {condition}", rule.describe(unit.trim_start())),
        }
    }
}

/// A number with at most four significant decimals and no trailing zeros.
fn short_number(value: f64) -> String {
    let text = format!("{value:.4}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    text.to_string()
}

/// A published number or statement of a paper, and how it is judged.
#[derive(Debug, Clone, PartialEq)]
pub struct Claim {
    /// What is claimed, as the report prints it ("valid tracking, SNR 0 dB,
    /// 60 km/h (Fig. 2), within 15 %").
    pub what: String,
    /// Unit of the measured value ("" for orderings).
    pub unit: String,
    /// The paper's number, where the claim has one.
    pub paper_value: Option<f64>,
    /// The paper's side as the report prints it ("99 blocks", "ordering of
    /// Figs. 4-5", "-" for variants the paper does not have).
    pub paper_text: String,
    /// How the measured value is judged.
    pub rule: Rule,
    /// Reported beside the paper's claims, not counted among them and not
    /// setting the exit status: a variant, diagnostic or speed target of
    /// ours.
    pub informational: bool,
}

impl Claim {
    /// A target claim.
    pub fn new(
        what: impl Into<String>,
        unit: &str,
        paper_value: Option<f64>,
        paper_text: impl Into<String>,
        rule: Rule,
    ) -> Self {
        Self {
            what: what.into(),
            unit: unit.to_string(),
            paper_value,
            paper_text: paper_text.into(),
            rule,
            informational: false,
        }
    }

    /// The same claim, reported but not a target.
    #[must_use]
    pub fn informational(self) -> Self {
        Self { informational: true, ..self }
    }
}

/// A claim against what was measured.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// The claim.
    pub claim: Claim,
    /// The measured value, in the claim's unit (`None`: not measured, or
    /// an ordering of several values).
    pub measured: Option<f64>,
    /// Whether the claim holds.
    pub met: bool,
    /// The measurement as the report prints it, with units and details
    /// ("168 blocks", "> 400 blocks", "-21.3 / -20.1 / -19.0 / -2.4 dB").
    pub note: String,
}

impl Verdict {
    /// Judges `measured` by the claim's numeric rule: not met when nothing
    /// was measured, nor for an [`Rule::Ordering`] claim (which takes
    /// [`Verdict::decided`]).
    pub fn judged(claim: Claim, measured: Option<f64>, note: impl Into<String>) -> Self {
        let met = measured.and_then(|m| claim.rule.holds(m)).unwrap_or(false);
        Self { claim, measured, met, note: note.into() }
    }

    /// Judges `measured` by a [`Rule::Given`] claim: met when the inner
    /// numeric rule holds and the experiment's `condition_holds`.
    ///
    /// # Panics
    /// When the claim's rule is not [`Rule::Given`] (a programming error).
    pub fn judged_given(claim: Claim, measured: Option<f64>, condition_holds: bool, note: impl Into<String>) -> Self {
        let Rule::Given { rule, .. } = &claim.rule else {
            panic!("judged_given needs a Rule::Given claim, got {:?}", claim.rule)
        };
        let met = condition_holds && measured.and_then(|m| rule.holds(m)).unwrap_or(false);
        Self { claim, measured, met, note: note.into() }
    }

    /// A verdict the experiment decided itself (orderings).
    pub fn decided(claim: Claim, met: bool, note: impl Into<String>) -> Self {
        Self { claim, measured: None, met, note: note.into() }
    }

    /// The verdict column of the reports: "met", "**missed**", or for
    /// informational claims whether the relation holds.
    #[must_use]
    pub fn word(&self) -> &'static str {
        match (self.met, self.claim.informational) {
            (true, false) => "met",
            (false, false) => "**missed**",
            (true, true) => "holds (ours, not counted)",
            (false, true) => "does not hold (ours, not counted)",
        }
    }
}

/// `| claim | paper | measured | verdict |` rows, one per verdict (the
/// header is the experiment's).
#[must_use]
pub fn verdict_rows(verdicts: &[Verdict]) -> String {
    let mut out = String::new();
    for v in verdicts {
        let _ = writeln!(out, "| {} | {} | {} | {} |", v.claim.what, v.claim.paper_text, v.note, v.word());
    }
    out
}

/// A generated block of a README: the text between `<!-- {name}:begin -->`
/// and `<!-- {name}:end -->` ([`crate::readme_block`] writes it).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReadmeBlock {
    /// The block's name (`reproduce-shaham`).
    pub name: &'static str,
    /// Its new body.
    pub body: String,
}

/// What one run of an experiment produced.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The experiment's name (`shaham`, the CLI's subcommand).
    pub experiment: &'static str,
    /// The numbers measured, for the regression check (also written as
    /// `metrics.json` in the output directory).
    pub metrics: Vec<Metric>,
    /// The paper's claims against the measurement.
    pub verdicts: Vec<Verdict>,
    /// Every file written, under the output directory.
    pub files: Vec<PathBuf>,
    /// The Markdown report (`reproduce.md`).
    pub report: String,
    /// The README block the run rewrites when asked to.
    pub readme: ReadmeBlock,
}

/// The target claims met among `verdicts` and the target claims in all
/// (informational ones do not count).
#[must_use]
pub fn claims_met<'a>(verdicts: impl IntoIterator<Item = &'a Verdict>) -> (usize, usize) {
    let targets = verdicts.into_iter().filter(|v| !v.claim.informational);
    targets.fold((0, 0), |(met, total), v| (met + usize::from(v.met), total + 1))
}

impl Outcome {
    /// The target claims met and the target claims in all (informational
    /// ones do not count).
    #[must_use]
    pub fn claims_met(&self) -> (usize, usize) {
        claims_met(&self.verdicts)
    }

    /// Every target claim met.
    #[must_use]
    pub fn targets_met(&self) -> bool {
        let (met, total) = self.claims_met();
        met == total
    }

    /// The line a front end prints on stderr when a target claim was
    /// missed (the CLI then exits 1; an error exits 1 too, with its own
    /// `error:` line), or `None` when every target was met.
    #[must_use]
    pub fn missed_line(&self, output_dir: &Path) -> Option<String> {
        let (met, total) = self.claims_met();
        (met < total).then(|| {
            format!(
                "reproduce {}: {} missed (exit 1; the run itself succeeded); see {}",
                self.experiment,
                mmtrack_core::words::counted_as((total - met) as u64, "paper claim", "paper claims"),
                output_dir.join("reproduce.md").display()
            )
        })
    }

    /// What a front end prints after a run written to `output_dir`: how many
    /// of the paper's claims were met, one row per claim, and where the full
    /// report (`reproduce.md`) and the outputs are.
    #[must_use]
    pub fn summary(&self, output_dir: &Path) -> String {
        let (met, total) = self.claims_met();
        format!(
            "reproduce {}: {met} of {total} paper claims met\n\n| claim | paper | measured | verdict |\n|---|---|---|---|\n{}\n\
             report: {}\noutputs: {}\n",
            self.experiment,
            verdict_rows(&self.verdicts),
            output_dir.join("reproduce.md").display(),
            output_dir.display()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Before: `mmtrack reproduce <experiment>` printed the whole report.
    #[test]
    fn the_summary_counts_the_target_claims_and_a_miss_has_its_line() {
        let claim = |what: &str| Claim::new(what, "m", Some(1.0), "1 m", Rule::AtMost { bound: 1.0 });
        let verdicts = vec![
            Verdict::judged(claim("a"), Some(0.5), "0.5 m"),
            Verdict::judged(claim("b"), Some(2.0), "2.0 m"),
            Verdict::judged(claim("c").informational(), Some(2.0), "2.0 m"),
        ];
        let readme = ReadmeBlock { name: "x", body: String::new() };
        let outcome = Outcome {
            experiment: "x",
            metrics: vec![],
            verdicts,
            files: vec![],
            report: "| long |\n".repeat(200),
            readme,
        };
        assert_eq!(outcome.claims_met(), (1, 2));
        assert!(!outcome.targets_met());
        let text = outcome.summary(Path::new("out/x"));
        assert!(text.starts_with("reproduce x: 1 of 2 paper claims met\n"), "{text}");
        assert!(text.contains("| b | 1 m | 2.0 m | **missed** |") && !text.contains("| long |"), "{text}");
        assert!(text.contains("report: out/x/reproduce.md\noutputs: out/x\n"), "{text}");
        // Before: a missed target with `mmtrack reproduce -q` exited 1 without a word.
        let line = outcome.missed_line(Path::new("out/x")).unwrap();
        assert!(line.contains(": 1 paper claim missed") && line.contains("out/x/reproduce.md"), "{line}");
        let all_met = Outcome { verdicts: vec![outcome.verdicts[0].clone(), outcome.verdicts[2].clone()], ..outcome };
        assert_eq!(all_met.missed_line(Path::new("out/x")), None);
    }

    #[test]
    fn rules_judge_the_measured_value_and_nothing_measured_is_a_miss() {
        let claim = |rule| Claim::new("x", "m", Some(1.0), "1 m", rule);
        assert!(Verdict::judged(claim(Rule::Below { bound: 1.0 }), Some(0.99), "").met);
        assert!(!Verdict::judged(claim(Rule::Below { bound: 1.0 }), Some(1.0), "").met);
        assert!(Verdict::judged(claim(Rule::AtMost { bound: 1.0 }), Some(1.0), "").met);
        assert!(Verdict::judged(claim(Rule::AtLeast { bound: 1.0 }), Some(1.0), "").met);
        assert!(Verdict::judged(claim(Rule::Within { target: 10.0, tolerance: 1.5 }), Some(8.5), "").met);
        assert!(!Verdict::judged(claim(Rule::Within { target: 10.0, tolerance: 1.5 }), Some(8.4), "").met);
        assert!(!Verdict::judged(claim(Rule::AtMost { bound: 1.0 }), None, "").met);
        let ordering = claim(Rule::Ordering { description: "a < b".into() });
        assert!(!Verdict::judged(ordering.clone(), Some(0.0), "").met, "orderings are decided, not judged");
        assert!(Verdict::decided(ordering, true, "").met);
        let given = claim(Rule::Given {
            rule: Box::new(Rule::Within { target: 10.0, tolerance: 1.5 }),
            condition: "the link is kept".into(),
        });
        assert!(!Verdict::judged(given.clone(), Some(10.0), "").met, "the condition is the experiment's");
        assert!(Verdict::judged_given(given.clone(), Some(10.0), true, "").met);
        assert!(!Verdict::judged_given(given.clone(), Some(10.0), false, "").met, "condition fails");
        assert!(!Verdict::judged_given(given.clone(), Some(12.0), true, "").met, "value outside");
        assert!(!Verdict::judged_given(given.clone(), None, true, "").met, "nothing measured");
        assert_eq!(given.rule.describe("x"), "within 10 +- 1.5 x, given the link is kept");
    }

    #[test]
    fn a_rule_prints_its_bound_with_the_unit() {
        assert_eq!(Rule::AtMost { bound: 0.22 }.describe("deg"), "<= 0.22 deg");
        assert_eq!(Rule::Below { bound: 5.0 }.describe("%"), "< 5 %");
        assert_eq!(Rule::AtLeast { bound: 1.0 / 3.0 }.describe(""), ">= 0.3333");
    }

    #[test]
    fn informational_claims_do_not_set_the_outcome_and_print_their_own_words() {
        let missed =
            Verdict::decided(Claim::new("v", "", None, "-", Rule::AtLeast { bound: 1.0 }).informational(), false, "0");
        assert_eq!(missed.word(), "does not hold (ours, not counted)");
        let outcome = Outcome {
            experiment: "x",
            metrics: Vec::new(),
            verdicts: vec![missed.clone()],
            files: Vec::new(),
            report: String::new(),
            readme: ReadmeBlock { name: "x", body: String::new() },
        };
        assert!(outcome.targets_met());
        assert_eq!(verdict_rows(&[missed]), "| v | - | 0 | does not hold (ours, not counted) |\n");
    }
}
