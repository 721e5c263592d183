//! Where a pipeline writes: the output options every pipeline shares
//! (`--sequence`, `--force`, `--run-id` on the command line) and the run
//! directory they resolve to.
//!
//! `--run-id ID` puts one run's tables under `<output>/run=<ID>/`: runs
//! written under one `-o` directory with different ids sit side by side
//! (`<output>/run=a/<table>/sequence=<seq>/part-0.parquet`,
//! `<output>/run=b/...`) and read back together with a `run` column (DuckDB /
//! polars Hive partitioning) instead of overwriting each other. Every
//! pipeline resolves its flags to a [`RunDir`] before any work, refuses
//! existing tables there without `--force` ([`RunDir::refuse_existing`]),
//! writes there, and records [`run_id_of`] that directory as `"run_id"` in
//! its run configuration JSON.
//!
//! # A run's tables appear together
//!
//! A run's tables are one result: a failed run (a full disk, a bad table
//! half-way, an interruption) must not leave some of them beside the
//! previous run's others, nor a partition that blocks the rerun without
//! `--force`. Every pipeline therefore writes through [`RunDir::tables`]: each
//! table is written complete into a hidden partial file beside its final
//! path ([`mmtrack_io::table::stage_table`]) and nothing is published until
//! [`RunTables::publish`] renames them all into place together
//! ([`mmtrack_io::atomic::commit_all`]: all or none, old tables put back if a
//! rename fails). A [`RunTables`] dropped without publishing (any error on
//! the way) removes its partial files and the directories it created that
//! are still empty, so a failed run leaves nothing of its own and the
//! previous tables (replaced only with `--force`) untouched. The cost: the
//! disk holds the whole new set beside the old one until the publish.
//!
//! The thread count is not here: it does not change what is written (every
//! pipeline runs on the caller's rayon pool).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use mmtrack_io::Overwrite;
use mmtrack_io::atomic::{CreatedDirRegistration, register_created_dir};
use mmtrack_io::table::{
    RunInfo, StagedTable, TableRow, TableSpec, TableWriteSummary, TableWriter, check_partition_name, publish_tables,
    stage_table, table_path,
};

/// Where a pipeline writes, as the front end gave it: the output directory,
/// an optional run id and whether existing tables may be replaced.
#[derive(Clone, Debug, Default)]
pub struct OutputOptions {
    /// Sequence id of the output partitions (default: the recording's).
    pub sequence: Option<String>,
    /// The tables go to `<output>/run=<ID>/` (see the module docs).
    pub run_id: Option<String>,
    /// Replace existing tables of the sequences written (only this run's).
    pub force: bool,
}

impl OutputOptions {
    /// The sequence id to write: [`Self::sequence`], else the recording's.
    #[must_use]
    pub fn sequence_or(&self, recording_sequence: &str) -> String {
        self.sequence.clone().unwrap_or_else(|| recording_sequence.to_string())
    }

    /// The sequence id the run will most likely write, known before any
    /// work: [`Self::sequence`], else the id in the recording's metadata
    /// (its first record). `None` when that cannot be read; the pipeline then
    /// reports the problem itself and checks again after its work.
    #[must_use]
    pub fn sequence_hint(&self, recording: &Path) -> Option<String> {
        self.sequence.clone().or_else(|| recording_metadata(recording).ok().flatten().map(|m| m.sequence_id))
    }

    /// The run directory under `output` with the overwrite policy of
    /// [`Self::force`].
    ///
    /// # Errors
    /// A bad run id ([`run_dir`]) or sequence id (naming `--sequence`). Call
    /// it before any work.
    pub fn resolve(&self, output: &Path) -> anyhow::Result<RunDir> {
        if let Some(sequence) = &self.sequence
            && let Err(detail) = check_partition_name(sequence)
        {
            bail!("--sequence: {detail}; it names the partitions sequence=<ID> of the tables; nothing was written");
        }
        let overwrite = if self.force { Overwrite::Replace } else { Overwrite::Refuse };
        Ok(RunDir { path: run_dir(output, self.run_id.as_deref())?, overwrite })
    }
}

/// The recording's metadata (writers put it first), read up to the first
/// message; `None` when it has none.
///
/// # Errors
/// The file cannot be opened, or a record before the first message is bad.
pub fn recording_metadata(recording: &Path) -> anyhow::Result<Option<mmtrack_io::RecordingMetadata>> {
    let mut reader = mmtrack_io::RecordingReader::open(recording)?;
    if let Some(Err(e)) = reader.next_item() {
        return Err(e.into());
    }
    Ok(reader.metadata().and_then(mmtrack_io::RecordingMetadata::from_map))
}

/// The directory the tables go to: `output` itself without a run id, else
/// `<output>/run=<ID>`.
///
/// # Errors
/// An id that is not one safe path component (the characters of a
/// sequence id: letters, digits, `-`, `_`, `.`; not `.` or `..`), naming
/// `--run-id`. Call it before any work, so nothing is written.
pub fn run_dir(output: &Path, run_id: Option<&str>) -> anyhow::Result<PathBuf> {
    let Some(id) = run_id else { return Ok(output.to_path_buf()) };
    if !is_run_id(id) {
        bail!(
            "--run-id '{id}': not a valid run id (use letters, digits, '-', '_', '.'; it names the directory \
             run=<ID> under {}); nothing was written",
            output.display()
        );
    }
    Ok(output.join(format!("run={id}")))
}

