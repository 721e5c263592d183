//! Multipath-component detection plus short- and long-term tracking
//! throughput, against a same-run baseline of one forward + inverse FFT per
//! snapshot, with the GM-PHD baseline tracker's time on the same detections
//! as a ratio.
//!
//! The input is generated in memory on the shared signal model
//! (`mmtrack_core::sounder`): sets of 6 snapshots 0.717 ms apart, a set every
//! 10 ms, 2048 taps of 1 ns at a 5.7 GHz carrier, 40 paths per snapshot with
//! delays spread over the window, powers -90..-125 dB, a slow linear delay
//! drift (Doppler up to +-400 Hz) and seeded complex white noise at -140 dB.
//! Generation is not timed; only [`CHUNK_SETS`] sets are held at a time (about
//! 13 MB of taps), so memory does not grow with the snapshot count. Every
//! timed stage sees the same chunk.
//!
//! The GM-PHD baseline is also timed alone on drawn sparse and dense
//! detections ([`gmphd`]), so its cost per snapshot can be followed apart
//! from the detector.

pub mod gmphd;

use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;
use mmtrack_core::limits;
use mmtrack_core::random::standard_normal;
use mmtrack_core::sounder::{SounderBand, cir_from_spectrum};
use mmtrack_core::{CirSnapshot, Complex64, MpcDetection, MpcTrack};
use mmtrack_mpc::short_term::is_full_lifetime;
use mmtrack_mpc::{
    GmPhdConfig, GmPhdSnapshot, LongTermTracker, MpcConfig, MpcPipeline, SounderPulse, short_term_tracks, track_gmphd,
};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;
use rustfft::{Fft, FftPlanner};

use super::{check_count, verdict_cell};
use crate::common::load_average;

/// The target: this many snapshots ...
pub const MPC_TARGET_SNAPSHOTS: usize = 10_000;
/// ... in at most this many seconds on one thread of this 2-core machine
/// (the paper's implementation needed 95 s per 100 snapshots) ...
pub const MPC_TARGET_S: f64 = 1.0;
/// ... at most this many times the FFT baseline of the same run ...
pub const MPC_TARGET_FFT_RATIO: f64 = 8.0;
/// ... with at most this many detections per true path.
pub const MPC_TARGET_DETECTIONS_PER_PATH: f64 = 1.3;

/// The README block that [`markdown`] fills.
pub const README_BLOCK: &str = "bench-mpc";

/// Taps per CIR (the benchmark size).
const TAPS: usize = 2048;
/// 1 GHz sounder bandwidth: 1 ns taps, as the paper's sounder.
const TAP_SPACING_S: f64 = 1e-9;
/// The paper's carrier.
const CARRIER_HZ: f64 = 5.7e9;
/// The paper's set structure: 6 snapshots 0.717 ms apart, a set every 10 ms.
const SNAPSHOTS_PER_SET: usize = 6;
const SNAPSHOT_PERIOD_NS: i64 = 717_000;
const SET_PERIOD_NS: i64 = 10_000_000;
/// Mean noise power per tap, dB.
const NOISE_DB: f64 = -140.0;
/// Path powers are drawn uniformly from this range, dB.
const POWER_RANGE_DB: (f64, f64) = (-125.0, -90.0);
/// Path Dopplers are drawn uniformly from +- this, Hz.
const MAX_DOPPLER_HZ: f64 = 400.0;
/// Delays stay this far from both ends of the CIR window, seconds.
const DELAY_MARGIN_S: f64 = 16e-9;
/// Sets generated and held at a time.
pub const CHUNK_SETS: usize = 64;
const SEED: u64 = 5;

/// What to measure.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MpcBenchOptions {
    /// Snapshots to process (sets of 6; the last set may be shorter).
    pub snapshots: usize,
    /// Paths per snapshot.
    pub mpcs: usize,
    /// Thread counts to measure, each at least 1.
    pub threads: Vec<usize>,
}

impl Default for MpcBenchOptions {
    fn default() -> Self {
        Self { snapshots: MPC_TARGET_SNAPSHOTS, mpcs: 40, threads: vec![1, 2] }
    }
}

