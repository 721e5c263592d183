//! Issue 24: no two files import each other, directly or in a circle,
//! anywhere in the workspace (inside a folder too: layer `config <- run <-
//! report`).
//!
//! The graph, per crate: a node per `.rs` file under `src/`; an edge from a
//! file to the file of each module that a `crate::`, `super::` or `self::`
//! path in it names (the longest prefix of the path that is a module with a
//! file of its own; `crate::Item` names the crate root). Grouped paths give
//! one edge per item (`use super::{a::X, b::{Y, Z}}`: `a` and `b`). Not
//! edges: everything from the first `#[cfg(test)]` of a file on (test code
//! may reach anywhere), `pub use` re-exports and `mod` declarations (they are
//! the module tree, not a use of it), and whole-line comments. A cycle is a
//! strongly connected component of more than one file.
//!
//! Plain string scanning, no parser: a child module named from its parent
//! without a prefix (`child::f()`) and paths in block comments or strings are
//! read as they stand. A crate with both `lib.rs` and `main.rs` has its
//! library graph checked: `main.rs` is the root of a separate binary crate,
//! which library files cannot name.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

#[test]
fn no_two_files_import_each_other() {
    let problems: Vec<String> = workspace_cycles(&super::common::root())
        .iter()
        .map(|cycle| format!("cycle of {} files: {}", cycle.files.len(), cycle.describe()))
        .collect();
    assert!(problems.is_empty(), "files that import each other (issue 24):\n{}", problems.join("\n"));
}

/// One strongly connected component of a crate's file graph.
#[derive(Debug)]
struct Cycle {
    /// The files, relative to the workspace root, sorted.
    files: Vec<String>,
    /// The edges inside the component, relative to the crate's `src/`.
    edges: Vec<(String, String)>,
}

impl Cycle {
    fn describe(&self) -> String {
        let edges: Vec<String> = self.edges.iter().map(|(from, to)| format!("{from} -> {to}")).collect();
        format!("{}\n    ({})", self.files.join(", "), edges.join(", "))
    }
}

/// The cycles of every crate under `root/crates`, in crate order.
fn workspace_cycles(root: &Path) -> Vec<Cycle> {
    let mut crates: Vec<String> = std::fs::read_dir(root.join("crates"))
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    crates.sort();
    let mut out = Vec::new();
    for name in crates {
        let src = root.join("crates").join(&name).join("src");
        if !src.is_dir() {
            continue;
        }
        let graph = crate_graph(&src);
        for component in strongly_connected(&graph) {
            let members: BTreeSet<&String> = component.iter().collect();
            let edges = component
                .iter()
                .flat_map(|from| {
                    graph[from].iter().filter(|to| members.contains(to)).map(|to| (from.clone(), to.clone()))
                })
                .collect();
            let files = component.iter().map(|f| format!("crates/{name}/src/{f}")).collect();
            out.push(Cycle { files, edges });
        }
    }
    out
}

/// Every `.rs` file under `dir`, relative with `/` separators, sorted.
fn rs_files(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(dir).unwrap();
                out.push(rel.components().map(|c| c.as_os_str().to_string_lossy()).collect::<Vec<_>>().join("/"));
            }
        }
    }
    out.sort();
    out
}

/// The module path of a file: `lib.rs`/`main.rs` the root, `a/mod.rs` and
/// `a.rs` module `a`.
fn module_path(file: &str) -> Vec<String> {
    let mut segments: Vec<String> = file.trim_end_matches(".rs").split('/').map(str::to_string).collect();
    if segments == ["lib"] || segments == ["main"] {
        return Vec::new();
    }
    if segments.last().is_some_and(|s| s == "mod") {
        segments.pop();
    }
    segments
}

