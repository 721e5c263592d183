//! `--threads N`: the rayon pool a command's parallel stages run on.
//!
//! Every parallel stage (PNG decoding, odometry input, MPC detection, the
//! simulators' rendering) runs on the current rayon pool, so one flag sizes
//! them all; outputs are identical for any thread count.

use anyhow::Context;
use clap::Args;

/// The `--threads` flag of commands with parallel stages.
#[derive(Args, Clone, Copy, Debug, Default)]
pub struct ThreadsArg {
    /// Worker threads of the parallel stages (0: RAYON_NUM_THREADS when set,
    /// else one per core). The output does not depend on it.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub threads: usize,
}

impl ThreadsArg {
    /// Runs `work` on a thread of a pool of `--threads` threads; for 0, on
    /// the current pool when called from one, else on a new pool of rayon's
    /// default size. Commands run inside their pool, so parallel loops start
    /// on a pool thread instead of handing work over from the main thread at
    /// every loop (a wake-up across threads per MPC set or decode batch,
    /// which cost 20 % of `bench mpc` on one thread).
    pub fn install<R: Send>(self, work: impl FnOnce() -> R + Send) -> anyhow::Result<R> {
        let limit = mmtrack_core::limits::THREADS;
        anyhow::ensure!(
            limit.allows_count(self.threads as u64),
            "--threads {}: expected {} (nothing was done)",
            self.threads,
            limit.expected
        );
        if self.threads == 0 && rayon::current_thread_index().is_some() {
            return Ok(work());
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads)
            .build()
            .with_context(|| format!("--threads {}: cannot start the thread pool", self.threads))?;
        Ok(pool.install(work))
    }
}
