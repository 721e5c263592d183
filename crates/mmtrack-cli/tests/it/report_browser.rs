//! The analysis report (the demo's tables: radar odometry, multipath, SPEBT,
//! SLAM) and the compare report (two odometry runs) as a reader sees them:
//! rendered in headless Chromium at 1400 px wide, with screenshots kept in
//! the test's output folder (printed). Asserted: every plot inline (no
//! `<img src>` and no link to a file beside the page), no console message,
//! every SVG with tick labels on each of its axes at 12 px or more, body
//! text computed at 12 px or more, no sideways scrolling of the page, a
//! table of contents whose anchors all exist, and the provenance (commit,
//! time from `SOURCE_DATE_EPOCH`, command line), with which the page is
//! byte-identical when the same command is run again.
//!
//! Chromium is Debian's `chromium` package; the set-up installs it
//! (`apt-get update && apt-get install -y chromium`, as root) when no
//! browser is on the PATH, so the test runs rather than skips on a fresh
//! machine.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use super::common::{root, text};

/// A fixed report time (2023-11-14 22:13:20 UTC).
const SOURCE_DATE_EPOCH: &str = "1700000000";

/// A Chromium binary on the PATH, installed from Debian's packages when
/// there is none (once per test process).
fn chromium() -> String {
    static INSTALLED: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _guard = INSTALLED.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let find = || {
        ["chromium", "chromium-browser", "google-chrome", "google-chrome-stable"]
            .into_iter()
            .find(|b| Command::new(b).arg("--version").output().is_ok_and(|o| o.status.success()))
    };
    if let Some(browser) = find() {
        return browser.to_string();
    }
    let uid = Command::new("id").arg("-u").output().map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
    assert_eq!(
        uid.as_deref().unwrap_or("?"),
        "0",
        "no chromium on the PATH and not root: install Debian's `chromium` package (apt-get install -y chromium)"
    );
    eprintln!("installing chromium: apt-get update && apt-get install -y chromium");
    let status = Command::new("sh")
        .args(["-c", "apt-get update -q && apt-get install -y -q chromium"])
        .env("DEBIAN_FRONTEND", "noninteractive")
        .status()
        .expect("apt-get");
    assert!(status.success(), "apt-get install -y chromium failed: {status}");
    find().expect("chromium installed but not on the PATH").to_string()
}

/// The `<svg>...</svg>` documents inline in `page`.
fn inline_svgs(page: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = page;
    while let Some(start) = rest.find("<svg") {
        let end = rest[start..].find("</svg>").expect("an <svg> without </svg>") + start + "</svg>".len();
        out.push(&rest[start..end]);
        rest = &rest[end..];
    }
    out
}

fn is_number(text: &str) -> bool {
    let t = text.trim().trim_start_matches(['-', '+', '\u{2212}']);
    let mantissa = t.split(['e', 'E']).next().unwrap_or("");
    !mantissa.is_empty() && mantissa.chars().all(|c| c.is_ascii_digit() || c == '.') && t.parse::<f64>().is_ok()
}

/// What one SVG's text says about its axes: per panel (one per rotated
/// y-axis description) the numeric tick labels of its y and x axes, and the
/// smallest font size of any text.
#[derive(Debug)]
struct Axes {
    /// (y tick labels, x tick labels) per panel.
    ticks: Vec<(usize, usize)>,
    /// Tick labels that repeat another of their axis (e.g. `-113` five times
    /// where the steps are 0.2 dB).
    repeated: Vec<String>,
    /// Axis descriptions (y: rotated; x: plotters' bottom-aligned middle text).
    descriptions: Vec<String>,
    min_font_px: f64,
}

/// Axis names without a unit: counts, indices and probabilities.
const UNITLESS_AXES: [&str; 5] = ["CDF", "sets", "MPCs per set", "sources", "slot"];

