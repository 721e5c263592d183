//! `report.html`: the Markdown report of `mmtrack analyze` as one
//! self-contained page, for a browser or to hand to a colleague.
//!
//! The page opens with what produced it (software version, the command's
//! configuration, its inputs), then the report's sections. Every plot the
//! report shows as an image (`![caption](plots/...svg)`) is embedded as a
//! data URI, so the page needs no other file; plots the report only links to
//! (per-sequence plot columns of tables) stay relative links. No scripts,
//! no external resources.
//!
//! The converter handles the Markdown the report writers produce: `#`
//! headings, paragraphs, `-` lists, pipe tables, `![image](src)` lines and
//! inline `code`, `**bold**` and `[links](href)`. Text is HTML-escaped.

use std::fmt::Write as _;
use std::path::Path;

/// What produced the report, shown at the top of the page.
#[derive(Debug, Clone, PartialEq)]
pub struct Provenance<'a> {
    /// The run configuration as JSON (the tables' `RunInfo`), shown
    /// pretty-printed; its `tables` value, when present, is the input.
    pub config_json: &'a str,
    /// Software version.
    pub version: &'a str,
}

const STYLE: &str = "body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;\
line-height:1.45;color:#222}table{border-collapse:collapse;margin:1em 0;font-size:0.9em;display:block;\
overflow-x:auto}th,td{border:1px solid #ccc;padding:0.25em 0.5em;text-align:left}th{background:#f2f2f2}\
code{background:#f4f4f4;padding:0 0.2em}figure{margin:1em 0}figure img{max-width:100%;height:auto;\
border:1px solid #eee}figcaption{font-size:0.9em;color:#555}pre{background:#f7f7f7;padding:0.8em;\
overflow-x:auto;font-size:0.85em}.missing{color:#a00}";

/// The page for `markdown`, reading the plots it shows from `dir` (the
/// results directory the Markdown's links are relative to).
#[must_use]
pub fn html(markdown: &str, dir: &Path, provenance: &Provenance<'_>) -> String {
    let title =
        markdown.lines().find_map(|l| l.strip_prefix("# ")).unwrap_or("mmtrack analysis report").trim().to_string();
    let mut out = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>{}</title>\n\
         <style>{STYLE}</style>\n</head>\n<body>\n",
        escape(&title)
    );
    let mut body = Converter { dir, out: String::new(), paragraph: Vec::new(), list: Vec::new(), table: Vec::new() };
    let mut provenance_done = false;
    for line in markdown.lines() {
        body.line(line);
        // The provenance goes right under the title.
        if !provenance_done && line.starts_with("# ") {
            body.out.push_str(&provenance_html(provenance));
            provenance_done = true;
        }
    }
    body.flush();
    if !provenance_done {
        out.push_str(&provenance_html(provenance));
    }
    out.push_str(&body.out);
    out.push_str("</body>\n</html>\n");
    out
}

fn provenance_html(p: &Provenance<'_>) -> String {
    let parsed: Option<serde_json::Value> = serde_json::from_str(p.config_json).ok();
    let input = parsed.as_ref().and_then(|v| v.get("tables")).and_then(|t| t.as_str()).map(str::to_string);
    let pretty =
        parsed.as_ref().and_then(|v| serde_json::to_string_pretty(v).ok()).unwrap_or(p.config_json.to_string());
    let mut out = String::from("<section id=\"provenance\">\n<h2>Provenance</h2>\n<ul>\n");
    let _ = writeln!(out, "<li>Software: mmtrack {}</li>", escape(p.version));
    if let Some(input) = input {
        let _ = writeln!(out, "<li>Input tables: <code>{}</code></li>", escape(&input));
    }
    let _ = write!(out, "</ul>\n<p>Configuration:</p>\n<pre>{}</pre>\n</section>\n", escape(&pretty));
    out
}

