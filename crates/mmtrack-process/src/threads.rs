//! The worker pool a call's parallel stages run on (`--threads N` of the
//! CLI, `threads=N` of the Python package).
//!
//! Every parallel stage (PNG decoding, odometry input, MPC detection, the
//! simulators' rendering) runs on the current rayon pool, so one number
//! sizes them all; outputs are identical for any thread count.

use anyhow::Context;

/// Runs `work` on a thread of a pool of `threads` threads; for 0, on the
/// current pool when called from one, else on a new pool of rayon's default
/// size (RAYON_NUM_THREADS when set, else one per core). Calls run inside
/// their pool, so parallel loops start on a pool thread instead of handing
/// work over from the caller's thread at every loop (a wake-up across
/// threads per MPC set or decode batch, which cost 20 % of `bench mpc` on
/// one thread).
///
/// # Errors
/// A count beyond [`mmtrack_core::limits::THREADS`] (nothing is done), or a
/// pool that cannot start.
pub fn install<R: Send>(threads: usize, work: impl FnOnce() -> R + Send) -> anyhow::Result<R> {
    let limit = mmtrack_core::limits::THREADS;
    if !limit.allows_count(threads as u64) {
        let message = format!("--threads {threads}: expected {} (nothing was done)", limit.expected);
        return Err(mmtrack_core::error::UsageError(message).into());
    }
    if threads == 0 && rayon::current_thread_index().is_some() {
        return Ok(work());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .with_context(|| format!("--threads {threads}: cannot start the thread pool"))?;
    Ok(pool.install(work))
}
