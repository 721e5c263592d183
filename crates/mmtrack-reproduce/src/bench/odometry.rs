//! End-to-end radar odometry throughput on real Oxford-size scans (400 x
//! 3768), PNG decoding included, with the per-stage split, against a
//! same-run baseline that only reads and decodes; and the memory of
//! `process odometry` on a short and a long simulated drive (it must not
//! grow with the sequence).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::Context;
use mmtrack_core::limits;
use mmtrack_core::progress::NoProgress;
use mmtrack_ingest::oxford::{OxfordFolder, OxfordOptions, ingest_oxford};
use mmtrack_io::recording::Compression;
use mmtrack_io::{Durability, Overwrite, RecordingOptions};
use mmtrack_odometry::OdometryConfig;
use mmtrack_process::events::for_each_event;
use mmtrack_process::odometry::run_odometry;

use super::measure::{ChildMemory, child_memory};
use super::{check_count, verdict_cell};

/// End-to-end scans per second on this 2-core machine (CFEAR-1 reports
/// about 160 Hz for filtering and registration alone, without decode).
pub const ODOMETRY_TARGET_SCANS_PER_S: f64 = 150.0;

/// End to end over the same run's decode-only baseline, for `cfear` (issue
/// #29): its own work should cost no more than a sixth of the decoding.
pub const CFEAR_TARGET_RATIO_TO_DECODE_ONLY: f64 = 0.85;

/// The preset the ratio target applies to.
pub const RATIO_TARGET_PRESET: &str = "cfear";

/// "Memory does not grow with sequence length": resident memory late in the
/// long run may exceed that early in it by at most this factor.
pub const MEMORY_GROWTH_LIMIT: f64 = 1.10;

/// Sweeps per lap of the memory check's circular drive.
pub const MEMORY_LAP_SCANS: usize = 100;

/// The README block that [`markdown`] fills.
pub const README_BLOCK: &str = "bench-odometry";

/// What to measure.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OdometryBenchOptions {
    /// Oxford folder whose real scans are used.
    pub from: PathBuf,
    /// Passes over the sequence per preset (each pass starts a fresh pipeline).
    pub passes: usize,
    /// Scans of the long simulated drive of the memory check (laps of
    /// [`MEMORY_LAP_SCANS`]; one lap is the short drive).
    pub memory_scans: usize,
}

impl OdometryBenchOptions {
    /// Refuses absurd counts before the bench recording is built.
    ///
    /// # Errors
    /// `passes` or `memory_scans` outside [`limits::BENCH_RUNS`] or
    /// [`limits::BENCH_SCANS_ON_DISK`].
    pub fn validate(&self) -> anyhow::Result<()> {
        check_count("--passes", self.passes, 1, limits::BENCH_RUNS)?;
        check_count("--memory-scans", self.memory_scans, 4, limits::BENCH_SCANS_ON_DISK)
    }
}

/// How to start `process odometry` with the `cfear` preset on a recording,
/// writing its tables into a directory, in a child process (so that the
/// simulator's memory in this one does not count): the front end knows how
/// to start itself.
pub type ProcessOdometryCommand<'a> = &'a dyn Fn(&Path, &Path) -> Command;

/// One preset over all passes.
#[derive(Debug, Clone, PartialEq)]
pub struct PresetRow {
    /// The odometry preset (`OdometryConfig::preset`).
    pub preset: String,
    /// Scans processed over all passes.
    pub scans: usize,
    /// End to end, scans over the pipelines' elapsed time.
    pub scans_per_s: f64,
    /// `scans_per_s` over the decode-only baseline's.
    pub ratio_to_decode_only: f64,
    /// Per-scan time of the filtering stage.
    pub filter_ms_per_scan: f64,
    /// Per-scan time of the surface-point stage.
    pub surface_ms_per_scan: f64,
    /// Per-scan time of registration.
    pub register_ms_per_scan: f64,
    /// `scans_per_s >= ODOMETRY_TARGET_SCANS_PER_S`.
    pub target_met: bool,
    /// `ratio_to_decode_only >= CFEAR_TARGET_RATIO_TO_DECODE_ONLY`, for
    /// [`RATIO_TARGET_PRESET`] only (`None` for the others).
    pub ratio_target_met: Option<bool>,
}