/// Line-by-line Markdown to HTML for the report's subset.
struct Converter<'a> {
    dir: &'a Path,
    out: String,
    paragraph: Vec<String>,
    list: Vec<String>,
    table: Vec<String>,
}

impl Converter<'_> {
    fn line(&mut self, line: &str) {
        let trimmed = line.trim_end();
        if trimmed.starts_with('|') {
            self.flush_paragraph();
            self.flush_list();
            self.table.push(trimmed.to_string());
            return;
        }
        self.flush_table();
        if trimmed.is_empty() {
            self.flush();
        } else if let Some((level, text)) = heading(trimmed) {
            self.flush();
            let _ = writeln!(self.out, "<h{level}>{}</h{level}>", inline(text));
        } else if let Some(item) = trimmed.strip_prefix("- ") {
            self.flush_paragraph();
            self.list.push(item.to_string());
        } else if let Some((alt, src)) = whole_image(trimmed) {
            self.flush_paragraph();
            self.flush_list();
            let figure = self.figure(alt, src);
            self.out.push_str(&figure);
        } else {
            self.flush_list();
            self.paragraph.push(trimmed.to_string());
        }
    }

    fn flush(&mut self) {
        self.flush_paragraph();
        self.flush_list();
        self.flush_table();
    }

    fn flush_paragraph(&mut self) {
        if !self.paragraph.is_empty() {
            let _ = writeln!(self.out, "<p>{}</p>", inline(&self.paragraph.join(" ")));
            self.paragraph.clear();
        }
    }

    fn flush_list(&mut self) {
        if !self.list.is_empty() {
            self.out.push_str("<ul>\n");
            for item in self.list.drain(..) {
                let _ = writeln!(self.out, "<li>{}</li>", inline(&item));
            }
            self.out.push_str("</ul>\n");
        }
    }

    fn flush_table(&mut self) {
        if self.table.is_empty() {
            return;
        }
        let rows: Vec<Vec<String>> = self.table.drain(..).map(|r| cells(&r)).collect();
        let is_rule = |r: &Vec<String>| r.iter().all(|c| !c.is_empty() && c.chars().all(|ch| matches!(ch, '-' | ':')));
        self.out.push_str("<table>\n");
        let (header, body) = match rows.get(1) {
            Some(rule) if is_rule(rule) => (rows.first(), &rows[2..]),
            _ => (None, &rows[..]),
        };
        if let Some(header) = header {
            self.out.push_str("<thead><tr>");
            for c in header {
                let _ = write!(self.out, "<th>{}</th>", inline(c));
            }
            self.out.push_str("</tr></thead>\n");
        }
        self.out.push_str("<tbody>\n");
        for row in body {
            self.out.push_str("<tr>");
            for c in row {
                let _ = write!(self.out, "<td>{}</td>", inline(c));
            }
            self.out.push_str("</tr>\n");
        }
        self.out.push_str("</tbody>\n</table>\n");
    }

    /// An image line: the SVG embedded, or a visible note when it is not
    /// there.
    fn figure(&self, alt: &str, src: &str) -> String {
        let path = self.dir.join(src);
        match std::fs::read(&path) {
            Ok(bytes) if src.ends_with(".svg") => format!(
                "<figure><img src=\"data:image/svg+xml;base64,{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>\n",
                base64(&bytes),
                escape(alt),
                inline(alt)
            ),
            _ => format!(
                "<p class=\"missing\">Plot not available: {} (<code>{}</code>).</p>\n",
                inline(alt),
                escape(src)
            ),
        }
    }
}

/// `# text` -> (1, text), up to level 4.
fn heading(line: &str) -> Option<(usize, &str)> {
    let level = line.chars().take_while(|c| *c == '#').count();
    (1..=4).contains(&level).then(|| line[level..].strip_prefix(' ')).flatten().map(|text| (level, text))
}

/// A line that is exactly `![alt](src)`.
fn whole_image(line: &str) -> Option<(&str, &str)> {
    let rest = line.strip_prefix("![")?;
    let (alt, rest) = rest.split_once("](")?;
    let src = rest.strip_suffix(')')?;
    (!src.contains(['(', ')', ' '])).then_some((alt, src))
}

