//! What every experiment does around its Monte Carlo: refuse an existing
//! output (without `force`) and a README without the experiment's block
//! before any work, read the experiment file (or the embedded default),
//! read the trajectory a drive follows, pick the run count, write the
//! outputs into a staging directory that replaces the output whole, and
//! note the machine's load beside timings.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use mmtrack_core::StampedPose;
use mmtrack_ingest::poses::{Plane, TrajectoryFormat, read_trajectory};
use serde::de::DeserializeOwned;

use crate::model::Tier;

/// Checks, before any work, that `output` may be written and that `readme`
/// (when given) holds the block `block`. `--force` replaces only an empty
/// directory or an earlier experiment output (one holding `reproduce.md`),
/// so a mistyped `-o` cannot delete unrelated files.
///
/// # Errors
/// `output` exists and `force` is off, or it is not an earlier output; the
/// README lacks the block.
pub fn check_start(output: &Path, force: bool, readme: Option<&Path>, block: &str) -> anyhow::Result<()> {
    mmtrack_io::check_output_dir(output)?;
    if output.exists() && !force {
        bail!("{}: exists; use --force to replace it (nothing was done)", output.display());
    }
    if output.exists() {
        let empty = std::fs::read_dir(output)
            .with_context(|| format!("{}: not a directory this command can replace", output.display()))?
            .next()
            .is_none();
        if !empty && !output.join("reproduce.md").is_file() {
            bail!(
                "{}: holds no reproduce.md, so it is not an earlier output of an experiment; refusing to replace it \
                 with --force (nothing was done)",
                output.display()
            );
        }
    }
    if let Some(readme) = readme {
        crate::readme_block::check_block(readme, block)?;
    }
    Ok(())
}

/// The experiment file at `path`, else the embedded default (named
/// `embedded_name` in messages): its name and parsed contents.
///
/// # Errors
/// The file cannot be read or parsed, naming it.
pub fn load_experiment<T: DeserializeOwned>(
    path: Option<&Path>,
    embedded: &str,
    embedded_name: &str,
) -> anyhow::Result<(String, T)> {
    let (source, text) = match path {
        Some(path) => (path.display().to_string(), mmtrack_io::paths::read_config_text(path)?),
        None => (format!("embedded {embedded_name}"), embedded.to_string()),
    };
    let experiment = toml::from_str(&text).with_context(|| source.clone())?;
    Ok((source, experiment))
}

/// The trajectory the drives of the odometry and SPEBT experiments follow
/// by default: the Oxford full-sequence ground truth
/// (`gt/radar_odometry.csv`) among the real-data samples beside the
/// repository, relative to the repository root.
pub const DEFAULT_TRAJECTORY: &str = "../shared/realdata/oxford-gt-full-seq/radar_odometry.csv";

/// The poses of the trajectory file at `path`.
///
/// # Errors
/// The file is missing (saying where the default one lives when it is
/// [`DEFAULT_TRAJECTORY`]), cannot be read or parsed (naming it and the pose).
pub fn read_drive(path: &Path, format: TrajectoryFormat) -> anyhow::Result<Vec<StampedPose>> {
    if !path.exists() {
        if path == Path::new(DEFAULT_TRAJECTORY) {
            bail!(
                "default {DEFAULT_TRAJECTORY} not found (the Oxford full-sequence ground truth among the real-data \
                 samples beside the repository; run from the repository root); pass --trajectory PATH"
            );
        }
        bail!("{}: not found (--trajectory)", path.display());
    }
    Ok(read_trajectory(path, format, None, 0, Plane::Xy)?)
}

/// Monte Carlo runs: `explicit` (the CLI's `--runs`), else the
/// experiment's count for `tier`.
///
/// # Errors
/// Zero runs.
pub fn run_count(explicit: Option<u64>, tier: Tier, smoke_runs: u64, full_runs: u64) -> anyhow::Result<u64> {
    let runs = explicit.unwrap_or(if tier.is_smoke() { smoke_runs } else { full_runs });
    let limit = mmtrack_core::limits::MONTE_CARLO_RUNS;
    if !(runs >= 1 && limit.allows_count(runs)) {
        let message = format!("--runs {runs}: expected {} (nothing was done)", limit.expected);
        return Err(mmtrack_core::error::UsageError(message).into());
    }
    Ok(runs)
}