/// Memory of `process odometry` (cfear) on a short and a long drive.
#[derive(Debug, Clone, PartialEq)]
pub struct MemoryCheck {
    /// Scans of the short drive.
    pub short_scans: usize,
    /// Scans of the long drive.
    pub long_scans: usize,
    /// Size of the short drive's recording.
    pub short_recording_mb: f64,
    /// Size of the long drive's recording.
    pub long_recording_mb: f64,
    /// Peak resident memory of the child on the short drive.
    pub short_peak_mb: f64,
    /// Peak resident memory of the child on the long drive.
    pub long_peak_mb: f64,
    /// Mean resident memory over the second and the last quarter of the long run.
    pub long_second_quarter_rss_mb: f64,
    /// Mean resident memory over the last quarter of the long run.
    pub long_last_quarter_rss_mb: f64,
    /// Last quarter over second quarter.
    pub growth_ratio: f64,
    /// The target: [`MEMORY_GROWTH_LIMIT`].
    pub growth_limit: f64,
    /// `growth_ratio <= growth_limit`.
    pub target_met: bool,
}

/// The measurements of one `bench odometry` run.
#[derive(Debug, Clone, PartialEq)]
pub struct OdometryBench {
    /// What was measured.
    pub options: OdometryBenchOptions,
    /// Scans of the recording (one pass).
    pub scans_per_pass: usize,
    /// Threads of the rayon pool that decodes.
    pub decode_threads: usize,
    /// The baseline: reading and decoding alone.
    pub decode_only_scans_per_s: f64,
    /// The target: [`ODOMETRY_TARGET_SCANS_PER_S`].
    pub target_scans_per_s: f64,
    /// One row per preset, in [`OdometryConfig::PRESETS`] order.
    pub presets: Vec<PresetRow>,
    /// Memory of `process odometry` against sequence length.
    pub memory: MemoryCheck,
}

impl OdometryBench {
    /// Every preset meets the speed target and memory stays flat.
    #[must_use]
    pub fn target_met(&self) -> bool {
        self.presets.iter().all(|r| r.target_met && r.ratio_target_met != Some(false)) && self.memory.target_met
    }
}

/// Measures every preset against decoding alone, then the memory check.
///
/// # Errors
/// `from` is not an Oxford folder, a pipeline fails, or the child process
/// of the memory check fails.
pub fn run(
    options: &OdometryBenchOptions,
    process_odometry: ProcessOdometryCommand<'_>,
) -> anyhow::Result<OdometryBench> {
    options.validate()?;
    let dir = tempfile::tempdir()?;
    let recording = dir.path().join("bench.mcap");
    ingest_quietly(&options.from, &recording)
        .with_context(|| format!("{}: cannot build the bench recording", options.from.display()))?;

    // One pass of each in turn (decode only, then every preset), so that a
    // change of load during the run touches the baseline and the presets alike.
    let configs: Vec<OdometryConfig> = OdometryConfig::PRESETS
        .iter()
        .map(|preset| OdometryConfig::preset(preset).context("preset"))
        .collect::<anyhow::Result<_>>()?;
    let (mut decoded, mut decode_s) = (0usize, 0.0);
    // Per preset: scans, elapsed, filter, surface, registration seconds.
    let mut totals = vec![(0usize, 0.0, 0.0, 0.0, 0.0); configs.len()];
    for _ in 0..options.passes {
        let started = Instant::now();
        decoded += decode_only(&recording)?;
        decode_s += started.elapsed().as_secs_f64();
        for (config, total) in configs.iter().zip(&mut totals) {
            let run = run_odometry(&recording, config.clone(), &NoProgress)?;
            total.0 += run.estimates.len();
            total.1 += run.elapsed_s;
            for t in &run.timings {
                total.2 += t.filter_s;
                total.3 += t.surface_s;
                total.4 += t.register_s;
            }
        }
    }
    let decode_only_scans_per_s = decoded as f64 / decode_s;

    let mut presets = Vec::new();
    for (preset, &(scans, elapsed_s, filter_s, surface_s, register_s)) in OdometryConfig::PRESETS.iter().zip(&totals) {
        let per_scan_ms = |s: f64| s / scans as f64 * 1e3;
        let scans_per_s = scans as f64 / elapsed_s;
        let ratio_to_decode_only = scans_per_s / decode_only_scans_per_s;
        presets.push(PresetRow {
            preset: preset.to_string(),
            scans,
            scans_per_s,
            ratio_to_decode_only,
            filter_ms_per_scan: per_scan_ms(filter_s),
            surface_ms_per_scan: per_scan_ms(surface_s),
            register_ms_per_scan: per_scan_ms(register_s),
            target_met: scans_per_s >= ODOMETRY_TARGET_SCANS_PER_S,
            ratio_target_met: (*preset == RATIO_TARGET_PRESET)
                .then_some(ratio_to_decode_only >= CFEAR_TARGET_RATIO_TO_DECODE_ONLY),
        });
    }
    let memory = memory_check(options.memory_scans, dir.path(), process_odometry)?;
    Ok(OdometryBench {
        options: options.clone(),
        scans_per_pass: presets.first().map_or(0, |r| r.scans / options.passes.max(1)),
        decode_threads: rayon::current_num_threads(),
        decode_only_scans_per_s,
        target_scans_per_s: ODOMETRY_TARGET_SCANS_PER_S,
        presets,
        memory,
    })
}

