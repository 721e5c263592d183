//! `mmtrack reproduce --all [--smoke]`: every paper experiment in one
//! command, each checked against the values this code is expected to
//! measure.
//!
//! Each experiment writes, beside its own report, `metrics.json`: the
//! numbers it measured, with units and the paper's number where the paper
//! gives one ([`write_metrics`]). Beside each experiment's configuration in
//! `data/reproduce/` lies `<experiment>.expected.toml`: for every metric the
//! value expected from the full run and from the `--quick` (smoke) run, each
//! with an absolute tolerance. Expected values are what this code measured
//! when the README's results were written, not the paper's numbers (which
//! several experiments miss, with the reasons in the README); the paper's
//! number is printed beside them. A metric outside its tolerance, a metric
//! the expectation names but the run did not produce, and a metric without
//! an expectation are misses: the command exits 1.
//!
//! With `--readme README.md` (full runs only) the experiments that have a
//! README block rewrite it, and the block `reproduce-all` receives the
//! table of every metric; a test checks that block against the expectation
//! files, so a README that no longer matches them fails CI.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, bail};
use clap::Args;
use serde::{Deserialize, Serialize};

/// File name of an experiment's measured metrics.
pub const METRICS_FILE: &str = "metrics.json";
/// The README block `--readme` rewrites.
pub const README_BLOCK: &str = "reproduce-all";

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

/// One experiment of `--all`.
struct Spec {
    /// Subcommand name.
    name: &'static str,
    /// Whether it takes `--readme` (has a README block of its own).
    readme: bool,
    /// Its expectation file (embedded: the command runs from anywhere).
    expected: &'static str,
    /// The file's path in the repository, for messages.
    expected_path: &'static str,
}

const EXPERIMENTS: [Spec; 6] = [
    Spec {
        name: "odometry",
        readme: false,
        expected: include_str!("../../../data/reproduce/odometry.expected.toml"),
        expected_path: "data/reproduce/odometry.expected.toml",
    },
    Spec {
        name: "mpc-artificial",
        readme: true,
        expected: include_str!("../../../data/reproduce/mpc-artificial.expected.toml"),
        expected_path: "data/reproduce/mpc-artificial.expected.toml",
    },
    Spec {
        name: "shaham",
        readme: true,
        expected: include_str!("../../../data/reproduce/shaham.expected.toml"),
        expected_path: "data/reproduce/shaham.expected.toml",
    },
    Spec {
        name: "spebt",
        readme: true,
        expected: include_str!("../../../data/reproduce/spebt.expected.toml"),
        expected_path: "data/reproduce/spebt.expected.toml",
    },
    Spec {
        name: "zoechmann",
        readme: true,
        expected: include_str!("../../../data/reproduce/zoechmann.expected.toml"),
        expected_path: "data/reproduce/zoechmann.expected.toml",
    },
    Spec {
        name: "kim",
        readme: true,
        expected: include_str!("../../../data/reproduce/kim.expected.toml"),
        expected_path: "data/reproduce/kim.expected.toml",
    },
];

/// An expected value and its absolute tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expected {
    /// The value.
    pub value: f64,
    /// Largest accepted |measured - value|, in the metric's unit.
    pub tolerance: f64,
}

/// One metric's expectations.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpectedMetric {
    /// [`Metric::key`].
    pub key: String,
    /// From the full run.
    pub full: Expected,
    /// From the `--quick` run.
    pub smoke: Expected,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ExpectationFile {
    metric: Vec<ExpectedMetric>,
}

