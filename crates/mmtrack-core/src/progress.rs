//! Progress of long work: the libraries report it through [`Progress`], the
//! front end draws it (the CLI with progress bars, Python not at all).
//!
//! A library call takes `&dyn Progress` and reports stages (`start`), how far
//! it got (`set_position` / `advance`) and notes for the user (`note`: a
//! skipped record, a warning). It never prints itself. [`NoProgress`]
//! discards everything, for tests and quiet callers.
//!
//! The long loops also ask [`Progress::check_cancelled`] once per item: a
//! front end that cannot stop the process to interrupt a call (Python's
//! Ctrl-C) answers [`Cancelled`] there, and the call returns that error
//! like any other, dropping its partial outputs on the way out.

/// Receives the progress of a long-running library call.
///
/// Implementations must be cheap: `advance` may be called once per item
/// from several threads.
pub trait Progress: Sync {
    /// A new stage of `total` items of `unit` ("scans", "runs", "sets";
    /// `"bytes"` for reading files) begins; `total` 0 means unknown.
    fn start(&self, stage: &str, total: u64, unit: &str);
    /// `done` items of the current stage are finished.
    fn set_position(&self, done: u64);
    /// `by` more items of the current stage are finished.
    fn advance(&self, by: u64);
    /// The current stage is over.
    fn finish(&self);
    /// A line the user should see (a warning, a count of skipped records).
    fn note(&self, text: &str);
    /// `Err(Cancelled)` once the caller wants the call to stop early; the
    /// library returns that error at once. Never cancelled by default.
    ///
    /// # Errors
    /// [`Cancelled`] when the front end asked to stop.
    fn check_cancelled(&self) -> Result<(), Cancelled> {
        Ok(())
    }
}

/// The error of a call stopped by its front end ([`Progress::check_cancelled`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cancelled;

impl std::fmt::Display for Cancelled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("interrupted")
    }
}

impl std::error::Error for Cancelled {}

/// A [`Progress`] that discards everything.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&self, _stage: &str, _total: u64, _unit: &str) {}
    fn set_position(&self, _done: u64) {}
    fn advance(&self, _by: u64) {}
    fn finish(&self) {}
    fn note(&self, _text: &str) {}
}
