//! How recordings and tables name the files they came from.

use std::path::Path;

/// The canonical absolute form of `path` as text (absolute, symbolic links
/// and `..` resolved), so that the same input named from another working
/// directory, or through a link, gives byte-identical recordings and
/// tables; `path` as given when it cannot be resolved (a missing file: the
/// reader reports that itself).
#[must_use]
pub fn canonical(path: &Path) -> String {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()).display().to_string()
}

#[cfg(test)]
mod tests {
    use super::canonical;

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
