//! Dataset regression suites (`mmtrack check <suite.toml>`): the same
//! expectation model as the paper experiments' ([`crate::expectation`]:
//! an expected value with a tolerance, checked against what the run
//! measured), pointed at a user's own fixtures and any column of any table.
//!
//! A suite lists the command lines to run (ingest, simulate, process,
//! analyze, export; exactly as typed after `mmtrack`) and the metrics to
//! read from the tables they wrote:
//!
//! ```toml
//! description = "The Oxford sample through CFEAR odometry"
//!
//! [[step]]
//! args = ["ingest", "oxford", "{suite}/data/oxford-tiny", "-o", "{work}/tiny.mcap"]
//! [[step]]
//! args = ["process", "odometry", "{work}/tiny.mcap", "--preset", "cfear", "-o", "{work}/tables"]
//! [[step]]
//! args = ["analyze", "{work}/tables", "-o", "{work}/analysis"]
//!
//! [[metric]]
//! name = "ATE RMSE"
//! table = "analysis/tables/trajectory_metrics"   # relative to {work}
//! sequence = "tiny"                               # the sequence=... partition (optional)
//! where = { preset = "cfear" }                    # more column or partition equalities (optional)
//! column = "ate_rmse_m"
//! expected = 0.0731
//! tolerance = 0.001            # absolute, in the column's unit; or relative_tolerance = 0.01
//! ```
//!
//! `{suite}` is the directory of the suite file and `{work}` the directory
//! the steps write to (a fresh one per check), so a suite runs from any
//! working directory. `{env:NAME}` is the environment variable NAME, or
//! where it is unset the suite's default for it (`[env] NAME = "..."`, which
//! may use `{suite}`): data kept elsewhere on another machine. A metric selects rows by partition keys (`sequence`,
//! `run`, any `key=value` folder) and column equalities, and needs an
//! `aggregate` (mean, min, max, sum, count) when more than one row is
//! selected ([`select`]). `--bless` writes the measured values into the
//! suite's `expected` keys ([`bless`]), keeping its comments and layout.

pub mod select;

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Deserialize;

pub use select::{Aggregate, Selected, Selection, Wanted};

/// Most steps one suite may list.
pub const MAX_STEPS: usize = 1000;
/// Most metrics one suite may list.
pub const MAX_METRICS: usize = 10_000;
/// The commands a step may run: those that read fixtures and write files.
pub const STEP_COMMANDS: [&str; 5] = ["ingest", "simulate", "process", "analyze", "export"];

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SuiteFile {
    description: Option<String>,
    /// Defaults of the `{env:NAME}` placeholders, used where NAME is unset.
    #[serde(default)]
    env: BTreeMap<String, String>,
    #[serde(default)]
    step: Vec<StepFile>,
    #[serde(default)]
    metric: Vec<MetricFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StepFile {
    args: Vec<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MetricFile {
    name: String,
    table: String,
    sequence: Option<String>,
    run: Option<String>,
    #[serde(default, rename = "where")]
    filters: BTreeMap<String, Wanted>,
    column: String,
    aggregate: Option<Aggregate>,
    expected: f64,
    tolerance: Option<f64>,
    relative_tolerance: Option<f64>,
}

/// How far a measured value may be from the expected one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// `|measured - expected| <= t`, in the column's unit.
    Absolute(f64),
    /// `|measured - expected| <= r |expected|`.
    Relative(f64),
}

impl Tolerance {
    /// The largest accepted `|measured - expected|`.
    #[must_use]
    pub fn allowed(self, expected: f64) -> f64 {
        match self {
            Self::Absolute(t) => t,
            Self::Relative(r) => r * expected.abs(),
        }
    }
}

impl std::fmt::Display for Tolerance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Absolute(t) => write!(f, "+-{}", number(*t)),
            Self::Relative(r) => write!(f, "+-{}%", number(r * 100.0)),
        }
    }
}

/// One metric of a suite.
#[derive(Debug, Clone, PartialEq)]
pub struct SuiteMetric {
    /// Its name in the suite (unique).
    pub name: String,
    /// The table directory, relative to the work directory.
    pub table: PathBuf,
    /// Rows and column.
    pub selection: Selection,
    /// The expected value.
    pub expected: f64,
    /// Its tolerance.
    pub tolerance: Tolerance,
}

/// A suite, read and checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Suite {
    /// The suite file.
    pub path: PathBuf,
    /// What it checks, if it says.
    pub description: Option<String>,
    /// Command lines after `mmtrack`, placeholders still in.
    pub steps: Vec<Vec<String>>,
    /// The `[env]` table: the value of `{env:NAME}` where the environment
    /// variable NAME is unset or empty (may hold `{suite}`).
    pub env: BTreeMap<String, String>,
    /// The metrics, in file order.
    pub metrics: Vec<SuiteMetric>,
}

