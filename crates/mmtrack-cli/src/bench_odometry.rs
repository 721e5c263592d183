//! `mmtrack bench odometry`: end-to-end radar odometry throughput on real
//! Oxford-size scans (400 x 3768), PNG decoding included, with the per-stage
//! split, against a same-run baseline that only reads and decodes.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use mmtrack_odometry::OdometryConfig;

use crate::ingest::{CompressionArg, OutputArgs};
use mmtrack_core::progress::NoProgress;
use mmtrack_process::events::for_each_event;
use mmtrack_process::odometry::run_odometry;

use crate::readme_block::replace_block;

/// Issue #4: end-to-end scans per second on this 2-core machine (CFEAR-1
/// reports about 160 Hz for filtering and registration alone, without decode).
pub const ODOMETRY_TARGET_SCANS_PER_S: f64 = 150.0;

/// Default `--from`: the Oxford sample beside the repository.
const DEFAULT_FROM: &str = "../shared/realdata/oxford-radar-tiny";

#[derive(Args)]
pub struct OdometryBenchArgs {
    /// Oxford folder whose real scans are used. The default is the Oxford sample among the
    /// real-data samples beside the repository, a path relative to the current directory: run
    /// from the repository root, or pass --from.
    #[arg(long, value_name = "OXFORD_FOLDER", default_value = DEFAULT_FROM)]
    from: PathBuf,
    /// Passes over the sequence per preset (each pass starts a fresh pipeline).
    #[arg(long, default_value_t = 20)]
    passes: usize,
    /// Exit 1 when the target is missed.
    #[arg(long)]
    check: bool,
    /// Scans of the long simulated drive of the memory check (laps of 100 scans; one lap is the short drive).
    #[arg(long, default_value_t = 1200)]
    memory_scans: usize,
    /// Replace the block `<!-- bench-odometry:begin -->` ... `end` in this file.
    #[arg(long, value_name = "README.md")]
    readme: Option<PathBuf>,
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

struct PresetResult {
    preset: &'static str,
    scans: usize,
    scans_per_s: f64,
    filter_ms: f64,
    surface_ms: f64,
    register_ms: f64,
}

pub fn run(args: &OdometryBenchArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    if args.from == Path::new(DEFAULT_FROM) && !args.from.exists() {
        anyhow::bail!(
            "default {DEFAULT_FROM} not found (the Oxford sample among the real-data samples beside the \
             repository; run from the repository root); pass --from PATH"
        );
    }
    let dir = tempfile::tempdir()?;
    let recording = dir.path().join("bench.mcap");
    ingest_quietly(&args.from, &recording)
        .with_context(|| format!("{}: cannot build the bench recording", args.from.display()))?;

    let started = Instant::now();
    let mut decoded = 0;
    for _ in 0..args.passes {
        decoded += decode_only(&recording)?;
    }
    let decode_per_s = decoded as f64 / started.elapsed().as_secs_f64();

    let mut results = Vec::new();
    for preset in OdometryConfig::PRESETS {
        let config = OdometryConfig::preset(preset).context("preset")?;
        let (mut scans, mut elapsed_s) = (0usize, 0.0);
        let (mut filter_s, mut surface_s, mut register_s) = (0.0, 0.0, 0.0);
        for _ in 0..args.passes {
            let run = run_odometry(&recording, config.clone(), &NoProgress)?;
            scans += run.estimates.len();
            elapsed_s += run.elapsed_s;
            for t in &run.timings {
                filter_s += t.filter_s;
                surface_s += t.surface_s;
                register_s += t.register_s;
            }
        }
        let per_scan_ms = |s: f64| s / scans as f64 * 1e3;
        results.push(PresetResult {
            preset,
            scans,
            scans_per_s: scans as f64 / elapsed_s,
            filter_ms: per_scan_ms(filter_s),
            surface_ms: per_scan_ms(surface_s),
            register_ms: per_scan_ms(register_s),
        });
    }
    let memory = memory_check(args.memory_scans, dir.path())?;
    let mut text = markdown(args, decode_per_s, &results);
    text.push_str(&memory.markdown());
    if !quiet {
        print!("{text}");
    }
    if let Some(readme) = &args.readme {
        replace_block(readme, "bench-odometry", &text)?;
    }
    let met = results.iter().all(|r| r.scans_per_s >= ODOMETRY_TARGET_SCANS_PER_S) && memory.flat();
    Ok(if args.check && !met { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}

fn markdown(args: &OdometryBenchArgs, decode_per_s: f64, results: &[PresetResult]) -> String {
    let mut out = format!(
        "`mmtrack bench odometry`: the {} real Oxford scans (400 x 3768) of `{}` in a recording, {} passes per \
         preset, each a fresh pipeline; scans are decoded on the rayon pool ({} threads), a few ahead of the odometry. Baseline in \
         the same run: reading and decoding alone, {decode_per_s:.0} scans/s.\n\n\
         | preset | scans | end-to-end scans/s | / decode-only | filter ms | surface points ms | registration ms | \
         target >= {ODOMETRY_TARGET_SCANS_PER_S} scans/s |\n|---|---|---|---|---|---|---|---|\n",
        results.first().map(|r| r.scans / args.passes.max(1)).unwrap_or(0),
        args.from.display(),
        args.passes,
        rayon::current_num_threads(),
    );
    for r in results {
        out.push_str(&format!(
            "| {} | {} | {:.0} | {:.2} | {:.2} | {:.2} | {:.2} | {} |\n",
            r.preset,
            r.scans,
            r.scans_per_s,
            r.scans_per_s / decode_per_s,
            r.filter_ms,
            r.surface_ms,
            r.register_ms,
            if r.scans_per_s >= ODOMETRY_TARGET_SCANS_PER_S { "met" } else { "**missed**" }
        ));
    }
    out
}

/// Memory of `process odometry` (cfear) on a short and a long drive.
struct MemoryCheck {
    short_scans: usize,
    long_scans: usize,
    short: ChildMemory,
    long: ChildMemory,
    short_recording_mb: f64,
    long_recording_mb: f64,
}

/// "Memory does not grow with sequence length": resident memory late in the
/// long run may exceed that early in it by at most this factor.
const MEMORY_GROWTH_LIMIT: f64 = 1.10;

impl MemoryCheck {
    /// Mean resident memory over the last quarter of the long run against the second quarter.
    fn growth(&self) -> f64 {
        self.long.mean_rss_mb(3) / self.long.mean_rss_mb(1)
    }

    fn flat(&self) -> bool {
        self.growth() <= MEMORY_GROWTH_LIMIT
    }

    fn markdown(&self) -> String {
        format!(
            "\nMemory (`cfear` on simulated Oxford-size drives around a generated circular street, laps of \
             {MEMORY_LAP_SCANS} scans, in a `process odometry` child process sampled every 5 ms): {} scans ({:.0} MB \
             recording) peak {:.0} MB; {} scans ({:.0} MB recording) peak {:.0} MB, mean resident memory {:.1} MB \
             over the second quarter of the run and {:.1} MB over the last: ratio {:.2} (target: at most \
             {MEMORY_GROWTH_LIMIT:.2}, memory does not grow with the sequence): {}.\n",
            self.short_scans,
            self.short_recording_mb,
            self.short.peak_mb,
            self.long_scans,
            self.long_recording_mb,
            self.long.peak_mb,
            self.long.mean_rss_mb(1),
            self.long.mean_rss_mb(3),
            self.growth(),
            if self.flat() { "met" } else { "**missed**" }
        )
    }
}

/// Resident memory of a child process over its life.
struct ChildMemory {
    /// `VmHWM` at the last sample, MB.
    peak_mb: f64,
    /// `VmRSS` samples, MB, in time order (taken at a fixed period).
    rss_mb: Vec<f64>,
}

impl ChildMemory {
    /// Mean of the samples of quarter `q` (0..4) of the run.
    fn mean_rss_mb(&self, q: usize) -> f64 {
        let n = self.rss_mb.len();
        let part = &self.rss_mb[n * q / 4..(n * (q + 1) / 4).max(n * q / 4 + 1).min(n)];
        part.iter().sum::<f64>() / part.len().max(1) as f64
    }
}

/// Ingests an Oxford folder into a zstd recording without display channels.
fn ingest_quietly(folder: &Path, recording: &Path) -> anyhow::Result<()> {
    let output = OutputArgs {
        output: recording.to_path_buf(),
        force: true,
        compression: CompressionArg::Zstd,
        zstd_level: 1,
        no_foxglove_views: true,
        no_radar_cartesian: true,
        radar_cartesian_m_per_px: mmtrack_io::recording::CartesianGrid::default().metres_per_pixel,
        radar_cartesian_size_px: mmtrack_io::recording::CartesianGrid::default().size_px,
        no_sync: true,
    };
    crate::ingest::oxford_folder(folder, &output, &Default::default(), true)?;
    Ok(())
}

/// Sweeps per lap of the memory check's circular drive.
const MEMORY_LAP_SCANS: usize = 100;

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
    mmtrack_process::simulate::radar::write_oxford_streaming(&scenario, simulator, &folder, true, &NoProgress)?;
    let recording = dir.join(format!("drive-{scans}.mcap"));
    ingest_quietly(&folder, &recording)?;
    std::fs::remove_dir_all(&folder)?;
    Ok(recording)
}

/// Runs `mmtrack process odometry` (cfear) as a child process, so the
/// simulator's memory in this one does not count, and samples its resident
/// memory (`/proc/<pid>/status`, Linux) until it exits.
fn child_memory(recording: &Path, tables: &Path) -> anyhow::Result<ChildMemory> {
    let exe = std::env::current_exe()?;
    let mut child = std::process::Command::new(exe)
        .args(["--quiet", "process", "odometry", "--preset", "cfear", "-o"])
        .arg(tables)
        .arg(recording)
        .stdout(std::process::Stdio::null())
        .spawn()?;
    let status_path = format!("/proc/{}/status", child.id());
    let field_kib = |status: &str, name: &str| {
        status
            .lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|v| v.parse::<u64>().ok())
    };
    let mut memory = ChildMemory { peak_mb: 0.0, rss_mb: Vec::new() };
    let status = loop {
        if let Ok(status) = std::fs::read_to_string(&status_path)
            && let (Some(rss), Some(hwm)) = (field_kib(&status, "VmRSS:"), field_kib(&status, "VmHWM:"))
        {
            memory.rss_mb.push(rss as f64 * 1024.0 / 1e6);
            memory.peak_mb = memory.peak_mb.max(hwm as f64 * 1024.0 / 1e6);
        }
        if let Some(status) = child.try_wait()? {
            break status;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    };
    anyhow::ensure!(status.success(), "{}: process odometry failed ({status})", recording.display());
    anyhow::ensure!(!memory.rss_mb.is_empty(), "no /proc/<pid>/status to read memory from (Linux only)");
    Ok(memory)
}

fn memory_check(long_scans: usize, dir: &Path) -> anyhow::Result<MemoryCheck> {
    let short_scans = MEMORY_LAP_SCANS.min(long_scans / 4).max(2);
    let mb = |b: u64| b as f64 / 1e6;
    let mut runs = Vec::new();
    let mut sizes = Vec::new();
    for scans in [short_scans, long_scans] {
        let recording = simulated_recording(scans, dir)?;
        sizes.push(mb(std::fs::metadata(&recording)?.len()));
        let tables = dir.join(format!("tables-{scans}"));
        runs.push(child_memory(&recording, &tables)?);
        std::fs::remove_file(&recording)?;
    }
    let long = runs.pop().context("long run")?;
    let short = runs.pop().context("short run")?;
    Ok(MemoryCheck { short_scans, long_scans, short, long, short_recording_mb: sizes[0], long_recording_mb: sizes[1] })
}