/// Whether `id` can name a `run=<id>` directory: the partition-name rule of
/// the sequence ids, so both read back the same way.
#[must_use]
pub fn is_run_id(id: &str) -> bool {
    table_path(Path::new(""), "run", id).is_ok()
}

/// The directory a pipeline writes its tables to (`<output>` or
/// `<output>/run=<ID>`), and whether it may replace tables there.
#[derive(Clone, Debug)]
pub struct RunDir {
    /// The directory.
    pub path: PathBuf,
    /// `Replace` with `--force`, else `Refuse`.
    pub overwrite: Overwrite,
}

impl RunDir {
    /// What the run configuration records as `"run_id"` ([`run_id_of`]).
    #[must_use]
    pub fn run_id(&self) -> Option<String> {
        run_id_of(&self.path)
    }

    /// Without `--force`, an error naming the first of `tables` that
    /// `sequence` already has here; with or without it, an error for a table
    /// path (or a folder above it) that is neither a file nor a directory
    /// ([`mmtrack_io::check_output_file`]).
    ///
    /// # Errors
    /// That table, or a `sequence` that is not a partition name.
    pub fn refuse_existing(&self, tables: &[&str], sequence: &str) -> anyhow::Result<()> {
        for table in tables {
            let path = table_path(&self.path, table, sequence)?;
            // With or without --force: a table folder or file that is a FIFO or a device node.
            mmtrack_io::check_output_file(&path)?;
            if self.overwrite == Overwrite::Refuse && path.exists() {
                return Err(exists_error(&path));
            }
        }
        Ok(())
    }
}

/// A run's tables while they are written: staged, then published together
/// (see the module docs). Dropped unpublished, it leaves nothing.
#[derive(Debug)]
#[must_use = "nothing is published until `publish`"]
pub struct RunTables {
    dir: RunDir,
    staged: Vec<StagedTable>,
    /// Directories this run created, outermost first: removed when still
    /// empty if the run does not publish; in the registry of partial
    /// outputs meanwhile, so that an interruption (Ctrl-C) removes them too.
    created_dirs: Vec<CreatedDirRegistration>,
}

impl RunDir {
    /// Starts the set of tables of one run here.
    pub fn tables(&self) -> RunTables {
        RunTables { dir: self.clone(), staged: Vec::new(), created_dirs: Vec::new() }
    }
}

impl RunTables {
    /// Writes `rows` as the `sequence` partition of their table, complete but
    /// not yet visible.
    ///
    /// # Errors
    /// An existing table (without `--force`), a bad partition name, or a
    /// table that cannot be written.
    pub fn write<T: TableRow>(&mut self, sequence: &str, rows: &[T], run: &RunInfo) -> anyhow::Result<()> {
        self.note_created_dirs(T::SPEC.name, sequence)?;
        self.staged.push(stage_table(&self.dir.path, sequence, rows, run, self.dir.overwrite)?);
        Ok(())
    }

    /// A writer of the `sequence` partition of `spec`'s table, for rows
    /// that come in many calls; hand it back with [`RunTables::add`].
    ///
    /// # Errors
    /// As [`RunTables::write`].
    pub fn writer(&mut self, spec: &'static TableSpec, sequence: &str, run: &RunInfo) -> anyhow::Result<TableWriter> {
        self.note_created_dirs(spec.name, sequence)?;
        Ok(TableWriter::create(&self.dir.path, spec, sequence, run, self.dir.overwrite)?)
    }

    /// Adds a table completed by a [`RunTables::writer`] to the run.
    ///
    /// # Errors
    /// The file cannot be completed.
    pub fn add(&mut self, writer: TableWriter) -> anyhow::Result<()> {
        self.staged.push(writer.stage()?);
        Ok(())
    }

    /// Remembers the directories the table's partition will create, so an
    /// unpublished run removes them.
    fn note_created_dirs(&mut self, table: &str, sequence: &str) -> anyhow::Result<()> {
        let target = table_path(&self.dir.path, table, sequence)?;
        let mut missing: Vec<PathBuf> = target
            .ancestors()
            .skip(1)
            .take_while(|dir| !dir.as_os_str().is_empty() && !dir.exists())
            .map(Path::to_path_buf)
            .collect();
        missing.reverse();
        self.created_dirs.extend(missing.iter().map(|dir| register_created_dir(dir)));
        Ok(())
    }

    /// Publishes every table written, together: all of them, or none.
    ///
    /// # Errors
    /// A table that appeared meanwhile (without `--force`) or a rename that
    /// failed; nothing of this run is left then.
    pub fn publish(mut self) -> anyhow::Result<Vec<TableWriteSummary>> {
        let written = publish_tables(std::mem::take(&mut self.staged), self.dir.overwrite)?;
        self.created_dirs.clear();
        Ok(written)
    }
}

