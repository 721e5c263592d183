//! The Monte Carlo of the Shaham experiment: every tracker on the same
//! realisations of each scenario point, the RMS pointing error per block
//! and the valid-tracking duration.
//!
//! Runs are split into fixed chunks computed on rayon and merged in chunk
//! order, so the numbers do not depend on the thread count.

use std::time::Instant;

use anyhow::Context;
use mmtrack_beam::valid_tracking::{RmsPerBlock, valid_tracking_blocks};
use mmtrack_beam::{OpenLoop, ProcessModel};
use mmtrack_core::progress::Progress;
use mmtrack_sim::beam::overpass::OverpassScenario;
use rayon::prelude::*;

use super::config::{Config, TRACKER_COUNT, TRACKERS, threshold_rad};
use super::overpass::{angle_ekf, pv_ekf, track};
use crate::common::load_average;

/// Runs per rayon task: fixed, so partial sums merge in the same order on
/// any number of threads.
const RUNS_PER_CHUNK: u64 = 25;

/// What one scenario point measured.
#[derive(Debug, Clone)]
pub struct PointResult {
    /// SNR, dB.
    pub snr_db: f64,
    /// Initial speed, km/h.
    pub speed_kmh: f64,
    /// RMS AoD error per block, radians, per tracker.
    pub rms_rad: [Vec<f64>; TRACKER_COUNT],
    /// Mean AoD error per block (beam minus truth), radians, per tracker:
    /// the part of the RMS error that is a systematic lag.
    pub mean_error_rad: [Vec<f64>; TRACKER_COUNT],
    /// Mean over runs of the true horizontal distance from the overpass per
    /// block, metres (negative before it).
    pub distance_m: Vec<f64>,
    /// Valid-tracking blocks per tracker (`None`: never ended).
    pub valid_blocks: [Option<usize>; TRACKER_COUNT],
    /// Seconds spent in each tracker, summed over threads (wall time inside
    /// each run: other load on the machine inflates it).
    pub tracker_cpu_s: [f64; TRACKER_COUNT],
}

/// What the whole Monte Carlo measured, and how long it took.
#[derive(Debug, Clone)]
pub struct Measured {
    /// Runs per point.
    pub runs: u64,
    /// Half the beamwidth, radians.
    pub threshold_rad: f64,
    /// One per scenario point, in the order of the targets.
    pub points: Vec<PointResult>,
    /// Wall time, seconds.
    pub elapsed_s: f64,
    /// Threads of the rayon pool.
    pub threads: usize,
    /// 1-minute load average before and after.
    pub load: (Option<f64>, Option<f64>),
}

/// Runs `runs` realisations of every scenario point of `config`.
///
/// # Errors
/// No targets, an invalid scenario or a tracker failure (naming the point
/// and run).
pub fn measure(config: &Config, runs: u64, progress: &dyn Progress) -> anyhow::Result<Measured> {
    let source = &config.source;
    anyhow::ensure!(!config.targets.is_empty(), "{source}: no [[targets]] (nothing was done)");
    let points = config.scenario_points();
    let threshold_rad = threshold_rad(&config.scenario).with_context(|| source.clone())?;

    let load_before = load_average();
    let started = Instant::now();
    let chunks = runs.div_ceil(RUNS_PER_CHUNK);
    progress.start("reproduce shaham", chunks * points.len() as u64 * RUNS_PER_CHUNK, "runs");
    let mut results = Vec::new();
    for &(snr_db, speed_kmh) in &points {
        let scenario =
            OverpassScenario { snr_db, initial_speed_kmh: speed_kmh, blocks: config.blocks, ..config.scenario.clone() };
        scenario.validate().with_context(|| format!("{source}: [scenario]"))?;
        let partials: Vec<Chunk> = (0..chunks)
            .into_par_iter()
            .map(|c| {
                let range = c * RUNS_PER_CHUNK..((c + 1) * RUNS_PER_CHUNK).min(runs);
                progress.check_cancelled()?;
                let chunk = run_chunk(&scenario, config, range);
                progress.advance(RUNS_PER_CHUNK);
                chunk
            })
            .collect::<anyhow::Result<_>>()
            .with_context(|| format!("SNR {snr_db} dB, {speed_kmh} km/h"))?;
        let mut total = Chunk::new(config.blocks);
        for part in &partials {
            total.merge(part);
        }
        let rms_rad: [Vec<f64>; TRACKER_COUNT] = std::array::from_fn(|t| total.rms[t].rms_rad());
        let valid_blocks = std::array::from_fn(|t| valid_tracking_blocks(&rms_rad[t], threshold_rad));
        let per_run = 1.0 / runs as f64;
        let mean_error_rad = total.sum_error.map(|sums| sums.iter().map(|s| s * per_run).collect());
        let distance_m = total.sum_distance_m.iter().map(|s| s * per_run).collect();
        results.push(PointResult {
            snr_db,
            speed_kmh,
            rms_rad,
            mean_error_rad,
            distance_m,
            valid_blocks,
            tracker_cpu_s: total.cpu_s,
        });
    }
    progress.finish();
    Ok(Measured {
        runs,
        threshold_rad,
        points: results,
        elapsed_s: started.elapsed().as_secs_f64(),
        threads: rayon::current_num_threads(),
        load: (load_before, load_average()),
    })
}

