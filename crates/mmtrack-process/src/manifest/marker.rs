//! Completion records of manifest tasks: how `--skip-existing` tells a
//! finished task from an interrupted one and from outputs it never wrote.
//!
//! One JSON file per task under `<tables>/.mmtrack-tasks/`, named by the
//! CRC-32 of the task's command line (without `--force`) and holding that
//! command line, so a task changed in the manifest is a different task:
//!
//! ```json
//! {"command":["process","odometry","a.mcap","-o","t"],"state":"done",
//!  "outputs":[{"path":"t/odometry/sequence=a/part-0.parquet","bytes":48213}]}
//! ```
//!
//! `started` is written (atomically, like every output) before the task
//! runs, `done` with its outputs after it succeeded; a task that fails
//! returns an error after removing its own partial outputs, and its record
//! is removed too. So a record that still says `started` belongs to a run
//! killed during the task ([`resume`]). The directory is hidden, so Hive
//! readers (`<table>/*/*.parquet`) and `mmtrack analyze` do not see it.

use std::path::{Path, PathBuf};

use anyhow::Context;
use mmtrack_io::Overwrite;
use serde::{Deserialize, Serialize};

/// The directory of the records, under the manifest's `-o`.
pub const DIR: &str = ".mmtrack-tasks";

/// Where a task is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum State {
    /// Running, or killed while running.
    Started,
    /// Finished; its outputs are listed.
    Done,
}

/// One output of a finished task: a file, or a directory (its files'
/// bytes summed).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct OutputFile {
    /// As the task wrote it (relative to the directory the manifest ran in,
    /// when the task's paths are).
    pub path: String,
    /// Its size in bytes.
    pub bytes: u64,
}

/// A task's completion record.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Record {
    /// The command line after `mmtrack`, without `--force`.
    pub command: Vec<String>,
    /// Started or done.
    pub state: State,
    /// With `done`: what it wrote.
    pub outputs: Vec<OutputFile>,
}

/// What `--skip-existing` does with a task.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Resume {
    /// Done, every output there at its size: skip it.
    Skip,
    /// Interrupted, or done with an output gone or changed: run it again
    /// with `--force` (what is there is its own).
    Redo,
    /// No record: run it as given (an existing output is refused).
    Run,
}

/// The record file of `command` under `tables`.
#[must_use]
pub fn path(tables: &Path, command: &[String]) -> PathBuf {
    let mut hasher = crc32fast::Hasher::new();
    for word in command {
        hasher.update(word.as_bytes());
        hasher.update(&[0]);
    }
    tables.join(DIR).join(format!("task-{:08x}.json", hasher.finalize()))
}

/// The record of `command`, if there is one (a record of another command
/// under the same name is none).
///
/// # Errors
/// A record that cannot be read or parsed, naming it.
pub fn read(tables: &Path, command: &[String]) -> anyhow::Result<Option<Record>> {
    let file = path(tables, command);
    let text = match std::fs::read_to_string(&file) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e).with_context(|| format!("{}: cannot read the task record", file.display())),
    };
    let record: Record = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a task record (remove it to run the task again)", file.display()))?;
    Ok((record.command == command).then_some(record))
}

/// Writes `record` atomically.
///
/// # Errors
/// The record cannot be written, naming it.
pub fn write(tables: &Path, record: &Record) -> anyhow::Result<()> {
    let target = path(tables, &record.command);
    let context = || format!("{}: cannot write the task record", target.display());
    let mut text = serde_json::to_vec(record).with_context(context)?;
    text.push(b'\n');
    mmtrack_io::atomic::write_file(&target, &text, Overwrite::Replace).with_context(context)?;
    Ok(())
}

/// Puts back a record as it was before a task that then failed: its
/// contents and its time ([`written_at`]), which decides whether the tasks
/// that need it are stale. Rewriting it with a new time made
/// `--skip-existing` redo every task after a failed re-run of a complete one.
///
/// # Errors
/// The record cannot be written or its time set, naming it.
pub fn restore(tables: &Path, record: &Record, written: Option<std::time::SystemTime>) -> anyhow::Result<()> {
    write(tables, record)?;
    if let Some(time) = written {
        let target = path(tables, &record.command);
        let context = || format!("{}: cannot set the task record's time", target.display());
        std::fs::File::options().write(true).open(&target).and_then(|f| f.set_modified(time)).with_context(context)?;
    }
    Ok(())
}

