//! Time per epoch of the 5G mmWave SLAM filter on the paper's world (2000
//! particles, 10 iterations by default), against the 200 ms epoch (real
//! time) and against the same filter on one thread in the same run. Target:
//! under [`TARGET_MS_PER_EPOCH`] per epoch (50 times faster than real time)
//! on this project's 2-core machine.

use std::time::Instant;

use anyhow::Context;
use mmtrack_sim::slam::{SlamRun, SlamScenario};
use mmtrack_slam::{SlamConfig, SlamFilter};

use super::measure::process_cpu_s;
use super::verdict_cell;
use crate::common::load_average;

/// Target time per epoch, milliseconds.
pub const TARGET_MS_PER_EPOCH: f64 = 4.0;

/// The README block that [`markdown`] fills.
pub const README_BLOCK: &str = "bench-slam";

/// What to measure.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlamBenchOptions {
    /// UE particles.
    pub particles: usize,
    /// Message-passing iterations (tempering stages and EKF relinearisations).
    pub iterations: usize,
    /// Epochs of the drive (100: one lap of the paper's road).
    pub epochs: usize,
    /// Runs per measurement; the best is reported.
    pub repeats: usize,
    /// Worker threads of the measured run (0: one per core).
    pub threads: usize,
}

impl Default for SlamBenchOptions {
    fn default() -> Self {
        Self { particles: 2000, iterations: 10, epochs: 100, repeats: 3, threads: 0 }
    }
}

/// The drive timed on one pool.
#[derive(Debug, Clone, PartialEq)]
pub struct SlamRow {
    /// Worker threads of the pool.
    pub threads: usize,
    /// Wall time of the best run per epoch.
    pub ms_per_epoch: f64,
    /// The slowest epoch of the best run.
    pub slowest_epoch_ms: f64,
    /// CPU time of the process (all threads) per epoch in the best run; `None` without `/proc`.
    pub cpu_ms_per_epoch: Option<f64>,
    /// Epoch duration over `ms_per_epoch`.
    pub times_faster_than_real_time: f64,
    /// `ms_per_epoch < TARGET_MS_PER_EPOCH`.
    pub target_met: bool,
}

/// The measurements of one `bench slam` run.
#[derive(Debug, Clone, PartialEq)]
pub struct SlamBench {
    /// What was measured.
    pub options: SlamBenchOptions,
    /// Epochs of the drive.
    pub epochs: usize,
    /// Duration of one epoch (real time).
    pub epoch_ms: f64,
    /// Mean paths (measurements) per epoch.
    pub paths_per_epoch: f64,
    /// 1-minute load average before and after the run (Linux).
    pub load_before: Option<f64>,
    /// 1-minute load average after the run (Linux).
    pub load_after: Option<f64>,
    /// The target: [`TARGET_MS_PER_EPOCH`].
    pub target_ms_per_epoch: f64,
    /// The filter on one thread: the baseline.
    pub one_thread: SlamRow,
    /// The filter on the measured pool (`threads`, or one per core).
    pub pool: SlamRow,
    /// `one_thread` time over `pool` time.
    pub speed_up: f64,
}

impl SlamBench {
    /// The target is the measured pool's.
    #[must_use]
    pub fn target_met(&self) -> bool {
        self.pool.target_met
    }
}

/// One timed drive: total seconds, slowest epoch seconds, CPU seconds.
struct Timed {
    total_s: f64,
    slowest_s: f64,
    cpu_s: Option<f64>,
}

/// Best-of-`repeats` time of the whole drive on a pool of `threads`.
fn time_drive(run: &SlamRun, config: &SlamConfig, threads: usize, repeats: usize) -> anyhow::Result<Timed> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .with_context(|| format!("--threads {threads}: cannot start the thread pool"))?;
    let prior = run.truth.first().context("no epochs")?.ue;
    let mut best = Timed { total_s: f64::INFINITY, slowest_s: 0.0, cpu_s: None };
    for _ in 0..repeats.max(1) {
        let measured = pool.install(|| -> anyhow::Result<Timed> {
            let mut filter = SlamFilter::new(config.clone(), prior, 1)?;
            let (mut total_s, mut slowest_s) = (0.0, 0.0_f64);
            let cpu_before = process_cpu_s();
            // The total is the sum of the epochs' own times (not the loop's
            // wall time), so the mean is never above the slowest epoch when
            // the process is descheduled between two epochs.
            for epoch in &run.epochs {
                let t = Instant::now();
                filter.step(epoch)?;
                let epoch_s = t.elapsed().as_secs_f64();
                total_s += epoch_s;
                slowest_s = slowest_s.max(epoch_s);
            }
            let cpu_s = cpu_before.zip(process_cpu_s()).map(|(a, b)| b - a);
            Ok(Timed { total_s, slowest_s, cpu_s })
        })?;
        if measured.total_s < best.total_s {
            best = measured;
        }
    }
    Ok(best)
}

