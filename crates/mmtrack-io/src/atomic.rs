//! Atomic output files: write to a temporary file beside the target, then
//! rename over it. An error or a dropped writer leaves the previous output (if
//! any) untouched and no partial file behind.
//!
//! # Partial outputs and interruptions
//!
//! A partial output is named `.<name>.<pid>.<random>.partial` beside its
//! target `<name>` (a staging directory: `<prefix><pid>.<random>.partial`),
//! where `<pid>` is the writing process. Two mechanisms keep them from piling
//! up when a run cannot clean up after itself:
//!
//! - every partial this process is writing is in a registry, and
//!   [`remove_partial_outputs`] removes them all: the CLI calls it when
//!   SIGINT, SIGTERM or SIGHUP arrives, then exits. It holds the registry
//!   until the exit, and everything that creates a partial or a directory
//!   inside one ([`create_output_dirs`]) takes the registry first, so
//!   nothing removed comes back; a command that ends meanwhile (its next
//!   write failed) waits for the exit ([`wait_for_interruption`]) instead
//!   of cutting the clean-up short;
//! - a run that starts writing `<name>` (or a staging directory with a given
//!   prefix) first removes the partials of that same name left by earlier
//!   runs that were killed outright (SIGKILL, an aborted allocation, a power
//!   cut). A partial is left alone while the process named by its `<pid>` is
//!   alive, so two runs writing the same output at once do not delete each
//!   other's work; one of this process's own pid that it is not writing is
//!   stale (an earlier process that had the same pid, as in containers).
//!   Liveness is read from `/proc`, so it holds for writers in the same PID
//!   namespace (one machine, one container); where there is no `/proc`, only
//!   partials of this process's own pid are removed. Files that do not match
//!   the pattern exactly are never touched. A process counts as gone once
//!   it has exited, also while it is still a zombie waiting to be reaped.
//!
//! # Replaced outputs moved aside
//!
//! Replacing a set of files ([`commit_all`]) or an output directory
//! ([`publish_dir`]) first renames the old output aside, to
//! `.<name>.<pid>.<random>.replaced` (a directory:
//! `<prefix><pid>.<random>.replaced`), and deletes it once the new output
//! is in place. A process killed outright between those steps leaves the
//! aside copy; readers that glob a folder recursively (DuckDB `dir/**`,
//! `pl.scan_parquet(dir)`) would read it as data. Once a later run has
//! published a new output at the same target, that output supersedes the
//! old one, and the run removes the asides of that target whose writer is
//! gone (by the same pid rule as partials). An aside is kept until then:
//! it is the only copy of the previous output while the target is missing.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

use tempfile::NamedTempFile;

use crate::error::{IoError, Result, os_err};

/// What to do when the output already exists.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Overwrite {
    /// Refuse with [`IoError::OutputExists`] (the default; `--force` changes it).
    #[default]
    Refuse,
    /// Replace the existing output atomically when the new one is complete.
    Replace,
}

/// Whether a committed file is flushed to disk before it replaces the target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Durability {
    /// `fsync` before the rename (the default): crash-safe replacement.
    #[default]
    Fsync,
    /// Leave flushing to the operating system: faster for large files; a power
    /// cut right after the rename may lose the new file's contents.
    PageCache,
}

/// A file being written that only appears at `target` on [`AtomicFile::commit`].
#[derive(Debug)]
pub struct AtomicFile {
    target: PathBuf,
    // Dropped before `registration`: the file is gone before it leaves the registry.
    temp: NamedTempFile,
    registration: Registration,
}

impl AtomicFile {
    /// Starts writing `target`: checks the overwrite policy, creates the parent
    /// directories, removes stale partials of `target` left by killed runs
    /// (see the module docs) and creates a hidden temporary file
    /// `.<name>.<pid>.<random>.partial` in the same directory (so the final
    /// rename never crosses file systems).
    pub fn create(target: &Path, overwrite: Overwrite) -> Result<Self> {
        check_output_file(target)?;
        if overwrite == Overwrite::Refuse && target.exists() {
            return Err(IoError::OutputExists { path: target.to_path_buf() });
        }
        let dir = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        create_output_dirs(&dir).map_err(os_err(&dir))?;
        let file_name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let prefix = format!(".{file_name}.");
        // Registered under the lock it was created under: an interruption
        // either finds it in the registry or stops this before it exists.
        let mut live = live_partials();
        remove_stale_partials(&dir, &prefix, &live);
        let temp = with_default_mode(&mut tempfile::Builder::new(), 0o666)
            .prefix(&format!("{prefix}{}.", std::process::id()))
            .suffix(PARTIAL_SUFFIX)
            .tempfile_in(&dir)
            .map_err(os_err(&dir))?;
        live.insert(temp.path().to_path_buf(), PartialKind::File);
        drop(live);
        let registration = Registration(temp.path().to_path_buf());
        Ok(Self { target: target.to_path_buf(), temp, registration })
    }

    /// The final path.
    #[must_use]
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// A second handle on the temporary file, for writers that take ownership.
    pub fn writer(&self) -> Result<BufWriter<File>> {
        let file = self.temp.reopen().map_err(os_err(self.temp.path()))?;
        Ok(BufWriter::with_capacity(1 << 20, file))
    }

    /// Makes the file visible at its target, replacing what was there. Re-checks
    /// the overwrite policy, since another process may have created the target
    /// while this one was writing. With [`Durability::Fsync`] the data reaches
    /// the disk before the rename, so a power cut cannot leave an empty file
    /// in place of the old one. One file of [`commit_all`].
    pub fn commit(self, overwrite: Overwrite, durability: Durability) -> Result<PathBuf> {
        let target = self.target.clone();
        commit_all(vec![self], overwrite, durability)?;
        Ok(target)
    }
}

