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
//! The Markdown is CommonMark with GitHub's pipe tables, converted by
//! pulldown-cmark. Raw HTML in the Markdown is shown as text, not passed
//! through, so the page holds only what this module writes.

use std::fmt::Write as _;
use std::path::Path;

use pulldown_cmark::{CowStr, Event, HeadingLevel, Options, Parser, Tag, TagEnd};

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
    let events: Vec<Event<'_>> = Parser::new_ext(markdown, Options::ENABLE_TABLES).map(raw_html_as_text).collect();
    let title = first_title(&events).unwrap_or_else(|| "mmtrack analysis report".to_string());
    let mut body = Vec::with_capacity(events.len() + 1);
    let mut provenance_done = false;
    for piece in pieces(events) {
        match piece {
            Piece::Event(event) => {
                // The provenance goes right under the title.
                let title_end = matches!(event, Event::End(TagEnd::Heading(HeadingLevel::H1)));
                body.push(event);
                if title_end && !provenance_done {
                    body.push(Event::Html(provenance_html(provenance).into()));
                    provenance_done = true;
                }
            }
            Piece::Figures(images) => {
                body.extend(images.iter().map(|image| Event::Html(image.figure(dir).into())));
            }
            Piece::Image(image) => body.push(Event::InlineHtml(image.inline(dir).into())),
        }
    }
    let mut out = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>{}</title>\n\
         <style>{STYLE}</style>\n</head>\n<body>\n",
        escape(title.trim())
    );
    if !provenance_done {
        out.push_str(&provenance_html(provenance));
    }
    pulldown_cmark::html::push_html(&mut out, body.into_iter());
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

/// Raw HTML of the Markdown as text: an HTML block becomes a paragraph.
fn raw_html_as_text(event: Event<'_>) -> Event<'_> {
    match event {
        Event::Html(text) | Event::InlineHtml(text) => Event::Text(text),
        Event::Start(Tag::HtmlBlock) => Event::Start(Tag::Paragraph),
        Event::End(TagEnd::HtmlBlock) => Event::End(TagEnd::Paragraph),
        other => other,
    }
}

/// The plain text of the first `#` heading.
fn first_title(events: &[Event<'_>]) -> Option<String> {
    let start = events.iter().position(|e| matches!(e, Event::Start(Tag::Heading { level: HeadingLevel::H1, .. })))?;
    let mut title = String::new();
    for event in &events[start + 1..] {
        match event {
            Event::End(TagEnd::Heading(_)) => break,
            Event::Text(text) | Event::Code(text) => title.push_str(text),
            _ => {}
        }
    }
    Some(title)
}

/// An image of the Markdown: its source and the events of its alt text.
struct Image<'a> {
    src: CowStr<'a>,
    alt: Vec<Event<'a>>,
}

impl Image<'_> {
    /// The alt text as plain text, escaped for an attribute.
    fn alt_attribute(&self) -> String {
        let mut text = String::new();
        for event in &self.alt {
            if let Event::Text(t) | Event::Code(t) = event {
                text.push_str(t);
            }
        }
        escape(&text)
    }

    /// The alt text as HTML (it may hold `code` and emphasis).
    fn alt_html(&self) -> String {
        let mut out = String::new();
        pulldown_cmark::html::push_html(&mut out, self.alt.iter().cloned());
        out
    }

    /// The SVG the image shows, when it is one and is there.
    fn svg(&self, dir: &Path) -> Option<Vec<u8>> {
        if !self.src.ends_with(".svg") {
            return None;
        }
        std::fs::read(dir.join(self.src.as_ref())).ok()
    }

    /// An image alone in its paragraph: the SVG embedded as a figure, or a
    /// visible note when it is not there.
    fn figure(&self, dir: &Path) -> String {
        match self.svg(dir) {
            Some(bytes) => format!(
                "<figure><img src=\"data:image/svg+xml;base64,{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>\n",
                base64(&bytes),
                self.alt_attribute(),
                self.alt_html()
            ),
            None => format!(
                "<p class=\"missing\">Plot not available: {} (<code>{}</code>).</p>\n",
                self.alt_html(),
                escape(&self.src)
            ),
        }
    }

    /// An image within text: the SVG embedded, or the same note inline.
    fn inline(&self, dir: &Path) -> String {
        match self.svg(dir) {
            Some(bytes) => {
                format!("<img src=\"data:image/svg+xml;base64,{}\" alt=\"{}\">", base64(&bytes), self.alt_attribute())
            }
            None => format!(
                "<span class=\"missing\">Plot not available: {} (<code>{}</code>)</span>",
                self.alt_html(),
                escape(&self.src)
            ),
        }
    }
}

