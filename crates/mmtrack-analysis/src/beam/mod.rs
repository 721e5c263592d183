//! Beam-tracking results: the valid-tracking experiment of Shaham et al.
//! 2020 as result tables ([`tables`]) and figures ([`plots`]); measured beam
//! sweeps (`mmtrack process beam`) summarised per sequence and pooled per
//! site ([`sweeps`]).
//!
//! Pure data in, tables and SVG documents out; the experiment itself runs in
//! the CLI (`mmtrack reproduce shaham`), which owns the Monte Carlo loop.
//! The SPEBT experiment of Liu et al. 2024 (`mmtrack reproduce spebt`) has
//! its own tables ([`spebt_tables`]) and figure ([`spebt_plots`]).

pub mod plots;
pub mod spebt_plots;
pub mod spebt_tables;
pub mod sweeps;
pub mod tables;