/// Writes `contents` to `target` atomically ([`AtomicFile`], synced before
/// the rename): a small output written whole (a text report, a manifest, a
/// task record).
///
/// # Errors
/// As [`AtomicFile::create`] and [`AtomicFile::commit`], or the OS error
/// of writing, naming `target`.
pub fn write_file(target: &Path, contents: &[u8], overwrite: Overwrite) -> Result<PathBuf> {
    use std::io::Write as _;
    let file = AtomicFile::create(target, overwrite)?;
    let mut writer = file.writer()?;
    writer.write_all(contents).and_then(|()| writer.flush()).map_err(os_err(target))?;
    drop(writer);
    file.commit(overwrite, Durability::Fsync)
}

/// Makes `files` visible at their targets together: either all of them are
/// published or, on an error, none (a target published before the error is
/// removed again, or the file it replaced is put back). Each is synced first
/// (with [`Durability::Fsync`]); no rename starts before every file is
/// complete, so a full disk while writing never publishes part of the set.
///
/// The renames run while holding the registry of partial outputs, so an
/// interruption ([`remove_partial_outputs`]) finds either the whole set
/// still partial (and removes it) or the whole set published. With
/// [`Overwrite::Replace`], an existing target of every file but the last is
/// first renamed aside (`.<name>.<pid>.<random>.replaced`), so it can be put
/// back if a later rename fails, and is deleted once the set is in place: a
/// reader may see that table missing for the instant between the two
/// renames. A process killed outright in that instant leaves the aside file;
/// the next run that publishes the same target removes it then (see the
/// module docs).
///
/// # Errors
/// [`IoError::OutputExists`] for a target that appeared meanwhile (with
/// [`Overwrite::Refuse`]), or the OS error of a sync or rename; nothing of
/// the set is published then.
pub fn commit_all(files: Vec<AtomicFile>, overwrite: Overwrite, durability: Durability) -> Result<Vec<PathBuf>> {
    if durability == Durability::Fsync {
        for file in &files {
            file.temp.as_file().sync_all().map_err(os_err(file.temp.path()))?;
        }
    }
    let last = files.len().saturating_sub(1);
    // The registrations are dropped only after the registry lock below is
    // released (their drop takes it).
    let (mut registrations, mut pending) = (Vec::with_capacity(files.len()), Vec::with_capacity(files.len()));
    for AtomicFile { target, temp, registration } in files {
        registrations.push(registration);
        pending.push((target, temp));
    }
    let live = live_partials();
    let mut published: Vec<(PathBuf, Option<PathBuf>)> = Vec::with_capacity(pending.len());
    let mut failure = None;
    for (i, (target, temp)) in pending.into_iter().enumerate() {
        match publish_one(temp, &target, overwrite, i < last) {
            Ok(aside) => published.push((target, aside)),
            Err(e) => {
                failure = Some(e);
                break;
            }
        }
    }
    if let Some(error) = failure {
        // Newest first, so a target is restored before anything older.
        for (target, aside) in published.iter().rev() {
            let _ = std::fs::remove_file(target);
            if let Some(aside) = aside {
                let _ = std::fs::rename(aside, target);
            }
        }
        drop(live);
        return Err(error);
    }
    for aside in published.iter().filter_map(|(_, aside)| aside.as_ref()) {
        // Best effort: a leftover is a hidden copy of the replaced output.
        let _ = std::fs::remove_file(aside);
    }
    remove_stale_asides_of(published.iter().map(|(target, _)| target.as_path()), &live);
    drop(live);
    drop(registrations);
    Ok(published.into_iter().map(|(target, _)| target).collect())
}

/// Renames `temp` to `target` under `overwrite`; with `keep_old` and
/// [`Overwrite::Replace`], an existing target file is first renamed aside
/// and that path returned.
fn publish_one(temp: NamedTempFile, target: &Path, overwrite: Overwrite, keep_old: bool) -> Result<Option<PathBuf>> {
    let os = |source: std::io::Error| IoError::Os { path: target.to_path_buf(), source };
    match overwrite {
        Overwrite::Replace => {
            // Re-checked: a directory, FIFO or device node may have appeared meanwhile.
            check_output_file(target)?;
            let is_file = std::fs::symlink_metadata(target).is_ok_and(|m| !m.is_dir());
            let aside = (keep_old && is_file).then(|| {
                let partial = temp.path().file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
                let stem = partial.strip_suffix(PARTIAL_SUFFIX).unwrap_or(&partial);
                temp.path().with_file_name(format!("{stem}{REPLACED_SUFFIX}"))
            });
            if let Some(aside) = &aside {
                std::fs::rename(target, aside).map_err(os)?;
            }
            if let Err(e) = temp.persist(target) {
                if let Some(aside) = &aside {
                    let _ = std::fs::rename(aside, target);
                }
                return Err(os(e.error));
            }
            Ok(aside)
        }
        Overwrite::Refuse => {
            temp.persist_noclobber(target).map_err(|e| {
                if e.error.kind() == std::io::ErrorKind::AlreadyExists {
                    IoError::OutputExists { path: target.to_path_buf() }
                } else {
                    os(e.error)
                }
            })?;
            Ok(None)
        }
    }
}

