//! `mmtrack check <suite.toml>`: a dataset regression suite
//! ([`mmtrack_reproduce::suite`]): run its steps into a work directory,
//! read its metrics from the tables they wrote, print metric, expected,
//! measured, tolerance and verdict; exit 1 on any regression; `--bless`
//! writes the measured values into the suite.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::Args;
use mmtrack_io::atomic::Overwrite;
use mmtrack_reproduce::suite::{self, Suite, SuiteCheck};

#[derive(Args)]
#[command(after_help = "A suite (TOML) lists [[step]] command lines (ingest, simulate, process, analyze, export, \
as typed after `mmtrack`; `{suite}` is the suite file's directory, `{work}` the work directory) and [[metric]] \
entries: `name`, `table` (a table directory under the work directory, e.g. \"analysis/tables/trajectory_metrics\"), \
optional `sequence`, `run` and `where = { column = value }` to pick rows, `column`, `aggregate` (mean, min, max, sum, \
count) when several rows are picked, `expected`, and `tolerance` (absolute) or `relative_tolerance`. \
Example: examples/regression-suite.toml; format: docs/check.md.\n\n\
Exit codes: 0 every metric within its tolerance (or blessed), 1 a regression, a metric not measured, or a step \
that failed (named on stderr).")]
pub struct CheckArgs {
    /// The suite file.
    #[arg(value_name = "SUITE.toml")]
    pub suite: PathBuf,
    /// Write the measured values into the suite as its new expectations
    /// (tolerances, comments and layout kept; nothing is written unless every metric was measured).
    #[arg(long)]
    pub bless: bool,
    /// Run the steps in DIR and keep their outputs there (DIR must not exist
    /// or be empty); default: a temporary directory removed at the end.
    #[arg(long, value_name = "DIR")]
    pub work_dir: Option<PathBuf>,
}

/// The work directory: the one asked for (kept) or a temporary one
/// (removed on drop and on an interruption).
enum WorkDir {
    Kept(PathBuf),
    Temporary(tempfile::TempDir),
}

impl WorkDir {
    fn path(&self) -> &Path {
        match self {
            Self::Kept(p) => p,
            Self::Temporary(t) => t.path(),
        }
    }
}

fn work_dir(asked: Option<&Path>) -> anyhow::Result<WorkDir> {
    let Some(dir) = asked else {
        let temp = mmtrack_io::atomic::staging_dir(&std::env::temp_dir(), ".mmtrack-check-")
            .context("cannot create a temporary work directory")?;
        return Ok(WorkDir::Temporary(temp));
    };
    if dir.exists() {
        let mut entries = std::fs::read_dir(dir).with_context(|| format!("{}: --work-dir", dir.display()))?;
        if entries.next().is_some() {
            bail!(
                "{}: --work-dir is not empty; give a new or empty directory (nothing in it is removed)",
                dir.display()
            );
        }
    } else {
        std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create the --work-dir", dir.display()))?;
    }
    Ok(WorkDir::Kept(std::path::absolute(dir).with_context(|| dir.display().to_string())?))
}

pub fn run(args: &CheckArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let suite: Suite = suite::read_suite(&args.suite)?;
    let suite_name = args.suite.display().to_string();
    let parent = args.suite.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let suite_dir = std::path::absolute(parent).with_context(|| suite_name.clone())?;
    let work = work_dir(args.work_dir.as_deref())?;
    if !quiet && let Some(description) = &suite.description {
        println!("{suite_name}: {description}");
    }
    let steps = suite.steps.len();
    for (i, step) in suite.steps.iter().enumerate() {
        let words = suite::step_words(step, &suite_dir, work.path(), &suite.env, &|name| std::env::var(name).ok())
            .with_context(|| format!("{suite_name}: step {}", i + 1))?;
        let shown = words.iter().map(|w| mmtrack_process::manifest::shell_word(w)).collect::<Vec<_>>().join(" ");
        if !quiet {
            println!("step {}/{steps}: mmtrack {shown}", i + 1);
        }
        crate::run_words(&words, &suite::STEP_COMMANDS)
            .with_context(|| format!("{suite_name}: step {} (mmtrack {shown})", i + 1))?;
    }
    let checks = suite::measure(&suite, work.path());
    if !quiet || checks.iter().any(|c| !c.ok()) {
        print!("{}", suite::table(&checks));
    }
    if let WorkDir::Kept(dir) = &work
        && !quiet
    {
        println!("outputs kept in {}", dir.display());
    }
    if args.bless {
        let text = mmtrack_io::paths::read_config_text(&args.suite)?;
        let blessed = suite::bless(&text, &checks).with_context(|| format!("{suite_name}: --bless"))?;
        // Atomic: the old suite stays whole on any failure.
        mmtrack_io::atomic::write_file(&args.suite, blessed.as_bytes(), Overwrite::Replace)?;
        if !quiet {
            let moved = checks.iter().filter(|c| !c.ok()).count();
            println!("blessed {suite_name}: {} expectations written ({moved} of them had moved)", checks.len());
        }
        return Ok(ExitCode::SUCCESS);
    }
    let failed: Vec<&SuiteCheck> = checks.iter().filter(|c| !c.ok()).collect();
    if failed.is_empty() {
        if !quiet {
            println!("{suite_name}: all {} metrics within their tolerances", checks.len());
        }
        return Ok(ExitCode::SUCCESS);
    }
    let named: Vec<String> = failed
        .iter()
        .map(|c| match &c.measured {
            Ok(m) => format!(
                "`{}` measured {} against {} {} (change {})",
                c.name,
                m.value,
                c.expected,
                c.tolerance,
                suite::change(c.expected, m.value)
            ),
            Err(_) => format!("`{}` not measured", c.name),
        })
        .collect();
    bail!("{suite_name}: {} of {} metrics regressed: {}", failed.len(), checks.len(), named.join("; "))
}
