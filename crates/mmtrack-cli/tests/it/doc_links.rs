//! Every relative link of README.md and docs/**/*.md resolves: the file or
//! directory exists, and a `#anchor` into a Markdown file names one of its
//! headings (GitHub's slugs). Links with a scheme (`https:`) are not
//! followed; links inside code spans and fenced code are not links.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::common::root;

/// One link as written: the file it is in, its line, the target.
struct Link {
    file: PathBuf,
    line: usize,
    target: String,
    /// Inside a generated `<!-- name:begin -->` ... `end` block.
    generated: bool,
}

/// `text` without its inline code spans (`` `...` ``), so that code such as
/// `` `[a](b)` `` is not taken for a link.
fn without_code_spans(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut in_code = false;
    for c in text.chars() {
        if c == '`' {
            in_code = !in_code;
        } else if !in_code {
            out.push(c);
        }
    }
    out
}

/// The link targets of one line: `[text](target)` and `![alt](target)`.
fn targets_of(line: &str) -> Vec<String> {
    let line = without_code_spans(line);
    let mut targets = Vec::new();
    let mut rest = line.as_str();
    while let Some(at) = rest.find("](") {
        let after = &rest[at + 2..];
        let end = after.find(|c: char| c == ')' || c.is_whitespace()).unwrap_or(after.len());
        targets.push(after[..end].trim_matches(|c| c == '<' || c == '>').to_string());
        rest = &after[end..];
    }
    targets
}

/// Whether `line` opens or closes a fenced code block.
fn is_fence(line: &str) -> bool {
    let t = line.trim_start();
    t.starts_with("```") || t.starts_with("~~~")
}

/// Every link of `file`, outside fenced code.
fn links_in(file: &Path) -> Vec<Link> {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let (mut fenced, mut generated) = (false, false);
    let mut links = Vec::new();
    for (k, line) in text.lines().enumerate() {
        if is_fence(line) {
            fenced = !fenced;
            continue;
        }
        let t = line.trim();
        if t.starts_with("<!-- ") && t.ends_with(":begin -->") {
            generated = true;
        }
        if t.starts_with("<!-- ") && t.ends_with(":end -->") {
            generated = false;
        }
        if fenced {
            continue;
        }
        for target in targets_of(line) {
            links.push(Link { file: file.to_path_buf(), line: k + 1, target, generated });
        }
    }
    links
}

/// GitHub's anchor of a heading: the rendered text (code marks and link
/// targets dropped) in lower case, every character but letters, digits,
/// `-`, `_` and spaces dropped, spaces turned into `-`.
fn slug(heading: &str) -> String {
    let mut text = String::new();
    let mut rest = heading;
    // [text](url) -> text
    while let Some(open) = rest.find('[') {
        let Some(mid) = rest[open..].find("](").map(|m| open + m) else { break };
        let Some(close) = rest[mid..].find(')').map(|c| mid + c) else { break };
        text.push_str(&rest[..open]);
        text.push_str(&rest[open + 1..mid]);
        rest = &rest[close + 1..];
    }
    text.push_str(rest);
    text.to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a Markdown file's headings (outside fenced code), with
/// GitHub's `-1`, `-2` suffixes for repeated ones.
fn anchors(file: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(file).unwrap_or_default();
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut fenced = false;
    let mut out = Vec::new();
    for line in text.lines() {
        if is_fence(line) {
            fenced = !fenced;
            continue;
        }
        let hashes = line.chars().take_while(|&c| c == '#').count();
        if fenced || !(1..=6).contains(&hashes) || !line[hashes..].starts_with(' ') {
            continue;
        }
        let base = slug(line[hashes..].trim().trim_end_matches('#').trim());
        let n = seen.entry(base.clone()).or_insert(0);
        out.push(if *n == 0 { base.clone() } else { format!("{base}-{n}") });
        *n += 1;
    }
    out
}

/// The broken links among those of `files`, one line each, naming file,
/// line, target and what is wrong. Run outputs (`out/...`) named inside a
/// generated block are not in the repository and are not checked: the run
/// that wrote the block wrote them.
fn broken_links(files: &[PathBuf]) -> Vec<String> {
    let mut problems = Vec::new();
    for file in files {
        for link in links_in(file) {
            let target = link.target.as_str();
            if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            if link.generated && target.starts_with("out/") {
                continue;
            }
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target, None),
            };
            let resolved = if path.is_empty() { file.clone() } else { file.parent().unwrap().join(path) };
            let at = format!("{}:{}: ({target})", link.file.display(), link.line);
            if !resolved.exists() {
                problems.push(format!("{at}: {} does not exist", resolved.display()));
                continue;
            }
            if let Some(anchor) = anchor
                && resolved.extension().is_some_and(|e| e == "md")
                && !anchors(&resolved).iter().any(|a| a == anchor)
            {
                problems.push(format!("{at}: no heading with anchor #{anchor} in {}", resolved.display()));
            }
        }
    }
    problems
}

