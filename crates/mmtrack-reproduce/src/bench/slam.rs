//! Time per epoch of the 5G mmWave SLAM filter on the paper's world (500,
//! 2000 and 8000 particles, 10 iterations by default), against the 200 ms
//! epoch (real time) and against the same filter on one thread in the same
//! run. Targets at [`TARGET_PARTICLES`]: under [`TARGET_MS_PER_EPOCH`] per
//! epoch (50 times faster than real time) on this project's 2-core machine,
//! and a speed-up of the pool over one thread of at least
//! [`TARGET_SPEED_UP`].

use std::time::Instant;

use anyhow::Context;
use mmtrack_core::limits;
use mmtrack_sim::slam::{SlamRun, SlamScenario};
use mmtrack_slam::{SlamConfig, SlamFilter};

use super::measure::process_cpu_s;
use super::{check_count, verdict_cell};
use crate::common::load_average;

/// Target time per epoch, milliseconds, at [`TARGET_PARTICLES`].
pub const TARGET_MS_PER_EPOCH: f64 = 4.0;

/// Target speed-up of the pool (2 threads on this machine) over one thread
/// at [`TARGET_PARTICLES`].
pub const TARGET_SPEED_UP: f64 = 1.7;

/// The particle count the targets apply to (the paper's).
pub const TARGET_PARTICLES: usize = 2000;

/// The README block that [`markdown`] fills.
pub const README_BLOCK: &str = "bench-slam";

/// What to measure.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlamBenchOptions {
    /// UE particle counts, one pair of rows each.
    pub particles: Vec<usize>,
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
        Self { particles: vec![500, TARGET_PARTICLES, 8000], iterations: 10, epochs: 100, repeats: 3, threads: 0 }
    }
}

impl SlamBenchOptions {
    /// Refuses absurd counts before the drive is simulated or a pool
    /// started.
    ///
    /// # Errors
    /// No particle count, or a count outside [`limits::PARTICLES`],
    /// [`limits::ITERATIONS`], [`limits::SLAM_EPOCHS`], [`limits::BENCH_RUNS`]
    /// or [`limits::THREADS`].
    pub fn validate(&self) -> anyhow::Result<()> {
        anyhow::ensure!(!self.particles.is_empty(), "--particles: give at least one particle count (nothing was done)");
        for &particles in &self.particles {
            check_count("--particles", particles, 2, limits::PARTICLES)?;
        }
        check_count("--iterations", self.iterations, 1, limits::ITERATIONS)?;
        check_count("--epochs", self.epochs, 1, limits::SLAM_EPOCHS)?;
        check_count("--repeats", self.repeats, 1, limits::BENCH_RUNS)?;
        check_count("--threads", self.threads, 0, limits::THREADS)
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

/// One particle count on one thread and on the pool.
#[derive(Debug, Clone, PartialEq)]
pub struct ParticleRows {
    /// UE particles.
    pub particles: usize,
    /// The filter on one thread: the baseline.
    pub one_thread: SlamRow,
    /// The filter on the measured pool (`threads`, or one per core).
    pub pool: SlamRow,
    /// `one_thread` time over `pool` time.
    pub speed_up: f64,
    /// Whether the rows carry the targets (`particles == TARGET_PARTICLES`).
    pub is_target: bool,
}

impl ParticleRows {
    /// Both targets, on the pool: time per epoch and speed-up.
    #[must_use]
    pub fn targets_met(&self) -> bool {
        self.pool.target_met && self.speed_up >= TARGET_SPEED_UP
    }
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
    /// The target: [`TARGET_SPEED_UP`].
    pub target_speed_up: f64,
    /// Threads of the measured pool.
    pub threads: usize,
    /// One pair of rows per particle count, in the order asked.
    pub rows: Vec<ParticleRows>,
}

impl SlamBench {
    /// The rows at [`TARGET_PARTICLES`] were measured and meet both targets.
    #[must_use]
    pub fn target_met(&self) -> bool {
        let mut target_rows = self.rows.iter().filter(|r| r.is_target).peekable();
        target_rows.peek().is_some() && target_rows.all(ParticleRows::targets_met)
    }
}

/// One timed drive: total seconds, slowest epoch seconds, CPU seconds.
struct Timed {
    total_s: f64,
    slowest_s: f64,
    cpu_s: Option<f64>,
}

/// One timed drive on `pool`.
fn time_drive(run: &SlamRun, config: &SlamConfig, pool: &rayon::ThreadPool) -> anyhow::Result<Timed> {
    let prior = run.truth.first().context("no epochs")?.ue;
    pool.install(|| -> anyhow::Result<Timed> {
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
    })
}

/// A thread pool of `threads` workers.
fn pool_of(threads: usize) -> anyhow::Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .with_context(|| format!("--threads {threads}: cannot start the thread pool"))
}

/// Times the filter on one thread and on the measured pool, for every
/// particle count. The two are timed alternately (one thread, the pool, one
/// thread, ...) and the best of `repeats` runs of each is kept, so a change
/// of load during the run touches both alike.
///
/// # Errors
/// The options are invalid (no particle counts, no epochs, a bad filter
/// configuration), or a thread pool cannot start.
pub fn run(options: &SlamBenchOptions) -> anyhow::Result<SlamBench> {
    options.validate()?;
    let scenario = SlamScenario { epochs: options.epochs, ..SlamScenario::default() };
    let drive = scenario.realise(1, 0)?;
    let paths: usize = drive.epochs.iter().map(|e| e.paths.len()).sum();
    let threads = if options.threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        options.threads
    };
    let (one_pool, measured_pool) = (pool_of(1)?, pool_of(threads)?);
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
    let load_before = load_average();
    let mut rows = Vec::with_capacity(options.particles.len());
    for &particles in &options.particles {
        let config = SlamConfig { particles, iterations: options.iterations, ..SlamConfig::default() };
        config.validate()?;
        let unmeasured = || Timed { total_s: f64::INFINITY, slowest_s: 0.0, cpu_s: None };
        let (mut one, mut pool) = (unmeasured(), unmeasured());
        for _ in 0..options.repeats.max(1) {
            for (best, on) in [(&mut one, &one_pool), (&mut pool, &measured_pool)] {
                let measured = time_drive(&drive, &config, on)?;
                if measured.total_s < best.total_s {
                    *best = measured;
                }
            }
        }
        rows.push(ParticleRows {
            particles,
            one_thread: row(1, &one),
            pool: row(threads, &pool),
            speed_up: one.total_s / pool.total_s,
            is_target: particles == TARGET_PARTICLES,
        });
    }
    let load_after = load_average();
    Ok(SlamBench {
        options: options.clone(),
        epochs: drive.epochs.len(),
        epoch_ms,
        paths_per_epoch: paths as f64 / epochs,
        load_before,
        load_after,
        target_ms_per_epoch: TARGET_MS_PER_EPOCH,
        target_speed_up: TARGET_SPEED_UP,
        threads,
        rows,
    })
}