impl MpcBenchOptions {
    /// Refuses absurd counts before any snapshot is made or pool started.
    ///
    /// # Errors
    /// `snapshots`, `mpcs` or a thread count outside
    /// [`limits::BENCH_SNAPSHOTS`], [`limits::BENCH_PATHS`] or
    /// [`limits::THREADS`] (each at least 1 here), or no thread count.
    pub fn validate(&self) -> anyhow::Result<()> {
        check_count("--snapshots", self.snapshots, 1, limits::BENCH_SNAPSHOTS)?;
        check_count("--mpcs", self.mpcs, 1, limits::BENCH_PATHS)?;
        anyhow::ensure!(!self.threads.is_empty(), "--threads: give at least one thread count (nothing was done)");
        for &threads in &self.threads {
            check_count("--threads", threads, 1, limits::THREADS)?;
        }
        Ok(())
    }
}

/// One simulated path: delay at t = 0, linear delay drift and amplitude.
struct SimPath {
    delay_s: f64,
    /// `d tau / dt`, s/s (Doppler `-f_c d tau / dt`).
    delay_rate: f64,
    magnitude: f64,
    phase_rad: f64,
}

/// The simulated channel: fixed paths drifting in delay, seen through a flat pulse.
struct Channel {
    band: SounderBand,
    pulse: SounderPulse,
    paths: Vec<SimPath>,
}

impl Channel {
    /// `mpcs` paths, one per equal slot of the delay window (placed in the
    /// middle half of its slot, so neighbours stay several pulse widths apart).
    fn new(mpcs: usize) -> anyhow::Result<Self> {
        let band = SounderBand::new(TAPS, TAP_SPACING_S)?;
        let pulse = SounderPulse::flat(&band);
        let mut rng = Pcg64::seed_from_u64(SEED);
        let span_s = TAPS as f64 * TAP_SPACING_S - 2.0 * DELAY_MARGIN_S;
        let slot_s = span_s / mpcs.max(1) as f64;
        let paths = (0..mpcs)
            .map(|i| {
                let power_db = POWER_RANGE_DB.0 + (POWER_RANGE_DB.1 - POWER_RANGE_DB.0) * rng.random::<f64>();
                let doppler_hz = MAX_DOPPLER_HZ * (2.0 * rng.random::<f64>() - 1.0);
                SimPath {
                    delay_s: DELAY_MARGIN_S + slot_s * (i as f64 + 0.25 + 0.5 * rng.random::<f64>()),
                    delay_rate: -doppler_hz / CARRIER_HZ,
                    magnitude: 10f64.powf(power_db / 20.0),
                    phase_rad: std::f64::consts::TAU * rng.random::<f64>(),
                }
            })
            .collect();
        Ok(Self { band, pulse, paths })
    }

    /// Snapshot `k` of set `set`: the paths at their drifted delays (carrier
    /// phase following the delay) plus white noise seeded by the snapshot's
    /// position, so the content does not depend on the thread count.
    fn snapshot(&self, set: u64, k: u32) -> CirSnapshot {
        let t_ns = set as i64 * SET_PERIOD_NS + i64::from(k) * SNAPSHOT_PERIOD_NS;
        let t_s = t_ns as f64 * 1e-9;
        let mut spectrum = vec![Complex64::default(); TAPS];
        for path in &self.paths {
            let drift_s = path.delay_rate * t_s;
            let phase = path.phase_rad - std::f64::consts::TAU * CARRIER_HZ * drift_s;
            let amplitude = Complex64::from_polar(path.magnitude, phase);
            self.band.add_path(&mut spectrum, self.pulse.spectrum(), path.delay_s + drift_s, amplitude);
        }
        let mut taps = cir_from_spectrum(&spectrum);
        let index = set * SNAPSHOTS_PER_SET as u64 + u64::from(k);
        let mut rng = Pcg64::seed_from_u64((SEED << 48) ^ (index + 1));
        let sigma = (10f64.powf(NOISE_DB / 10.0) / 2.0).sqrt();
        for tap in &mut taps {
            *tap += Complex64::new(sigma * standard_normal(&mut rng), sigma * standard_normal(&mut rng));
        }
        CirSnapshot {
            t_ns,
            set_index: set,
            snapshot_index: k,
            tx_antenna: 0,
            rx_antenna: 0,
            carrier_hz: CARRIER_HZ,
            tap_spacing_s: TAP_SPACING_S,
            delay_offset_s: 0.0,
            taps,
            first_path_hint_s: None,
        }
    }