/// Reads and checks the suite at `path`.
///
/// # Errors
/// The file cannot be read, is larger than
/// [`mmtrack_core::limits::CONFIG_FILE_BYTES`] (a configuration file), or
/// [`parse_suite`] refuses it.
pub fn read_suite(path: &Path) -> anyhow::Result<Suite> {
    let text = mmtrack_io::paths::read_config_text(path).context("cannot read the suite")?;
    parse_suite(path, &text)
}

/// Parses the suite text of `path`.
///
/// # Errors
/// TOML errors and unknown keys; no step or no metric; more than
/// [`MAX_STEPS`] / [`MAX_METRICS`]; a step that is empty, runs a command
/// outside [`STEP_COMMANDS`] or uses a placeholder other than `{suite}`
/// and `{work}`; a metric with a duplicated name, an absolute or `..`
/// table path, a non-finite expectation, or not exactly one finite
/// non-negative tolerance. Each names the file and the step or metric.
pub fn parse_suite(path: &Path, text: &str) -> anyhow::Result<Suite> {
    let name = path.display().to_string();
    let file: SuiteFile = toml::from_str(text).with_context(|| name.clone())?;
    if file.step.is_empty() {
        bail!("{name}: no [[step]] entries (the commands that write the tables)");
    }
    if file.metric.is_empty() {
        bail!("{name}: no [[metric]] entries (the values to check)");
    }
    if file.step.len() > MAX_STEPS {
        bail!("{name}: {} steps; at most {MAX_STEPS}", file.step.len());
    }
    if file.metric.len() > MAX_METRICS {
        bail!("{name}: {} metrics; at most {MAX_METRICS}", file.metric.len());
    }
    for (key, value) in &file.env {
        if !is_env_name(key) {
            bail!("{name}: [env]: `{key}` is not an environment variable name (letters, digits, '_')");
        }
        check_placeholders(value, false).with_context(|| format!("{name}: [env] {key}"))?;
    }
    let mut steps = Vec::with_capacity(file.step.len());
    for (i, step) in file.step.into_iter().enumerate() {
        let at = format!("{name}: step {}", i + 1);
        let Some(command) = step.args.first() else { bail!("{at}: empty args") };
        if !STEP_COMMANDS.contains(&command.as_str()) {
            bail!("{at}: `{command}` is not a step command (one of {})", STEP_COMMANDS.join(", "));
        }
        for word in &step.args {
            check_placeholders(word, true).with_context(|| at.clone())?;
        }
        steps.push(step.args);
    }
    let mut metrics: Vec<SuiteMetric> = Vec::with_capacity(file.metric.len());
    for (i, m) in file.metric.into_iter().enumerate() {
        let at = format!("{name}: metric {} (`{}`)", i + 1, m.name);
        if metrics.iter().any(|o| o.name == m.name) {
            bail!("{at}: the name is used twice");
        }
        let table = PathBuf::from(&m.table);
        if m.table.is_empty()
            || table.is_absolute()
            || table.components().any(|c| !matches!(c, std::path::Component::Normal(_)))
        {
            bail!("{at}: table: `{}` must be a path inside the work directory, e.g. \"tables/odometry\"", m.table);
        }
        if !m.expected.is_finite() {
            bail!("{at}: expected: {} is not a finite number", m.expected);
        }
        let tolerance = match (m.tolerance, m.relative_tolerance) {
            (Some(t), None) if t.is_finite() && t >= 0.0 => Tolerance::Absolute(t),
            (None, Some(r)) if r.is_finite() && r >= 0.0 => Tolerance::Relative(r),
            (Some(t), None) => bail!("{at}: tolerance: {t}; expected a finite number >= 0"),
            (None, Some(r)) => bail!("{at}: relative_tolerance: {r}; expected a finite number >= 0"),
            (Some(_), Some(_)) => bail!("{at}: give tolerance or relative_tolerance, not both"),
            (None, None) => bail!("{at}: no tolerance; give tolerance (absolute) or relative_tolerance"),
        };
        let mut filters: Vec<(String, Wanted)> = Vec::new();
        for (key, value) in [("sequence", m.sequence), ("run", m.run)] {
            if let Some(value) = value {
                if m.filters.contains_key(key) {
                    bail!("{at}: `{key}` is given twice (as a key and in `where`)");
                }
                filters.push((key.to_string(), Wanted::Text(value)));
            }
        }
        filters.extend(m.filters);
        metrics.push(SuiteMetric {
            name: m.name,
            table,
            selection: Selection { filters, column: m.column, aggregate: m.aggregate },
            expected: m.expected,
            tolerance,
        });
    }
    Ok(Suite { path: path.to_path_buf(), description: file.description, steps, env: file.env, metrics })
}