/// The Markdown table of `bench` (also the README block's body).
#[must_use]
pub fn markdown(bench: &SlamBench) -> String {
    let load_text = |l: Option<f64>| l.map_or("-".into(), |v| format!("{v:.2}"));
    let cpu_text = |c: Option<f64>| c.map_or("-".into(), |c| format!("{c:.2}"));
    let mut out = format!(
        "`mmtrack bench slam`: the SLAM filter over one lap of the paper's world ({} epochs of {} ms, {:.1} paths per \
         epoch), {} iterations, best of {} runs, one thread and {} threads timed alternately (load average {} \
         before, {} after).\n\n\
         | particles | threads | ms per epoch | slowest epoch (ms) | CPU ms per epoch (all threads) | times faster \
         than real time | speed-up over 1 thread |\n\
         |---|---|---|---|---|---|---|\n",
        bench.epochs,
        bench.epoch_ms,
        bench.paths_per_epoch,
        bench.options.iterations,
        bench.options.repeats.max(1),
        bench.threads,
        load_text(bench.load_before),
        load_text(bench.load_after),
    );
    for r in &bench.rows {
        for (row, speed_up) in [(&r.one_thread, "1.00x".to_string()), (&r.pool, format!("{:.2}x", r.speed_up))] {
            out.push_str(&format!(
                "| {} | {} | {:.2} | {:.2} | {} | {:.0} | {} |\n",
                r.particles,
                row.threads,
                row.ms_per_epoch,
                row.slowest_epoch_ms,
                cpu_text(row.cpu_ms_per_epoch),
                row.times_faster_than_real_time,
                speed_up,
            ));
        }
    }
    for r in bench.rows.iter().filter(|r| r.is_target) {
        out.push_str(&format!(
            "| **target** ({} particles) | {} | < {} ms: {} | | | | >= {}x: {} |\n",
            r.particles,
            r.pool.threads,
            bench.target_ms_per_epoch,
            verdict_cell(r.pool.target_met),
            bench.target_speed_up,
            verdict_cell(r.speed_up >= bench.target_speed_up),
        ));
    }
    out.push_str(
        "\nCPU time is the process's (/proc/self/stat, 10 ms ticks): below the wall time when other work shares \
         the cores.\n",
    );
    out
}
