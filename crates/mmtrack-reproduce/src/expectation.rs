//! The regression check: "did our numbers move?", never "does it reproduce
//! the paper?" (that is [`crate::model::Verdict`]).
//!
//! Beside each experiment's configuration in `data/reproduce/` lies
//! `<experiment>.expected.toml`: for every metric the value expected from
//! the full run and from the smoke run, each with an absolute tolerance.
//! Expected values are what this code measured when the results pages
//! (docs/results/) were written, not the paper's numbers (which several
//! experiments miss, with the reasons on those pages); the paper's number is printed beside
//! them. A metric outside its tolerance, a metric the expectation names but
//! the run did not produce, and a metric without an expectation are misses.

use std::fmt::Write as _;

use anyhow::{Context, bail};
use serde::Deserialize;

use crate::model::{Metric, Tier};

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
    /// From the smoke run (the CLI's `--quick`).
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

/// Every metric of `measured` and `expected` paired, expected order first;
/// `tier` picks the smoke or the full expectation.
#[must_use]
pub fn compare(experiment: &str, measured: &[Metric], expected: &[ExpectedMetric], tier: Tier) -> Vec<Check> {
    let mut checks: Vec<Check> = expected
        .iter()
        .map(|e| {
            let m = measured.iter().find(|m| m.key == e.key);
            Check {
                experiment: experiment.to_string(),
                key: e.key.clone(),
                unit: m.map(|m| m.unit.clone()).unwrap_or_default(),
                measured: m.map(|m| m.value),
                expected: Some(if tier.is_smoke() { e.smoke } else { e.full }),
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
        "| experiment | metric | unit | measured | expected (an earlier run of this code) | regression |\n\
         |---|---|---|---|---|---|\n",
    );
    for c in checks {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} |",
            c.experiment,
            c.key,
            c.unit,
            c.measured.map_or("not produced".into(), number),
            c.expected.map_or("no expectation".into(), |e| format!("{} +- {}", number(e.value), number(e.tolerance))),
            if c.ok() { "unchanged" } else { "**moved**" }
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn misses_are_values_outside_the_tolerance_missing_metrics_and_unexpected_ones() {
        let expected = parse_expected(
            "x.toml",
            "[[metric]]\nkey = \"a\"\nfull = { value = 10.0, tolerance = 1.0 }\nsmoke = { value = 5.0, tolerance = 0.5 }\n\
             [[metric]]\nkey = \"b\"\nfull = { value = 1.0, tolerance = 0.0 }\nsmoke = { value = 1.0, tolerance = 0.0 }\n",
        )
        .unwrap();
        let measured = vec![Metric::new("a", 10.9, "deg", Some(3.0)), Metric::new("c", 2.0, "%", None)];
        let full = compare("e", &measured, &expected, Tier::Full);
        assert_eq!(
            full.iter().map(|c| (c.key.as_str(), c.ok())).collect::<Vec<_>>(),
            [("a", true), ("b", false), ("c", false)]
        );
        let smoke = compare("e", &measured, &expected, Tier::Smoke);
        assert!(!smoke[0].ok(), "10.9 is outside 5 +- 0.5");
        let text = table(&full);
        assert!(text.contains("| e | a | deg | 10.9000 | 10.0000 +- 1.0000 | unchanged |"), "{text}");
        assert!(text.contains("| e | b |  | not produced |") && text.contains("no expectation"), "{text}");
        let err = parse_expected("x.toml", "[[metric]]\nkey = \"a\"\nfull = { value = 1.0, tolerance = -1.0 }\nsmoke = { value = 1.0, tolerance = 0.0 }\n").unwrap_err();
        assert!(format!("{err:#}").contains("x.toml: metric `a` full"), "{err:#}");
    }
}
