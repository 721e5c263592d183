//! Generated blocks of a README: the text between `<!-- {name}:begin -->` and
//! `<!-- {name}:end -->`, replaced by `bench ... --readme` and `reproduce ...
//! --readme` so that the results tables are written by the runs, never typed.
//!
//! Everything outside the block is left byte for byte. A file without exactly
//! one pair of markers, in that order, is refused and left untouched.

use std::ops::Range;
use std::path::Path;

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
}
