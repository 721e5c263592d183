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
    /// Runs `work` on a pool of `--threads` threads, or on rayon's global
    /// pool for 0.
    pub fn install<R: Send>(self, work: impl FnOnce() -> R + Send) -> anyhow::Result<R> {
        if self.threads == 0 {
            return Ok(work());
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads)
            .build()
            .with_context(|| format!("--threads {}: cannot start the thread pool", self.threads))?;
        Ok(pool.install(work))
    }
}