/// Times the filter on one thread and on the measured pool.
///
/// # Errors
/// The options are invalid (no epochs, a bad filter configuration), or the
/// thread pool cannot start.
pub fn run(options: &SlamBenchOptions) -> anyhow::Result<SlamBench> {
    let scenario = SlamScenario { epochs: options.epochs, ..SlamScenario::default() };
    let drive = scenario.realise(1, 0)?;
    let config = SlamConfig { particles: options.particles, iterations: options.iterations, ..SlamConfig::default() };
    config.validate()?;
    let paths: usize = drive.epochs.iter().map(|e| e.paths.len()).sum();
    let threads = if options.threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        options.threads
    };
    let load_before = load_average();
    let one = time_drive(&drive, &config, 1, options.repeats)?;
    let pool = time_drive(&drive, &config, threads, options.repeats)?;
    let load_after = load_average();
    let epochs = drive.epochs.len() as f64;
    let epoch_ms = 1e3 * scenario.epoch_s;
    let row = |threads: usize, timed: &Timed| {
        let ms_per_epoch = 1e3 * timed.total_s / epochs;
        SlamRow {
            threads,
            ms_per_epoch,
            slowest_epoch_ms: 1e3 * timed.slowest_s,
            cpu_ms_per_epoch: timed.cpu_s.map(|c| 1e3 * c / epochs),
            times_faster_than_real_time: epoch_ms / ms_per_epoch,
            target_met: ms_per_epoch < TARGET_MS_PER_EPOCH,
        }
    };
    Ok(SlamBench {
        options: options.clone(),
        epochs: drive.epochs.len(),
        epoch_ms,
        paths_per_epoch: paths as f64 / epochs,
        load_before,
        load_after,
        target_ms_per_epoch: TARGET_MS_PER_EPOCH,
        one_thread: row(1, &one),
        pool: row(threads, &pool),
        speed_up: one.total_s / pool.total_s,
    })
}

/// The Markdown table of `bench` (also the README block's body).
#[must_use]
pub fn markdown(bench: &SlamBench) -> String {
    let load_text = |l: Option<f64>| l.map_or("-".into(), |v| format!("{v:.2}"));
    let cpu_text = |c: Option<f64>| c.map_or("-".into(), |c| format!("{c:.2}"));
    let row = |r: &SlamRow| {
        format!(
            "| {} | {:.2} | {:.2} | {} | {:.0} | {} |\n",
            r.threads,
            r.ms_per_epoch,
            r.slowest_epoch_ms,
            cpu_text(r.cpu_ms_per_epoch),
            r.times_faster_than_real_time,
            verdict_cell(r.target_met),
        )
    };
    format!(
        "`mmtrack bench slam`: the SLAM filter over one lap of the paper's world ({} epochs of {} ms, {:.1} paths per \
         epoch), {} particles, {} iterations, best of {} runs (load average {} before, {} after).\n\n\
         | threads | ms per epoch | slowest epoch (ms) | CPU ms per epoch (all threads) | times faster than real time \
         | target < {} ms |\n\
         |---|---|---|---|---|---|\n\
         {}{}\n\
         Speed-up of {} threads over 1: {:.2}x. CPU time is the process's (/proc/self/stat, 10 ms ticks): \
         below the wall time when other work shares the cores.\n",
        bench.epochs,
        bench.epoch_ms,
        bench.paths_per_epoch,
        bench.options.particles,
        bench.options.iterations,
        bench.options.repeats.max(1),
        load_text(bench.load_before),
        load_text(bench.load_after),
        bench.target_ms_per_epoch,
        row(&bench.one_thread),
        row(&bench.pool),
        bench.pool.threads,
        bench.speed_up,
    )
}