/// A staging directory beside an output directory (`parent`), renamed over
/// it when complete. Created with the mode `create_dir` gives (0777 less the
/// umask), not the private 0700 of temporary directories, so the published
/// output is readable as any other.
///
/// # Errors
/// The OS error of creating it.
///
/// Named `<prefix><pid>.<random>.partial`; stale ones of the same prefix
/// left by killed runs are removed first, and the directory is removed by
/// [`remove_partial_outputs`] while it exists (see the module docs).
pub fn staging_dir(parent: &Path, prefix: &str) -> std::io::Result<tempfile::TempDir> {
    let mut live = live_partials();
    // Staging directories are renamed into place (or dropped) by their
    // callers; forget those that are gone.
    live.retain(|path, kind| *kind == PartialKind::File || path.exists());
    remove_stale_partials(parent, prefix, &live);
    let dir = with_default_mode(&mut tempfile::Builder::new(), 0o777)
        .prefix(&format!("{prefix}{}.", std::process::id()))
        .suffix(PARTIAL_SUFFIX)
        .tempdir_in(parent)?;
    live.insert(dir.path().to_path_buf(), PartialKind::Directory);
    Ok(dir)
}

/// Moves the complete staging directory `staged` (from [`staging_dir`],
/// beside `out`) to `out`, replacing an existing `out`: that one is first
/// renamed aside (`<staging name>.replaced`, so a later run never mistakes
/// it for a partial), put back if the second rename fails, and deleted once
/// the new one is in place. The renames run while holding the registry of
/// partial outputs, so an interruption ([`remove_partial_outputs`]) finds
/// the staging directory still partial (and removes it, `out` untouched) or
/// the new `out` in place, never `out` missing with the old results hidden
/// aside. The caller checks first that `out` may be replaced
/// ([`check_replaceable_dir`]).
///
/// # Errors
/// The OS error of a rename (nothing changed then), or of deleting the old
/// copy after the new one is in place (the error names the copy left).
pub fn publish_dir(staged: &Path, out: &Path) -> Result<()> {
    let name = staged.file_name().and_then(|n| n.to_str()).unwrap_or_default();
    // The staging prefix: the name before `<pid>.<random>.partial`.
    let prefix = name
        .strip_suffix(PARTIAL_SUFFIX)
        .and_then(|stem| stem.rsplit_once('.'))
        .map(|(head, _random)| head.trim_end_matches(|c: char| c.is_ascii_digit()).to_string())
        .filter(|prefix| prefix.len() > 1);
    let aside = swap_dir_into_place(staged, out)?;
    if let (Some(prefix), Some(parent)) = (prefix, out.parent()) {
        // The new output is in place: asides of killed runs are superseded.
        let parent = if parent.as_os_str().is_empty() { Path::new(".") } else { parent };
        let live = live_partials();
        remove_stale(parent, &[prefix.as_str()], REPLACED_SUFFIX, &live);
    }
    match aside {
        Some(aside) => aside.remove(),
        None => Ok(()),
    }
}

/// The old output moved aside by [`publish_dir`], registered as a partial
/// output until it is removed: an interruption while it is being deleted
/// removes the rest of it ([`remove_partial_outputs`]).
#[derive(Debug)]
struct ReplacedDir(PathBuf);

impl ReplacedDir {
    fn remove(self) -> Result<()> {
        std::fs::remove_dir_all(&self.0).map_err(os_err(&self.0))
    }
}

impl Drop for ReplacedDir {
    fn drop(&mut self) {
        live_partials().remove(&self.0);
    }
}

/// The renames of [`publish_dir`], under the registry lock; the old output,
/// if any, is returned registered.
fn swap_dir_into_place(staged: &Path, out: &Path) -> Result<Option<ReplacedDir>> {
    let mut live = live_partials();
    if std::fs::symlink_metadata(out).is_err() {
        return std::fs::rename(staged, out).map(|()| None).map_err(os_err(out));
    }
    let name = staged.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let stem = name.strip_suffix(PARTIAL_SUFFIX).unwrap_or(&name);
    let aside = staged.with_file_name(format!("{stem}{REPLACED_SUFFIX}"));
    std::fs::rename(out, &aside).map_err(os_err(out))?;
    if let Err(e) = std::fs::rename(staged, out) {
        let _ = std::fs::rename(&aside, out);
        return Err(IoError::Os { path: out.to_path_buf(), source: e });
    }
    live.insert(aside.clone(), PartialKind::Directory);
    Ok(Some(ReplacedDir(aside)))
}

/// Creates `dir` and its missing parents (as `create_dir_all`) for an
/// output, holding the registry of partial outputs: never while an
/// interruption is removing them ([`remove_partial_outputs`] holds the
/// registry until the process exits), so a writer cannot bring back a
/// staging directory the interruption just removed. Use it for every
/// directory made inside a staging directory.
///
/// # Errors
/// The OS error of creating it.
pub fn create_output_dirs(dir: &Path) -> std::io::Result<()> {
    let _live = live_partials();
    std::fs::create_dir_all(dir)
}

/// Waits while an interruption is being handled ([`remove_partial_outputs`]
/// holds the registry until the process exits), for a command that ends
/// meanwhile: it must not exit, with the error of a file the clean-up just
/// removed, before the clean-up is done. Returns at once otherwise.
pub fn wait_for_interruption() {
    drop(live_partials());
}

