//! Atomic output files: write to a temporary file beside the target, then
//! rename over it. A crash, an error or a dropped writer leaves the previous
//! output (if any) untouched and no partial file behind.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

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
    temp: NamedTempFile,
}

impl AtomicFile {
    /// Starts writing `target`: checks the overwrite policy, creates the parent
    /// directories and a hidden temporary file in the same directory (so the
    /// final rename never crosses file systems).
    pub fn create(target: &Path, overwrite: Overwrite) -> Result<Self> {
        if overwrite == Overwrite::Refuse && target.exists() {
            return Err(IoError::OutputExists { path: target.to_path_buf() });
        }
        let dir = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&dir).map_err(os_err(&dir))?;
        let file_name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let temp = with_default_mode(&mut tempfile::Builder::new(), 0o666)
            .prefix(&format!(".{file_name}."))
            .suffix(".partial")
            .tempfile_in(&dir)
            .map_err(os_err(&dir))?;
        Ok(Self { target: target.to_path_buf(), temp })
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
    /// in place of the old one.
    pub fn commit(self, overwrite: Overwrite, durability: Durability) -> Result<PathBuf> {
        let Self { target, temp } = self;
        if durability == Durability::Fsync {
            temp.as_file().sync_all().map_err(os_err(temp.path()))?;
        }
        match overwrite {
            Overwrite::Replace => {
                temp.persist(&target).map_err(|e| IoError::Os { path: target.clone(), source: e.error })?;
            }
            Overwrite::Refuse => {
                temp.persist_noclobber(&target).map_err(|e| {
                    if e.error.kind() == std::io::ErrorKind::AlreadyExists {
                        IoError::OutputExists { path: target.clone() }
                    } else {
                        IoError::Os { path: target.clone(), source: e.error }
                    }
                })?;
            }
        }
        Ok(target)
    }
}

/// A staging directory beside an output directory (`parent`), renamed over
/// it when complete. Created with the mode `create_dir` gives (0777 less the
/// umask), not the private 0700 of temporary directories, so the published
/// output is readable as any other.
///
/// # Errors
/// The OS error of creating it.
pub fn staging_dir(parent: &Path, prefix: &str) -> std::io::Result<tempfile::TempDir> {
    with_default_mode(&mut tempfile::Builder::new(), 0o777).prefix(prefix).suffix(".partial").tempdir_in(parent)
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