/// The Markdown table and memory line of `bench` (also the README block's body).
#[must_use]
pub fn markdown(bench: &OdometryBench) -> String {
    let target = bench.target_scans_per_s;
    let ratio_target = CFEAR_TARGET_RATIO_TO_DECODE_ONLY;
    let mut out = format!(
        "`mmtrack bench odometry`: the {} real Oxford scans (400 x 3768) of `{}` in a recording, {} passes per \
         preset, each a fresh pipeline; scans are decoded on the rayon pool ({} threads), a few ahead of the odometry. Baseline in \
         the same run, its passes alternating with the presets': reading and decoding alone, {:.0} scans/s.\n\n\
         | preset | scans | end-to-end scans/s | / decode-only | filter ms | surface points ms | registration ms | \
         target >= {target} scans/s | target / decode-only >= {ratio_target} ({RATIO_TARGET_PRESET}) |\n\
         |---|---|---|---|---|---|---|---|---|\n",
        bench.scans_per_pass,
        bench.options.from.display(),
        bench.options.passes,
        bench.decode_threads,
        bench.decode_only_scans_per_s,
    );
    for r in &bench.presets {
        out.push_str(&format!(
            "| {} | {} | {:.0} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {} |\n",
            r.preset,
            r.scans,
            r.scans_per_s,
            r.ratio_to_decode_only,
            r.filter_ms_per_scan,
            r.surface_ms_per_scan,
            r.register_ms_per_scan,
            verdict_cell(r.target_met),
            r.ratio_target_met.map_or("-", verdict_cell),
        ));
    }
    let m = &bench.memory;
    out.push_str(&format!(
        "\nMemory (`cfear` on simulated Oxford-size drives around a generated circular street, laps of \
         {MEMORY_LAP_SCANS} scans, in a `process odometry` child process sampled every 5 ms): {} scans ({:.0} MB \
         recording) peak {:.0} MB; {} scans ({:.0} MB recording) peak {:.0} MB, mean resident memory {:.1} MB \
         over the second quarter of the run and {:.1} MB over the last: ratio {:.2} (target: at most \
         {:.2}, memory does not grow with the sequence): {}.\n",
        m.short_scans,
        m.short_recording_mb,
        m.short_peak_mb,
        m.long_scans,
        m.long_recording_mb,
        m.long_peak_mb,
        m.long_second_quarter_rss_mb,
        m.long_last_quarter_rss_mb,
        m.growth_ratio,
        m.growth_limit,
        verdict_cell(m.target_met),
    ));
    out
}

/// Reads and decodes every scan of the recording through the same reader
/// and rayon decoding as `process odometry`: the baseline.
fn decode_only(recording: &Path) -> anyhow::Result<usize> {
    let mut scans = 0;
    for_each_event(recording, |event, _| {
        if let mmtrack_io::RecordingEvent::RadarScan(_) = event {
            scans += 1;
        }
        Ok(())
    })?;
    Ok(scans)
}