/// What the page is made of: Markdown events, images within text, and
/// paragraphs that hold nothing but images (one figure each).
enum Piece<'a> {
    Event(Event<'a>),
    Image(Image<'a>),
    Figures(Vec<Image<'a>>),
}

/// The events with each image taken out whole, and image-only paragraphs
/// turned into figures.
fn pieces(events: Vec<Event<'_>>) -> Vec<Piece<'_>> {
    let mut out = Vec::new();
    let mut events = events.into_iter();
    while let Some(event) = events.next() {
        match event {
            Event::Start(Tag::Image { dest_url, .. }) => {
                let alt = events.by_ref().take_while(|e| !matches!(e, Event::End(TagEnd::Image))).collect();
                out.push(Piece::Image(Image { src: dest_url, alt }));
            }
            Event::End(TagEnd::Paragraph) => {
                let start = out.iter().rposition(|p| matches!(p, Piece::Event(Event::Start(Tag::Paragraph))));
                let only_images = start.is_some_and(|start| {
                    let inner = &out[start + 1..];
                    inner.iter().any(|p| matches!(p, Piece::Image(_)))
                        && inner.iter().all(|p| match p {
                            Piece::Image(_) | Piece::Event(Event::SoftBreak | Event::HardBreak) => true,
                            Piece::Event(Event::Text(t)) => t.trim().is_empty(),
                            _ => false,
                        })
                });
                match start {
                    Some(start) if only_images => {
                        let images = out
                            .drain(start..)
                            .filter_map(|p| match p {
                                Piece::Image(image) => Some(image),
                                _ => None,
                            })
                            .collect();
                        out.push(Piece::Figures(images));
                    }
                    _ => out.push(Piece::Event(Event::End(TagEnd::Paragraph))),
                }
            }
            other => out.push(Piece::Event(other)),
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
    fn converts_the_report_markdown_and_embeds_plots() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("plots/a")).unwrap();
        std::fs::write(dir.path().join("plots/a/t.svg"), "<svg xmlns=\"http://www.w3.org/2000/svg\"/>").unwrap();
        let markdown = "# mmtrack analysis report\n\n## Trajectory (table `odometry`)\n\nText with <b> & **bold**\n\
                        and a [link](plots/a/t.svg).\n\n| a | b |\n|---|---:|\n| 1 | n/a |\n\n- `s`: why\n\n\
                        ![trajectory](plots/a/t.svg)\n![gone](plots/a/none.svg)\n\nInline ![`t` plot](plots/a/t.svg) \
                        and ![lost](plots/a/lost.svg).\n\n<script>alert(1)</script>\n";
        let config = r#"{"command":"analyze","tables":"in/tables"}"#;
        let page = html(markdown, dir.path(), &Provenance { config_json: config, version: "0.1.0" });
        assert!(page.starts_with("<!DOCTYPE html>") && page.contains("<title>mmtrack analysis report</title>"));
        assert!(page.contains("<li>Software: mmtrack 0.1.0</li>") && page.contains("<code>in/tables</code>"), "{page}");
        // The provenance right under the title, before the first section.
        let at = |needle: &str| page.find(needle).unwrap_or_else(|| panic!("{needle} not in {page}"));
        assert!(at("<h1>mmtrack analysis report</h1>") < at("<section id=\"provenance\">"));
        assert!(at("</section>") < at("<h2>Trajectory"));
        assert!(page.contains("<h2>Trajectory (table <code>odometry</code>)</h2>"), "{page}");
        // Raw HTML is text; a soft line break stays a line break in the paragraph.
        assert!(
            page.contains(
                "<p>Text with &lt;b&gt; &amp; <strong>bold</strong>\nand a <a href=\"plots/a/t.svg\">link</a>.</p>"
            ),
            "{page}"
        );
        assert!(page.contains("&lt;script&gt;alert(1)&lt;/script&gt;") && !page.contains("<script"), "{page}");
        assert!(page.contains("<thead><tr><th>a</th><th style=\"text-align: right\">b</th></tr></thead>"), "{page}");
        assert!(page.contains("<td>1</td><td style=\"text-align: right\">n/a</td>"), "{page}");
        assert!(page.contains("<ul>\n<li><code>s</code>: why</li>\n</ul>"), "{page}");
        // Image-only lines: a figure each, the plot embedded, or a note.
        assert!(
            page.contains(
                "<figure><img src=\"data:image/svg+xml;base64,PHN2ZyB4bWxucz0iaHR0cDovL3d3dy53My5vcmcvMjAwMC9zdmciLz4=\" \
                 alt=\"trajectory\"><figcaption>trajectory</figcaption></figure>"
            ),
            "{page}"
        );
        assert!(
            page.contains("<p class=\"missing\">Plot not available: gone (<code>plots/a/none.svg</code>).</p>"),
            "{page}"
        );
        // Images within text: embedded in place, or the note in place.
        assert!(page.contains("<p>Inline <img src=\"data:image/svg+xml;base64,PHN2Zy"), "{page}");
        assert!(page.contains("alt=\"t plot\"> and <span class=\"missing\">Plot not available: lost"), "{page}");
        assert!(!page.contains("src=\"plots/"), "every shown plot is embedded: {page}");
    }

    #[test]
    fn page_without_a_title_starts_with_the_provenance() {
        let page = html("Just text.\n", Path::new("."), &Provenance { config_json: "not json", version: "0.1.0" });
        assert!(page.contains("<title>mmtrack analysis report</title>"), "{page}");
        assert!(page.contains("<pre>not json</pre>"), "{page}");
        let at = |needle: &str| page.find(needle).unwrap_or_else(|| panic!("{needle} not in {page}"));
        assert!(at("<section id=\"provenance\">") < at("<p>Just text.</p>"));
    }
}