    /// Sets `first..first + count` of a run of `total` snapshots, generated on
    /// rayon's global pool.
    fn sets(&self, first: u64, count: usize, total: usize) -> Vec<Vec<CirSnapshot>> {
        (first..first + count as u64)
            .into_par_iter()
            .map(|s| {
                let start = s as usize * SNAPSHOTS_PER_SET;
                let len = total.saturating_sub(start).min(SNAPSHOTS_PER_SET);
                (0..len as u32).map(|k| self.snapshot(s, k)).collect()
            })
            .collect()
    }
}

/// The proposed method ([`MpcPipeline`]) at one thread count, with its
/// accumulated times.
///
/// The pipeline reports no timings, so the split is measured beside it: the
/// short- and long-term tracking stages are run again, timed, on the
/// detections the pipeline returned (a second [`LongTermTracker`] fed the
/// same full-lifetime tracks), and detection is the pipeline's time minus
/// that (it includes the set checks and statistics, which are small).
struct Proposed {
    threads: usize,
    pipeline: MpcPipeline,
    config: MpcConfig,
    long_term: LongTermTracker,
    total_s: f64,
    track_s: f64,
    detections: usize,
}

impl Proposed {
    fn new(config: &MpcConfig, channel: &Channel, threads: usize) -> anyhow::Result<Self> {
        let pipeline = MpcPipeline::new(config.clone(), &channel.pulse, TAP_SPACING_S, CARRIER_HZ)?;
        let long_term = LongTermTracker::new(config.long_term.clone(), CARRIER_HZ, 0)?;
        Ok(Self { threads, pipeline, config: config.clone(), long_term, total_s: 0.0, track_s: 0.0, detections: 0 })
    }

    fn detect_s(&self) -> f64 {
        self.total_s - self.track_s
    }

    /// Processes consecutive sets together, as `process mpc` does
    /// ([`MpcPipeline::SETS_PER_THREAD`] per thread); returns each set's
    /// detections per snapshot.
    fn push_sets(&mut self, sets: &[Vec<CirSnapshot>]) -> anyhow::Result<Vec<Vec<Vec<MpcDetection>>>> {
        let started = Instant::now();
        let outputs = self.pipeline.push_sets(sets)?;
        self.total_s += started.elapsed().as_secs_f64();
        let mut all_found = Vec::with_capacity(sets.len());
        for (set, output) in sets.iter().zip(outputs) {
            let found: Vec<Vec<MpcDetection>> = output.per_snapshot.into_iter().map(|s| s.detections).collect();
            self.detections += found.iter().map(Vec::len).sum::<usize>();

            let started = Instant::now();
            let tracks = short_term_tracks(&found, CARRIER_HZ, &self.config.short_term, 0);
            let full_lifetime: Vec<MpcTrack> = tracks.into_iter().filter(|t| is_full_lifetime(t, set.len())).collect();
            let entries = self.long_term.push_set(&full_lifetime);
            self.track_s += started.elapsed().as_secs_f64();
            anyhow::ensure!(
                entries.len() == output.long_term_entries.len(),
                "set {}: the re-timed tracking gave {} long-term entries, the pipeline {}",
                set.first().map_or(0, |s| s.set_index),
                entries.len(),
                output.long_term_entries.len()
            );
            all_found.push(found);
        }
        Ok(all_found)
    }
}