/// Removes the record of `command` (nothing when there is none).
///
/// # Errors
/// It exists and cannot be removed.
pub fn remove(tables: &Path, command: &[String]) -> anyhow::Result<()> {
    let file = path(tables, command);
    match std::fs::remove_file(&file) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("{}: cannot remove the task record", file.display()))
        }
        _ => Ok(()),
    }
}

/// When the record of `command` was last written, if there is one: a task
/// whose need's record is newer than its own read outputs that changed
/// after it ran, so `--skip-existing` redoes it.
#[must_use]
pub fn written_at(tables: &Path, command: &[String]) -> Option<std::time::SystemTime> {
    std::fs::metadata(path(tables, command)).ok()?.modified().ok()
}

/// The size of `path`: a file's length, a directory's files summed; `None`
/// when it is missing or cannot be read.
#[must_use]
pub fn size_of(path: &Path) -> Option<u64> {
    let meta = std::fs::metadata(path).ok()?;
    if !meta.is_dir() {
        return Some(meta.len());
    }
    let mut total = 0;
    for entry in std::fs::read_dir(path).ok()? {
        total += size_of(&entry.ok()?.path())?;
    }
    Some(total)
}

/// The outputs `paths` as a record lists them.
#[must_use]
pub fn outputs_of(paths: &[PathBuf]) -> Vec<OutputFile> {
    let mut outputs: Vec<OutputFile> =
        paths.iter().map(|p| OutputFile { path: p.display().to_string(), bytes: size_of(p).unwrap_or(0) }).collect();
    outputs.sort_by(|a, b| a.path.cmp(&b.path));
    outputs.dedup();
    outputs
}

/// What `--skip-existing` does with a task that has `record`.
#[must_use]
pub fn resume(record: Option<&Record>) -> Resume {
    match record {
        None => Resume::Run,
        Some(r) if r.state == State::Done && !r.outputs.is_empty() => {
            let intact = r.outputs.iter().all(|o| size_of(Path::new(&o.path)) == Some(o.bytes));
            if intact { Resume::Skip } else { Resume::Redo }
        }
        Some(_) => Resume::Redo,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_round_trip_and_decide_the_resume() {
        let dir = tempfile::tempdir().unwrap();
        let tables = dir.path();
        let command: Vec<String> = ["process", "mpc", "a.mcap", "-o", "t"].map(String::from).to_vec();
        assert_eq!(read(tables, &command).unwrap(), None);
        assert_eq!(resume(None), Resume::Run);

        let started = Record { command: command.clone(), state: State::Started, outputs: Vec::new() };
        write(tables, &started).unwrap();
        assert_eq!(read(tables, &command).unwrap().as_ref(), Some(&started));
        assert_eq!(resume(Some(&started)), Resume::Redo);

        let out = tables.join("out.bin");
        std::fs::write(&out, b"12345").unwrap();
        let done =
            Record { command: command.clone(), state: State::Done, outputs: outputs_of(std::slice::from_ref(&out)) };
        assert_eq!(done.outputs[0].bytes, 5);
        write(tables, &done).unwrap();
        assert_eq!(resume(read(tables, &command).unwrap().as_ref()), Resume::Skip);
        std::fs::write(&out, b"123").unwrap();
        assert_eq!(resume(Some(&done)), Resume::Redo, "an output changed size");
        std::fs::remove_file(&out).unwrap();
        assert_eq!(resume(Some(&done)), Resume::Redo, "an output gone");

        // Another command is another record; a record is removed once.
        let other: Vec<String> = ["process", "mpc", "b.mcap", "-o", "t"].map(String::from).to_vec();
        assert_ne!(path(tables, &command), path(tables, &other));
        assert_eq!(read(tables, &other).unwrap(), None);
        remove(tables, &command).unwrap();
        remove(tables, &command).unwrap();
        assert_eq!(read(tables, &command).unwrap(), None);
    }
}