/// Reads the axes of a plotters SVG: each panel's y-axis description is the
/// one rotated text; y tick labels are numeric texts anchored at their end,
/// x tick labels numeric texts anchored in the middle; a tick label belongs
/// to the panel whose description is nearest.
fn axes(svg: &str) -> Axes {
    let doc = roxmltree::Document::parse(svg).unwrap_or_else(|e| panic!("not well-formed SVG: {e}"));
    let at = |n: &roxmltree::Node, a: &str| n.attribute(a).and_then(|v| v.parse::<f64>().ok()).unwrap_or(f64::NAN);
    let mut panels: Vec<(f64, f64)> = Vec::new();
    let mut ticks: Vec<(bool, f64, f64, String)> = Vec::new();
    let mut min_font_px = f64::INFINITY;
    let mut descriptions = Vec::new();
    for t in doc.descendants().filter(|n| n.has_tag_name(("http://www.w3.org/2000/svg", "text"))) {
        let content: String = t.descendants().filter(roxmltree::Node::is_text).filter_map(|n| n.text()).collect();
        if content.trim().is_empty() {
            continue;
        }
        min_font_px = min_font_px.min(at(&t, "font-size"));
        let (x, y) = (at(&t, "x"), at(&t, "y"));
        if t.attribute("transform").is_some_and(|tr| tr.contains("rotate")) {
            panels.push((x, y));
            descriptions.push(content.trim().to_string());
        } else if t.attribute("dy") == Some("-0.5ex") && !is_number(&content) {
            descriptions.push(content.trim().to_string());
        } else if is_number(&content) {
            match t.attribute("text-anchor") {
                Some("end") => ticks.push((true, x, y, content.trim().to_string())),
                Some("middle") => ticks.push((false, x, y, content.trim().to_string())),
                _ => {}
            }
        }
    }
    let mut per_panel = vec![(0, 0); panels.len()];
    let mut labels: BTreeMap<(usize, bool), Vec<String>> = BTreeMap::new();
    let mut repeated = Vec::new();
    for (is_y, x, y, label) in ticks {
        let nearest = (0..panels.len()).min_by(|&a, &b| {
            let d = |k: usize| (panels[k].0 - x).hypot(panels[k].1 - y);
            d(a).total_cmp(&d(b))
        });
        if let Some(k) = nearest {
            let axis = labels.entry((k, is_y)).or_default();
            if axis.contains(&label) {
                repeated.push(label.clone());
            }
            axis.push(label);
            if is_y { per_panel[k].0 += 1 } else { per_panel[k].1 += 1 }
        }
    }
    Axes { ticks: per_panel, repeated, descriptions, min_font_px }
}

/// Appended to a copy of the page: after load, measures what the reader
/// sees and writes it into the body's `data-check` attribute.
const CHECK_SCRIPT: &str = r##"<script>
window.addEventListener('load', () => {
  let bodyMin = 1e9, bodyMinAt = '';
  const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    const el = n.parentElement;
    if (!n.textContent.trim() || el.closest('svg') || el.tagName === 'SCRIPT') continue;
    const px = parseFloat(getComputedStyle(el).fontSize);
    if (px < bodyMin) { bodyMin = px; bodyMinAt = el.tagName; }
  }
  const svgs = [...document.querySelectorAll('svg')];
  let svgMin = 1e9;
  for (const svg of svgs) {
    const vb = svg.viewBox.baseVal;
    const scale = vb && vb.width ? svg.getBoundingClientRect().width / vb.width : 1;
    for (const t of svg.querySelectorAll('text')) {
      if (t.textContent.trim()) svgMin = Math.min(svgMin, parseFloat(getComputedStyle(t).fontSize) * scale);
    }
  }
  const missing = [...document.querySelectorAll('a[href^="#"]')]
    .filter((a) => !document.getElementById(decodeURIComponent(a.getAttribute('href').slice(1)))).length;
  const anchors = document.querySelectorAll('nav.toc a[href^="#"]').length;
  const overflow = document.documentElement.scrollWidth - window.innerWidth;
  document.body.setAttribute('data-check',
    `svgs=${svgs.length} images=${document.images.length} body_min_px=${bodyMin} body_min_at=${bodyMinAt} ` +
    `svg_min_px=${svgMin.toFixed(2)} overflow_px=${overflow} toc_anchors=${anchors} missing_anchors=${missing}`);
});
</script></body>"##;

