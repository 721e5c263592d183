//! `mmtrack bench slam`: time per epoch of the 5G mmWave SLAM filter on the
//! paper's world (2000 particles, 10 iterations by default), against the
//! 200 ms epoch (real time) and against the same filter on one thread in
//! the same run. Target: under 4 ms per epoch (50 times faster than real
//! time) on this project's 2-core machine.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use mmtrack_sim::slam::{SlamRun, SlamScenario};
use mmtrack_slam::{SlamConfig, SlamFilter};

use crate::readme_block::replace_block;

/// Target time per epoch, milliseconds.
const TARGET_MS_PER_EPOCH: f64 = 4.0;

#[derive(Args)]
pub struct SlamBenchArgs {
    /// UE particles.
    #[arg(long, default_value_t = 2000)]
    particles: usize,
    /// Message-passing iterations (tempering stages and EKF relinearisations).
    #[arg(long, default_value_t = 10)]
    iterations: usize,
    /// Epochs of the drive (100: one lap of the paper's road).
    #[arg(long, default_value_t = 100)]
    epochs: usize,
    /// Runs per measurement; the best is reported.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// Worker threads of the measured run (0: one per core).
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Exit 1 when the target is missed.
    #[arg(long)]
    check: bool,
    /// Replace the block `<!-- bench-slam:begin -->` ... `end` in this file.
    #[arg(long, value_name = "README.md")]
    readme: Option<PathBuf>,
}

/// CPU time of this process so far (user + system, all threads), seconds,
/// from `/proc/self/stat` (Linux; clock ticks of 10 ms, the kernel's
/// USER_HZ of 100); `None` elsewhere.
fn process_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok());
    Some((ticks(11)? + ticks(12)?) / 100.0)
}

/// Best-of-`repeats` time of the whole drive on a pool of `threads`:
/// (total seconds, slowest epoch seconds in that run, CPU seconds of that run).
fn time_drive(
    run: &SlamRun,
    config: &SlamConfig,
    threads: usize,
    repeats: usize,
) -> anyhow::Result<(f64, f64, Option<f64>)> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .with_context(|| format!("--threads {threads}: cannot start the thread pool"))?;
    let prior = run.truth.first().context("no epochs")?.ue;
    let mut best = (f64::INFINITY, 0.0, None);
    for _ in 0..repeats.max(1) {
        let measured = pool.install(|| -> anyhow::Result<(f64, f64, Option<f64>)> {
            let mut filter = SlamFilter::new(config.clone(), prior, 1)?;
            let mut slowest: f64 = 0.0;
            let cpu_before = process_cpu_s();
            let start = Instant::now();
            for epoch in &run.epochs {
                let t = Instant::now();
                filter.step(epoch)?;
                slowest = slowest.max(t.elapsed().as_secs_f64());
            }
            let cpu = cpu_before.zip(process_cpu_s()).map(|(a, b)| b - a);
            Ok((start.elapsed().as_secs_f64(), slowest, cpu))
        })?;
        if measured.0 < best.0 {
            best = measured;
        }
    }
    Ok(best)
}

pub fn run(args: &SlamBenchArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let scenario = SlamScenario { epochs: args.epochs, ..SlamScenario::default() };
    let drive = scenario.realise(1, 0)?;
    let config = SlamConfig { particles: args.particles, iterations: args.iterations, ..SlamConfig::default() };
    config.validate()?;
    let paths: usize = drive.epochs.iter().map(|e| e.paths.len()).sum();
    let threads =
        if args.threads == 0 { std::thread::available_parallelism().map_or(1, |n| n.get()) } else { args.threads };
    let load_before = crate::bench_mpc::load_average();
    let (one_s, one_slowest_s, one_cpu_s) = time_drive(&drive, &config, 1, args.repeats)?;
    let (pool_s, pool_slowest_s, pool_cpu_s) = time_drive(&drive, &config, threads, args.repeats)?;
    let load_after = crate::bench_mpc::load_average();
    let epochs = drive.epochs.len() as f64;
    let ms = |s: f64| 1e3 * s / epochs;
    let epoch_ms = 1e3 * scenario.epoch_s;
    let pool_ms = ms(pool_s);
    let met = pool_ms < TARGET_MS_PER_EPOCH;
    let load_text = |l: Option<f64>| l.map_or("-".into(), |v| format!("{v:.2}"));
    let cpu_text = |c: Option<f64>| c.map_or("-".into(), |c| format!("{:.2}", ms(c)));
    let text = format!(
        "`mmtrack bench slam`: the SLAM filter over one lap of the paper's world ({} epochs of {} ms, {:.1} paths per \
         epoch), {} particles, {} iterations, best of {} runs (load average {} before, {} after).\n\n\
         | threads | ms per epoch | slowest epoch (ms) | CPU ms per epoch (all threads) | times faster than real time \
         | target < {TARGET_MS_PER_EPOCH} ms |\n\
         |---|---|---|---|---|---|\n\
         | 1 | {:.2} | {:.2} | {} | {:.0} | {} |\n\
         | {threads} | {:.2} | {:.2} | {} | {:.0} | {} |\n\n\
         Speed-up of {threads} threads over 1: {:.2}x. CPU time is the process's (/proc/self/stat, 10 ms ticks): \
         below the wall time when other work shares the cores.\n",
        drive.epochs.len(),
        epoch_ms,
        paths as f64 / epochs,
        args.particles,
        args.iterations,
        args.repeats.max(1),
        load_text(load_before),
        load_text(load_after),
        ms(one_s),
        1e3 * one_slowest_s,
        cpu_text(one_cpu_s),
        epoch_ms / ms(one_s),
        if ms(one_s) < TARGET_MS_PER_EPOCH { "met" } else { "**missed**" },
        pool_ms,
        1e3 * pool_slowest_s,
        cpu_text(pool_cpu_s),
        epoch_ms / pool_ms,
        if met { "met" } else { "**missed**" },
        one_s / pool_s,
    );
    if !quiet {
        print!("{text}");
    }
    if let Some(readme) = &args.readme {
        replace_block(readme, "bench-slam", &text)?;
    }
    Ok(if args.check && !met { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}
