//! `reproduce --all [--smoke]`: every paper experiment in one call. Two
//! answers, kept apart (issue 25):
//!
//! - against the papers: every [`Verdict`] of every experiment, headed by
//!   "N of M paper claims met", with the paper's value, the rule and the
//!   measured value; a missed claim is reported, never hidden, and does not
//!   set the exit status of `--all` (each experiment's own command does);
//! - against ourselves: each metric checked against the values this code
//!   measured before ([`crate::expectation`]); a metric that moved is what
//!   makes `--all` (and CI) fail.
//!
//! Each experiment writes, beside its own report, `metrics.json`: the
//! numbers it measured, with units and the paper's number where the paper
//! gives one ([`crate::model::write_metrics`]). A metric outside its
//! tolerance, a metric the expectation names but the run did not produce,
//! and a metric without an expectation are misses (the CLI exits 1).
//!
//! With `--readme docs/results/README.md` (full runs only) the block
//! `reproduce-all` there receives the table of every metric, and each
//! experiment that has a block rewrites it in the page beside it that holds
//! it ([`readme_block::locate_block`]); a test checks the `reproduce-all`
//! block against the expectation files, so a results page that no longer
//! matches them fails CI.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use mmtrack_core::progress::Progress;

use crate::expectation::{Check, ExpectedMetric, compare, parse_expected, table};
use crate::model::{Outcome, RunOptions, Tier, Verdict};
use crate::{kim, mpc_artificial, mpc_convoy, odometry, readme_block, shaham, spebt, zoechmann};

/// The block (in docs/results/README.md) that receives the table of every
/// metric.
pub const README_BLOCK: &str = "reproduce-all";

/// One experiment of [`run_all`].
pub struct Experiment {
    /// Its name (the CLI's subcommand).
    pub name: &'static str,
    /// The name of its own generated block (in its page under
    /// docs/results/), if it has one.
    pub block: Option<&'static str>,
    /// Its expectation file (embedded: the call runs from anywhere).
    pub expected: &'static str,
    /// The file's path in the repository, for messages.
    pub expected_path: &'static str,
    /// Its check before the work (output directory replaceable, README
    /// block present).
    check_start: fn(&Path, bool, Option<&Path>) -> anyhow::Result<()>,
    /// Its run on the embedded configuration.
    run: fn(&RunOptions, &dyn Progress) -> anyhow::Result<Outcome>,
}

impl Experiment {
    /// The parsed expectation file.
    ///
    /// # Errors
    /// See [`parse_expected`].
    pub fn expectations(&self) -> anyhow::Result<Vec<ExpectedMetric>> {
        parse_expected(self.expected_path, self.expected)
    }
}

/// Every experiment, in the order [`run_all`] runs them.
pub const EXPERIMENTS: [Experiment; 7] = [
    Experiment {
        name: odometry::NAME,
        block: None,
        expected: include_str!("../../../data/reproduce/odometry.expected.toml"),
        expected_path: "data/reproduce/odometry.expected.toml",
        check_start: odometry::check_start,
        run: run_odometry,
    },
    Experiment {
        name: mpc_artificial::NAME,
        block: Some(mpc_artificial::README_BLOCK),
        expected: include_str!("../../../data/reproduce/mpc-artificial.expected.toml"),
        expected_path: "data/reproduce/mpc-artificial.expected.toml",
        check_start: mpc_artificial::check_start,
        run: run_mpc_artificial,
    },
    Experiment {
        name: mpc_convoy::NAME,
        block: Some(mpc_convoy::README_BLOCK),
        expected: include_str!("../../../data/reproduce/mpc-convoy.expected.toml"),
        expected_path: "data/reproduce/mpc-convoy.expected.toml",
        check_start: mpc_convoy::check_start,
        run: run_mpc_convoy,
    },
    Experiment {
        name: shaham::NAME,
        block: Some(shaham::README_BLOCK),
        expected: include_str!("../../../data/reproduce/shaham.expected.toml"),
        expected_path: "data/reproduce/shaham.expected.toml",
        check_start: shaham::check_start,
        run: run_shaham,
    },
    Experiment {
        name: spebt::NAME,
        block: Some(spebt::README_BLOCK),
        expected: include_str!("../../../data/reproduce/spebt.expected.toml"),
        expected_path: "data/reproduce/spebt.expected.toml",
        check_start: spebt::check_start,
        run: run_spebt,
    },
    Experiment {
        name: zoechmann::NAME,
        block: Some(zoechmann::README_BLOCK),
        expected: include_str!("../../../data/reproduce/zoechmann.expected.toml"),
        expected_path: "data/reproduce/zoechmann.expected.toml",
        check_start: zoechmann::check_start,
        run: run_zoechmann,
    },
    Experiment {
        name: kim::NAME,
        block: Some(kim::README_BLOCK),
        expected: include_str!("../../../data/reproduce/kim.expected.toml"),
        expected_path: "data/reproduce/kim.expected.toml",
        check_start: kim::check_start,
        run: run_kim,
    },
];