/// Runs headless Chromium at 1400 px wide on `url` with `args`; returns
/// stdout and the browser's log.
fn browse(browser: &str, args: &[&str], url: &str) -> (String, String) {
    let run = Command::new(browser)
        .args(["--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--window-size=1400,900"])
        .args(["--enable-logging=stderr", "--v=0", "--virtual-time-budget=10000"])
        .args(args)
        .arg(url)
        .output()
        .unwrap();
    let (out, log) = text(&run);
    assert!(run.status.success(), "{browser} {args:?} {url}: {log}");
    (out, log)
}

/// Checks one report page; returns the measurements of the browser.
fn check_page(browser: &str, page_path: &Path, shots: &Path, name: &str) -> BTreeMap<String, String> {
    let page = std::fs::read_to_string(page_path).unwrap();
    // Self-contained: no image file, no link to a file beside the page.
    assert!(!page.contains("<img"), "{name}: an <img> (plots must be inline SVG)");
    for href in page.split("href=\"").skip(1).map(|rest| rest.split('"').next().unwrap()) {
        assert!(href.starts_with('#') || href.starts_with("https://"), "{name}: link to {href}");
    }
    assert!(!page.contains("<script"), "{name}: the report holds no scripts");
    // Every plot: tick labels on each axis of each panel, text of 12 px or more.
    let svgs = inline_svgs(&page);
    assert!(svgs.len() >= 2, "{name}: {} plots", svgs.len());
    for (k, svg) in svgs.iter().enumerate() {
        let a = axes(svg);
        assert!(!a.ticks.is_empty(), "{name}: plot {k} has no y-axis description: {a:?}");
        assert!(a.ticks.iter().all(|&(y, x)| y >= 2 && x >= 2), "{name}: plot {k}: an axis without tick labels: {a:?}");
        assert!(a.min_font_px >= 12.0, "{name}: plot {k}: text of {} px", a.min_font_px);
        assert!(a.repeated.is_empty(), "{name}: plot {k}: tick labels repeat on one axis: {:?}", a.repeated);
        assert!(a.descriptions.len() >= 2 * a.ticks.len(), "{name}: plot {k}: an axis without a name: {a:?}");
        for d in &a.descriptions {
            assert!(d.contains('(') || UNITLESS_AXES.contains(&d.as_str()), "{name}: plot {k}: axis `{d}` has no unit");
        }
    }
    // Provenance.
    let at_epoch = "2023-11-14 22:13:20 UTC (SOURCE_DATE_EPOCH)";
    assert!(page.contains(&format!("<li>Written: {at_epoch}</li>")), "{name}: time");
    assert!(page.contains("<li>Command line: <code>"), "{name}: command line");
    let head = Command::new("git").args(["rev-parse", "HEAD"]).current_dir(root()).output();
    if let Some(head) = head.ok().filter(|h| h.status.success()) {
        let commit = String::from_utf8_lossy(&head.stdout).trim().to_string();
        assert!(page.contains(&format!("commit <code>{commit}</code>")), "{name}: commit {commit}");
    } else {
        assert!(page.contains("commit <code>unknown</code>"), "{name}: commit");
    }

    // In the browser: measurements, console, screenshot.
    let check_path = page_path.with_file_name(format!("check-{name}.html"));
    std::fs::write(&check_path, page.replace("</body>", CHECK_SCRIPT)).unwrap();
    let (dom, log) = browse(browser, &["--dump-dom"], &format!("file://{}", check_path.display()));
    let console: Vec<&str> = log
        .lines()
        .filter(|l| l.contains("CONSOLE") || l.contains("Uncaught") || (l.contains(":ERROR:") && l.contains("file://")))
        .collect();
    assert!(console.is_empty(), "{name}: console messages: {console:?}");
    let check = dom
        .split("data-check=\"")
        .nth(1)
        .and_then(|rest| rest.split('"').next())
        .unwrap_or_else(|| panic!("{name}: the check did not run: {log}\n{}", &dom[..dom.len().min(2000)]));
    let values: BTreeMap<String, String> = check
        .split_whitespace()
        .filter_map(|kv| kv.split_once('=').map(|(k, v)| (k.to_string(), v.to_string())))
        .collect();
    let num = |k: &str| values[k].parse::<f64>().unwrap_or_else(|_| panic!("{name}: {k} in {check}"));
    assert_eq!(num("svgs") as usize, svgs.len(), "{name}: {check}");
    assert_eq!(num("images"), 0.0, "{name}: {check}");
    assert!(num("body_min_px") >= 12.0, "{name}: body text below 12 px: {check}");
    assert!(num("svg_min_px") >= 12.0, "{name}: plot text shown below 12 px: {check}");
    assert!(num("overflow_px") <= 0.0, "{name}: the page scrolls sideways: {check}");
    assert!(num("toc_anchors") >= 3.0 && num("missing_anchors") == 0.0, "{name}: contents: {check}");
    let shot = shots.join(format!("{name}.png"));
    let shot_arg = format!("--screenshot={}", shot.display());
    let page_url = format!("file://{}", page_path.display());
    let (_, log) = browse(browser, &[&shot_arg, "--window-size=1400,2400"], &page_url);
    let png = std::fs::read(&shot).unwrap_or_else(|e| panic!("{}: {e}: {log}", shot.display()));
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n") && png.len() > 10_000, "{}", shot.display());
    values
}