/// Checks, before any work, that the directory `dir` may be written by
/// `command`: absent or empty; or, with [`Overwrite::Replace`], holding only entries
/// `command` writes itself (`owns(relative path, is_dir)`, asked for each
/// entry, and for the entries of every directory it owns). A directory
/// holding anything else is never replaced ([`IoError::ForeignEntries`],
/// naming them), so a mistyped `-o --force` cannot delete unrelated files.
///
/// # Errors
/// [`IoError::OutputExists`] (an existing `dir` without `Replace`),
/// [`IoError::ForeignEntries`], [`IoError::NotADirectory`], or an
/// unreadable directory.
pub fn check_replaceable_dir(
    dir: &Path,
    command: &str,
    owns: &dyn Fn(&Path, bool) -> bool,
    overwrite: Overwrite,
) -> Result<()> {
    check_output_dir(dir)?;
    if !dir.exists() {
        return Ok(());
    }
    let mut foreign = Vec::new();
    let mut any = false;
    let mut pending = vec![PathBuf::new()];
    while let Some(relative) = pending.pop() {
        let listed = dir.join(&relative);
        for entry in std::fs::read_dir(&listed).map_err(os_err(&listed))? {
            let entry = entry.map_err(os_err(&listed))?;
            any = true;
            let name = relative.join(entry.file_name());
            let is_dir = entry.file_type().map_err(os_err(&listed))?.is_dir();
            if !owns(&name, is_dir) {
                foreign.push(name.to_string_lossy().into_owned());
            } else if is_dir {
                pending.push(name);
            }
        }
    }
    if !foreign.is_empty() {
        foreign.sort();
        return Err(IoError::ForeignEntries {
            path: dir.to_path_buf(),
            command: command.to_string(),
            entries: foreign,
        });
    }
    if any && overwrite == Overwrite::Refuse {
        return Err(IoError::OutputExists { path: dir.to_path_buf() });
    }
    Ok(())
}

/// Checks that the output file `target` can be replaced by renaming a new
/// file over it: absent, or a regular file (a symbolic link is followed:
/// one to a regular file is replaced by the new file, one to anything else
/// is refused), and its nearest existing ancestor a directory. Every file
/// output goes through [`AtomicFile::create`], which calls this with or
/// without [`Overwrite::Replace`], so no command's `--force` replaces a
/// directory, a FIFO or a device node.
///
/// # Errors
/// [`IoError::NotARegularFile`] naming what `target` is, or
/// [`IoError::NotADirectory`] for an ancestor that is not a directory.
pub fn check_output_file(target: &Path) -> Result<()> {
    match std::fs::metadata(target) {
        Ok(meta) if meta.is_file() => Ok(()),
        Ok(meta) => Err(IoError::NotARegularFile { path: target.to_path_buf(), kind: kind_in_words(meta.file_type()) }),
        // Absent (or a dangling link, replaced as before): the parent must be a directory.
        Err(_) => target.parent().map_or(Ok(()), check_output_dir),
    }
}

/// Checks that the output directory `dir` is absent or a directory (a
/// symbolic link is followed), and that its nearest existing ancestor is a
/// directory, so it can be created or replaced.
///
/// # Errors
/// [`IoError::NotADirectory`] naming the path in the way and what it is.
pub fn check_output_dir(dir: &Path) -> Result<()> {
    for ancestor in dir.ancestors().take_while(|a| !a.as_os_str().is_empty()) {
        match std::fs::metadata(ancestor) {
            Ok(meta) if meta.is_dir() => return Ok(()),
            Ok(meta) => {
                return Err(IoError::NotADirectory {
                    path: ancestor.to_path_buf(),
                    kind: kind_in_words(meta.file_type()),
                });
            }
            Err(_) => {}
        }
    }
    Ok(())
}

/// Refuses an `output` that is the same file or directory as one of
/// `inputs` (compared after resolving links and `..`), before any work: a
/// replaced input would be lost, and a folder input cannot be a file output.
///
/// # Errors
/// [`IoError::OutputIsInput`] naming both.
pub fn check_output_is_not_input(output: &Path, inputs: &[&Path]) -> Result<()> {
    let Ok(resolved) = std::fs::canonicalize(output) else { return Ok(()) };
    for input in inputs {
        if std::fs::canonicalize(input).is_ok_and(|i| i == resolved) {
            return Err(IoError::OutputIsInput { path: output.to_path_buf(), input: input.to_path_buf() });
        }
    }
    Ok(())
}

/// What a file type is, in words with an article, for error messages.
fn kind_in_words(file_type: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return "a FIFO";
        }
        if file_type.is_char_device() {
            return "a character device";
        }
        if file_type.is_block_device() {
            return "a block device";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    if file_type.is_dir() {
        "a directory"
    } else if file_type.is_file() {
        "a regular file"
    } else if file_type.is_symlink() {
        "a symbolic link"
    } else {
        "neither a regular file nor a directory"
    }
}

/// The end of every partial output's name.
const PARTIAL_SUFFIX: &str = ".partial";

/// The end of the name of an output moved aside by [`commit_all`] until its
/// replacement's set is in place, or by [`publish_dir`] until it is deleted.
const REPLACED_SUFFIX: &str = ".replaced";

/// What a registered partial output is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PartialKind {
    File,
    Directory,
    /// A directory this process created for outputs it has not published:
    /// removed on an interruption when it is empty once the partials are.
    CreatedDirectory,
}

/// Registers `dir`, a directory this process just created for outputs not
/// yet published, so that an interruption ([`remove_partial_outputs`])
/// removes it if it is empty by then (the partial files in it go first).
/// Dropping the result takes it out of the registry (the outputs were
/// published, or the writer removed the directory itself).
pub fn register_created_dir(dir: &Path) -> CreatedDirRegistration {
    live_partials().insert(dir.to_path_buf(), PartialKind::CreatedDirectory);
    CreatedDirRegistration { registration: Registration(dir.to_path_buf()) }
}

/// Keeps a directory in the registry of [`register_created_dir`] until dropped.
#[derive(Debug)]
pub struct CreatedDirRegistration {
    registration: Registration,
}

impl CreatedDirRegistration {
    /// The directory.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.registration.0
    }
}

/// The partial outputs this process is writing.
static LIVE_PARTIALS: Mutex<BTreeMap<PathBuf, PartialKind>> = Mutex::new(BTreeMap::new());

