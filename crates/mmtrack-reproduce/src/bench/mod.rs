//! The benchmarks behind `mmtrack bench`: each measures a pipeline's speed
//! as a ratio against a baseline run in the same process (never against a
//! wall-clock number from another machine), returns the measurements as a
//! typed value (rows with their units in the names, the ratios, the targets
//! and whether each is met), and renders that value as the Markdown table
//! the README block holds.
//!
//! - [`io`]: MCAP write and read of Oxford-size radar scans against
//!   `std::fs::copy` of the same bytes;
//! - [`ingest`]: Oxford-folder ingest in scans/s against copying the folder,
//!   and its peak memory at two folder sizes;
//! - [`odometry`]: end-to-end radar odometry scans/s on real scans against
//!   decoding alone, per preset and stage, and memory against sequence length;
//! - [`mpc`]: MPC detection and tracking snapshots/s against one FFT pair per
//!   snapshot, with the GM-PHD baseline's time as a ratio;
//! - [`slam`]: the SLAM filter's time per epoch against real time and
//!   against one thread;
//! - [`measure`]: best-of-n timing, CPU time and memory from `/proc`.
//!
//! Nothing here prints or parses arguments. Where a measurement needs a
//! separate process (memory that the measuring process must not share), the
//! caller says how to start it: a [`std::process::Command`] built by the
//! front end. Whether a missed target fails the run is the caller's choice.

pub mod ingest;
pub mod io;
pub mod measure;
pub mod mpc;
pub mod odometry;
pub mod slam;

use mmtrack_core::limits::Limit;

/// Refuses the count `value` of the flag `flag` (e.g. `--repeats`) below
/// `min` or beyond `limit`, before a benchmark does any work: the error names
/// the flag, the value and what was expected.
///
/// # Errors
/// `value < min` or `value` beyond `limit`.
pub fn check_count(flag: &str, value: usize, min: usize, limit: Limit) -> anyhow::Result<()> {
    anyhow::ensure!(
        value >= min && limit.allows_count(value as u64),
        "{flag} {value}: expected {} (nothing was done)",
        limit.expected
    );
    Ok(())
}

/// The verdict cell of a benchmark table: `met` or `**missed**`.
#[must_use]
pub fn verdict_cell(met: bool) -> &'static str {
    if met { "met" } else { "**missed**" }
}
