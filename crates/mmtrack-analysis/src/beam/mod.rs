//! Beam-tracking results: the valid-tracking experiment of Shaham et al.
//! 2020 as result tables ([`tables`]) and figures ([`plots`]).
//!
//! Pure data in, tables and SVG documents out; the experiment itself runs in
//! the CLI (`mmtrack reproduce shaham`), which owns the Monte Carlo loop.

pub mod plots;
pub mod tables;
