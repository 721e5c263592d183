//! Progress bars on stderr; hidden with `--quiet` or when stderr is not a terminal.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar for `total` items of `unit` (e.g. "scans").
pub fn bar(total: u64, message: &str, unit: &str, quiet: bool) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(
        Some(total),
        if quiet { ProgressDrawTarget::hidden() } else { ProgressDrawTarget::stderr() },
    );
    let template = format!("{{msg}} [{{bar:30}}] {{pos}}/{{len}} {unit} ({{per_sec}}, eta {{eta}})");
    if let Ok(style) = ProgressStyle::with_template(&template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(message.to_string());
    bar
}

/// A bar counting bytes, for reading large files.
pub fn bytes_bar(message: &str, quiet: bool) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(
        Some(0),
        if quiet { ProgressDrawTarget::hidden() } else { ProgressDrawTarget::stderr() },
    );
    if let Ok(style) =
        ProgressStyle::with_template("{msg} [{bar:30}] {bytes}/{total_bytes} ({bytes_per_sec}, eta {eta})")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(message.to_string());
    bar
}

/// The CLI's [`Progress`](mmtrack_core::progress::Progress): one bar per
/// stage on stderr (bytes or items by the stage's unit), notes printed above
/// it; nothing with `--quiet`.
pub struct Bars {
    quiet: bool,
    current: std::sync::Mutex<Option<ProgressBar>>,
}

impl Bars {
    /// Bars, hidden when `quiet`.
    #[must_use]
    pub fn new(quiet: bool) -> Self {
        Self { quiet, current: std::sync::Mutex::new(None) }
    }

    fn with_bar(&self, f: impl FnOnce(&ProgressBar)) {
        let bar = self.current.lock().ok().and_then(|b| b.clone());
        if let Some(bar) = bar {
            f(&bar);
        }
    }
}

impl mmtrack_core::progress::Progress for Bars {
    fn start(&self, stage: &str, total: u64, unit: &str) {
        let bar = if unit == "bytes" {
            let bar = bytes_bar(stage, self.quiet);
            bar.set_length(total);
            bar
        } else {
            bar(total, stage, unit, self.quiet)
        };
        if let Ok(mut current) = self.current.lock()
            && let Some(old) = current.replace(bar)
        {
            old.finish_and_clear();
        }
    }

    fn set_position(&self, done: u64) {
        self.with_bar(|b| b.set_position(done));
    }

    fn advance(&self, by: u64) {
        self.with_bar(|b| b.inc(by));
    }

    fn finish(&self) {
        if let Some(bar) = self.current.lock().ok().and_then(|mut b| b.take()) {
            bar.finish_and_clear();
        }
    }

    fn note(&self, text: &str) {
        if !self.quiet {
            let bar = self.current.lock().ok().and_then(|b| b.clone());
            match bar {
                Some(bar) => bar.suspend(|| eprintln!("{text}")),
                None => eprintln!("{text}"),
            }
        }
    }
}