/// Ingests an Oxford folder into a zstd (level 1) recording without display
/// channels and without the final fsync.
fn ingest_quietly(folder: &Path, recording: &Path) -> anyhow::Result<()> {
    let folder = OxfordFolder::open(folder)?;
    let options = RecordingOptions {
        compression: Compression::Zstd { level: 1 },
        overwrite: Overwrite::Replace,
        foxglove_views: false,
        durability: Durability::PageCache,
        radar_cartesian: None,
        ..RecordingOptions::default()
    };
    ingest_oxford(&folder, recording, &OxfordOptions::default(), &options, &mut |_, _| {})?;
    Ok(())
}

/// Simulates a drive of `scans` sweeps as an Oxford folder and ingests it.
fn simulated_recording(scans: usize, dir: &Path) -> anyhow::Result<PathBuf> {
    use mmtrack_sim::radar::{
        ConstantTurn, GeneratorConfig, RadarSimulator, ScanLimits, Scenario, SimOptions, Trajectory,
    };
    let scenario: Scenario = toml::from_str("seed = 11\n[generator]\n")?;
    debug_assert_eq!(scenario.generator, Some(GeneratorConfig::default()));
    // Laps of a circle of one short drive (a quarter of the long one): every lap
    // sees the same street, so only the sequence length differs.
    let lap_s = (scans.min(MEMORY_LAP_SCANS)) as f64 * 0.25;
    let motion = ConstantTurn { speed_mps: 8.0, yaw_rate_radps: std::f64::consts::TAU / lap_s };
    let trajectory = Trajectory::constant_turn(motion, 1_700_000_000_000_000_000, scans as f64 * 0.25 + 1.0)?;
    let world = scenario.build_world(&trajectory)?;
    let options =
        SimOptions { limits: ScanLimits { max_scans: Some(scans), max_distance_m: None }, ..scenario.options() };
    let simulator = RadarSimulator::new(&world, &scenario.sensor, &trajectory, options)?;
    let folder = dir.join(format!("drive-{scans}"));
    mmtrack_process::simulate::radar::write_oxford_streaming(
        &scenario,
        simulator,
        mmtrack_io::recording::TimeBase::ScenarioStart,
        &folder,
        mmtrack_io::Overwrite::Replace,
        &NoProgress,
    )?;
    let recording = dir.join(format!("drive-{scans}.mcap"));
    ingest_quietly(&folder, &recording)?;
    std::fs::remove_dir_all(&folder)?;
    Ok(recording)
}

/// Runs `process odometry` in a child process on a short and a long drive
/// and samples its memory.
fn memory_check(
    long_scans: usize,
    dir: &Path,
    process_odometry: ProcessOdometryCommand<'_>,
) -> anyhow::Result<MemoryCheck> {
    let short_scans = MEMORY_LAP_SCANS.min(long_scans / 4).max(2);
    let mb = |b: u64| b as f64 / 1e6;
    let mut runs: Vec<(f64, ChildMemory)> = Vec::new();
    for scans in [short_scans, long_scans] {
        let recording = simulated_recording(scans, dir)?;
        let recording_mb = mb(std::fs::metadata(&recording)?.len());
        let tables = dir.join(format!("tables-{scans}"));
        let what = format!("{}: process odometry", recording.display());
        runs.push((recording_mb, child_memory(process_odometry(&recording, &tables), &what)?));
        std::fs::remove_file(&recording)?;
    }
    let (long_recording_mb, long) = runs.pop().context("long run")?;
    let (short_recording_mb, short) = runs.pop().context("short run")?;
    let (second, last) = (long.mean_rss_mb(1), long.mean_rss_mb(3));
    let growth_ratio = last / second;
    Ok(MemoryCheck {
        short_scans,
        long_scans,
        short_recording_mb,
        long_recording_mb,
        short_peak_mb: short.peak_mb,
        long_peak_mb: long.peak_mb,
        long_second_quarter_rss_mb: second,
        long_last_quarter_rss_mb: last,
        growth_ratio,
        growth_limit: MEMORY_GROWTH_LIMIT,
        target_met: growth_ratio <= MEMORY_GROWTH_LIMIT,
    })
}