/// Partial sums of a chunk of runs.
struct Chunk {
    rms: [RmsPerBlock; TRACKER_COUNT],
    sum_error: [Vec<f64>; TRACKER_COUNT],
    sum_distance_m: Vec<f64>,
    cpu_s: [f64; TRACKER_COUNT],
}

impl Chunk {
    fn new(blocks: usize) -> Self {
        Self {
            rms: std::array::from_fn(|_| RmsPerBlock::new(blocks + 1)),
            sum_error: std::array::from_fn(|_| vec![0.0; blocks + 1]),
            sum_distance_m: vec![0.0; blocks + 1],
            cpu_s: [0.0; TRACKER_COUNT],
        }
    }

    fn merge(&mut self, other: &Chunk) {
        for t in 0..TRACKER_COUNT {
            self.rms[t].merge(&other.rms[t]);
            add(&mut self.sum_error[t], &other.sum_error[t]);
            self.cpu_s[t] += other.cpu_s[t];
        }
        add(&mut self.sum_distance_m, &other.sum_distance_m);
    }
}

fn add(sum: &mut [f64], values: &[f64]) {
    for (s, v) in sum.iter_mut().zip(values) {
        *s += v;
    }
}

fn run_chunk(scenario: &OverpassScenario, config: &Config, runs: std::ops::Range<u64>) -> anyhow::Result<Chunk> {
    let mut chunk = Chunk::new(scenario.blocks);
    for run_index in runs {
        let run = scenario.realise(config.seed, run_index)?;
        let distances: Vec<f64> = run.states().iter().map(|s| s.distance_m).collect();
        add(&mut chunk.sum_distance_m, &distances);
        for (t, name) in TRACKERS.iter().enumerate() {
            let started = Instant::now();
            let errors = match *name {
                "pv-ekf" => track(scenario, &run, &mut pv_ekf(scenario, &run, ProcessModel::Kinematic)?),
                "pv-ekf-paper-table" => track(scenario, &run, &mut pv_ekf(scenario, &run, ProcessModel::PaperTable)?),
                "angle-ekf" => track(scenario, &run, &mut angle_ekf(scenario, &run, config.angle_sigma_deg)?),
                _ => track(scenario, &run, &mut OpenLoop(pv_ekf(scenario, &run, ProcessModel::Kinematic)?)),
            }
            .with_context(|| format!("{name}, run {run_index}"))?;
            chunk.cpu_s[t] += started.elapsed().as_secs_f64();
            chunk.rms[t].add_run(&errors);
            add(&mut chunk.sum_error[t], &errors);
        }
    }
    Ok(chunk)
}
