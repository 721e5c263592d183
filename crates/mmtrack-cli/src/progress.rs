//! Progress bars on stderr; hidden with `--quiet` or when stderr is not a terminal.

use std::sync::{PoisonError, RwLock};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use mmtrack_core::progress::Progress;

/// A bar for `total` items of `unit` (e.g. "scans").
pub fn bar(total: u64, message: &str, unit: &str, quiet: bool) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(
        Some(total),
        if quiet { ProgressDrawTarget::hidden() } else { ProgressDrawTarget::stderr() },
    );
    let template = format!("{{msg}} [{{bar:30}}] {{pos}}/{{len}} {unit} ({{rate}}, eta {{eta}})");
    if let Ok(style) = ProgressStyle::with_template(&template) {
        let style = style.with_key("rate", |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
            let _ = w.write_str(&mmtrack_core::words::rate_per_s(state.per_sec()));
        });
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(message.to_string());
    bar
}

/// A bar counting `total` bytes, for reading large files (created with its
/// length: a bar of length 0 is drawn full, "0 B/0 B").
pub fn bytes_bar(total: u64, message: &str, quiet: bool) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(
        Some(total),
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

/// [`Progress`] of the library calls drawn as [`bar`]s: one bar per stage,
/// notes on stderr (above the bar while one is drawn); nothing with
/// `--quiet`.
pub struct IndicatifProgress {
    quiet: bool,
    /// The current stage's bar (a hidden one between stages).
    bar: RwLock<ProgressBar>,
}

impl IndicatifProgress {
    /// Progress shown on stderr unless `quiet`.
    pub fn new(quiet: bool) -> Self {
        Self { quiet, bar: RwLock::new(ProgressBar::hidden()) }
    }

    fn current(&self) -> ProgressBar {
        // A poisoned lock only means a thread panicked while swapping bars;
        // the bar itself is still usable.
        self.bar.read().unwrap_or_else(PoisonError::into_inner).clone()
    }
}

impl Progress for IndicatifProgress {
    fn start(&self, stage: &str, total: u64, unit: &str) {
        let new =
            if unit == "bytes" { bytes_bar(total, stage, self.quiet) } else { bar(total, stage, unit, self.quiet) };
        let old = std::mem::replace(&mut *self.bar.write().unwrap_or_else(PoisonError::into_inner), new);
        old.finish_and_clear();
    }

    fn set_position(&self, done: u64) {
        self.current().set_position(done);
    }

    fn advance(&self, by: u64) {
        self.current().inc(by);
    }

    fn finish(&self) {
        let old =
            std::mem::replace(&mut *self.bar.write().unwrap_or_else(PoisonError::into_inner), ProgressBar::hidden());
        old.finish_and_clear();
    }

    fn note(&self, text: &str) {
        if self.quiet {
            return;
        }
        let current = self.current();
        if current.is_hidden() {
            eprintln!("{text}");
        } else {
            current.println(text);
        }
    }
}
