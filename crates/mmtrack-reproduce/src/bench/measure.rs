//! How the benchmarks measure: best-of-n wall time, the process's CPU time,
//! its peak resident memory, and the resident memory of a child process
//! sampled over its life (all from `/proc`, Linux; `None` or an error
//! elsewhere).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The shortest of `repeats` runs of `f` (at least one): the run least
/// disturbed by the rest of the machine.
///
/// # Errors
/// The first error of `f`.
pub fn best_of(repeats: usize, mut f: impl FnMut() -> anyhow::Result<()>) -> anyhow::Result<Duration> {
    let mut best = Duration::MAX;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        f()?;
        best = best.min(start.elapsed());
    }
    Ok(best)
}

/// CPU time of this process so far (user + system, all threads), seconds,
/// from `/proc/self/stat` (Linux; clock ticks of 10 ms, the kernel's
/// USER_HZ of 100); `None` elsewhere.
#[must_use]
pub fn process_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok());
    Some((ticks(11)? + ticks(12)?) / 100.0)
}

/// Resets the peak resident memory of this process (Linux: writes 5 to
/// `/proc/self/clear_refs`, which resets `VmHWM`); does nothing elsewhere.
pub fn reset_peak_rss() {
    // Best effort: where it fails, the peak read next covers the whole life.
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// Peak resident memory of this process since the last reset, bytes
/// (`VmHWM` of `/proc/self/status`); `None` elsewhere.
#[must_use]
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    status_kib(&status, "VmHWM:").map(|kib| kib * 1024)
}

/// The value of field `name` (e.g. `"VmRSS:"`) of a `/proc/<pid>/status`
/// text, KiB.
fn status_kib(status: &str, name: &str) -> Option<u64> {
    status.lines().find(|l| l.starts_with(name)).and_then(|l| l.split_whitespace().nth(1)).and_then(|v| v.parse().ok())
}

/// Resident memory of a child process over its life.
#[derive(Debug, Clone, PartialEq)]
pub struct ChildMemory {
    /// `VmHWM` at the last sample, MB.
    pub peak_mb: f64,
    /// `VmRSS` samples, MB, in time order (taken every [`CHILD_SAMPLE_PERIOD`]).
    pub rss_mb: Vec<f64>,
}

/// Period of the child's memory samples.
pub const CHILD_SAMPLE_PERIOD: Duration = Duration::from_millis(5);

impl ChildMemory {
    /// Mean of the samples of quarter `q` (0..4) of the run.
    #[must_use]
    pub fn mean_rss_mb(&self, q: usize) -> f64 {
        let n = self.rss_mb.len();
        let start = (n * q / 4).min(n);
        let end = (n * (q + 1) / 4).max(start + 1).min(n);
        let part = &self.rss_mb[start..end];
        part.iter().sum::<f64>() / part.len().max(1) as f64
    }
}

/// Runs `command` (its stdout discarded) and samples its resident memory
/// (`/proc/<pid>/status`, Linux) until it exits.
///
/// # Errors
/// The child cannot start or fails (`what` names it), or there is no
/// `/proc/<pid>/status` to read.
pub fn child_memory(mut command: Command, what: &str) -> anyhow::Result<ChildMemory> {
    let mut child = command.stdout(Stdio::null()).spawn()?;
    let status_path = format!("/proc/{}/status", child.id());
    let mut memory = ChildMemory { peak_mb: 0.0, rss_mb: Vec::new() };
    let status = loop {
        if let Ok(status) = std::fs::read_to_string(&status_path)
            && let (Some(rss), Some(hwm)) = (status_kib(&status, "VmRSS:"), status_kib(&status, "VmHWM:"))
        {
            memory.rss_mb.push(rss as f64 * 1024.0 / 1e6);
            memory.peak_mb = memory.peak_mb.max(hwm as f64 * 1024.0 / 1e6);
        }
        if let Some(status) = child.try_wait()? {
            break status;
        }
        std::thread::sleep(CHILD_SAMPLE_PERIOD);
    };
    anyhow::ensure!(status.success(), "{what} failed ({status})");
    anyhow::ensure!(!memory.rss_mb.is_empty(), "no /proc/<pid>/status to read memory from (Linux only)");
    Ok(memory)
}

/// Total bytes of the files in `dir` (not recursive).
///
/// # Errors
/// `dir` or an entry cannot be read.
pub fn dir_bytes(dir: &Path) -> anyhow::Result<u64> {
    let mut total = 0;
    for entry in std::fs::read_dir(dir)? {
        total += entry?.metadata()?.len();
    }
    Ok(total)
}