/// README.md and every Markdown file under docs/.
fn documentation() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut files = vec![root().join("README.md")];
    walk(&root().join("docs"), &mut files);
    files.sort();
    files
}

#[test]
fn every_relative_link_of_the_documentation_resolves() {
    let files = documentation();
    assert!(files.len() >= 10, "README.md and docs/: {files:?}");
    let links: usize = files.iter().map(|f| links_in(f).len()).sum();
    let problems = broken_links(&files);
    println!("{} files, {links} links checked, {} broken", files.len(), problems.len());
    assert!(problems.is_empty(), "broken links:\n{}", problems.join("\n"));
}

#[test]
fn the_readme_front_page_stays_short() {
    let lines = std::fs::read_to_string(root().join("README.md")).unwrap().lines().count();
    assert!(lines <= 250, "README.md has {lines} lines; move detail to docs/ (issue 28: at most 250)");
}

#[test]
fn the_readme_layout_lists_every_crate() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let layout = readme.split("## Layout").nth(1).expect("README.md has a Layout section");
    let mut crates: Vec<String> = std::fs::read_dir(root().join("crates"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    crates.sort();
    assert!(crates.len() >= 14, "{crates:?}");
    let missing: Vec<&String> = crates.iter().filter(|c| !layout.contains(&format!("crates/{c} "))).collect();
    assert!(missing.is_empty(), "README.md's Layout lacks {missing:?}");
}

#[test]
fn broken_links_and_anchors_are_found() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("docs")).unwrap();
    std::fs::write(dir.path().join("docs/page.md"), "# A page\n\n## `mmtrack process beam --tracker spebt`\n").unwrap();
    let readme = dir.path().join("README.md");
    std::fs::write(
        &readme,
        "# Top\n\n\
         [ok](docs/page.md) [ok](docs/page.md#a-page) [ok](docs/page.md#mmtrack-process-beam---tracker-spebt)\n\
         [ok](#top) [ok](docs) [web](https://example.com/x.md) `[code](missing.md)`\n\
         ```\n[fenced](missing.md)\n```\n\
         [gone](docs/missing.md)\n\
         [bad anchor](docs/page.md#no-such-heading)\n\
         [bad self anchor](#nowhere)\n\
         <!-- x:begin -->\n[run output](out/figure.svg)\n<!-- x:end -->\n\
         [outside a block](out/figure.svg)\n",
    )
    .unwrap();
    let problems = broken_links(&[readme]);
    assert_eq!(problems.len(), 4, "{problems:#?}");
    assert!(problems[0].contains(":8: (docs/missing.md)") && problems[0].contains("does not exist"), "{problems:#?}");
    assert!(problems[1].contains("#no-such-heading"), "{problems:#?}");
    assert!(problems[2].contains("#nowhere"), "{problems:#?}");
    assert!(problems[3].contains("(out/figure.svg)"), "{problems:#?}");
}

#[test]
fn slugs_follow_github() {
    assert_eq!(slug("HDF5 and MATLAB v7.3 input"), "hdf5-and-matlab-v73-input");
    assert_eq!(slug("`mmtrack reproduce --all`"), "mmtrack-reproduce---all");
    assert_eq!(slug("Campaigns: many sequences and runs at once"), "campaigns-many-sequences-and-runs-at-once");
    assert_eq!(slug("Beam tracking II: geometric (Zoechmann et al.)"), "beam-tracking-ii-geometric-zoechmann-et-al");
    assert_eq!(slug("See [the docs](x.md) now"), "see-the-docs-now");
}