#[test]
fn analysis_and_compare_reports_render_self_contained_in_headless_chromium() {
    let browser = chromium();
    let shots = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("report_browser");
    let _ = std::fs::remove_dir_all(&shots);
    std::fs::create_dir_all(&shots).unwrap();
    println!("report screenshots and pages: {}", shots.display());
    let dir = tempfile::tempdir().unwrap();
    let demo = Command::new(env!("CARGO_BIN_EXE_mmtrack"))
        .args(["demo", "--out", "d", "--quiet"])
        .env("SOURCE_DATE_EPOCH", SOURCE_DATE_EPOCH)
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(demo.status.success(), "{}", text(&demo).1);
    let d = dir.path().join("d");
    for (name, report) in [("analysis", "analysis/report.html"), ("compare", "compare/report.html")] {
        std::fs::copy(d.join(report), shots.join(format!("{name}.html"))).unwrap();
        let values = check_page(&browser, &d.join(report), &shots, name);
        println!("{name}: {values:?}");
    }
    let analysis = std::fs::read_to_string(d.join("analysis/report.html")).unwrap();
    for section in ["Multipath components", "SPEBT beam tracking", "5G mmWave SLAM", "Trajectory"] {
        let listed = analysis.split("</nav>").next().unwrap();
        assert!(listed.contains(section), "{section} in the contents");
    }
    // The SPEBT and SLAM plots the user found as links are inline.
    for plot in ["run 0 against the truth", "UE position and clock-bias errors", "confirmed VAs and SPs"] {
        assert!(analysis.contains(&format!("<figcaption>{plot}")), "{plot}");
    }
    let compare = std::fs::read_to_string(d.join("compare/report.html")).unwrap();
    assert!(compare.contains("<th style=\"text-align: right\">fast-cfear - cfear</th>"), "difference column");
    assert!(compare.contains("estimated trajectories of every run") && compare.contains("run fast-cfear"), "overlay");

    // The same command again: the same bytes (SOURCE_DATE_EPOCH fixes the time).
    let pages: Vec<Vec<u8>> = ["x", "y"]
        .iter()
        .map(|cwd| {
            let cwd = dir.path().join(cwd);
            std::fs::create_dir_all(&cwd).unwrap();
            let out = Command::new(env!("CARGO_BIN_EXE_mmtrack"))
                .args(["analyze", "../d/runs", "-o", "cmp", "--segment-lengths-m", "4,8,12", "-q"])
                .env("SOURCE_DATE_EPOCH", SOURCE_DATE_EPOCH)
                .current_dir(&cwd)
                .output()
                .unwrap();
            assert!(out.status.success(), "{}", text(&out).1);
            std::fs::read(cwd.join("cmp/report.html")).unwrap()
        })
        .collect();
    assert!(pages[0] == pages[1], "report.html differs between two runs of the same command");
}
