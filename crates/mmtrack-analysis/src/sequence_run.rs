//! The provenance of a run's result tables, per sequence: each sequence's
//! tables on the time base its input tables state.

use std::collections::BTreeMap;

use mmtrack_io::table::{RunInfo, TableTimeBase};

/// A run's provenance for the tables of each sequence: the run's, with the
/// time base the sequence's input tables state ([`RunResults::time_bases`](crate::pipeline::RunResults::time_bases);
/// the run's own where they state none).
pub(crate) struct SequenceRun<'a> {
    run: &'a RunInfo,
    time_bases: &'a BTreeMap<String, TableTimeBase>,
}

impl<'a> SequenceRun<'a> {
    /// `run`, with the time base of each sequence in `time_bases`.
    pub(crate) fn new(run: &'a RunInfo, time_bases: &'a BTreeMap<String, TableTimeBase>) -> Self {
        Self { run, time_bases }
    }

    /// For the tables of `sequence`.
    pub(crate) fn at(&self, sequence: &str) -> RunInfo {
        let mut run = self.run.clone();
        if let Some(time_base) = self.time_bases.get(sequence) {
            run.time_base = time_base.clone();
        }
        run
    }

    /// For a table pooling `sequences` (partition `all`): their common time
    /// base, or `mixed`.
    pub(crate) fn pooled<'s>(&self, sequences: impl IntoIterator<Item = &'s str>) -> RunInfo {
        let mut run = self.run.clone();
        let bases: Vec<&TableTimeBase> = sequences.into_iter().filter_map(|s| self.time_bases.get(s)).collect();
        if let Some(time_base) = TableTimeBase::pooled(bases) {
            run.time_base = time_base;
        }
        run
    }
}