/// The file graph of the crate whose sources are in `src`: for every file
/// (relative to `src`), the files it references.
fn crate_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let files = rs_files(src);
    let has_lib = files.iter().any(|f| f == "lib.rs");
    let mut modules: BTreeMap<Vec<String>, String> = BTreeMap::new();
    for file in files {
        if file == "main.rs" && has_lib {
            continue;
        }
        modules.entry(module_path(&file)).or_insert(file);
    }
    let mut graph = BTreeMap::new();
    for (module, file) in &modules {
        let text = std::fs::read_to_string(src.join(file)).unwrap();
        let mut targets = BTreeSet::new();
        for path in references(&strip_structure(&text), module) {
            if let Some(target) = (0..=path.len()).rev().find_map(|k| modules.get(&path[..k]))
                && target != file
            {
                targets.insert(target.clone());
            }
        }
        graph.insert(file.clone(), targets);
    }
    graph
}

/// The text of a file without what is not a dependency: everything from the
/// first `#[cfg(test)]` on, `pub use` statements and `mod name;` declarations
/// that start a line, and lines that are comments.
fn strip_structure(text: &str) -> String {
    let text = text.find("#[cfg(test)]").map_or(text, |i| &text[..i]);
    let bytes = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut line = 0;
    while line < bytes.len() {
        // At a line start: a `pub use`, then a `mod`, then a comment, may go.
        let mut keep = line;
        if let Some(end) = pub_use_end(bytes, skip_space(bytes, keep)) {
            keep = end;
        }
        if let Some(end) = mod_end(bytes, skip_space(bytes, keep)) {
            keep = end;
        }
        let start = skip_space(bytes, keep);
        if bytes[start..].starts_with(b"//") {
            keep = line_end(bytes, start);
        }
        let next = (line_end(bytes, keep) + 1).min(bytes.len());
        out.push_str(&text[keep.min(next)..next]);
        line = next;
    }
    out
}

fn skip_space(bytes: &[u8], mut i: usize) -> usize {
    while bytes.get(i).is_some_and(u8::is_ascii_whitespace) {
        i += 1;
    }
    i
}

/// Where the line holding byte `i` ends (its `\n`, or the end of the text).
fn line_end(bytes: &[u8], i: usize) -> usize {
    bytes[i.min(bytes.len())..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |p| i + p)
}

/// After `pub` and an optional `(...)` at `i`: where they end.
fn pub_end(bytes: &[u8], i: usize) -> Option<usize> {
    if !bytes[i..].starts_with(b"pub") {
        return None;
    }
    let i = i + 3;
    if bytes.get(i) == Some(&b'(') {
        let close = bytes[i..].iter().position(|&b| b == b')')?;
        return Some(i + close + 1);
    }
    Some(i)
}

/// The end of a `pub use ...;` (or `pub(crate) use`) starting at `i`.
fn pub_use_end(bytes: &[u8], i: usize) -> Option<usize> {
    let i = pub_end(bytes, i)?;
    if !bytes[i..].starts_with(b" use ") {
        return None;
    }
    let semicolon = bytes[i..].iter().position(|&b| b == b';')?;
    Some(i + semicolon + 1)
}

/// The end of a `mod name;` (optionally `pub`, `pub(...)`) starting at `i`.
fn mod_end(bytes: &[u8], i: usize) -> Option<usize> {
    let i = match pub_end(bytes, i) {
        Some(end) if bytes.get(end) == Some(&b' ') => end + 1,
        _ => i,
    };
    if !bytes[i..].starts_with(b"mod ") {
        return None;
    }
    let name = i + 4;
    let end = name + bytes[name..].iter().take_while(|&&b| b.is_ascii_alphanumeric() || b == b'_').count();
    (end > name && bytes.get(end) == Some(&b';')).then_some(end + 1)
}

/// The module paths (from the crate root) that the `crate::`, `super::` and
/// `self::` paths of `text`, in the file of module `module`, name.
fn references(text: &str, module: &[String]) -> Vec<Vec<String>> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        if let Some((paths, end)) = reference_at(&chars, i, module) {
            out.extend(paths);
            i = end;
        } else {
            i += 1;
        }
    }
    out
}

fn is_word(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

fn is_ident_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_'
}

fn starts_with(chars: &[char], i: usize, s: &str) -> bool {
    s.chars().enumerate().all(|(k, c)| chars.get(i + k) == Some(&c))
}

/// The identifier at `i` and where it ends.
fn ident_at(chars: &[char], i: usize) -> (String, usize) {
    let len = chars[i..].iter().take_while(|&&c| c.is_ascii_alphanumeric() || c == '_').count();
    (chars[i..i + len].iter().collect(), i + len)
}