/// One forward + inverse FFT per snapshot (rustfft, planned once): the
/// machine-independent reference.
struct FftBaseline {
    fft: Arc<dyn Fft<f64>>,
    ifft: Arc<dyn Fft<f64>>,
    buffer: Vec<Complex64>,
    scratch: Vec<Complex64>,
    total_s: f64,
}

impl FftBaseline {
    fn new() -> Self {
        let mut planner = FftPlanner::new();
        let fft = planner.plan_fft_forward(TAPS);
        let ifft = planner.plan_fft_inverse(TAPS);
        let scratch_len = fft.get_inplace_scratch_len().max(ifft.get_inplace_scratch_len());
        Self {
            fft,
            ifft,
            buffer: vec![Complex64::default(); TAPS],
            scratch: vec![Complex64::default(); scratch_len],
            total_s: 0.0,
        }
    }

    fn run(&mut self, snapshots: &[CirSnapshot]) {
        let started = Instant::now();
        for snapshot in snapshots {
            self.buffer.copy_from_slice(&snapshot.taps);
            self.fft.process_with_scratch(&mut self.buffer, &mut self.scratch);
            self.ifft.process_with_scratch(&mut self.buffer, &mut self.scratch);
        }
        self.total_s += started.elapsed().as_secs_f64();
    }
}

/// GM-PHD (Table I) per set on the proposed method's detections.
fn time_gmphd(set: &[CirSnapshot], found: Vec<Vec<MpcDetection>>, config: &GmPhdConfig) -> anyhow::Result<f64> {
    let snapshots: Vec<GmPhdSnapshot> =
        set.iter().zip(found).map(|(s, detections)| GmPhdSnapshot::of(s, detections)).collect();
    let started = Instant::now();
    let tracks = track_gmphd(&snapshots, config)?;
    let elapsed = started.elapsed().as_secs_f64();
    std::hint::black_box(tracks);
    Ok(elapsed)
}

/// The proposed method at one thread count.
#[derive(Debug, Clone, PartialEq)]
pub struct MpcRow {
    /// Worker threads of the pool the pipeline ran in.
    pub threads: usize,
    /// Snapshots over `total_s`.
    pub snapshots_per_s: f64,
    /// Time for all the snapshots.
    pub total_s: f64,
    /// Time for [`MPC_TARGET_SNAPSHOTS`] at the measured rate.
    pub s_per_target_snapshots: f64,
    /// Detection (the pipeline's time minus the re-timed tracking).
    pub detection_s: f64,
    /// Short- and long-term tracking.
    pub tracking_s: f64,
    /// `total_s` over the FFT baseline's time.
    pub ratio_to_fft: f64,
    /// Detections of the pipeline per snapshot.
    pub detections_per_snapshot: f64,
    /// Detections per true path.
    pub detections_per_path: f64,
    /// `s_per_target_snapshots <= MPC_TARGET_S`, `ratio_to_fft <=
    /// MPC_TARGET_FFT_RATIO` and `detections_per_path <=
    /// MPC_TARGET_DETECTIONS_PER_PATH` (the target holds for one thread).
    pub target_met: bool,
}

/// The measurements of one `bench mpc` run.
#[derive(Debug, Clone, PartialEq)]
pub struct MpcBench {
    /// Snapshots processed.
    pub snapshots: usize,
    /// Simulated paths per snapshot.
    pub mpcs: usize,
    /// 1-minute load average before and after the run (Linux), to show
    /// when other work on the machine shared the cores.
    pub load_before: Option<f64>,
    /// 1-minute load average after the run (Linux).
    pub load_after: Option<f64>,
    /// Cores of the machine.
    pub cores: usize,
    /// The FFT baseline over all the snapshots.
    pub fft_s: f64,
    /// The FFT baseline per snapshot.
    pub fft_us_per_snapshot: f64,
    /// GM-PHD (one filter per set, one thread) on the first row's detections.
    pub gmphd_s: f64,
    /// `gmphd_s` over the first row's tracking time; `None` when that is zero.
    pub gmphd_ratio_to_tracking: Option<f64>,
    /// GM-PHD alone on drawn sparse and dense detections.
    pub gmphd_rows: Vec<gmphd::GmPhdRow>,
    /// The target: [`MPC_TARGET_SNAPSHOTS`] ...
    pub target_snapshots: usize,
    /// ... in at most [`MPC_TARGET_S`].
    pub target_s: f64,
    /// One row per thread count, in the order asked.
    pub rows: Vec<MpcRow>,
}