/// The report line beside a run's timings: the 1-minute load average
/// before and after it (`(before, after)`, from [`load_average`]) on
/// `threads` threads.
#[must_use]
pub fn load_sentence(load: (Option<f64>, Option<f64>), threads: usize) -> String {
    let text = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.1}"));
    format!(
        "1-minute load average before / after the run: {} / {} (on {threads} threads; above that, other work shared \
         the cores and the times are longer).\n",
        text(load.0),
        text(load.1)
    )
}

/// The 1-minute load average (`/proc/loadavg`, Linux; `None` elsewhere),
/// printed beside timings: other work on the machine makes them longer.
#[must_use]
pub fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg").ok()?.split_whitespace().next()?.parse().ok()
}

/// A staging directory beside an experiment's output, published whole.
pub struct Staged {
    dir: tempfile::TempDir,
    output: PathBuf,
}

impl Staged {
    /// Starts staging for `output` (`name` marks the hidden directory).
    ///
    /// # Errors
    /// The parent cannot be created or the staging directory made.
    pub fn new(output: &Path, name: &str) -> anyhow::Result<Self> {
        let parent = match output.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).with_context(|| parent.display().to_string())?;
        let dir = mmtrack_io::staging_dir(&parent, &format!(".reproduce-{name}."))
            .with_context(|| format!("{}: cannot create a staging directory", parent.display()))?;
        Ok(Self { dir, output: output.to_path_buf() })
    }

    /// Where to write.
    #[must_use]
    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    /// The files staged so far, as the paths they will have under the
    /// output directory once published (sorted).
    ///
    /// # Errors
    /// The staging directory cannot be listed.
    pub fn files(&self) -> anyhow::Result<Vec<PathBuf>> {
        let mut files = Vec::new();
        files_below(self.dir.path(), Path::new(""), &mut files)?;
        files.sort();
        Ok(files.into_iter().map(|relative| self.output.join(relative)).collect())
    }

    /// Replaces the output by what was staged.
    ///
    /// # Errors
    /// The old output cannot be removed or the staged one moved into place.
    pub fn publish(self) -> anyhow::Result<()> {
        if self.output.exists() {
            std::fs::remove_dir_all(&self.output).with_context(|| self.output.display().to_string())?;
        }
        let staged = self.dir.keep();
        std::fs::rename(&staged, &self.output).with_context(|| self.output.display().to_string())
    }
}

/// Appends the files below `root.join(relative)` to `out`, as paths relative to `root`.
fn files_below(root: &Path, relative: &Path, out: &mut Vec<PathBuf>) -> anyhow::Result<()> {
    let dir = root.join(relative);
    for entry in std::fs::read_dir(&dir).with_context(|| dir.display().to_string())? {
        let entry = entry.with_context(|| dir.display().to_string())?;
        let path = relative.join(entry.file_name());
        if entry.file_type().with_context(|| path.display().to_string())?.is_dir() {
            files_below(root, &path, out)?;
        } else {
            out.push(path);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn force_replaces_only_empty_dirs_and_earlier_outputs() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        assert!(check_start(&out, false, None, "b").is_ok(), "absent");
        std::fs::create_dir(&out).unwrap();
        assert!(check_start(&out, false, None, "b").unwrap_err().to_string().contains("--force"));
        assert!(check_start(&out, true, None, "b").is_ok(), "empty");
        std::fs::write(out.join("notes.txt"), "mine").unwrap();
        let err = check_start(&out, true, None, "b").unwrap_err().to_string();
        assert!(err.contains("holds no reproduce.md"), "{err}");
        std::fs::write(out.join("reproduce.md"), "").unwrap();
        assert!(check_start(&out, true, None, "b").is_ok(), "an earlier output");
    }

    #[test]
    fn staged_files_are_listed_and_published_in_place_of_the_output() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("old.txt"), "old").unwrap();
        let staged = Staged::new(&out, "test").unwrap();
        std::fs::create_dir(staged.path().join("tables")).unwrap();
        std::fs::write(staged.path().join("tables/t.parquet"), "t").unwrap();
        std::fs::write(staged.path().join("reproduce.md"), "r").unwrap();
        assert_eq!(staged.files().unwrap(), [out.join("reproduce.md"), out.join("tables/t.parquet")]);
        staged.publish().unwrap();
        assert!(out.join("tables/t.parquet").is_file());
        assert!(!out.join("old.txt").exists());
    }
}
