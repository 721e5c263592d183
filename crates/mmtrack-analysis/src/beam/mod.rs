//! Beam-tracking results: figures of the valid-tracking experiment of
//! Shaham et al. 2020 ([`plots`]); measured beam sweeps (`mmtrack process
//! beam`) summarised per sequence and pooled per site ([`sweeps`]).
//!
//! Pure data in, rows and SVG documents out; the experiment itself runs in
//! the CLI (`mmtrack reproduce shaham`), which owns the Monte Carlo loop.
//! The SPEBT experiment of Liu et al. 2024 (`mmtrack reproduce spebt`) has
//! its figure ([`spebt_plots`]); `mmtrack analyze` checks and pools the
//! tables `process beam --tracker spebt` writes ([`spebt_analysis`]). The
//! geometric Doppler-bearing tracker of Zoechmann et al. 2019 (`mmtrack
//! reproduce zoechmann`) has its figures ([`zoechmann_plots`]); `mmtrack
//! analyze` summarises the table `process beam --tracker geometric` writes
//! ([`geometric_analysis`], [`geometric_plots`]). Every table these write is
//! declared in `mmtrack_io::table`.

pub mod geometric_analysis;
pub mod geometric_plots;
pub mod plots;
pub mod spebt_analysis;
pub mod spebt_plots;
pub mod sweeps;
pub mod zoechmann_plots;

/// What `mmtrack analyze` computed from beam-tracking tables.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BeamResults {
    /// Measured beam sweeps (`beam_sweeps_tracked`).
    pub sweeps: sweeps::BeamSweepResults,
    /// SPEBT runs (`spebt_summary` + `spebt_per_slot`).
    pub spebt: spebt_analysis::SpebtResults,
    /// Geometric Doppler-bearing tracker runs (`geometric_per_epoch`).
    pub geometric: geometric_analysis::GeometricResults,
}

impl BeamResults {
    /// Whether there is nothing.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.sweeps.is_empty() && self.spebt.is_empty() && self.geometric.is_empty()
    }
}