fn run_odometry(options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    odometry::run(&odometry::Config::embedded()?, options, progress)
}

fn run_mpc_artificial(options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    mpc_artificial::run(&mpc_artificial::Config::default(), options, progress)
}

fn run_mpc_convoy(options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    mpc_convoy::run(&mpc_convoy::Config::embedded()?, options, progress)
}

fn run_shaham(options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    shaham::run(&shaham::Config::embedded()?, options, progress)
}

fn run_spebt(options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    spebt::run(&spebt::Config::embedded()?, options, progress)
}

fn run_zoechmann(options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    zoechmann::run(&zoechmann::Config::embedded()?, options, progress)
}

fn run_kim(options: &RunOptions, progress: &dyn Progress) -> anyhow::Result<Outcome> {
    kim::run(&kim::Config::embedded()?, None, options, progress)
}

/// What [`run_all`] does.
#[derive(Debug, Clone)]
pub struct AllOptions {
    /// Smoke (each experiment's CI version, against the smoke
    /// expectations) or full.
    pub tier: Tier,
    /// One subdirectory per experiment, and `summary.md`.
    pub output_dir: PathBuf,
    /// The file whose `reproduce-all` block is rewritten
    /// (docs/results/README.md), the experiments' blocks in the Markdown
    /// files beside it (full runs only).
    pub readme: Option<PathBuf>,
}

/// What [`run_all`] measured.
#[derive(Debug, Clone)]
pub struct AllOutcome {
    /// Every paper claim of every experiment against what was measured:
    /// (experiment, verdict), in run order.
    pub claims: Vec<(&'static str, Verdict)>,
    /// Every metric against its expectation, experiment by experiment.
    pub checks: Vec<Check>,
    /// The Markdown summary (also `summary.md`, and the `reproduce-all` block).
    pub summary: String,
}

impl AllOutcome {
    /// Target claims (informational variants excluded) and how many are met.
    #[must_use]
    pub fn claims_met(&self) -> (usize, usize) {
        let targets = self.claims.iter().filter(|(_, v)| !v.claim.informational);
        targets.fold((0, 0), |(met, all), (_, v)| (met + usize::from(v.met), all + 1))
    }