/// A path starting at `i` with `crate`, `super` or `self` (not inside a
/// longer word): the module paths it names and where it ends.
fn reference_at(chars: &[char], i: usize, module: &[String]) -> Option<(Vec<Vec<String>>, usize)> {
    if i > 0 && is_word(chars[i - 1]) {
        return None;
    }
    let kind = ["crate", "super", "self"].into_iter().find(|k| starts_with(chars, i, k))?;
    let mut end = i + kind.len();
    let mut segments = Vec::new();
    while starts_with(chars, end, "::") && chars.get(end + 2).is_some_and(|&c| is_ident_start(c)) {
        let (ident, after) = ident_at(chars, end + 2);
        segments.push(ident);
        end = after;
    }
    let group = if starts_with(chars, end, "::{") {
        let (items, after) = group_at(chars, end + 3);
        end = after;
        Some(items)
    } else {
        None
    };
    if segments.is_empty() && group.is_none() {
        return None;
    }
    let mut base = match kind {
        "crate" => Vec::new(),
        "self" => module.to_vec(),
        _ => {
            let mut base = module.to_vec();
            base.pop();
            let supers = segments.iter().take_while(|s| *s == "super").count();
            segments.drain(..supers);
            base.truncate(base.len().saturating_sub(supers));
            base
        }
    };
    base.extend(segments);
    let paths = match group {
        None => vec![base],
        Some(items) => items.into_iter().map(|item| base.iter().cloned().chain(item).collect()).collect(),
    };
    Some((paths, end))
}

/// Whitespace and `//` comments from `i` on: where they end.
fn skip_blank(chars: &[char], mut i: usize) -> usize {
    loop {
        while chars.get(i).is_some_and(|c| c.is_whitespace()) {
            i += 1;
        }
        if !starts_with(chars, i, "//") {
            return i;
        }
        while chars.get(i).is_some_and(|&c| c != '\n') {
            i += 1;
        }
    }
}

/// The items of a `{...}` group whose `{` is just before `i`, as paths
/// relative to the group's prefix (`self`: the prefix itself; nested groups
/// flattened), and where the group ends.
fn group_at(chars: &[char], mut i: usize) -> (Vec<Vec<String>>, usize) {
    let mut items = Vec::new();
    loop {
        i = skip_blank(chars, i);
        match chars.get(i) {
            None => return (items, i),
            Some('}') => return (items, i + 1),
            Some(',') => {
                i += 1;
                continue;
            }
            Some(_) => {}
        }
        let start = i;
        let mut path = Vec::new();
        let mut nested = false;
        while chars.get(i).is_some_and(|&c| is_ident_start(c)) {
            let (ident, after) = ident_at(chars, i);
            i = after;
            if ident != "self" {
                path.push(ident);
            }
            if !starts_with(chars, i, "::") {
                break;
            }
            i += 2;
            if chars.get(i) == Some(&'{') {
                let (inner, after) = group_at(chars, i + 1);
                items.extend(inner.into_iter().map(|item| path.iter().cloned().chain(item).collect()));
                i = after;
                nested = true;
                break;
            }
        }
        if chars.get(i) == Some(&'*') {
            i += 1;
        }
        if i == start {
            // Not a path (e.g. a stray character): step over it.
            i += 1;
            continue;
        }
        if !nested {
            items.push(path);
        }
        // `X as Y`: the rename names nothing.
        let after = skip_blank(chars, i);
        if starts_with(chars, after, "as") && !chars.get(after + 2).copied().is_some_and(is_word) {
            let name = skip_blank(chars, after + 2);
            i = if chars.get(name).is_some_and(|&c| is_ident_start(c)) { ident_at(chars, name).1 } else { name };
        }
    }
}

