//! What the experiments still inside the CLI (`reproduce spebt`) share with
//! those of `mmtrack_reproduce` ([`mmtrack_reproduce::common`]).
// TODO(issue 24): remove once spebt moves to mmtrack-reproduce.

use mmtrack_reproduce::Tier;
pub use mmtrack_reproduce::common::{Staged, check_start, load_experiment};

/// Monte Carlo runs: `--runs`, else the experiment's quick or full count.
///
/// # Errors
/// Zero runs.
pub fn run_count(explicit: Option<u64>, quick: bool, quick_runs: u64, full_runs: u64) -> anyhow::Result<u64> {
    let tier = if quick { Tier::Smoke } else { Tier::Full };
    mmtrack_reproduce::common::run_count(explicit, tier, quick_runs, full_runs)
}
