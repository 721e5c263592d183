//! # mmtrack-analysis
//!
//! The `analyze` stage: reads the Parquet tables that `process` writes and
//! turns them into metrics, result tables, plots and a short report.
//!
//! - [`trajectory`]: pure metrics on in-memory poses (no I/O): association by
//!   time, KITTI drift as the KITTI devkit computes it, relative pose error,
//!   absolute trajectory error after SE(2) alignment;
//! - [`tables`]: result tables (`trajectory_metrics`, `drift_per_length`,
//!   `relative_pose_errors`) as `mmtrack-io` [`TableRow`](mmtrack_io::table::TableRow)s,
//!   with units; [`TABLES`] lists their specs for `schemas/`;
//! - [`mpc`], [`mpc_tables`], [`mpc_plots`], [`mpc_report`]: multipath-component
//!   statistics of `process mpc` tables (Mahler et al. 2017, Figs. 7-9,
//!   12-13), their result tables, plots and report section;
//! - [`mpc_artificial`]: the artificial-channel experiment's results (Sec.
//!   IV-A, Figs. 4-5) as plain data and their plots;
//! - [`beam`]: beam-tracking results (valid tracking, Shaham et al. 2020) as
//!   tables and figures;
//! - [`plots`]: SVG plots (plotters, SVG backend only);
//! - [`report`]: the Markdown report;
//! - [`pipeline`]: discovers which tables exist, picks the metrics that apply
//!   and computes them per sequence;
//! - [`output`]: writes tables, plots and report into an output directory
//!   that replaces an old one only when complete;
//! - [`export`]: trajectories as TUM, KITTI and Boreas text files for evo,
//!   the KITTI devkit and pyboreas.
//!
//! Place in the data flow: `tables (Parquet) --analyze--> metrics (Parquet) +
//! plots + report`. It depends on `mmtrack-core` and `mmtrack-io` only, never
//! on algorithm crates, and never prints (the CLI does).
//!
//! ARCHITECTURE.md places polars here. This crate does not use it yet: the
//! metrics so far are a few vectors per sequence, written through
//! `mmtrack-io`'s `TableRow`, and polars would multiply the build time of the
//! workspace on small machines for nothing we need. Campaign-wide queries run
//! on the Hive-partitioned output with DuckDB or polars outside the binary.

pub mod beam;
pub mod export;
pub mod mpc;
pub mod mpc_artificial;
pub mod mpc_plots;
pub mod mpc_report;
pub mod mpc_tables;
pub mod output;
pub mod pipeline;
pub mod plots;
pub mod report;
pub mod report_html;
pub mod slam;
pub mod tables;
pub mod trajectory;

pub use tables::TABLES;