/// Whether `name` can name an environment variable in `{env:NAME}`.
fn is_env_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The placeholders of `word` in order: `(start, end, inside the braces)`.
fn placeholders(word: &str) -> Vec<(usize, usize, &str)> {
    let mut found = Vec::new();
    let mut from = 0;
    while let Some(start) = word[from..].find('{').map(|s| from + s) {
        let end = word[start..].find('}').map_or(word.len(), |e| start + e + 1);
        found.push((start, end, word[start + 1..end].trim_end_matches('}')));
        from = end;
    }
    found
}

/// Refuses braces other than the `{suite}` and `{work}` placeholders and
/// (with `env`) `{env:NAME}`.
fn check_placeholders(word: &str, env: bool) -> anyhow::Result<()> {
    for (start, end, inside) in placeholders(word) {
        let known = inside == "suite"
            || (env && inside == "work")
            || (env && inside.strip_prefix("env:").is_some_and(is_env_name));
        if !known {
            let allowed = if env { "{suite}, {work} or {env:NAME}" } else { "{suite}" };
            bail!("`{word}`: unknown placeholder `{}` (use {allowed})", &word[start..end]);
        }
    }
    Ok(())
}

/// A step's words with `{suite}`, `{work}` and `{env:NAME}` replaced:
/// `lookup(NAME)` (the environment) where it is set and not empty, else
/// the suite's `[env]` default (`env_defaults`, its `{suite}` replaced).
///
/// # Errors
/// A directory that is not UTF-8 (the words are command-line text); an
/// `{env:NAME}` whose variable is unset with no default.
pub fn step_words(
    step: &[String],
    suite_dir: &Path,
    work_dir: &Path,
    env_defaults: &BTreeMap<String, String>,
    lookup: &dyn Fn(&str) -> Option<String>,
) -> anyhow::Result<Vec<String>> {
    let utf8 = |p: &Path| p.to_str().map(str::to_string).with_context(|| format!("{}: not a UTF-8 path", p.display()));
    let (suite, work) = (utf8(suite_dir)?, utf8(work_dir)?);
    let env = |name: &str| -> anyhow::Result<String> {
        if let Some(value) = lookup(name).filter(|v| !v.is_empty()) {
            return Ok(value);
        }
        match env_defaults.get(name) {
            Some(default) => Ok(default.replace("{suite}", &suite)),
            None => bail!(
                "{{env:{name}}}: the environment variable {name} is not set and the suite's [env] gives no default"
            ),
        }
    };
    step.iter()
        .map(|word| {
            let mut out = String::with_capacity(word.len());
            let mut from = 0;
            for (start, end, inside) in placeholders(word) {
                out.push_str(&word[from..start]);
                match inside {
                    "suite" => out.push_str(&suite),
                    "work" => out.push_str(&work),
                    other => match other.strip_prefix("env:") {
                        Some(name) => out.push_str(&env(name)?),
                        None => out.push_str(&word[start..end]),
                    },
                }
                from = end;
            }
            out.push_str(&word[from..]);
            Ok(out)
        })
        .collect()
}

/// One metric, measured (or why not) against its expectation.
#[derive(Debug, Clone, PartialEq)]
pub struct SuiteCheck {
    /// The metric's name.
    pub name: String,
    /// The expected value.
    pub expected: f64,
    /// The tolerance.
    pub tolerance: Tolerance,
    /// The measured value, or why the tables do not give one.
    pub measured: Result<Selected, String>,
}

impl SuiteCheck {
    /// Measured, and within the tolerance (NaN is not).
    #[must_use]
    pub fn ok(&self) -> bool {
        self.measured.as_ref().is_ok_and(|m| (m.value - self.expected).abs() <= self.tolerance.allowed(self.expected))
    }

    /// "ok", "REGRESSED" or "NOT MEASURED".
    #[must_use]
    pub fn verdict(&self) -> &'static str {
        match (&self.measured, self.ok()) {
            (Err(_), _) => "NOT MEASURED",
            (Ok(_), true) => "ok",
            (Ok(_), false) => "REGRESSED",
        }
    }
}

/// Every metric of `suite` read from the tables under `work_dir`.
#[must_use]
pub fn measure(suite: &Suite, work_dir: &Path) -> Vec<SuiteCheck> {
    suite
        .metrics
        .iter()
        .map(|m| SuiteCheck {
            name: m.name.clone(),
            expected: m.expected,
            tolerance: m.tolerance,
            measured: select::select(&work_dir.join(&m.table), &m.selection).map_err(|e| format!("{e:#}")),
        })
        .collect()
}

