//! `report.html`: the Markdown report of `mmtrack analyze` as one
//! self-contained page, for a browser or to hand to a colleague.
//!
//! The page opens with its title, a table of contents (every section and
//! every per-sequence subsection, each with an anchor) and what produced it
//! (software version and commit, when, the command line, the command's
//! configuration and inputs), then the report's sections. Every plot the
//! report shows (`![caption](plots/...svg)`) is embedded as inline SVG, so
//! the page needs no other file; a link to a file beside the report (another
//! run's report, a table) is shown as its path, not as a link that would
//! break once the page travels alone. Wide tables scroll inside their own
//! box. No scripts, no external resources.
//!
//! The Markdown is CommonMark with GitHub's pipe tables, converted by
//! pulldown-cmark. Raw HTML in the Markdown is shown as text, not passed
//! through, so the page holds only what this module writes and the SVG plots
//! this crate drew.

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
    /// The git commit the software was built from (`unknown` when built
    /// outside a git checkout), [`BUILD_COMMIT`].
    pub commit: &'a str,
    /// When the report was written, as [`report_time`] gives it.
    pub generated: &'a str,
    /// The command line of the process that wrote the report.
    pub command_line: &'a str,
}

/// The commit this crate was built from (`git rev-parse HEAD` at build
/// time, `unknown` without git; `build.rs`).
pub const BUILD_COMMIT: &str = env!("MMTRACK_BUILD_COMMIT");

/// The time a report states: `SOURCE_DATE_EPOCH` (seconds since 1970, the
/// reproducible-builds convention) when set and valid, else `now_s`; as
/// `YYYY-MM-DD HH:MM:SS UTC` with a note of its source. Byte-identical
/// reports of the same input need `SOURCE_DATE_EPOCH` set.
#[must_use]
pub fn report_time(source_date_epoch: Option<&str>, now_s: i64) -> String {
    match source_date_epoch.and_then(|v| v.trim().parse::<i64>().ok()) {
        Some(s) => format!("{} (SOURCE_DATE_EPOCH)", utc(s)),
        None => utc(now_s),
    }
}

/// Seconds since 1970-01-01 UTC as `YYYY-MM-DD HH:MM:SS UTC` (proleptic
/// Gregorian, [`mmtrack_core::calendar`]).
fn utc(seconds: i64) -> String {
    mmtrack_core::calendar::utc_text(seconds)
}

/// Page style: body text 16 px, tables 15 px, nothing below 14 px; tables
/// and code blocks scroll inside their own box, never the page.
const STYLE: &str = "body{font-family:system-ui,sans-serif;font-size:16px;max-width:1320px;margin:2em auto;\
padding:0 1em;line-height:1.45;color:#222}h1{font-size:28px}h2{font-size:23px;margin-top:2em;\
border-bottom:1px solid #ddd}h3{font-size:19px}.table-wrap{max-width:100%;overflow-x:auto;margin:1em 0}\
table{border-collapse:collapse;font-size:15px}th,td{border:1px solid #ccc;padding:0.25em 0.5em;text-align:left;\
vertical-align:top}th{background:#f2f2f2}code{background:#f4f4f4;padding:0 0.2em;font-size:15px}\
figure{margin:1em 0}.plot svg{max-width:100%;height:auto;border:1px solid #eee}figcaption{font-size:15px;\
color:#444}pre{background:#f7f7f7;padding:0.8em;font-size:14px;white-space:pre-wrap;overflow-wrap:anywhere}\
nav.toc{background:#fafafa;border:1px solid #e4e4e4;padding:0.5em 1em}nav.toc ul{margin:0.2em 0}\
.missing{color:#a00}";

/// A heading of the page: level, anchor, text.
struct Heading {
    level: HeadingLevel,
    id: String,
    text: String,
}

