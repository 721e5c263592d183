//! `--threads N`: the rayon pool a command's parallel stages run on.
//!
//! Every parallel stage (PNG decoding, odometry input, MPC detection, the
//! simulators' rendering) runs on the current rayon pool, so one flag sizes
//! them all; outputs are identical for any thread count.

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
    /// Runs `work` on a pool of `--threads` threads
    /// ([`mmtrack_process::threads::install`]).
    pub fn install<R: Send>(self, work: impl FnOnce() -> R + Send) -> anyhow::Result<R> {
        mmtrack_process::threads::install(self.threads, work)
    }
}