impl MpcBench {
    /// The one-thread row meets the target (false when one thread was not
    /// measured).
    #[must_use]
    pub fn target_met(&self) -> bool {
        self.rows.iter().any(|row| row.threads == 1 && row.target_met)
    }
}

/// Seconds for [`MPC_TARGET_SNAPSHOTS`] at the measured rate.
fn per_target(seconds: f64, snapshots: usize) -> f64 {
    seconds * MPC_TARGET_SNAPSHOTS as f64 / snapshots as f64
}

/// Runs the proposed method at each thread count, the FFT baseline and
/// GM-PHD on the same generated snapshots.
///
/// # Errors
/// The options are refused ([`MpcBenchOptions::validate`]), or a stage
/// fails.
pub fn run(options: &MpcBenchOptions) -> anyhow::Result<MpcBench> {
    options.validate()?;
    let load_before = load_average();
    let channel = Channel::new(options.mpcs)?;
    let config = MpcConfig::default();
    let gmphd_config = GmPhdConfig { carrier_hz: CARRIER_HZ, ..GmPhdConfig::default() };
    let mut proposed =
        options.threads.iter().map(|&t| Proposed::new(&config, &channel, t)).collect::<anyhow::Result<Vec<_>>>()?;
    // Each run happens in a pool of its thread count, installed around each
    // chunk of sets as `--threads` is around a command, so detection's
    // parallel loop starts inside the pool rather than handing every batch
    // over from this thread.
    let pools = options
        .threads
        .iter()
        .map(|&t| rayon::ThreadPoolBuilder::new().num_threads(t).build())
        .collect::<Result<Vec<_>, _>>()?;
    let mut fft = FftBaseline::new();
    let mut gmphd_s = 0.0;
    let total_sets = options.snapshots.div_ceil(SNAPSHOTS_PER_SET);
    for first in (0..total_sets).step_by(CHUNK_SETS) {
        let count = CHUNK_SETS.min(total_sets - first);
        let sets = channel.sets(first as u64, count, options.snapshots);
        for set in &sets {
            fft.run(set);
        }
        for (p, (run, pool)) in proposed.iter_mut().zip(&pools).enumerate() {
            let batch = MpcPipeline::SETS_PER_THREAD * run.threads;
            pool.install(|| -> anyhow::Result<()> {
                for batch in sets.chunks(batch) {
                    let first_set = batch.first().and_then(|set| set.first()).map_or(0, |s| s.set_index);
                    let found = run.push_sets(batch).with_context(|| format!("sets from {first_set}"))?;
                    if p == 0 {
                        for (set, found) in batch.iter().zip(found) {
                            gmphd_s += time_gmphd(set, found, &gmphd_config)?;
                        }
                    }
                }
                Ok(())
            })?;
        }
    }
    let n = options.snapshots;
    let rows: Vec<MpcRow> = proposed
        .iter()
        .map(|run| {
            let s_per_target_snapshots = per_target(run.total_s, n);
            let ratio_to_fft = run.total_s / fft.total_s;
            let detections_per_snapshot = run.detections as f64 / n as f64;
            let detections_per_path = detections_per_snapshot / options.mpcs.max(1) as f64;
            MpcRow {
                threads: run.threads,
                snapshots_per_s: n as f64 / run.total_s,
                total_s: run.total_s,
                s_per_target_snapshots,
                detection_s: run.detect_s(),
                tracking_s: run.track_s,
                ratio_to_fft,
                detections_per_snapshot,
                detections_per_path,
                target_met: s_per_target_snapshots <= MPC_TARGET_S
                    && ratio_to_fft <= MPC_TARGET_FFT_RATIO
                    && detections_per_path <= MPC_TARGET_DETECTIONS_PER_PATH,
            }
        })
        .collect();
    let gmphd_ratio_to_tracking = rows.first().filter(|r| r.tracking_s > 0.0).map(|r| gmphd_s / r.tracking_s);
    let gmphd_rows = gmphd::rows(&gmphd_config, n)?;
    Ok(MpcBench {
        snapshots: n,
        mpcs: options.mpcs,
        load_before,
        load_after: load_average(),
        cores: std::thread::available_parallelism().map_or(1, usize::from),
        fft_s: fft.total_s,
        fft_us_per_snapshot: fft.total_s / n as f64 * 1e6,
        gmphd_s,
        gmphd_ratio_to_tracking,
        gmphd_rows,
        target_snapshots: MPC_TARGET_SNAPSHOTS,
        target_s: MPC_TARGET_S,
        rows,
    })
}

