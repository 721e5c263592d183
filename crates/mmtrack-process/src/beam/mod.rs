//! The beam trackers as pipelines: the sweep trackers on measured beam
//! sweeps ([`sweep`]), SPEBT along a recording's ground truth ([`spebt`]) and
//! geometric Doppler-bearing tracking between two vehicles ([`geometric`]).

pub mod geometric;
pub mod spebt;
pub mod sweep;

use std::path::{Path, PathBuf};

use anyhow::bail;
use mmtrack_core::progress::Progress;

use crate::output::OutputOptions;
use geometric::{GeometricOptions, GeometricOutput};
use spebt::{SpebtOptions, SpebtOutput};
use sweep::{Reacquire, SweepOutput, SweepTrackerKind};

/// Refuses two recordings of one sequence among a run's inputs: both would
/// write the same partitions, and with `--force` the second replaced the
/// first (SPEBT and geometric did; the sweep trackers refused it).
///
/// # Errors
/// Naming both recordings and the sequence.
pub(crate) fn refuse_repeated_sequences<'a>(
    recordings: impl IntoIterator<Item = (&'a str, &'a Path)>,
) -> anyhow::Result<()> {
    let mut by_sequence = std::collections::BTreeMap::new();
    for (sequence, path) in recordings {
        if let Some(other) = by_sequence.insert(sequence, path) {
            bail!("{} and {}: both are sequence {sequence}; give each sequence once", other.display(), path.display());
        }
    }
    Ok(())
}

/// A tracker of `process beam --tracker`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum BeamTracker {
    /// A beam-sweep policy on measured sweeps.
    Sweep(SweepTrackerKind),
    /// SPEBT along a recording's ground truth (Liu et al. 2024).
    Spebt,
    /// Geometric Doppler-bearing tracking between two vehicles (Zoechmann et al. 2019).
    Geometric,
}

impl BeamTracker {
    /// Every tracker name, in `--tracker` order.
    pub const NAMES: [&'static str; 6] = ["window", "gnss-window", "last-full-sweep", "gnss-map", "spebt", "geometric"];

    /// The tracker of a `--tracker` name.
    ///
    /// # Errors
    /// An unknown name, listing the known ones.
    pub fn parse(name: &str) -> anyhow::Result<Self> {
        Ok(match name {
            "window" => Self::Sweep(SweepTrackerKind::Window),
            "gnss-window" => Self::Sweep(SweepTrackerKind::GnssWindow),
            "last-full-sweep" => Self::Sweep(SweepTrackerKind::LastFullSweep),
            "gnss-map" => Self::Sweep(SweepTrackerKind::GnssMap),
            "spebt" => Self::Spebt,
            "geometric" => Self::Geometric,
            other => bail!("--tracker '{other}': expected one of {}", Self::NAMES.join(", ")),
        })
    }
}

impl Reacquire {
    /// The re-acquisition of a `--reacquire` name (`coarse` or `full`).
    ///
    /// # Errors
    /// Any other name.
    pub fn parse(name: &str) -> anyhow::Result<Self> {
        match name {
            "coarse" => Ok(Self::Coarse),
            "full" => Ok(Self::Full),
            other => bail!("--reacquire '{other}': expected coarse or full"),
        }
    }
}

/// Everything `process beam` is asked to do.
#[derive(Debug, Clone)]
pub struct BeamRequest {
    /// Recordings, or directories of them ([`sweep::expand`]).
    pub recordings: Vec<PathBuf>,
    /// The trackers: sweep policies together, or `spebt` alone, or
    /// `geometric` alone.
    pub trackers: Vec<BeamTracker>,
    /// How the window trackers re-acquire the beam.
    pub reacquire: Reacquire,
    /// `--force`, `--run-id`.
    pub output: OutputOptions,
    /// The options of `spebt`.
    pub spebt: SpebtOptions,
    /// The options of `geometric`.
    pub geometric: GeometricOptions,
}

/// What [`process_beam`] did, by kind of tracker.
#[derive(Debug, Clone)]
pub enum BeamOutput {
    /// The sweep policies.
    Sweeps(SweepOutput),
    /// SPEBT.
    Spebt(SpebtOutput),
    /// Geometric tracking.
    Geometric(GeometricOutput),
}

/// `mmtrack process beam`: the trackers of `request` on its recordings,
/// tables under `output`.
///
/// # Errors
/// `spebt` or `geometric` given with other trackers, an option of one
/// tracker given to another, and the errors of the tracker's own call.
pub fn process_beam(output: &Path, request: &BeamRequest, progress: &dyn Progress) -> anyhow::Result<BeamOutput> {
    let out = request.output.resolve(output)?;
    let mut kinds = request.trackers.clone();
    kinds.sort();
    kinds.dedup();
    if kinds.is_empty() {
        return Err(mmtrack_core::error::UsageError(format!(
            "--tracker: name at least one of {}",
            BeamTracker::NAMES.join(", ")
        ))
        .into());
    }
    if request.recordings.is_empty() {
        let message = "no recordings: name at least one recording or folder (nothing was done)".to_string();
        return Err(mmtrack_core::error::UsageError(message).into());
    }
    let files = sweep::expand(&request.recordings)?;
    if kinds.contains(&BeamTracker::Geometric) {
        if kinds.len() > 1 {
            let message = "--tracker geometric runs alone (it tracks between two vehicles' ground truth); give the others in another call";
            return Err(mmtrack_core::error::UsageError::new(message).into());
        }
        return Ok(BeamOutput::Geometric(geometric::process_geometric(&files, &out, &request.geometric)?));
    }
    if let Some(flag) = request.geometric.given().first() {
        return Err(mmtrack_core::error::UsageError(format!("{flag} is an option of --tracker geometric only")).into());
    }
    if kinds.contains(&BeamTracker::Spebt) {
        if kinds.len() > 1 {
            let message = "--tracker spebt runs alone (it tracks a simulated link along the ground truth, not measured sweeps); \
                 give the sweep trackers in another call";
            return Err(mmtrack_core::error::UsageError::new(message).into());
        }
        return Ok(BeamOutput::Spebt(spebt::process_spebt(&files, &out, &request.spebt, progress)?));
    }
    if let Some(flag) = request.spebt.given().first() {
        return Err(mmtrack_core::error::UsageError(format!("{flag} is an option of --tracker spebt only")).into());
    }
    let sweep_kinds: Vec<SweepTrackerKind> = kinds
        .iter()
        .filter_map(|k| match k {
            BeamTracker::Sweep(kind) => Some(*kind),
            BeamTracker::Spebt | BeamTracker::Geometric => None,
        })
        .collect();
    Ok(BeamOutput::Sweeps(sweep::process_sweeps(
        &files,
        output,
        &sweep_kinds,
        request.reacquire,
        &request.output,
        progress,
    )?))
}
