//! # mmtrack-analysis
//!
//! The `analyze` stage: reads the Parquet tables that `process` writes and
//! turns them into metrics, result tables, plots and a short report.
//!
//! - [`trajectory`]: pure metrics on in-memory poses (no I/O): association by
//!   time, KITTI drift as the KITTI devkit computes it, relative pose error,
//!   absolute trajectory error after SE(2) alignment;
//! - [`mpc`], [`mpc_plots`], [`mpc_report`]: multipath-component
//!   statistics of `process mpc` tables (Mahler et al. 2017, Figs. 7-9,
//!   12-13), their plots and report section;
//! - [`mpc_artificial`]: the artificial-channel experiment's results (Sec.
//!   IV-A, Figs. 4-5) as plain data and their plots;
//! - [`beam`]: beam-tracking results (valid tracking, Shaham et al. 2020) as
//!   tables and figures;
//! - [`plots`]: SVG plots of a trajectory evaluation (plotters, SVG backend
//!   only); `plot_common`: the helpers every figure shares;
//! - [`report`]: the Markdown report;
//! - [`palette`]: the colours and dash patterns of every multi-series figure;
//! - [`pipeline`]: discovers which tables exist, picks the metrics that apply
//!   and computes them per sequence (it calls the analyses; they never call
//!   it back);
//! - [`output`]: writes tables, plots and report into an output directory
//!   that replaces an old one only when complete;
//! - [`export`]: trajectories as TUM, KITTI and Boreas text files for evo,
//!   the KITTI devkit and pyboreas.
//!
//! Place in the data flow: `tables (Parquet) --analyze--> metrics (Parquet) +
//! plots + report`. It depends on `mmtrack-core` and `mmtrack-io` only, never
//! on algorithm crates, and never prints (the CLI does).
//!
//! - [`compare_plots`]: the compare report's overlays of several runs.
//! - [`campaign`]: several runs side by side, on polars: the runs'
//!   Hive-partitioned result tables read into one frame, group-bys per run
//!   for the pooled rows (the pooling rules are stated there and used by
//!   every report); [`compared`]: what it compares and how a value is shown
//!   (the single-run report's units and decimals).
//!
//! Polars stays inside this crate (ARCHITECTURE.md), with the feature `lazy`
//! only (the `parquet` crate reads the files). The per-sequence metrics themselves (KITTI
//! drift, RPE, ATE, MPC statistics) are algorithms on a few vectors and stay
//! plain Rust. Every result table (`trajectory_metrics`, `mpc_summary`,
//! `run_comparison`, ...) is declared in `mmtrack-io`'s
//! [`table`](mmtrack_io::table) module, with its units, and listed in
//! [`RESULT_TABLES`](mmtrack_io::table::RESULT_TABLES) for `schemas/`: this
//! crate computes the rows and writes them through `TableRow`, so every table
//! carries the same units and run metadata.

pub mod analyze;
pub mod beam;
pub mod campaign;
pub mod compare_plots;
pub mod compared;
pub mod export;
pub mod mpc;
pub mod mpc_artificial;
pub mod mpc_plots;
pub mod mpc_report;
pub mod output;
pub mod palette;
pub mod pipeline;
mod plot_common;
pub mod plots;
pub mod report;
pub mod report_html;
mod sequence_run;
pub mod slam;
pub mod trajectory;