/// The page for `markdown`, reading the plots it shows from `dir` (the
/// results directory the Markdown's links are relative to).
#[must_use]
pub fn html(markdown: &str, dir: &Path, provenance: &Provenance<'_>) -> String {
    let mut events: Vec<Event<'_>> = Parser::new_ext(markdown, Options::ENABLE_TABLES).map(raw_html_as_text).collect();
    let title = first_title(&events).unwrap_or_else(|| "mmtrack analysis report".to_string());
    let headings = anchor_headings(&mut events);
    let front = format!("{}{}", toc_html(&headings), provenance_html(provenance));
    let mut body = Vec::with_capacity(events.len() + 1);
    let mut front_done = false;
    let mut link_depth = Vec::new();
    for piece in pieces(events) {
        match piece {
            Piece::Event(event) => {
                // The contents and provenance go right under the title.
                let title_end = matches!(event, Event::End(TagEnd::Heading(HeadingLevel::H1)));
                match event {
                    Event::Start(Tag::Table(_)) => {
                        body.push(Event::Html("<div class=\"table-wrap\">".into()));
                        body.push(event);
                    }
                    Event::End(TagEnd::Table) => {
                        body.push(event);
                        body.push(Event::Html("</div>\n".into()));
                    }
                    // A link to a file beside the report: its text and path, no link.
                    Event::Start(Tag::Link { ref dest_url, .. }) if is_local_file(dest_url) => {
                        link_depth.push(Some(dest_url.to_string()));
                    }
                    Event::Start(Tag::Link { .. }) => {
                        link_depth.push(None);
                        body.push(event);
                    }
                    Event::End(TagEnd::Link) => match link_depth.pop().flatten() {
                        Some(dest) => body.push(Event::InlineHtml(
                            format!(" (<code class=\"path\">{}</code>)", escape(&dest)).into(),
                        )),
                        None => body.push(event),
                    },
                    event => body.push(event),
                }
                if title_end && !front_done {
                    body.push(Event::Html(front.clone().into()));
                    front_done = true;
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
    if !front_done {
        out.push_str(&front);
    }
    pulldown_cmark::html::push_html(&mut out, body.into_iter());
    out.push_str("</body>\n</html>\n");
    out
}

/// Whether a link points at a file beside the report (not a URL, not an
/// anchor of the page).
fn is_local_file(dest: &str) -> bool {
    !(dest.is_empty() || dest.starts_with('#') || dest.contains("://") || dest.starts_with("mailto:"))
}

/// Gives every `##` and `###` heading an anchor (`id`), unique within the
/// page, and returns them in order for the table of contents.
fn anchor_headings(events: &mut [Event<'_>]) -> Vec<Heading> {
    let mut headings = Vec::new();
    let mut used: Vec<String> = vec!["contents".into(), "provenance".into()];
    for i in 0..events.len() {
        let Event::Start(Tag::Heading { level, .. }) = &events[i] else { continue };
        let level = *level;
        if !matches!(level, HeadingLevel::H2 | HeadingLevel::H3) {
            continue;
        }
        let mut text = String::new();
        for event in &events[i + 1..] {
            match event {
                Event::End(TagEnd::Heading(_)) => break,
                Event::Text(t) | Event::Code(t) => text.push_str(t),
                _ => {}
            }
        }
        let base = slug(&text);
        let mut id = base.clone();
        let mut n = 2;
        while used.contains(&id) {
            id = format!("{base}-{n}");
            n += 1;
        }
        used.push(id.clone());
        if let Event::Start(Tag::Heading { id: anchor, .. }) = &mut events[i] {
            *anchor = Some(CowStr::from(id.clone()));
        }
        headings.push(Heading { level, id, text });
    }
    headings
}

/// Lower-case letters and digits of `text`, runs of anything else as one `-`.
fn slug(text: &str) -> String {
    let mut out = String::new();
    for c in text.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('-') && !out.is_empty() {
            out.push('-');
        }
    }
    let out = out.trim_end_matches('-').to_string();
    if out.is_empty() { "section".into() } else { out }
}

/// The table of contents: the provenance, then every section with its
/// subsections (one per sequence) nested.
fn toc_html(headings: &[Heading]) -> String {
    let mut out = String::from(
        "<nav class=\"toc\" id=\"contents\">\n<strong>Contents</strong>\n<ul>\n<li><a href=\"#provenance\">Provenance</a></li>\n",
    );
    let mut open_sub = false;
    for (k, h) in headings.iter().enumerate() {
        let link = format!("<a href=\"#{}\">{}</a>", escape(&h.id), escape(&h.text));
        if h.level == HeadingLevel::H2 {
            if open_sub {
                out.push_str("</ul></li>\n");
                open_sub = false;
            } else if k > 0 {
                out.push_str("</li>\n");
            }
            let _ = write!(out, "<li>{link}");
        } else {
            if !open_sub {
                out.push_str("\n<ul>\n");
                open_sub = true;
            }
            let _ = writeln!(out, "<li>{link}</li>");
        }
    }
    if open_sub {
        out.push_str("</ul></li>\n");
    } else if !headings.is_empty() {
        out.push_str("</li>\n");
    }
    out.push_str("</ul>\n</nav>\n");
    out
}

fn provenance_html(p: &Provenance<'_>) -> String {
    let parsed: Option<serde_json::Value> = serde_json::from_str(p.config_json).ok();
    let input = parsed.as_ref().and_then(|v| v.get("tables")).map(|t| match t.as_str() {
        Some(s) => s.to_string(),
        None => t.to_string(),
    });
    let pretty =
        parsed.as_ref().and_then(|v| serde_json::to_string_pretty(v).ok()).unwrap_or(p.config_json.to_string());
    let mut out = String::from("<section id=\"provenance\">\n<h2>Provenance</h2>\n<ul>\n");
    let _ = writeln!(out, "<li>Software: mmtrack {}, commit <code>{}</code></li>", escape(p.version), escape(p.commit));
    let _ = writeln!(out, "<li>Written: {}</li>", escape(p.generated));
    let _ = writeln!(out, "<li>Command line: <code>{}</code></li>", escape(p.command_line));
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

    /// The SVG the image shows, when it is one and is there, as markup to
    /// place inline (any XML declaration or doctype before `<svg` dropped).
    fn svg(&self, dir: &Path) -> Option<String> {
        if !self.src.ends_with(".svg") || !is_local_file(&self.src) {
            return None;
        }
        let text = std::fs::read_to_string(dir.join(self.src.as_ref())).ok()?;
        let start = text.find("<svg")?;
        Some(text[start..].trim_end().to_string())
    }

    /// An image alone in its paragraph: the SVG inline in a figure, or a
    /// visible note when it is not there.
    fn figure(&self, dir: &Path) -> String {
        match self.svg(dir) {
            Some(svg) => format!(
                "<figure role=\"img\" aria-label=\"{}\"><div class=\"plot\">{svg}</div><figcaption>{}</figcaption></figure>\n",
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

    /// An image within text: the SVG inline, or the same note inline.
    fn inline(&self, dir: &Path) -> String {
        match self.svg(dir) {
            Some(svg) => {
                format!("<span class=\"plot\" role=\"img\" aria-label=\"{}\">{svg}</span>", self.alt_attribute())
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

#[cfg(test)]
mod tests {
    use super::*;

    fn provenance(config_json: &str) -> Provenance<'_> {
        Provenance {
            config_json,
            version: "0.1.0",
            commit: "abc123",
            generated: "2026-01-02 03:04:05 UTC",
            command_line: "mmtrack analyze in/tables -o out",
        }
    }

    #[test]
    fn report_time_honours_source_date_epoch_and_formats_utc() {
        assert_eq!(report_time(None, 0), "1970-01-01 00:00:00 UTC");
        // 2000-02-29 12:34:56 UTC = 951827696 s (a leap day).
        assert_eq!(report_time(None, 951_827_696), "2000-02-29 12:34:56 UTC");
        assert_eq!(report_time(Some("1700000000"), 5), "2023-11-14 22:13:20 UTC (SOURCE_DATE_EPOCH)");
        assert_eq!(report_time(Some("not a number"), 86_399), "1970-01-01 23:59:59 UTC");
    }

    #[test]
    fn converts_the_report_markdown_and_embeds_plots() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("plots/a")).unwrap();
        std::fs::write(
            dir.path().join("plots/a/t.svg"),
            "<?xml version=\"1.0\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\"><text>1</text></svg>\n",
        )
        .unwrap();
        let markdown = "# mmtrack analysis report\n\n## Trajectory (table `odometry`)\n\nText with <b> & **bold**\n\
                        and a [link](plots/a/t.svg), [web](https://example.org) and [up](#trajectory-table-odometry).\n\n\
                        | a | b |\n|---|---:|\n| 1 | n/a |\n\n- `s`: why\n\n\
                        ### `a`\n\n![trajectory](plots/a/t.svg)\n![gone](plots/a/none.svg)\n\nInline ![`t` plot](plots/a/t.svg) \
                        and ![lost](plots/a/lost.svg).\n\n### `a`\n\n<script>alert(1)</script>\n";
        let config = r#"{"command":"analyze","tables":"in/tables"}"#;
        let page = html(markdown, dir.path(), &provenance(config));
        assert!(page.starts_with("<!DOCTYPE html>") && page.contains("<title>mmtrack analysis report</title>"));
        for line in [
            "<li>Software: mmtrack 0.1.0, commit <code>abc123</code></li>",
            "<li>Written: 2026-01-02 03:04:05 UTC</li>",
            "<li>Command line: <code>mmtrack analyze in/tables -o out</code></li>",
            "<li>Input tables: <code>in/tables</code></li>",
        ] {
            assert!(page.contains(line), "{line}: {page}");
        }
        // Title, contents, provenance, then the first section.
        let at = |needle: &str| page.find(needle).unwrap_or_else(|| panic!("{needle} not in {page}"));
        assert!(at("<h1>mmtrack analysis report</h1>") < at("<nav class=\"toc\" id=\"contents\">"));
        assert!(at("</nav>") < at("<section id=\"provenance\">"));
        assert!(at("</section>") < at("<h2 id=\"trajectory-table-odometry\">"));
        // Every section and subsection anchored and listed; repeated names get distinct anchors.
        assert!(page.contains("<h3 id=\"a\">") && page.contains("<h3 id=\"a-2\">"), "{page}");
        for anchor in ["#provenance", "#trajectory-table-odometry", "#a\"", "#a-2\""] {
            assert!(page.contains(&format!("<a href=\"{anchor}")), "{anchor}: {page}");
        }
        // Raw HTML is text; a link to a file beside the report is its path; others stay links.
        assert!(
            page.contains(
                "<p>Text with &lt;b&gt; &amp; <strong>bold</strong>\nand a link (<code class=\"path\">plots/a/t.svg</code>), \
                 <a href=\"https://example.org\">web</a> and <a href=\"#trajectory-table-odometry\">up</a>.</p>"
            ),
            "{page}"
        );
        assert!(page.contains("&lt;script&gt;alert(1)&lt;/script&gt;") && !page.contains("<script"), "{page}");
        // Tables in their own scrolling box.
        assert!(
            page.contains(
                "<div class=\"table-wrap\"><table><thead><tr><th>a</th><th style=\"text-align: right\">b</th>"
            ),
            "{page}"
        );
        assert!(
            page.contains("<td>1</td><td style=\"text-align: right\">n/a</td></tr>\n</tbody></table>\n</div>"),
            "{page}"
        );
        assert!(page.contains("<ul>\n<li><code>s</code>: why</li>\n</ul>"), "{page}");
        // Image-only lines: a figure each, the plot inline, or a note.
        assert!(
            page.contains(
                "<figure role=\"img\" aria-label=\"trajectory\"><div class=\"plot\"><svg \
                 xmlns=\"http://www.w3.org/2000/svg\"><text>1</text></svg></div><figcaption>trajectory</figcaption></figure>"
            ),
            "{page}"
        );
        assert!(
            page.contains("<p class=\"missing\">Plot not available: gone (<code>plots/a/none.svg</code>).</p>"),
            "{page}"
        );
        // Images within text: inline in place, or the note in place.
        assert!(page.contains("<p>Inline <span class=\"plot\" role=\"img\" aria-label=\"t plot\"><svg"), "{page}");
        assert!(page.contains("</svg></span> and <span class=\"missing\">Plot not available: lost"), "{page}");
        assert!(!page.contains("<?xml") && !page.contains("src=\"") && !page.contains("href=\"plots/"), "{page}");
    }

    #[test]
    fn page_without_a_title_starts_with_the_contents_and_provenance() {
        let page = html("Just text.\n", Path::new("."), &provenance("not json"));
        assert!(page.contains("<title>mmtrack analysis report</title>"), "{page}");
        assert!(page.contains("<pre>not json</pre>"), "{page}");
        let at = |needle: &str| page.find(needle).unwrap_or_else(|| panic!("{needle} not in {page}"));
        assert!(at("<nav class=\"toc\"") < at("<section id=\"provenance\">"));
        assert!(at("<section id=\"provenance\">") < at("<p>Just text.</p>"));
    }

    #[test]
    fn slugs_are_lower_case_words_joined_by_dashes() {
        assert_eq!(
            slug("Trajectory (table `odometry` against `ground_truth`)"),
            "trajectory-table-odometry-against-ground-truth"
        );
        assert_eq!(slug("`oxford-demo` (MPC)"), "oxford-demo-mpc");
        assert_eq!(slug("()"), "section");
    }
}
