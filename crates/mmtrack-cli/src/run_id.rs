//! `--run-id ID`: one run's tables under `<output>/run=<ID>/`, the same flag
//! for every `mmtrack process` pipeline.
//!
//! Runs written under one `-o` directory with different ids sit side by side
//! (`<output>/run=a/<table>/sequence=<seq>/part-0.parquet`,
//! `<output>/run=b/...`) and read back together with a `run` column (DuckDB /
//! polars Hive partitioning) instead of overwriting each other. Every
//! pipeline writes into [`RunIdArg::run_dir`], checks `--force` there (the
//! partition that would be overwritten), and records [`run_id_of`] that
//! directory as `"run_id"` in its run configuration JSON.

use std::path::{Path, PathBuf};

use anyhow::bail;
use clap::Args;
use mmtrack_io::table::table_path;

/// The `--run-id` flag of the `mmtrack process` pipelines.
#[derive(Args, Clone, Debug, Default)]
pub struct RunIdArg {
    /// Name of this run: the tables go to `<output>/run=<ID>/`, so runs written under one directory read back
    /// together with a `run` column (DuckDB/polars Hive partitioning) instead of overwriting each other.
    #[arg(long, value_name = "ID")]
    pub run_id: Option<String>,
}

impl RunIdArg {
    /// The directory the tables go to: `output` itself without `--run-id`,
    /// else `<output>/run=<ID>`.
    ///
    /// # Errors
    /// An id that is not one safe path component (the characters of a
    /// sequence id: letters, digits, `-`, `_`, `.`; not `.` or `..`), naming
    /// `--run-id`. Call it before any work, so nothing is written.
    pub fn run_dir(&self, output: &Path) -> anyhow::Result<PathBuf> {
        let Some(id) = &self.run_id else { return Ok(output.to_path_buf()) };
        // The partition-name rule of the sequence ids, so both read back the same way.
        if table_path(output, "run", id).is_err() {
            bail!(
                "--run-id '{id}': not a valid run id (use letters, digits, '-', '_', '.'; it names the directory \
                 run=<ID> under {}); nothing was written",
                output.display()
            );
        }
        Ok(output.join(format!("run={id}")))
    }
}

/// The run id of a table directory `.../run=<id>`, if it is one: what a
/// pipeline records as `"run_id"` in its run configuration (`null` otherwise).
#[must_use]
pub fn run_id_of(dir: &Path) -> Option<String> {
    dir.file_name()?.to_str()?.strip_prefix("run=").map(str::to_string)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_dirs_are_one_checked_path_component() {
        let output = Path::new("tables");
        let arg = |id: Option<&str>| RunIdArg { run_id: id.map(str::to_string) };
        assert_eq!(arg(None).run_dir(output).unwrap(), output);
        assert_eq!(arg(Some("fast-1.2_b")).run_dir(output).unwrap(), output.join("run=fast-1.2_b"));
        for bad in ["../x", "a/b", "", ".", "..", "a b", "a=b"] {
            let err = arg(Some(bad)).run_dir(output).unwrap_err().to_string();
            assert!(err.starts_with(&format!("--run-id '{bad}': not a valid run id")), "{bad}: {err}");
        }
        assert_eq!(run_id_of(&output.join("run=a")).as_deref(), Some("a"));
        assert_eq!(run_id_of(output), None);
    }
}