/// Parses an expectation file.
///
/// # Errors
/// TOML errors, unknown fields, a duplicated key, or a negative or
/// non-finite value or tolerance, naming `path` and the metric.
pub fn parse_expected(path: &str, text: &str) -> anyhow::Result<Vec<ExpectedMetric>> {
    let file: ExpectationFile = toml::from_str(text).with_context(|| path.to_string())?;
    for (i, m) in file.metric.iter().enumerate() {
        if file.metric[..i].iter().any(|o| o.key == m.key) {
            bail!("{path}: metric `{}` is listed twice", m.key);
        }
        for (mode, e) in [("full", m.full), ("smoke", m.smoke)] {
            if !(e.value.is_finite() && e.tolerance.is_finite() && e.tolerance >= 0.0) {
                bail!(
                    "{path}: metric `{}` {mode}: value {} tolerance {}; expected finite, tolerance >= 0",
                    m.key,
                    e.value,
                    e.tolerance
                );
            }
        }
    }
    Ok(file.metric)
}

/// A metric against its expectation.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// Experiment name.
    pub experiment: String,
    /// Metric key.
    pub key: String,
    /// Unit ("" when the run did not produce it).
    pub unit: String,
    /// Measured value, if the run produced it.
    pub measured: Option<f64>,
    /// Expected value, if the file has one.
    pub expected: Option<Expected>,
    /// The paper's number.
    pub paper: Option<f64>,
}

impl Check {
    /// Within tolerance.
    #[must_use]
    pub fn ok(&self) -> bool {
        matches!((self.measured, self.expected), (Some(m), Some(e)) if (m - e.value).abs() <= e.tolerance)
    }
}

/// Every metric of `measured` and `expected` paired, expected order first.
#[must_use]
pub fn compare(experiment: &str, measured: &[Metric], expected: &[ExpectedMetric], smoke: bool) -> Vec<Check> {
    let mut checks: Vec<Check> = expected
        .iter()
        .map(|e| {
            let m = measured.iter().find(|m| m.key == e.key);
            Check {
                experiment: experiment.to_string(),
                key: e.key.clone(),
                unit: m.map(|m| m.unit.clone()).unwrap_or_default(),
                measured: m.map(|m| m.value),
                expected: Some(if smoke { e.smoke } else { e.full }),
                paper: m.and_then(|m| m.paper),
            }
        })
        .collect();
    for m in measured.iter().filter(|m| !expected.iter().any(|e| e.key == m.key)) {
        checks.push(Check {
            experiment: experiment.to_string(),
            key: m.key.clone(),
            unit: m.unit.clone(),
            measured: Some(m.value),
            expected: None,
            paper: m.paper,
        });
    }
    checks
}

fn number(v: f64) -> String {
    if v.abs() >= 100.0 { format!("{v:.1}") } else { format!("{v:.4}") }
}

/// The Markdown table of `checks`.
#[must_use]
pub fn table(checks: &[Check]) -> String {
    let mut out = String::from(
        "| experiment | metric | unit | measured | expected | paper | verdict |\n|---|---|---|---|---|---|---|\n",
    );
    for c in checks {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} |",
            c.experiment,
            c.key,
            c.unit,
            c.measured.map_or("not produced".into(), number),
            c.expected.map_or("no expectation".into(), |e| format!("{} +- {}", number(e.value), number(e.tolerance))),
            c.paper.map_or("-".into(), number),
            if c.ok() { "ok" } else { "**MISS**" }
        );
    }
    out
}

/// Checks the README's `reproduce-all` block against the expectation
/// files: every full-run expectation appears as a row whose measured value
/// lies within its tolerance. Returns the problems (empty when current).
#[must_use]
#[cfg(test)]
pub fn stale_readme_rows(readme: &str) -> Vec<String> {
    let begin = format!("<!-- {README_BLOCK}:begin -->");
    let end = format!("<!-- {README_BLOCK}:end -->");
    let Some(block) = readme.split(&begin).nth(1).and_then(|rest| rest.split(&end).next()) else {
        return vec![format!("README has no {begin} ... {end} block")];
    };
    let mut problems = Vec::new();
    for spec in &EXPERIMENTS {
        let expected = match parse_expected(spec.expected_path, spec.expected) {
            Ok(e) => e,
            Err(e) => return vec![format!("{e:#}")],
        };
        for e in expected {
            let row = block.lines().find(|l| l.starts_with(&format!("| {} | {} |", spec.name, e.key)));
            let measured = row.and_then(|r| r.split('|').nth(4)).and_then(|cell| cell.trim().parse::<f64>().ok());
            match measured {
                None => problems.push(format!("{} `{}`: no row with a measured value", spec.name, e.key)),
                Some(m) if (m - e.full.value).abs() > e.full.tolerance => problems.push(format!(
                    "{} `{}`: README says {m}, {} expects {} +- {}",
                    spec.name, e.key, spec.expected_path, e.full.value, e.full.tolerance
                )),
                Some(_) => {}
            }
        }
    }
    problems
}