/// The registry, also after a panic elsewhere (it holds plain paths).
fn live_partials() -> MutexGuard<'static, BTreeMap<PathBuf, PartialKind>> {
    LIVE_PARTIALS.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Takes an [`AtomicFile`]'s partial out of the registry when it is committed
/// or dropped.
#[derive(Debug)]
struct Registration(PathBuf);

impl Drop for Registration {
    fn drop(&mut self) {
        live_partials().remove(&self.0);
    }
}

/// What [`remove_partial_outputs`] did; holds the registry until dropped.
#[must_use = "drop it only after the process has decided to exit"]
pub struct PartialOutputsRemoved {
    /// How many partial files and staging directories were removed.
    pub removed: usize,
    /// Partials that could not be removed, with the reason.
    pub failed: Vec<(PathBuf, std::io::Error)>,
    _registry: MutexGuard<'static, BTreeMap<PathBuf, PartialKind>>,
}

/// Removes every partial output this process is writing, for a process that
/// is being interrupted (SIGINT, SIGTERM). The result keeps the registry
/// locked, so no new partial output can start (its writer waits) while the
/// caller exits: keep it alive until `std::process::exit`.
pub fn remove_partial_outputs() -> PartialOutputsRemoved {
    let registry = live_partials();
    let mut removed = 0;
    let mut failed = Vec::new();
    for (path, kind) in registry.iter() {
        let result = match kind {
            PartialKind::File => std::fs::remove_file(path),
            PartialKind::Directory => remove_directory_being_written(path),
            PartialKind::CreatedDirectory => continue,
        };
        match result {
            Ok(()) => removed += 1,
            // Committed, or dropped, in the meantime.
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => failed.push((path.clone(), e)),
        }
    }
    // Then the directories created for them, innermost first (path order
    // puts a directory before what is inside it); only empty ones go, so
    // nothing another writer put there is touched.
    for (path, _) in registry.iter().rev().filter(|(_, kind)| **kind == PartialKind::CreatedDirectory) {
        let _ = std::fs::remove_dir(path);
    }
    PartialOutputsRemoved { removed, failed, _registry: registry }
}

/// Removes a staging directory another thread may still be writing into by
/// path: first renamed to a sibling of the same pattern (the writer's next
/// file then fails instead of refilling it, and a later run still removes
/// it if this fails), then removed, retried while a file that was already
/// open lands in it.
fn remove_directory_being_written(path: &Path) -> std::io::Result<()> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let moved = [PARTIAL_SUFFIX, REPLACED_SUFFIX]
        .iter()
        .find_map(|suffix| name.strip_suffix(suffix).map(|stem| path.with_file_name(format!("{stem}x{suffix}"))))
        .filter(|moved| std::fs::rename(path, moved).is_ok());
    let target = moved.as_deref().unwrap_or(path);
    let mut attempts = 0;
    loop {
        match std::fs::remove_dir_all(target) {
            // Another thread adding files, or deleting them (an old output
            // being removed by `publish_dir`) as this walks the tree.
            Err(e)
                if (e.kind() == std::io::ErrorKind::DirectoryNotEmpty
                    || (e.kind() == std::io::ErrorKind::NotFound && target.exists()))
                    && attempts < 100 =>
            {
                attempts += 1;
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
            result => return result,
        }
    }
}

/// Removes the partial outputs in `dir` named `<prefix><pid>.<random>.partial`
/// whose writer is gone: the process `<pid>` is not running, or it is this
/// process and `live` (this process's registry) does not hold it. Best
/// effort: what cannot be read or removed is left. Returns how many went.
fn remove_stale_partials(dir: &Path, prefix: &str, live: &BTreeMap<PathBuf, PartialKind>) -> usize {
    remove_stale(dir, &[prefix], PARTIAL_SUFFIX, live)
}

/// Removes the asides `.<name>.<pid>.<random>.replaced` of `targets` (just
/// published, so superseded) whose writer is gone, by the rule of
/// [`remove_stale_partials`]; one directory listing per parent directory.
/// Called with the registry held, so no commit of this process is between
/// its two renames.
fn remove_stale_asides_of<'t>(targets: impl Iterator<Item = &'t Path>, live: &BTreeMap<PathBuf, PartialKind>) -> usize {
    let mut prefixes_by_dir: BTreeMap<PathBuf, Vec<String>> = BTreeMap::new();
    for target in targets {
        let Some(name) = target.file_name().and_then(|n| n.to_str()) else { continue };
        let dir = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        prefixes_by_dir.entry(dir).or_default().push(format!(".{name}."));
    }
    prefixes_by_dir
        .iter()
        .map(|(dir, prefixes)| {
            let prefixes: Vec<&str> = prefixes.iter().map(String::as_str).collect();
            remove_stale(dir, &prefixes, REPLACED_SUFFIX, live)
        })
        .sum()
}

/// Removes the entries of `dir` named `<prefix><pid>.<random><suffix>`, for
/// any of `prefixes`, whose writer is gone (see [`remove_stale_partials`]).
fn remove_stale(dir: &Path, prefixes: &[&str], suffix: &str, live: &BTreeMap<PathBuf, PartialKind>) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else { return 0 };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(|n| prefixes.iter().find_map(|p| writer_pid(n, p, suffix))) else {
            continue;
        };
        let path = entry.path();
        // By name: the registry holds the paths as created (tempfile makes
        // them absolute), `path` is as listed under `dir` (maybe relative);
        // the pid and random part make a partial's name unique.
        let is_live = live.keys().any(|p| p.file_name() == Some(name.as_os_str()));
        if is_live || (pid != std::process::id() && process_may_be_running(pid)) {
            continue;
        }
        let result = match entry.file_type() {
            Ok(t) if t.is_file() => std::fs::remove_file(&path),
            Ok(t) if t.is_dir() => std::fs::remove_dir_all(&path),
            _ => continue,
        };
        if result.is_ok() {
            removed += 1;
        }
    }
    removed
}

