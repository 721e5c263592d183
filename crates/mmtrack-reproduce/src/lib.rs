//! # mmtrack-reproduce
//!
//! The paper experiments of mmtrack as library values: each experiment is a
//! folder with its configuration (today's `data/reproduce/<name>.toml`,
//! embedded), its Monte Carlo, and its report, and one entry point
//! `run(config, options, progress) -> Outcome`. The outcome holds the
//! metrics measured, the verdicts on the paper's claims, the files written,
//! the Markdown report and the README block.
//!
//! It sits in the *reproduce* stage of the data flow, above the algorithms
//! (`mmtrack-odometry`, `-mpc`, `-beam`, `-slam`), the simulators
//! (`mmtrack-sim`), the pipelines (`mmtrack-process`: the odometry tables,
//! the SPEBT Monte Carlo), `io` and `analysis`. It writes files (tables,
//! figures, reports) but never prints and knows no command line: progress
//! goes through
//! [`mmtrack_core::progress::Progress`], and the CLI (or Python) decides
//! what to show and which exit code a missed target gives.
//!
//! - [`model`]: the one model every experiment reports in ([`Metric`],
//!   [`Claim`] and its [`Rule`], [`Verdict`], [`Tier`], [`RunOptions`],
//!   [`Outcome`]);
//! - [`expectation`]: the regression check against
//!   `data/reproduce/<experiment>.expected.toml` (separate from the
//!   verdicts: "did our numbers move?", not "does it reproduce the paper?");
//! - [`odometry`], [`mpc_artificial`], [`mpc_convoy`], [`shaham`], [`spebt`],
//!   [`zoechmann`], [`kim`]: the experiments, one folder each
//!   (`config <- run <- report`, and `mod.rs` with `run()`);
//! - [`all`]: every experiment in one call, checked against its expectations;
//! - [`suite`]: dataset regression suites (`mmtrack check`): a user's own steps and
//!   metrics checked with the same expectation model;
//! - [`bench`]: the benchmarks of `mmtrack bench`, speed as ratios to same-run baselines;
//! - [`common`], [`readme_block`]: output directories, experiment files,
//!   trajectories, README blocks.

pub mod all;
pub mod bench;
pub mod common;
pub mod expectation;
pub mod kim;
pub mod model;
pub mod mpc_artificial;
pub mod mpc_convoy;
pub mod odometry;
pub mod readme_block;
pub mod request;
pub mod shaham;
pub mod spebt;
pub mod suite;
pub mod zoechmann;

pub use model::{Claim, Metric, Outcome, ReadmeBlock, Rule, RunOptions, Tier, Verdict};