/// Options of `reproduce --all`.
#[derive(Args, Debug, Clone)]
pub struct AllArgs {
    /// Run every experiment (odometry, mpc-artificial, shaham, spebt, zoechmann, kim) and check each metric against
    /// data/reproduce/<experiment>.expected.toml; exit 1 on a miss.
    #[arg(long)]
    pub all: bool,
    /// With --all: the CI versions (each experiment's --quick) against their smoke expectations.
    #[arg(long, requires = "all")]
    pub smoke: bool,
    /// With --all: output directory (one subdirectory per experiment, summary.md).
    #[arg(short, long, value_name = "DIR", default_value = "out/reproduce/all", requires = "all")]
    pub output: PathBuf,
    /// With --all (full runs only): rewrite the README blocks of the experiments and the
    /// `reproduce-all` table in this file.
    #[arg(long, value_name = "README.md", requires = "all", conflicts_with = "smoke")]
    pub readme: Option<PathBuf>,
}

/// `reproduce --all`.
pub fn run(args: &AllArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    if let Some(readme) = &args.readme {
        crate::readme_block::check_block(readme, README_BLOCK)?;
    }
    let expectations: Vec<Vec<ExpectedMetric>> =
        EXPERIMENTS.iter().map(|s| parse_expected(s.expected_path, s.expected)).collect::<anyhow::Result<_>>()?;
    std::fs::create_dir_all(&args.output).with_context(|| args.output.display().to_string())?;
    let mode = if args.smoke { "smoke (--quick)" } else { "full" };
    let started = Instant::now();
    let mut checks = Vec::new();
    let mut timings = Vec::new();
    for (k, (spec, expected)) in EXPERIMENTS.iter().zip(&expectations).enumerate() {
        let dir = args.output.join(spec.name);
        let mut line = vec![
            "reproduce".to_string(),
            spec.name.to_string(),
            "-o".into(),
            crate::path_word(&dir)?,
            "--force".into(),
        ];
        if args.smoke {
            line.push("--quick".into());
        }
        if let (Some(readme), true) = (&args.readme, spec.readme) {
            line.extend(["--readme".to_string(), crate::path_word(readme)?]);
        }
        line.push("--quiet".into());
        if !quiet {
            eprintln!("[{}/{}] mmtrack {}", k + 1, EXPERIMENTS.len(), line.join(" "));
        }
        let experiment_started = Instant::now();
        // Exit code 1 is a missed paper target: expected for some
        // experiments (README); the expectations decide here.
        crate::run_words(&line).with_context(|| format!("`mmtrack {}`", line.join(" ")))?;
        let seconds = experiment_started.elapsed().as_secs_f64();
        timings.push((spec.name, seconds));
        let metrics_path = dir.join(METRICS_FILE);
        let text = std::fs::read_to_string(&metrics_path).with_context(|| metrics_path.display().to_string())?;
        let measured: Vec<Metric> = serde_json::from_str(&text).with_context(|| metrics_path.display().to_string())?;
        let these = compare(spec.name, &measured, expected, args.smoke);
        if !quiet {
            let misses = these.iter().filter(|c| !c.ok()).count();
            eprintln!("      {} metrics, {misses} missed, {seconds:.1} s", these.len());
        }
        checks.extend(these);
    }
    let total_s = started.elapsed().as_secs_f64();
    let misses = checks.iter().filter(|c| !c.ok()).count();
    let threads = rayon::current_num_threads();
    let timing = timings.iter().map(|(n, s)| format!("{n} {s:.1} s")).collect::<Vec<_>>().join(", ");
    let mut summary = format!(
        "Written by `mmtrack reproduce --all{}`: {} metrics of {} experiments, {misses} outside their expected \
         range. Expected values (data/reproduce/<experiment>.expected.toml) are what this code measured when the \
         results were written, with absolute tolerances; the paper's numbers beside them.\n\n",
        if args.smoke { " --smoke" } else { "" },
        checks.len(),
        EXPERIMENTS.len()
    );
    summary.push_str(&table(&checks));
    let _ = writeln!(summary, "\n{mode} runs in {total_s:.1} s on {threads} threads ({timing}).");
    let summary_path = args.output.join("summary.md");
    std::fs::write(&summary_path, &summary).with_context(|| summary_path.display().to_string())?;
    if let Some(readme) = &args.readme {
        crate::readme_block::replace_block(readme, README_BLOCK, &summary)?;
    }
    if !quiet {
        print!("{summary}");
        println!("\noutputs: {}", args.output.display());
    }
    Ok(if misses == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The README's `reproduce-all` table agrees with the expectation
    /// files (written by `reproduce --all --readme README.md`).
    #[test]
    fn the_readme_table_matches_the_expectation_files() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../README.md");
        let readme = std::fs::read_to_string(&path).unwrap();
        let problems = stale_readme_rows(&readme);
        assert!(
            problems.is_empty(),
            "README.md's {README_BLOCK} block is stale (run `mmtrack reproduce --all --readme README.md`):\n{}",
            problems.join("\n")
        );
    }

    #[test]
    fn every_expectation_file_parses() {
        for spec in &EXPERIMENTS {
            let expected = parse_expected(spec.expected_path, spec.expected).unwrap();
            assert!(!expected.is_empty(), "{}", spec.expected_path);
        }
    }

    #[test]
    fn misses_are_values_outside_the_tolerance_missing_metrics_and_unexpected_ones() {
        let expected = parse_expected(
            "x.toml",
            "[[metric]]\nkey = \"a\"\nfull = { value = 10.0, tolerance = 1.0 }\nsmoke = { value = 5.0, tolerance = 0.5 }\n\
             [[metric]]\nkey = \"b\"\nfull = { value = 1.0, tolerance = 0.0 }\nsmoke = { value = 1.0, tolerance = 0.0 }\n",
        )
        .unwrap();
        let measured = vec![Metric::new("a", 10.9, "deg", Some(3.0)), Metric::new("c", 2.0, "%", None)];
        let full = compare("e", &measured, &expected, false);
        assert_eq!(
            full.iter().map(|c| (c.key.as_str(), c.ok())).collect::<Vec<_>>(),
            [("a", true), ("b", false), ("c", false)]
        );
        let smoke = compare("e", &measured, &expected, true);
        assert!(!smoke[0].ok(), "10.9 is outside 5 +- 0.5");
        let text = table(&full);
        assert!(text.contains("| e | a | deg | 10.9000 | 10.0000 +- 1.0000 | 3.0000 | ok |"), "{text}");
        assert!(text.contains("| e | b |  | not produced |") && text.contains("no expectation"), "{text}");
        let err = parse_expected("x.toml", "[[metric]]\nkey = \"a\"\nfull = { value = 1.0, tolerance = -1.0 }\nsmoke = { value = 1.0, tolerance = 0.0 }\n").unwrap_err();
        assert!(format!("{err:#}").contains("x.toml: metric `a` full"), "{err:#}");
    }
}
