//! Progress of long work: the libraries report it through [`Progress`], the
//! front end draws it (the CLI with progress bars, Python not at all).
//!
//! A library call takes `&dyn Progress` and reports stages (`start`), how far
//! it got (`set_position` / `advance`) and notes for the user (`note`: a
//! skipped record, a warning). It never prints itself. [`NoProgress`]
//! discards everything, for tests and quiet callers.

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
}

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