/// A number for the table: six significant digits.
fn number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let magnitude = v.abs().log10().floor();
    if !(-3.0..6.0).contains(&magnitude) {
        let text = format!("{v:.5e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        let mantissa =
            if mantissa.contains('.') { mantissa.trim_end_matches('0').trim_end_matches('.') } else { mantissa };
        return format!("{mantissa}e{exponent}");
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let decimals = (5.0 - magnitude).max(0.0) as usize;
    let text = format!("{v:.decimals$}");
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { text }
}

/// `expected` and `measured` for the table: six significant digits, or
/// every digit (the shortest text that reads back as the same number) when
/// six would show two different values as equal.
fn expected_and_measured(expected: f64, measured: f64) -> (String, String) {
    let (e, m) = (number(expected), number(measured));
    if e == m && expected.to_bits() != measured.to_bits() {
        (format!("{expected}"), format!("{measured}"))
    } else {
        (e, m)
    }
}

/// How far `measured` moved from `expected`: the signed difference and,
/// where `expected` is not zero, the same relative to it in percent
/// (`+0.5001 (+5.001%)`), the two ways a tolerance is given; `0` when the
/// value did not move.
#[must_use]
pub fn change(expected: f64, measured: f64) -> String {
    let signed = |v: f64| if v > 0.0 { format!("+{}", number(v)) } else { number(v) };
    let difference = measured - expected;
    if expected == 0.0 || difference == 0.0 || !difference.is_finite() {
        signed(difference)
    } else {
        format!("{} ({}%)", signed(difference), signed(difference / expected.abs() * 100.0))
    }
}

/// The plain-text table of `checks`: metric, expected, measured, change
/// (measured - expected, absolute and relative), tolerance, verdict (and
/// the reason under a metric not measured).
#[must_use]
pub fn table(checks: &[SuiteCheck]) -> String {
    let rows: Vec<[String; 6]> = checks
        .iter()
        .map(|c| {
            let (expected, measured, moved) = match &c.measured {
                Ok(m) => {
                    let (e, v) = expected_and_measured(c.expected, m.value);
                    (e, v, change(c.expected, m.value))
                }
                Err(_) => (number(c.expected), "-".to_string(), "-".to_string()),
            };
            [c.name.clone(), expected, measured, moved, c.tolerance.to_string(), c.verdict().to_string()]
        })
        .collect();
    let header = ["metric", "expected", "measured", "change", "tolerance", "verdict"].map(str::to_string);
    let widths: Vec<usize> = (0..header.len())
        .map(|i| rows.iter().chain(std::iter::once(&header)).map(|r| r[i].chars().count()).max().unwrap_or(0))
        .collect();
    let mut out = String::new();
    for (row, check) in std::iter::once((&header, None)).chain(rows.iter().zip(checks).map(|(r, c)| (r, Some(c)))) {
        let cells: Vec<String> = row.iter().zip(&widths).map(|(cell, w)| format!("{cell:<w$}")).collect();
        let _ = writeln!(out, "{}", cells.join("  ").trim_end());
        if let Some(SuiteCheck { measured: Err(why), .. }) = check {
            let _ = writeln!(out, "    {why}");
        }
    }
    out
}

/// The suite text with each metric's `expected` replaced by its measured
/// value (comments, order and layout kept).
///
/// # Errors
/// A metric not measured (nothing is blessed then), a non-finite value,
/// or a text that is not the suite the checks came from.
pub fn bless(text: &str, checks: &[SuiteCheck]) -> anyhow::Result<String> {
    let mut document: toml_edit::DocumentMut = text.parse().context("the suite is no longer valid TOML")?;
    let metrics = document
        .get_mut("metric")
        .and_then(toml_edit::Item::as_array_of_tables_mut)
        .context("the suite has no [[metric]] tables")?;
    if metrics.len() != checks.len() {
        bail!("the suite has {} metrics, the run measured {}", metrics.len(), checks.len());
    }
    for (table, check) in metrics.iter_mut().zip(checks) {
        let value = match &check.measured {
            Ok(m) if m.value.is_finite() => m.value,
            Ok(m) => bail!("metric `{}`: measured {}; only finite values are blessed", check.name, m.value),
            Err(why) => bail!("metric `{}` was not measured, nothing blessed: {why}", check.name),
        };
        let decor = table.get("expected").and_then(toml_edit::Item::as_value).map(|v| v.decor().clone());
        let mut new = toml_edit::Value::from(value);
        if let Some(decor) = decor {
            *new.decor_mut() = decor;
        }
        table.insert("expected", toml_edit::Item::Value(new));
    }
    Ok(document.to_string())
}

#[cfg(test)]
mod tests;