/// The writer's pid of a partial output named `<prefix><pid>.<random>.partial`
/// (`<random>`: ASCII letters and digits), `None` for any other name.
#[cfg(test)]
fn partial_writer_pid(name: &str, prefix: &str) -> Option<u32> {
    writer_pid(name, prefix, PARTIAL_SUFFIX)
}

/// The writer's pid of a name `<prefix><pid>.<random><suffix>` (`<random>`:
/// ASCII letters and digits), `None` for any other name.
fn writer_pid(name: &str, prefix: &str, suffix: &str) -> Option<u32> {
    let middle = name.strip_prefix(prefix)?.strip_suffix(suffix)?;
    let (pid, random) = middle.split_once('.')?;
    let all_digits = !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit());
    let random_ok = !random.is_empty() && random.bytes().all(|b| b.is_ascii_alphanumeric());
    if all_digits && random_ok { pid.parse().ok() } else { None }
}

/// Whether process `pid` may be running: `/proc/<pid>` exists and its state
/// (`/proc/<pid>/stat`, the field after the command name) is not zombie
/// (`Z`) or dead (`X`), or there is no `/proc` to tell (then every other
/// process is assumed alive). A zombie has exited and writes nothing; its
/// parent may reap it late.
fn process_may_be_running(pid: u32) -> bool {
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return true;
    }
    let dir = proc.join(pid.to_string());
    if !dir.exists() {
        return false;
    }
    match std::fs::read_to_string(dir.join("stat")) {
        // `<pid> (<comm>) <state> ...`; the command name may hold ')'.
        Ok(stat) => {
            !matches!(stat.rsplit_once(')').and_then(|(_, rest)| rest.trim_start().chars().next()), Some('Z' | 'X'))
        }
        Err(_) => true,
    }
}