/// The cells of a pipe-table row.
fn cells(row: &str) -> Vec<String> {
    let inner = row.trim().trim_start_matches('|');
    let inner = inner.strip_suffix('|').unwrap_or(inner);
    inner.split('|').map(|c| c.trim().to_string()).collect()
}

/// Inline Markdown: `code`, **bold**, [text](href), the rest escaped.
fn inline(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix('`')
            && let Some((code, tail)) = after.split_once('`')
        {
            let _ = write!(out, "<code>{}</code>", escape(code));
            rest = tail;
        } else if let Some(after) = rest.strip_prefix("**")
            && let Some((bold, tail)) = after.split_once("**")
        {
            let _ = write!(out, "<strong>{}</strong>", inline(bold));
            rest = tail;
        } else if let Some(after) = rest.strip_prefix('[')
            && let Some((label, tail)) = after.split_once("](")
            && let Some((href, tail)) = tail.split_once(')')
            && !label.contains('[')
        {
            let _ = write!(out, "<a href=\"{}\">{}</a>", escape(href), inline(label));
            rest = tail;
        } else {
            let mut chars = rest.chars();
            if let Some(c) = chars.next() {
                out.push_str(&escape(c.encode_utf8(&mut [0; 4])));
            }
            rest = chars.as_str();
        }
    }
    out
}

fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// Standard base64 with padding (RFC 4648).
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], chunk.get(1).copied().unwrap_or(0), chunk.get(2).copied().unwrap_or(0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(char::from(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        for (plain, encoded) in
            [("", ""), ("f", "Zg=="), ("fo", "Zm8="), ("foo", "Zm9v"), ("foob", "Zm9vYg=="), ("foobar", "Zm9vYmFy")]
        {
            assert_eq!(base64(plain.as_bytes()), encoded);
        }
    }

    #[test]
    fn converts_the_report_subset_and_embeds_plots() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("plots/a")).unwrap();
        std::fs::write(dir.path().join("plots/a/t.svg"), "<svg xmlns=\"http://www.w3.org/2000/svg\"/>").unwrap();
        let markdown = "# mmtrack analysis report\n\n## Trajectory (table `odometry`)\n\nText with <b> & **bold**\n\
                        and a [link](plots/a/t.svg).\n\n| a | b |\n|---|---|\n| 1 | n/a |\n\n- `s`: why\n\n\
                        ![trajectory](plots/a/t.svg)\n![gone](plots/a/none.svg)\n";
        let config = r#"{"command":"analyze","tables":"in/tables"}"#;
        let page = html(markdown, dir.path(), &Provenance { config_json: config, version: "0.1.0" });
        assert!(page.starts_with("<!DOCTYPE html>") && page.contains("<title>mmtrack analysis report</title>"));
        assert!(page.contains("<li>Software: mmtrack 0.1.0</li>") && page.contains("<code>in/tables</code>"), "{page}");
        assert!(page.contains("<h2>Trajectory (table <code>odometry</code>)</h2>"), "{page}");
        assert!(
            page.contains(
                "<p>Text with &lt;b&gt; &amp; <strong>bold</strong> and a <a href=\"plots/a/t.svg\">link</a>.</p>"
            ),
            "{page}"
        );
        assert!(
            page.contains("<thead><tr><th>a</th><th>b</th></tr></thead>") && page.contains("<td>n/a</td>"),
            "{page}"
        );
        assert!(page.contains("<ul>\n<li><code>s</code>: why</li>\n</ul>"), "{page}");
        assert!(page.contains("<img src=\"data:image/svg+xml;base64,PHN2ZyB4bWxucz0i"), "{page}");
        assert!(page.contains("class=\"missing\">Plot not available: gone"), "{page}");
        assert!(!page.contains("<script"));
    }
}
