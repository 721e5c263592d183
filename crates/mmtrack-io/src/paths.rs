//! How recordings and tables name the files they came from.

use std::path::Path;

use crate::error::IoError;

/// The canonical absolute form of `path` as text (absolute, symbolic links
/// and `..` resolved), so that the same input named from another working
/// directory, or through a link, gives byte-identical recordings and
/// tables; `path` as given when it cannot be resolved (a missing file: the
/// reader reports that itself).
#[must_use]
pub fn canonical(path: &Path) -> String {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()).display().to_string()
}

/// Reads a configuration file (a scenario, a pipeline or experiment
/// configuration, a manifest, a regression suite) as UTF-8 text, refusing a
/// device (`/dev/zero`) and a file over
/// [`mmtrack_core::limits::CONFIG_FILE_BYTES`] before reading it, and
/// stopping one byte past the limit where the OS reports no size (a pipe).
///
/// # Errors
/// The file cannot be opened or read, is a device, is too large, or is not
/// UTF-8; each names the file.
pub fn read_config_text(path: &Path) -> Result<String, IoError> {
    use std::io::Read as _;
    let limit = &mmtrack_core::limits::CONFIG_FILE_BYTES;
    let bad = |field: &'static str, detail: String| IoError::BadValue {
        path: path.to_path_buf(),
        record: "the file".into(),
        field,
        detail,
    };
    let os = |source| IoError::Os { path: path.to_path_buf(), source };
    let file = std::fs::File::open(path).map_err(os)?;
    let metadata = file.metadata().map_err(os)?;
    if is_device(&metadata) {
        return Err(bad("type", "is a device, not a configuration file".into()));
    }
    let max_bytes = limit.max as u64;
    if metadata.len() > max_bytes {
        return Err(bad("size", format!("{} bytes is too large: expected {}", metadata.len(), limit.expected)));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(metadata.len()).unwrap_or(0));
    file.take(max_bytes + 1).read_to_end(&mut bytes).map_err(os)?;
    if bytes.len() as u64 > max_bytes {
        return Err(bad("size", format!("more than {max_bytes} bytes is too large: expected {}", limit.expected)));
    }
    String::from_utf8(bytes)
        .map_err(|e| bad("text", format!("not UTF-8 text: invalid byte at offset {}", e.utf8_error().valid_up_to())))
}

/// Whether `metadata` is of a character or block device (`/dev/zero`,
/// `/dev/urandom`): endless input no reader should take.
#[must_use]
pub fn is_device(metadata: &std::fs::Metadata) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        metadata.file_type().is_char_device() || metadata.file_type().is_block_device()
    }
    #[cfg(not(unix))]
    {
        let _ = metadata;
        false
    }
}

#[cfg(test)]
mod tests {
    use super::{canonical, read_config_text};

    #[test]
    fn configuration_files_are_read_within_their_cap() {
        let dir = tempfile::tempdir().unwrap();
        let ok = dir.path().join("s.toml");
        std::fs::write(&ok, "seed = 1\n").unwrap();
        assert_eq!(read_config_text(&ok).unwrap(), "seed = 1\n");
        let started = std::time::Instant::now();
        let zero = read_config_text(std::path::Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(zero.contains("/dev/zero") && zero.contains("is a device"), "{zero}");
        assert!(started.elapsed().as_secs_f64() < 1.0, "refused before reading");
        let big = dir.path().join("big.toml");
        std::fs::File::create(&big).unwrap().set_len(16 * 1024 * 1024 + 1).unwrap();
        let text = read_config_text(&big).unwrap_err().to_string();
        assert!(text.contains("big.toml") && text.contains("16777217 bytes is too large"), "{text}");
        let latin = dir.path().join("latin.toml");
        std::fs::write(&latin, b"a = \"\xe9\"").unwrap();
        assert!(read_config_text(&latin).unwrap_err().to_string().contains("not UTF-8 text"));
    }

    #[test]
    fn relative_and_dotted_paths_name_the_same_file() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("a")).unwrap();
        std::fs::write(dir.path().join("a/f.txt"), b"x").unwrap();
        let plain = canonical(&dir.path().join("a/f.txt"));
        assert_eq!(canonical(&dir.path().join("a/../a/./f.txt")), plain);
        assert!(std::path::Path::new(&plain).is_absolute(), "{plain}");
        assert_eq!(canonical(std::path::Path::new("missing/file")), "missing/file");
    }
}