/// Asks for `mode` less the umask, as `File::create` (0666) and `create_dir`
/// (0777) do, instead of tempfile's private 0600/0700: temporary outputs are
/// renamed into place and keep their mode.
fn with_default_mode<'b, 'p, 's>(
    builder: &'b mut tempfile::Builder<'p, 's>,
    mode: u32,
) -> &'b mut tempfile::Builder<'p, 's> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(mode))
    }
    #[cfg(not(unix))]
    {
        let _ = mode;
        builder
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// Outputs get the mode of any new file or directory (umask applied),
    /// not the temporary file's 0600 / 0700.
    #[cfg(unix)]
    #[test]
    fn published_outputs_have_the_usual_mode() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        let plain = dir.path().join("plain");
        std::fs::write(&plain, b"x").unwrap();
        let target = dir.path().join("out.bin");
        let f = AtomicFile::create(&target, Overwrite::Refuse).unwrap();
        f.commit(Overwrite::Refuse, Durability::PageCache).unwrap();
        assert_eq!(mode(&target), mode(&plain));
        let plain_dir = dir.path().join("plain-dir");
        std::fs::create_dir(&plain_dir).unwrap();
        let staged = staging_dir(dir.path(), ".x.").unwrap();
        assert_eq!(mode(staged.path()), mode(&plain_dir));
    }

    #[test]
    fn dropped_file_leaves_nothing_and_commit_publishes() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("sub/out.bin");
        {
            let f = AtomicFile::create(&target, Overwrite::Refuse).unwrap();
            f.writer().unwrap().write_all(b"half").unwrap();
        }
        assert!(!target.exists());
        assert_eq!(std::fs::read_dir(dir.path().join("sub")).unwrap().count(), 0);

        let f = AtomicFile::create(&target, Overwrite::Refuse).unwrap();
        let mut w = f.writer().unwrap();
        w.write_all(b"whole").unwrap();
        w.flush().unwrap();
        drop(w);
        f.commit(Overwrite::Refuse, Durability::Fsync).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"whole");
    }

    #[test]
    fn partial_names_carry_the_writer_pid() {
        let prefix = ".out.mcap.";
        assert_eq!(partial_writer_pid(".out.mcap.123.AbC9x1.partial", prefix), Some(123));
        for other in [
            ".out.mcap.AbC9x1.partial",       // no pid (older mmtrack): not ours to judge
            ".out.mcap.1.123.abc.partial",    // `.out.mcap.1`'s partial
            ".out.mcap.12x.abc.partial",      // not a pid
            ".out.mcap.123..partial",         // no random part
            ".out.mcap.123.abc.partial.keep", // not a partial
            ".other.mcap.123.abc.partial",    // another output's
        ] {
            assert_eq!(partial_writer_pid(other, prefix), None, "{other}");
        }
    }

    /// Partials of killed runs are removed when the next run starts writing
    /// the same output; those of running writers and other names stay.
    #[test]
    fn stale_partials_of_the_same_output_are_removed_by_the_next_run() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.bin");
        let plant = |name: &str| {
            let path = dir.path().join(name);
            std::fs::write(&path, b"partial").unwrap();
            path
        };
        // No process has pid u32::MAX (Linux pids stop at 2^22).
        let dead_writer = plant(&format!(".out.bin.{}.AbC123.partial", u32::MAX));
        // This process's pid, not in its registry: an earlier process's.
        let earlier_same_pid = plant(&format!(".out.bin.{}.xyz789.partial", std::process::id()));
        let staged_dir = dir.path().join(format!(".out.bin.{}.dir001.partial", u32::MAX));
        std::fs::create_dir(&staged_dir).unwrap();
        std::fs::write(staged_dir.join("inner"), b"x").unwrap();
        // Pid 1 is always running: a concurrent writer's.
        let running_writer = plant(".out.bin.1.QQQ111.partial");
        let others = [plant(".out.bin.AbC123.partial"), plant(".other.bin.99999999.abc.partial"), plant("notes.txt")];

        let first = AtomicFile::create(&target, Overwrite::Refuse).unwrap();
        assert!(!dead_writer.exists() && !earlier_same_pid.exists() && !staged_dir.exists());
        assert!(running_writer.exists() && others.iter().all(|p| p.exists()));
        let first_partial = first.temp.path().to_path_buf();
        assert!(partial_writer_pid(&first_partial.file_name().unwrap().to_string_lossy(), ".out.bin.").is_some());

        // A second writer of the same output in this process keeps the first's partial.
        let second = AtomicFile::create(&target, Overwrite::Replace).unwrap();
        assert!(first_partial.exists());
        drop(second);
        first.commit(Overwrite::Refuse, Durability::PageCache).unwrap();
        assert!(!first_partial.exists() && target.exists());
    }

    /// Before: a process killed between the two renames of `commit_all`
    /// left `.<name>.<pid>.<random>.replaced` for good, and readers globbing
    /// the folder read it as data. Now the next run that publishes the same
    /// target removes the asides of dead writers, and only those: not before
    /// its own output is in place, not a running writer's, not other names.
    #[test]
    fn asides_of_killed_runs_are_removed_once_the_target_is_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let plant = |name: &str| {
            let path = dir.path().join(name);
            std::fs::write(&path, b"old copy").unwrap();
            path
        };
        // No process has pid u32::MAX (Linux pids stop at 2^22); pid 1 always runs.
        let dead = [plant(&format!(".a.{}.AbC123.replaced", u32::MAX)), plant(&format!(".b.{}.x9.replaced", u32::MAX))];
        let earlier_same_pid = plant(&format!(".a.{}.QwE456.replaced", std::process::id()));
        let kept = [
            plant(".a.1.QQQ111.replaced"),                          // a running writer's
            plant(".a.AbC123.replaced"),                            // no pid: not our pattern
            plant(&format!(".c.{}.AbC123.replaced", u32::MAX)),     // another target's
            plant(&format!(".a.{}.AbC123.replaced.bak", u32::MAX)), // not an aside
            plant("notes.txt"),
        ];
        std::fs::write(dir.path().join("a"), b"old a").unwrap();
        let staged = |name: &str| {
            let f = AtomicFile::create(&dir.path().join(name), Overwrite::Replace).unwrap();
            f.writer().unwrap().write_all(b"new").unwrap();
            f
        };
        let set = vec![staged("a"), staged("b")];
        assert!(dead.iter().all(|p| p.exists()), "kept while the old output may be the only copy");
        commit_all(set, Overwrite::Replace, Durability::PageCache).unwrap();
        assert!(dead.iter().all(|p| !p.exists()) && !earlier_same_pid.exists());
        assert!(kept.iter().all(|p| p.exists()));
        assert_eq!(std::fs::read(dir.path().join("a")).unwrap(), b"new");

        // The same for an output directory replaced by `publish_dir`.
        let out = dir.path().join("results");
        std::fs::create_dir(&out).unwrap();
        let dead_dir = dir.path().join(format!(".results.{}.dir001.replaced", u32::MAX));
        std::fs::create_dir(&dead_dir).unwrap();
        std::fs::write(dead_dir.join("old.txt"), b"old").unwrap();
        let running_dir = dir.path().join(".results.1.dir002.replaced");
        std::fs::create_dir(&running_dir).unwrap();
        let staged_dir = staging_dir(dir.path(), ".results.").unwrap().keep();
        publish_dir(&staged_dir, &out).unwrap();
        assert!(!dead_dir.exists() && running_dir.exists() && out.exists());
        // A staging prefix not ending in '.' (`.simulate-`): its own asides only.
        let sim = dir.path().join("sim");
        let dead_sim = dir.path().join(format!(".simulate-{}.dir003.replaced", u32::MAX));
        let not_ours = dir.path().join(format!(".{}.dir004.replaced", u32::MAX));
        for d in [&sim, &dead_sim, &not_ours] {
            std::fs::create_dir(d).unwrap();
        }
        publish_dir(&staging_dir(dir.path(), ".simulate-").unwrap().keep(), &sim).unwrap();
        assert!(!dead_sim.exists() && not_ours.exists());
    }

    /// A zombie (exited, not yet reaped) writes nothing: its partials are stale.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_zombie_process_is_not_running() {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        // Not reaped until `wait`: a zombie once it has exited.
        let mut zombie = false;
        for _ in 0..500 {
            let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
            if stat.rsplit_once(')').unwrap().1.trim_start().starts_with('Z') {
                zombie = true;
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        assert!(zombie, "`true` exited within 5 s");
        assert!(!process_may_be_running(pid));
        assert!(process_may_be_running(std::process::id()));
        child.wait().unwrap();
    }

    /// Before: the old output `publish_dir` moved aside was not in the
    /// registry, so an interruption while it was being deleted left it. Now
    /// it is registered from the rename until it is gone.
    #[test]
    fn an_old_output_moved_aside_is_a_registered_partial_until_removed() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("old.txt"), b"old").unwrap();
        let staged = staging_dir(dir.path(), ".results.").unwrap().keep();
        std::fs::write(staged.join("new.txt"), b"new").unwrap();
        let aside = swap_dir_into_place(&staged, &out).unwrap().unwrap();
        assert_eq!(std::fs::read(out.join("new.txt")).unwrap(), b"new");
        assert_eq!(std::fs::read(aside.0.join("old.txt")).unwrap(), b"old");
        assert!(aside.0.file_name().unwrap().to_string_lossy().ends_with(REPLACED_SUFFIX));
        assert_eq!(live_partials().get(&aside.0), Some(&PartialKind::Directory));
        let path = aside.0.clone();
        aside.remove().unwrap();
        assert!(!path.exists() && !live_partials().contains_key(&path));
        // Into a place that is free: nothing moved aside.
        let staged = staging_dir(dir.path(), ".other.").unwrap().keep();
        assert!(swap_dir_into_place(&staged, &dir.path().join("other")).unwrap().is_none());
    }

    /// Issue 26: a set of files is published whole or not at all; a rename
    /// failing half-way puts back the files already replaced.
    #[test]
    fn a_set_that_fails_to_publish_leaves_the_old_files() {
        let dir = tempfile::tempdir().unwrap();
        let staged = |name: &str, text: &[u8]| {
            let f = AtomicFile::create(&dir.path().join(name), Overwrite::Replace).unwrap();
            let mut w = f.writer().unwrap();
            w.write_all(text).unwrap();
            w.flush().unwrap();
            f
        };
        std::fs::write(dir.path().join("a"), b"old a").unwrap();
        let set = vec![staged("a", b"new a"), staged("b", b"new b"), staged("c", b"new c")];
        // A directory appears where the last file goes while the set is written: its publication fails.
        std::fs::create_dir_all(dir.path().join("c/inner")).unwrap();
        assert!(commit_all(set, Overwrite::Replace, Durability::PageCache).is_err());
        let mut left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, ["a", "c"], "no partial, aside or new file left");
        assert_eq!(std::fs::read(dir.path().join("a")).unwrap(), b"old a");

        std::fs::remove_dir_all(dir.path().join("c")).unwrap();
        let set = vec![staged("a", b"new a"), staged("b", b"new b"), staged("c", b"new c")];
        commit_all(set, Overwrite::Replace, Durability::PageCache).unwrap();
        for name in ["a", "b", "c"] {
            assert_eq!(std::fs::read(dir.path().join(name)).unwrap(), format!("new {name}").as_bytes());
        }
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3, "the aside copy of a is gone");
        assert!(live_partials().keys().all(|p| !p.starts_with(dir.path())), "the set left the registry");
    }

    /// Before: `--force` renamed the new file over whatever was at the
    /// target (a FIFO, a device node became a regular file), and a directory
    /// failed only at the final rename, after all the work. Now neither is
    /// started, with or without `Replace`. A FIFO stands in for a device node
    /// (never touch real ones in /dev).
    #[cfg(unix)]
    #[test]
    fn a_target_that_is_not_a_regular_file_is_refused_up_front() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(made.success());
        let folder = dir.path().join("folder");
        std::fs::create_dir(&folder).unwrap();
        for overwrite in [Overwrite::Refuse, Overwrite::Replace] {
            for (target, kind) in [(&fifo, "a FIFO"), (&folder, "a directory")] {
                let error = AtomicFile::create(target, overwrite).unwrap_err();
                assert!(matches!(error, IoError::NotARegularFile { kind: k, .. } if k == kind), "{error}");
                assert!(error.to_string().contains("not a regular file"), "{error}");
            }
            // An output inside the FIFO, and an output folder that is the FIFO.
            let inside = AtomicFile::create(&fifo.join("t/part-0.parquet"), overwrite).unwrap_err();
            assert!(matches!(inside, IoError::NotADirectory { kind: "a FIFO", .. }), "{inside}");
            let owns = |_: &Path, _: bool| true;
            let as_dir = check_replaceable_dir(&fifo, "mmtrack x", &owns, overwrite).unwrap_err();
            assert!(matches!(as_dir, IoError::NotADirectory { kind: "a FIFO", .. }), "{as_dir}");
        }
        let metadata = std::fs::symlink_metadata(&fifo).unwrap();
        assert!(!metadata.is_file() && !metadata.is_dir(), "the FIFO is still there");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2, "no partial left");
        // The same check at the rename: a FIFO that appears while writing.
        let late = dir.path().join("late");
        let file = AtomicFile::create(&late, Overwrite::Replace).unwrap();
        assert!(std::process::Command::new("mkfifo").arg(&late).status().unwrap().success());
        let error = file.commit(Overwrite::Replace, Durability::PageCache).unwrap_err();
        assert!(matches!(error, IoError::NotARegularFile { .. }), "{error}");
        assert!(!std::fs::symlink_metadata(&late).unwrap().is_file());
    }

    #[test]
    fn an_output_that_is_an_input_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in.mat");
        std::fs::write(&input, b"x").unwrap();
        let spelled_otherwise = dir.path().join(".").join("in.mat");
        let error = check_output_is_not_input(&spelled_otherwise, &[Path::new("/nonexistent"), &input]).unwrap_err();
        assert!(matches!(error, IoError::OutputIsInput { .. }), "{error}");
        check_output_is_not_input(&dir.path().join("out.mcap"), &[&input]).unwrap();
    }

    #[test]
    fn existing_output_is_refused_unless_replace() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.bin");
        std::fs::write(&target, b"old").unwrap();
        assert!(matches!(AtomicFile::create(&target, Overwrite::Refuse), Err(IoError::OutputExists { .. })));
        let f = AtomicFile::create(&target, Overwrite::Replace).unwrap();
        let mut w = f.writer().unwrap();
        w.write_all(b"new").unwrap();
        w.flush().unwrap();
        drop(w);
        f.commit(Overwrite::Replace, Durability::PageCache).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
    }
}