    /// Metrics outside their expectation (missing and unexpected ones included).
    #[must_use]
    pub fn misses(&self) -> usize {
        self.checks.iter().filter(|c| !c.ok()).count()
    }
}

/// Runs every experiment of [`EXPERIMENTS`] into `options.output_dir/<name>`
/// and checks each metric against its expectation; writes `summary.md`
/// and, with `options.readme`, the blocks. Progress: each experiment's
/// stages, and a note per experiment.
///
/// # Errors
/// A block that is missing or found twice (checked before any work), an expectation
/// file that does not parse, an experiment that fails, an output that
/// cannot be written. Misses are not errors: see [`AllOutcome::misses`].
pub fn run_all(options: &AllOptions, progress: &dyn Progress) -> anyhow::Result<AllOutcome> {
    anyhow::ensure!(
        !(options.tier.is_smoke() && options.readme.is_some()),
        "the README blocks come from full runs only (nothing was done)"
    );
    if let Some(readme) = &options.readme {
        readme_block::check_block(readme, README_BLOCK)?;
    }
    // Each experiment's block: in `readme` or the page beside it that holds it.
    let block_files: Vec<Option<PathBuf>> = EXPERIMENTS
        .iter()
        .map(|e| match (&options.readme, e.block) {
            (Some(readme), Some(block)) => readme_block::locate_block(readme, block).map(Some),
            _ => Ok(None),
        })
        .collect::<anyhow::Result<_>>()?;
    let expectations: Vec<Vec<ExpectedMetric>> =
        EXPERIMENTS.iter().map(Experiment::expectations).collect::<anyhow::Result<_>>()?;
    std::fs::create_dir_all(&options.output_dir).with_context(|| options.output_dir.display().to_string())?;
    let started = Instant::now();
    let mut claims = Vec::new();
    let mut checks = Vec::new();
    let mut timings = Vec::new();
    for (k, (experiment, expected)) in EXPERIMENTS.iter().zip(&expectations).enumerate() {
        let dir = options.output_dir.join(experiment.name);
        let readme = block_files[k].clone();
        progress.note(&format!(
            "[{}/{}] reproduce {}{} -> {}",
            k + 1,
            EXPERIMENTS.len(),
            experiment.name,
            if options.tier.is_smoke() { " (smoke)" } else { "" },
            dir.display()
        ));
        let run_options = RunOptions { tier: options.tier, runs: None, output_dir: dir, readme };
        let experiment_started = Instant::now();
        (experiment.check_start)(&run_options.output_dir, true, run_options.readme.as_deref())?;
        let outcome =
            (experiment.run)(&run_options, progress).with_context(|| format!("reproduce {}", experiment.name))?;
        if let Some(readme) = &run_options.readme {
            readme_block::replace_block(readme, outcome.readme.name, &outcome.readme.body)?;
        }
        claims.extend(outcome.verdicts.into_iter().map(|v| (experiment.name, v)));
        let measured = outcome.metrics;
        let seconds = experiment_started.elapsed().as_secs_f64();
        timings.push((experiment.name, seconds));
        let these = compare(experiment.name, &measured, expected, options.tier);
        let misses = these.iter().filter(|c| !c.ok()).count();
        progress.note(&format!("      {} metrics, {misses} missed, {seconds:.1} s", these.len()));
        checks.extend(these);
    }
    let total_s = started.elapsed().as_secs_f64();
    let misses = checks.iter().filter(|c| !c.ok()).count();
    let threads = rayon::current_num_threads();
    let timing = timings.iter().map(|(n, s)| format!("{n} {s:.1} s")).collect::<Vec<_>>().join(", ");
    let mode = if options.tier.is_smoke() { "smoke (--quick)" } else { "full" };
    let command = format!("mmtrack reproduce --all{}", if options.tier.is_smoke() { " --smoke" } else { "" });
    let mut summary = format!("#### Paper verdicts\n\n{}", claims_section(&claims, &command, options.tier));
    let _ = write!(
        summary,
        "\n#### Regression check\n\nWritten by `{command}`: {} metrics of {} experiments, {misses} outside their \
         expected range. Expected values (data/reproduce/<experiment>.expected.toml) are what this code measured \
         when the results were written, with absolute tolerances: \"unchanged\" says our numbers did not move, \
         not that they match the paper (the claims above say that).\n\n",
        checks.len(),
        EXPERIMENTS.len()
    );
    summary.push_str(&table(&checks));
    let _ = writeln!(summary, "\n{mode} runs in {total_s:.1} s on {threads} threads ({timing}).");
    let summary_path = options.output_dir.join("summary.md");
    std::fs::write(&summary_path, &summary).with_context(|| summary_path.display().to_string())?;
    if let Some(readme) = &options.readme {
        readme_block::replace_block(readme, README_BLOCK, &summary)?;
    }
    Ok(AllOutcome { claims, checks, summary })
}

/// "N of M paper claims met" and the table of every claim: experiment,
/// claim, the paper's side, the rule, what was measured, the verdict.
fn claims_section(claims: &[(&'static str, Verdict)], command: &str, tier: Tier) -> String {
    let (met, targets) = crate::model::claims_met(claims.iter().map(|(_, v)| v));
    let variants = claims.len() - targets;
    let mut out = format!(
        "**{met} of {} paper claims met**{} (`{command}`; {variants} variants, diagnostics and speed targets of ours \
         reported beside them, not counted). Each claim is judged against the paper by its rule; a missed claim stays \
         in the table.\n\n",
        targets,
        if tier.is_smoke() { " in the smoke runs (fewer runs than the papers: indicative only)" } else { "" }
    );
    out.push_str("| experiment | claim | paper | rule | measured | verdict |\n|---|---|---|---|---|---|\n");
    for (experiment, v) in claims {
        let _ = writeln!(
            out,
            "| {experiment} | {} | {} | {} | {} | {} |",
            v.claim.what,
            v.claim.paper_text,
            v.claim.rule.describe(&v.claim.unit),
            v.note,
            v.word()
        );
    }
    out
}

/// Checks the `reproduce-all` block (docs/results/README.md) against the expectation
/// files: every full-run expectation appears as a row whose measured value
/// lies within its tolerance. Returns the problems (empty when current).
#[must_use]
#[cfg(test)]
pub fn stale_readme_rows(readme: &str) -> Vec<String> {
    let begin = format!("<!-- {README_BLOCK}:begin -->");
    let end = format!("<!-- {README_BLOCK}:end -->");
    let Some(block) = readme.split(&begin).nth(1).and_then(|rest| rest.split(&end).next()) else {
        return vec![format!("no {begin} ... {end} block")];
    };
    let mut problems = Vec::new();
    for spec in &EXPERIMENTS {
        let expected = match spec.expectations() {
            Ok(e) => e,
            Err(e) => return vec![format!("{e:#}")],
        };
        for e in expected {
            let row = block.lines().find(|l| l.starts_with(&format!("| {} | {} |", spec.name, e.key)));
            let measured = row.and_then(|r| r.split('|').nth(4)).and_then(|cell| cell.trim().parse::<f64>().ok());
            match measured {
                None => problems.push(format!("{} `{}`: no row with a measured value", spec.name, e.key)),
                Some(m) if (m - e.full.value).abs() > e.full.tolerance => problems.push(format!(
                    "{} `{}`: the block says {m}, {} expects {} +- {}",
                    spec.name, e.key, spec.expected_path, e.full.value, e.full.tolerance
                )),
                Some(_) => {}
            }
        }
    }
    problems
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `reproduce-all` table of docs/results/README.md agrees with the
    /// expectation files (written by `reproduce --all --readme
    /// docs/results/README.md`).
    #[test]
    fn the_results_table_matches_the_expectation_files() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/results/README.md");
        let readme = std::fs::read_to_string(&path).unwrap();
        let problems = stale_readme_rows(&readme);
        assert!(
            problems.is_empty(),
            "docs/results/README.md's {README_BLOCK} block is stale (run `mmtrack reproduce --all --readme \
             docs/results/README.md`):\n{}",
            problems.join("\n")
        );
    }

    /// The front page's headline (claims met, metrics checked) is the one
    /// the last full run wrote into docs/results/README.md, not typed apart.
    #[test]
    fn the_front_page_headline_is_the_generated_one() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let results = std::fs::read_to_string(root.join("docs/results/README.md")).unwrap();
        let front = std::fs::read_to_string(root.join("README.md")).unwrap().replace('\n', " ");
        let between = |text: &str, start: &str, end: &str| -> String {
            let from = text.find(start).unwrap_or_else(|| panic!("`{start}` not found")) + start.len();
            text[from..].split(end).next().unwrap().trim().to_string()
        };
        let claims = between(&results, "**", " paper claims met**");
        let metrics = between(&results, "Written by `mmtrack reproduce --all`: ", " metrics of");
        assert!(
            front.contains(&format!("**{claims} paper claims met**")),
            "README.md lacks `{claims} paper claims met`"
        );
        assert!(front.contains(&format!("regression check of {metrics} metrics")), "README.md lacks {metrics} metrics");
    }

    /// The summary leads with the paper verdicts: a miss is counted and
    /// shown with its rule, variants are listed but not counted.
    #[test]
    fn the_summary_counts_paper_claims_and_shows_misses_with_their_rule() {
        use crate::model::{Claim, Rule};
        let claim = |what: &str, rule| Claim::new(what, "blocks", Some(99.0), "99 blocks", rule);
        let claims = vec![
            ("shaham", Verdict::judged(claim("valid tracking", Rule::AtLeast { bound: 99.0 }), Some(168.0), "168")),
            (
                "shaham",
                Verdict::judged(claim("gain", Rule::Within { target: 49.0, tolerance: 7.35 }), Some(282.0), "+282 %"),
            ),
            ("shaham", Verdict::judged(claim("variant", Rule::AtMost { bound: 1.0 }).informational(), Some(2.0), "2")),
        ];
        let text = claims_section(&claims, "mmtrack reproduce --all", Tier::Full);
        assert!(text.starts_with("**1 of 2 paper claims met** (`mmtrack reproduce --all`; 1 variants"), "{text}");
        assert!(
            text.contains("| shaham | gain | 99 blocks | within 49 +- 7.35 blocks | +282 % | **missed** |"),
            "{text}"
        );
        assert!(text.contains("| shaham | valid tracking | 99 blocks | >= 99 blocks | 168 | met |"), "{text}");
        assert!(text.contains("does not hold (ours, not counted)"), "{text}");
    }

    #[test]
    fn every_expectation_file_parses() {
        for spec in &EXPERIMENTS {
            let expected = spec.expectations().unwrap();
            assert!(!expected.is_empty(), "{}", spec.expected_path);
        }
    }
}
