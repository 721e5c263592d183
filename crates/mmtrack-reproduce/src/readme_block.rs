//! Generated blocks of a README: the text between `<!-- {name}:begin -->` and
//! `<!-- {name}:end -->`, replaced by `bench ... --readme` and `reproduce ...
//! --readme` so that the results tables are written by the runs, never typed.
//!
//! The blocks live in the docs (`docs/results/*.md`, `docs/benchmarks.md`).
//! Everything outside the block is left byte for byte. A file without exactly
//! one pair of markers, in that order, is refused and left untouched.

use std::ops::Range;
use std::path::{Path, PathBuf};

use anyhow::Context;

/// The byte range of block `name`'s body in `text` (from just after the
/// begin marker to the start of the end marker).
fn body_span(text: &str, path: &Path, name: &str) -> anyhow::Result<Range<usize>> {
    let (begin, end) = (format!("<!-- {name}:begin -->"), format!("<!-- {name}:end -->"));
    let find_one = |marker: &str| -> anyhow::Result<usize> {
        let found: Vec<usize> = text.match_indices(marker).map(|(i, _)| i).collect();
        match found[..] {
            [i] => Ok(i),
            [] => anyhow::bail!(
                "{}: marker {marker} not found; add the pair {begin} / {end} where the block belongs (nothing was changed)",
                path.display()
            ),
            _ => anyhow::bail!(
                "{}: marker {marker} found {} times, expected once (nothing was changed)",
                path.display(),
                found.len()
            ),
        }
    };
    let (start, stop) = (find_one(&begin)?, find_one(&end)?);
    anyhow::ensure!(start < stop, "{}: {end} comes before {begin} (nothing was changed)", path.display());
    Ok(start + begin.len()..stop)
}

/// Checks that `path` holds block `name` (before a long run, so that a wrong
/// README fails at once rather than after the work).
pub fn check_block(path: &Path, name: &str) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    body_span(&text, path, name).map(drop)
}

/// The file that holds block `name`: `readme` itself when it has the block's
/// begin marker, else the one Markdown file in the same directory that has
/// it. So `reproduce --all --readme docs/results/README.md` writes its own
/// table there and each experiment's block into that experiment's page
/// beside it. Checked before any work, like [`check_block`].
///
/// # Errors
/// `readme` cannot be read; no file, or more than one file beside it, has
/// the begin marker (all are named).
pub fn locate_block(readme: &Path, name: &str) -> anyhow::Result<PathBuf> {
    let begin = format!("<!-- {name}:begin -->");
    let text = std::fs::read_to_string(readme).with_context(|| readme.display().to_string())?;
    if text.contains(&begin) {
        return Ok(readme.to_path_buf());
    }
    let dir = match readme.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| dir.display().to_string())? {
        let path = entry.with_context(|| dir.display().to_string())?.path();
        if path.extension().is_some_and(|e| e == "md") && path.is_file() {
            let other = std::fs::read_to_string(&path).with_context(|| path.display().to_string())?;
            if other.contains(&begin) {
                found.push(path);
            }
        }
    }
    found.sort();
    match found.len() {
        1 => Ok(found.remove(0)),
        0 => anyhow::bail!(
            "marker {begin} found neither in {} nor in another .md file of {} (nothing was done)",
            readme.display(),
            dir.display()
        ),
        _ => anyhow::bail!(
            "marker {begin} found in {} files beside {}: {} (nothing was done)",
            found.len(),
            readme.display(),
            found.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
        ),
    }
}

/// Replaces the body of block `name` in `path` by `body` (a newline is added
/// when `body` does not end with one). Written in place, so the file keeps
/// its permissions.
pub fn replace_block(path: &Path, name: &str, body: &str) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    let span = body_span(&text, path, name)?;
    let newline = if body.ends_with('\n') { "" } else { "\n" };
    let updated = format!("{}\n{body}{newline}{}", &text[..span.start], &text[span.end..]);
    std::fs::write(path, updated).with_context(|| path.display().to_string())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_block_body_changes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("README.md");
        std::fs::write(&path, "a\n<!-- x:begin -->\nold\n<!-- x:end -->\nb\n").unwrap();
        replace_block(&path, "x", "new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a\n<!-- x:begin -->\nnew\n<!-- x:end -->\nb\n");
    }

    #[test]
    fn missing_repeated_or_swapped_markers_are_refused_and_the_file_kept() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("README.md");
        for (text, expected) in [
            ("no markers\n", "not found"),
            ("<!-- x:begin -->\n<!-- x:end -->\n<!-- x:begin -->\n", "found 2 times"),
            ("<!-- x:end -->\n<!-- x:begin -->\n", "comes before"),
            ("<!-- y:begin -->\n<!-- y:end -->\n", "<!-- x:begin --> not found"),
        ] {
            std::fs::write(&path, text).unwrap();
            let error = format!("{:#}", replace_block(&path, "x", "new").unwrap_err());
            assert!(error.contains(expected) && error.contains("README.md"), "{error}");
            assert!(check_block(&path, "x").is_err());
            assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
        }
    }

    #[test]
    fn a_block_is_found_in_the_file_or_the_one_page_beside_it() {
        let dir = tempfile::tempdir().unwrap();
        let index = dir.path().join("README.md");
        let page = dir.path().join("shaham.md");
        std::fs::write(&index, "<!-- all:begin -->\n<!-- all:end -->\n").unwrap();
        std::fs::write(&page, "# S\n<!-- reproduce-shaham:begin -->\nold\n<!-- reproduce-shaham:end -->\n").unwrap();
        std::fs::write(dir.path().join("notes.txt"), "<!-- reproduce-kim:begin -->\n").unwrap();
        assert_eq!(locate_block(&index, "all").unwrap(), index);
        assert_eq!(locate_block(&index, "reproduce-shaham").unwrap(), page);
        let none = format!("{:#}", locate_block(&index, "reproduce-kim").unwrap_err());
        assert!(none.contains("found neither in") && none.contains("README.md"), "{none}");
        std::fs::write(dir.path().join("copy.md"), std::fs::read_to_string(&page).unwrap()).unwrap();
        let two = format!("{:#}", locate_block(&index, "reproduce-shaham").unwrap_err());
        assert!(two.contains("found in 2 files") && two.contains("copy.md") && two.contains("shaham.md"), "{two}");
    }
}