/// The strongly connected components of more than one node (Tarjan), each
/// sorted, in order of their first file.
fn strongly_connected(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct Tarjan<'a> {
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        components: Vec<Vec<String>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a str) {
            let n = self.index.len();
            self.index.insert(v, n);
            self.low.insert(v, n);
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in &self.graph[v] {
                let w = w.as_str();
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let low = self.low[v].min(self.low[w]);
                    self.low.insert(v, low);
                } else if self.on_stack.contains(w) {
                    let low = self.low[v].min(self.index[w]);
                    self.low.insert(v, low);
                }
            }
            if self.low[v] == self.index[v] {
                let mut component = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack.remove(w);
                    component.push(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.components.push(component);
                }
            }
        }
    }
    let mut tarjan = Tarjan {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        components: Vec::new(),
    };
    for v in graph.keys() {
        if !tarjan.index.contains_key(v.as_str()) {
            tarjan.visit(v);
        }
    }
    let mut components = tarjan.components;
    components.sort();
    components
}

/// The scanner on small synthetic crates.
mod scanner {
    use super::{crate_graph, workspace_cycles};
    use std::collections::BTreeSet;
    use std::path::Path;

    /// A workspace with one crate `demo` holding `files` (path under `src/`, text).
    fn workspace(files: &[(&str, &str)]) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        for (path, text) in files {
            let path = dir.path().join("crates/demo/src").join(path);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, text).unwrap();
        }
        // A crate without src/ is skipped.
        std::fs::create_dir_all(dir.path().join("crates/empty")).unwrap();
        dir
    }

    fn cycles(root: &Path) -> Vec<Vec<String>> {
        workspace_cycles(root).into_iter().map(|c| c.files).collect()
    }

    fn demo(files: &[&str]) -> Vec<String> {
        files.iter().map(|f| format!("crates/demo/src/{f}")).collect()
    }

    #[test]
    fn a_two_file_cycle_is_found() {
        let dir = workspace(&[
            ("lib.rs", "pub mod a;\npub mod b;\n"),
            ("a.rs", "use crate::b::B;\npub struct A(pub B);\n"),
            ("b.rs", "pub struct B;\npub fn f() -> Option<crate::a::A> { None }\n"),
        ]);
        assert_eq!(cycles(dir.path()), vec![demo(&["a.rs", "b.rs"])]);
    }

    #[test]
    fn a_three_file_cycle_is_found() {
        let dir = workspace(&[
            ("lib.rs", "mod config;\nmod report;\nmod run;\nmod unrelated;\n"),
            ("config.rs", "use crate::report::Report;\npub struct Config;\n"),
            ("run.rs", "use crate::config::Config;\npub struct Run;\n"),
            ("report.rs", "use super::run::Run;\npub struct Report;\n"),
            ("unrelated.rs", "use crate::config::Config;\n"),
        ]);
        assert_eq!(cycles(dir.path()), vec![demo(&["config.rs", "report.rs", "run.rs"])]);
    }

    #[test]
    fn a_re_export_at_the_root_is_not_a_use_of_the_child() {
        let child = ("child.rs", "use crate::Root;\npub struct Thing(pub crate::Root);\npub fn helper() {}\n");
        let dir = workspace(&[
            (
                "lib.rs",
                "mod child;\npub use self::child::Thing;\npub(crate) use crate::child::helper;\npub struct Root;\n",
            ),
            child,
        ]);
        assert_eq!(cycles(dir.path()), Vec::<Vec<String>>::new());
        // A private `use` of the child is one.
        let dir = workspace(&[("lib.rs", "mod child;\nuse self::child::Thing;\npub struct Root;\n"), child]);
        assert_eq!(cycles(dir.path()), vec![demo(&["child.rs", "lib.rs"])]);
    }

    #[test]
    fn super_from_a_child_and_the_parent_using_it_is_a_cycle() {
        let dir = workspace(&[
            ("lib.rs", "pub mod net;\n"),
            ("net/mod.rs", "mod wire;\npub struct Frame;\npub fn send() { self::wire::encode(); }\n"),
            ("net/wire.rs", "use super::Frame;\npub fn encode() -> Option<Frame> { None }\n"),
        ]);
        assert_eq!(cycles(dir.path()), vec![demo(&["net/mod.rs", "net/wire.rs"])]);
    }

    #[test]
    fn grouped_imports_resolve_every_item() {
        let dir = workspace(&[
            ("lib.rs", "pub mod m;\npub mod top;\n"),
            ("m/mod.rs", "pub mod a;\npub mod b;\npub mod c;\npub mod d;\n"),
            ("m/a.rs", "pub struct X;\n"),
            ("m/b.rs", "pub struct Y;\n"),
            ("m/c.rs", "use super::{a::X, b::Y};\n"),
            ("m/d.rs", "use crate::{\n    m::{a::X as Z, b::{self, Y}},\n    // top::Nothing,\n    top::*,\n};\n"),
            ("top.rs", "pub struct T;\n"),
        ]);
        let graph = crate_graph(&dir.path().join("crates/demo/src"));
        let set = |files: &[&str]| files.iter().map(|f| (*f).to_string()).collect::<BTreeSet<_>>();
        assert_eq!(graph["m/c.rs"], set(&["m/a.rs", "m/b.rs"]));
        assert_eq!(graph["m/d.rs"], set(&["m/a.rs", "m/b.rs", "top.rs"]));
        // The grouped import closes a cycle when `a` uses `c` back.
        std::fs::write(dir.path().join("crates/demo/src/m/a.rs"), "pub struct X(super::c::C);\n").unwrap();
        assert_eq!(cycles(dir.path()), vec![demo(&["m/a.rs", "m/c.rs"])]);
    }

    #[test]
    fn test_code_comments_and_mod_lines_are_not_uses() {
        let dir = workspace(&[
            ("lib.rs", "pub mod a;\npub mod b;\n"),
            ("a.rs", "//! See [`crate::b`].\n/// Like [`crate::b::B`].\npub struct A;\n"),
            ("b.rs", "use crate::a::A;\npub struct B(A);\n#[cfg(test)]\nmod tests {\n    use crate::a::A;\n}\n"),
        ]);
        // `b` uses `a`, `a` names `b` in comments only.
        assert_eq!(crate_graph(&dir.path().join("crates/demo/src"))["a.rs"], BTreeSet::new());
        assert_eq!(cycles(dir.path()), Vec::<Vec<String>>::new());
        // `mod` declarations are the tree, not uses; `crate::` in code is.
        std::fs::write(dir.path().join("crates/demo/src/a.rs"), "pub(crate) mod inner;\nfn f() { crate::b::g() }\n")
            .unwrap();
        std::fs::create_dir_all(dir.path().join("crates/demo/src/a")).unwrap();
        std::fs::write(dir.path().join("crates/demo/src/a/inner.rs"), "").unwrap();
        assert_eq!(cycles(dir.path()), vec![demo(&["a.rs", "b.rs"])]);
    }

    #[test]
    fn cycles_in_every_crate_are_found_and_none_after_the_fix() {
        let dir = tempfile::tempdir().unwrap();
        for (path, text) in [
            ("mmtrack-analysis/src/lib.rs", "mod a;\nmod b;\n"),
            ("mmtrack-analysis/src/a.rs", "use crate::b::B;\npub struct A;\n"),
            ("mmtrack-analysis/src/b.rs", "use crate::a::A;\npub struct B;\n"),
            ("mmtrack-io/src/lib.rs", "mod a;\nmod b;\n"),
            ("mmtrack-io/src/a.rs", "use crate::b::B;\npub struct A;\n"),
            ("mmtrack-io/src/b.rs", "use super::a::A;\npub struct B;\n"),
        ] {
            let path = dir.path().join("crates").join(path);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, text).unwrap();
        }
        let files: Vec<Vec<String>> = workspace_cycles(dir.path()).into_iter().map(|c| c.files).collect();
        assert_eq!(
            files,
            [
                ["crates/mmtrack-analysis/src/a.rs", "crates/mmtrack-analysis/src/b.rs"],
                ["crates/mmtrack-io/src/a.rs", "crates/mmtrack-io/src/b.rs"]
            ]
        );
        std::fs::write(dir.path().join("crates/mmtrack-analysis/src/b.rs"), "pub struct B;\n").unwrap();
        std::fs::write(dir.path().join("crates/mmtrack-io/src/b.rs"), "pub struct B;\n").unwrap();
        assert!(workspace_cycles(dir.path()).is_empty());
    }
}