/// The Markdown table of `bench` (also the README block's body).
#[must_use]
pub fn markdown(bench: &MpcBench) -> String {
    let n = bench.snapshots;
    let (target_n, target_s) = (bench.target_snapshots, bench.target_s);
    let mut out = format!(
        "`mmtrack bench mpc`: {n} simulated snapshots of {TAPS} taps (1 ns, {:.1} GHz carrier) in sets of \
         {SNAPSHOTS_PER_SET} ({:.3} ms apart, a set every {} ms), {} paths each ({:.0}..{:.0} dB, delays spread over \
         the window, linear delay drift of up to +-{MAX_DOPPLER_HZ:.0} Hz Doppler), white noise at {NOISE_DB:.0} dB; \
         generated in memory {CHUNK_SETS} sets at a time, not timed. Baseline in the same run: one forward + \
         inverse {TAPS}-point FFT (rustfft) per snapshot, {:.1} us.\n\n\
         | threads | snapshots/s | s for {n} | s per {target_n} | detection s | tracking s | \
         / FFT baseline | detections per snapshot (of {}) | per true path | target: <= {target_s} s per {target_n}, \
         <= {MPC_TARGET_FFT_RATIO:.0} x FFT, <= {MPC_TARGET_DETECTIONS_PER_PATH} per path |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
        CARRIER_HZ / 1e9,
        SNAPSHOT_PERIOD_NS as f64 / 1e6,
        SET_PERIOD_NS / 1_000_000,
        bench.mpcs,
        POWER_RANGE_DB.1,
        POWER_RANGE_DB.0,
        bench.fft_us_per_snapshot,
        bench.mpcs,
    );
    for row in &bench.rows {
        out.push_str(&format!(
            "| {} | {:.0} | {:.2} | {:.2} | {:.2} | {:.3} | {:.1} | {:.1} | {:.2} | {} |\n",
            row.threads,
            row.snapshots_per_s,
            row.total_s,
            row.s_per_target_snapshots,
            row.detection_s,
            row.tracking_s,
            row.ratio_to_fft,
            row.detections_per_snapshot,
            row.detections_per_path,
            verdict_cell(row.target_met),
        ));
    }
    if let Some(first) = bench.rows.first() {
        let ratio = bench.gmphd_ratio_to_tracking.map_or_else(|| "-".into(), |r| format!("{r:.1}"));
        out.push_str(&format!(
            "\nGM-PHD baseline (Table I, one filter per set, one thread) on the same detections: {:.2} s, \
             {ratio} x the proposed short- and long-term tracking ({:.3} s, {} thread).\n",
            bench.gmphd_s, first.tracking_s, first.threads,
        ));
    }
    out.push_str(&gmphd::markdown(&bench.gmphd_rows));
    out.push_str(&format!("\nTarget (one thread): {}.\n", verdict_cell(bench.target_met())));
    let load = |l: Option<f64>| l.map_or_else(|| "-".to_string(), |l| format!("{l:.1}"));
    out.push_str(&format!(
        "\n1-minute load average before / after the run: {} / {} (on {} cores; above that, other work shared them).\n",
        load(bench.load_before),
        load(bench.load_after),
        bench.cores,
    ));
    out
}