impl Drop for RunTables {
    fn drop(&mut self) {
        // The partial files first (their drop removes them), then the
        // directories, innermost first; `remove_dir` removes only empty
        // ones, so nothing another writer put there goes.
        self.staged.clear();
        for dir in self.created_dirs.iter().rev() {
            let _ = std::fs::remove_dir(dir.path());
        }
    }
}

/// The ids of the `run=<ID>` directories in `dir` (none when `dir` is not a
/// directory), sorted: the runs a reader of `dir` can choose from.
///
/// # Errors
/// `dir` cannot be listed.
pub fn run_ids_in(dir: &Path) -> anyhow::Result<Vec<String>> {
    if !dir.is_dir() {
        return Ok(Vec::new());
    }
    let listing = || format!("{}: cannot list", dir.display());
    let mut ids = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(listing)? {
        let entry = entry.with_context(listing)?;
        if entry.path().is_dir() {
            ids.extend(run_id_of(&entry.path()));
        }
    }
    ids.sort();
    Ok(ids)
}

/// The refusal of an existing output `path` without `--force`, the same
/// words for every pipeline.
#[must_use]
pub fn exists_error(path: &Path) -> anyhow::Error {
    anyhow::anyhow!("{}: exists; use --force to replace it (nothing was written)", path.display())
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
        assert_eq!(run_dir(output, None).unwrap(), output);
        assert_eq!(run_dir(output, Some("fast-1.2_b")).unwrap(), output.join("run=fast-1.2_b"));
        for bad in ["../x", "a/b", "", ".", "..", "a b", "a=b"] {
            let err = run_dir(output, Some(bad)).unwrap_err().to_string();
            assert!(err.starts_with(&format!("--run-id '{bad}': not a valid run id")), "{bad}: {err}");
        }
        assert_eq!(run_id_of(&output.join("run=a")).as_deref(), Some("a"));
        assert_eq!(run_id_of(output), None);
    }

    #[test]
    fn a_bad_sequence_id_is_refused_naming_the_flag_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let output = dir.path().join("out");
        let with = |id: &str| OutputOptions { sequence: Some(id.to_string()), run_id: None, force: false };
        let long = "a".repeat(300);
        for bad in ["a b", "../up", "", "__HIVE_DEFAULT_PARTITION__", long.as_str()] {
            let err = with(bad).resolve(&output).unwrap_err().to_string();
            assert!(err.starts_with("--sequence: ") && err.ends_with("nothing was written"), "{bad}: {err}");
        }
        assert!(with(&long).resolve(&output).unwrap_err().to_string().contains("300 bytes is too long"));
        let longest = "a".repeat(mmtrack_io::table::MAX_PARTITION_NAME_BYTES);
        let run = with(&longest).resolve(&output).unwrap();
        // The longest accepted id makes a folder the file system takes; one byte more is refused.
        std::fs::create_dir_all(run.path.join("t").join(format!("sequence={longest}"))).unwrap();
        assert!(with(&format!("{longest}a")).resolve(&output).is_err());
    }

    #[test]
    fn refusals_look_in_the_run_directory_and_force_lifts_them() {
        let dir = tempfile::tempdir().unwrap();
        let flags =
            |force: bool, id: Option<&str>| OutputOptions { sequence: None, run_id: id.map(str::to_string), force };
        let existing = dir.path().join("run=a/t2/sequence=s/part-0.parquet");
        std::fs::create_dir_all(existing.parent().unwrap()).unwrap();
        std::fs::write(&existing, b"").unwrap();
        let run_a = flags(false, Some("a")).resolve(dir.path()).unwrap();
        assert_eq!((run_a.path.as_path(), run_a.run_id().as_deref()), (dir.path().join("run=a").as_path(), Some("a")));
        let err = run_a.refuse_existing(&["t1", "t2"], "s").unwrap_err().to_string();
        assert_eq!(err, format!("{}: exists; use --force to replace it (nothing was written)", existing.display()));
        // Another sequence, another run, no run id, or --force: nothing refused.
        run_a.refuse_existing(&["t1", "t2"], "other").unwrap();
        flags(false, Some("b")).resolve(dir.path()).unwrap().refuse_existing(&["t2"], "s").unwrap();
        flags(false, None).resolve(dir.path()).unwrap().refuse_existing(&["t2"], "s").unwrap();
        let forced = flags(true, Some("a")).resolve(dir.path()).unwrap();
        assert_eq!(forced.overwrite, Overwrite::Replace);
        forced.refuse_existing(&["t2"], "s").unwrap();
    }

    #[test]
    fn run_ids_are_the_run_directories_sorted() {
        let dir = tempfile::tempdir().unwrap();
        assert!(run_ids_in(&dir.path().join("missing")).unwrap().is_empty());
        for sub in ["run=b", "run=a", "odometry", "run=c.txt"] {
            std::fs::create_dir(dir.path().join(sub)).unwrap();
        }
        std::fs::write(dir.path().join("run=file"), b"").unwrap();
        assert_eq!(run_ids_in(dir.path()).unwrap(), ["a", "b", "c.txt"]);
    }
}
