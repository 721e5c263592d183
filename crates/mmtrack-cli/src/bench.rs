//! `mmtrack bench`: throughput measured against a baseline in the same run.
//!
//! `bench io`: MCAP write and read of Oxford-size radar scans (400 x 3768
//! bytes = 1.5 MB per message) against `std::fs::copy` of the same bytes. Each
//! measurement is the best of `--repeats` runs (the least disturbed by the
//! rest of the machine). Target from issue #2: write at least 0.5x the copy
//! speed with zstd level 1 or no compression.

use std::path::Path;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use clap::{Args, Subcommand};
use mmtrack_core::PolarScan;
use mmtrack_io::recording::{Compression, RecordingMetadata, TimeBase};
use mmtrack_io::{Durability, Overwrite, RecordingEvent, RecordingOptions, RecordingReader, RecordingWriter};
use mmtrack_sim::radar::{
    ConstantTurn, GeneratorConfig, RadarSimulator, ScanLimits, Sensor, SimOptions, Trajectory, World, generate_world,
};
use serde_json::json;

use crate::readme_block::replace_block;

#[derive(Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    kind: Kind,
}

#[derive(Subcommand)]
enum Kind {
    /// MPC detection plus short- and long-term tracking snapshots/s on simulated 2048-tap CIRs; GM-PHD ratio.
    Mpc(crate::bench_mpc::MpcBenchArgs),
    /// End-to-end radar odometry scans/s on real Oxford scans (PNG decode included), per stage.
    Odometry(crate::bench_odometry::OdometryBenchArgs),
    /// 5G mmWave SLAM filter: time per 200 ms epoch (2000 particles, 10 iterations) vs real time and one thread.
    Slam(crate::slam::bench::SlamBenchArgs),
    /// Oxford-folder ingest (PNG bytes carried) in scans/s vs copying the folder; peak memory at two folder sizes.
    Ingest {
        /// Scans in the large folder (400 x 3768 each).
        #[arg(long, default_value_t = 200)]
        scans: usize,
        /// Runs per measurement; the best is reported.
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// Exit 1 when a target is missed.
        #[arg(long)]
        check: bool,
        /// Directory for the temporary files (default: the system temp dir).
        #[arg(long)]
        dir: Option<std::path::PathBuf>,
        /// Replace the block `<!-- bench-ingest-real:begin -->` (with --from) or `bench-ingest-simulated` in this file.
        #[arg(long, value_name = "README.md")]
        readme: Option<std::path::PathBuf>,
        /// Build the folders from this Oxford folder's real PNG bytes, repeated under new
        /// stamps (e.g. ../shared/realdata/oxford-radar-tiny); default: simulated scans.
        #[arg(long, value_name = "OXFORD_FOLDER")]
        from: Option<std::path::PathBuf>,
    },
    /// MCAP write/read throughput of 1.5 MB radar-scan messages vs std::fs::copy.
    Io {
        /// Number of scans (1.5 MB each).
        #[arg(long, default_value_t = 60)]
        scans: usize,
        /// Runs per measurement; the best is reported.
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// Exit 1 when a target is missed.
        #[arg(long)]
        check: bool,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
        /// Directory for the temporary files (default: the system temp dir).
        #[arg(long)]
        dir: Option<std::path::PathBuf>,
        /// Replace the block between `<!-- bench-io:begin -->` and `<!-- bench-io:end -->` in this file.
        #[arg(long, value_name = "README.md")]
        readme: Option<std::path::PathBuf>,
    },
}

/// Oxford-size scans with realistic content (noise floor, walls, poles), so
/// compression sees data like the real sensor's rather than zeros.
/// `count` Oxford-size scans (400 x 3768) of a simulated drive through a
/// generated street (the full radar simulator, default sensor and scene).
fn oxford_size_scans(count: usize) -> anyhow::Result<Vec<PolarScan>> {
    let motion = ConstantTurn { speed_mps: 10.0, yaw_rate_radps: 0.02 };
    let trajectory = Trajectory::constant_turn(motion, 1_547_131_046_353_776_000, count as f64 * 0.25 + 1.0)?;
    let world = World::new(&generate_world(&GeneratorConfig::default(), &trajectory, 1)?)?;
    let sensor = Sensor::default();
    let options = SimOptions { seed: 1, limits: ScanLimits { max_scans: Some(count), max_distance_m: None } };
    Ok(RadarSimulator::new(&world, &sensor, &trajectory, options)?.map(|(scan, _)| scan).collect())
}

/// An Oxford folder of `count` Oxford-size scans (400 x 3768) of a simulated
/// drive through a generated street, written by `mmtrack simulate radar` in a
/// child process (scenario file in `scratch`).
fn simulated_oxford_folder(folder: &Path, count: usize, scratch: &Path) -> anyhow::Result<()> {
    let scenario = scratch.join("bench-scenario.toml");
    std::fs::write(
        &scenario,
        format!(
            "seed = 1\nstart_t_ns = 1_547_131_046_353_776_000\nmax_scans = {count}\n[motion]\nspeed_mps = 10.0\n\
             yaw_rate_radps = 0.02\nduration_s = {}\n[generator]\n",
            count as f64 * 0.25 + 1.0
        ),
    )?;
    let status = std::process::Command::new(std::env::current_exe()?)
        .args(["simulate", "radar", "--format", "oxford", "--quiet", "--force", "--scenario"])
        .arg(&scenario)
        .arg("-o")
        .arg(folder)
        .status()?;
    anyhow::ensure!(status.success(), "{}: simulating the bench scans failed", folder.display());
    Ok(())
}

fn best_of(repeats: usize, mut f: impl FnMut() -> anyhow::Result<()>) -> anyhow::Result<Duration> {
    let mut best = Duration::MAX;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        f()?;
        best = best.min(start.elapsed());
    }
    Ok(best)
}

fn write_recording(
    path: &Path,
    scans: &[PolarScan],
    compression: Compression,
    durability: Durability,
) -> anyhow::Result<()> {
    let metadata = RecordingMetadata {
        sequence_id: "bench".into(),
        source: "bench".into(),
        time_base: TimeBase::UnixEpoch,
        extra: Default::default(),
    };
    let options =
        RecordingOptions { compression, overwrite: Overwrite::Replace, durability, ..RecordingOptions::default() };
    let mut writer = RecordingWriter::create(path, &metadata, &options)?;
    for scan in scans {
        writer.write_radar_scan(scan)?;
    }
    writer.finish()?;
    Ok(())
}

fn read_recording(path: &Path) -> anyhow::Result<usize> {
    let mut count = 0;
    for event in RecordingReader::open(path)? {
        if let RecordingEvent::RadarScan(scan) = event? {
            count += scan.power.len();
        }
    }
    Ok(count)
}

struct IoArgs<'a> {
    scans: usize,
    repeats: usize,
    check: bool,
    json: bool,
    dir: Option<&'a Path>,
    readme: Option<&'a Path>,
}

fn io(args: &IoArgs<'_>, quiet: bool) -> anyhow::Result<ExitCode> {
    let IoArgs { scans, repeats, check, json: as_json, dir, readme } = *args;
    let scans_data = oxford_size_scans(scans)?;
    let payload_bytes: usize = scans_data.iter().map(|s| s.power.len()).sum();
    let payload_mb = payload_bytes as f64 / 1e6;
    let temp = match dir {
        Some(d) => tempfile::tempdir_in(d)?,
        None => tempfile::tempdir()?,
    };
    let raw = temp.path().join("raw.bin");
    let concatenated: Vec<u8> = scans_data.iter().flat_map(|s| s.power.iter().copied()).collect();
    std::fs::write(&raw, &concatenated)?;
    drop(concatenated);
    let copy_target = temp.path().join("copy.bin");
    let copy = best_of(repeats, || {
        std::fs::copy(&raw, &copy_target)?;
        Ok(())
    })?;
    let copy_sync = best_of(repeats, || {
        std::fs::copy(&raw, &copy_target)?;
        std::fs::File::open(&copy_target)?.sync_all()?;
        Ok(())
    })?;
    let mbps = |d: Duration| payload_mb / d.as_secs_f64();
    let (copy_mbps, copy_sync_mbps) = (mbps(copy), mbps(copy_sync));

    let mut rows = Vec::new();
    for (name, compression) in
        [("none", Compression::None), ("zstd-1", Compression::Zstd { level: 1 }), ("lz4", Compression::Lz4)]
    {
        let path = temp.path().join(format!("{name}.mcap"));
        let write = best_of(repeats, || write_recording(&path, &scans_data, compression, Durability::PageCache))?;
        let write_sync = best_of(repeats, || write_recording(&path, &scans_data, compression, Durability::Fsync))?;
        let file_mb = std::fs::metadata(&path)?.len() as f64 / 1e6;
        let read = best_of(repeats, || {
            let bytes = read_recording(&path)?;
            anyhow::ensure!(bytes == payload_bytes, "read {bytes} bytes of power, wrote {payload_bytes}");
            Ok(())
        })?;
        // The target (write >= 0.5 x copy) names no compression and zstd level 1.
        let target = (name != "lz4").then_some(WRITE_TARGET_RATIO);
        let write_ratio = mbps(write) / copy_mbps;
        rows.push(json!({
            "compression": name, "file_mb": file_mb,
            "write_mb_per_s": mbps(write), "write_ratio_to_copy": write_ratio,
            "write_fsync_mb_per_s": mbps(write_sync), "write_fsync_ratio_to_copy_fsync": mbps(write_sync) / copy_sync_mbps,
            "read_mb_per_s": mbps(read), "read_ratio_to_copy": mbps(read) / copy_mbps,
            "write_target_ratio": target, "target_met": target.map(|t| write_ratio >= t),
        }));
    }
    let met_by: Vec<&str> =
        rows.iter().filter(|r| r["target_met"] == json!(true)).filter_map(|r| r["compression"].as_str()).collect();
    let report = json!({
        "benchmark": "io", "scans": scans, "message_mb": payload_mb / scans as f64, "payload_mb": payload_mb,
        "repeats": repeats, "copy_mb_per_s": copy_mbps, "copy_fsync_mb_per_s": copy_sync_mbps,
        "results": rows, "target_met_by": met_by,
    });
    if as_json {
        println!("{report}");
    } else if !quiet {
        print!("{}", markdown(&report));
    }
    if let Some(readme) = readme {
        replace_block(readme, "bench-io", &markdown(&report))?;
    }
    Ok(if check && met_by.is_empty() { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}

/// Issue #2: MCAP write at least half the speed of copying the same bytes.
const WRITE_TARGET_RATIO: f64 = 0.5;

fn markdown(report: &serde_json::Value) -> String {
    let f = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    let mut out = format!(
        "`mmtrack bench io`: {} radar scans of {:.2} MB, best of {} runs. Baselines in the same run: \
         `std::fs::copy` of the same bytes {:.0} MB/s; copy + fsync {:.0} MB/s.\n\n\
         | compression | file MB | write MB/s | / copy | write+fsync MB/s | / copy+fsync | read MB/s | / copy | target: write >= {WRITE_TARGET_RATIO} x copy |\n\
         |---|---|---|---|---|---|---|---|---|\n",
        report["scans"],
        f(&report["message_mb"]),
        report["repeats"],
        f(&report["copy_mb_per_s"]),
        f(&report["copy_fsync_mb_per_s"]),
    );
    for r in report["results"].as_array().into_iter().flatten() {
        let target = match r["target_met"].as_bool() {
            Some(true) => "met",
            Some(false) => "**missed**",
            None => "-",
        };
        out.push_str(&format!(
            "| {} | {:.0} | {:.0} | {:.2} | {:.0} | {:.2} | {:.0} | {:.2} | {target} |\n",
            r["compression"].as_str().unwrap_or(""),
            f(&r["file_mb"]),
            f(&r["write_mb_per_s"]),
            f(&r["write_ratio_to_copy"]),
            f(&r["write_fsync_mb_per_s"]),
            f(&r["write_fsync_ratio_to_copy_fsync"]),
            f(&r["read_mb_per_s"]),
            f(&r["read_ratio_to_copy"]),
        ));
    }
    out
}

/// Issue #3: ingest of an Oxford folder, bytes carried, on this 2-core machine.
const INGEST_TARGET_SCANS_PER_S: f64 = 200.0;

/// Peak resident memory of this process since the last reset, bytes (Linux:
/// `VmHWM`, reset by writing 5 to `/proc/self/clear_refs`).
fn reset_peak_rss() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

fn copy_dir(from: &Path, to: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let target = to.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            copy_dir(&entry.path(), &target)?;
        } else {
            std::fs::copy(entry.path(), target)?;
        }
    }
    Ok(())
}

fn ingest_folder(folder: &Path, out: &Path) -> anyhow::Result<u64> {
    use mmtrack_ingest::oxford::{self, OxfordFolder, OxfordOptions};
    let folder = OxfordFolder::open(folder)?;
    let recording = RecordingOptions {
        compression: Compression::None,
        overwrite: Overwrite::Replace,
        durability: Durability::PageCache,
        ..RecordingOptions::default()
    };
    let report = oxford::ingest_oxford(&folder, out, &OxfordOptions::default(), &recording, &mut |_, _| {})?;
    Ok(report.scans)
}

fn ingest(args: &IngestBench<'_>, quiet: bool) -> anyhow::Result<ExitCode> {
    let temp = match args.dir {
        Some(d) => tempfile::tempdir_in(d)?,
        None => tempfile::tempdir()?,
    };
    let small_scans = (args.scans / 4).max(1);
    let (large, small) = (temp.path().join("large"), temp.path().join("small"));
    let source = match args.from {
        Some(real) => {
            replicate_real_folder(real, &large, args.scans)?;
            replicate_real_folder(real, &small, small_scans)?;
            format!("real PNG bytes of {} repeated", real.display())
        }
        None => {
            // In child processes: scans rendered here would leave their freed
            // memory with this process's allocator and hide the ingest's
            // own peak.
            simulated_oxford_folder(&large, args.scans, temp.path())?;
            simulated_oxford_folder(&small, small_scans, temp.path())?;
            "simulated scans of the radar simulator in a generated street".to_string()
        }
    };
    let folder_mb = dir_bytes(&large.join("radar"))? as f64 / 1e6;

    let copy_target = temp.path().join("copy");
    let copy = best_of(args.repeats, || {
        let _ = std::fs::remove_dir_all(&copy_target);
        copy_dir(&large, &copy_target)
    })?;
    let out = temp.path().join("out.mcap");
    let ingest_time = best_of(args.repeats, || {
        ingest_folder(&large, &out)?;
        Ok(())
    })?;
    reset_peak_rss();
    let before = peak_rss_bytes();
    ingest_folder(&small, &out)?;
    let peak_small = peak_rss_bytes();
    reset_peak_rss();
    ingest_folder(&large, &out)?;
    let peak_large = peak_rss_bytes();

    let scans_per_s = args.scans as f64 / ingest_time.as_secs_f64();
    let copy_scans_per_s = args.scans as f64 / copy.as_secs_f64();
    let met = scans_per_s >= INGEST_TARGET_SCANS_PER_S;
    let mb = |b: Option<u64>| b.map_or(f64::NAN, |b| b as f64 / 1e6);
    let text = format!(
        "`mmtrack bench ingest`: Oxford folder of {} scans (400 x 3779 PNG, {:.0} MB; {source}), PNG bytes carried, no chunk compression, best of {} runs.\n\n\
         | measure | value |\n|---|---|\n\
         | ingest | {scans_per_s:.0} scans/s |\n\
         | baseline: copy the folder | {copy_scans_per_s:.0} scans/s |\n\
         | ingest / copy | {:.2} |\n\
         | target: >= {INGEST_TARGET_SCANS_PER_S} scans/s | {} |\n\
         | peak memory, {small_scans} scans | {:.0} MB |\n\
         | peak memory, {} scans | {:.0} MB |\n\
         | memory before ingest | {:.0} MB |\n",
        args.scans,
        folder_mb,
        args.repeats,
        scans_per_s / copy_scans_per_s,
        if met { "met" } else { "**missed**" },
        mb(peak_small),
        args.scans,
        mb(peak_large),
        mb(before),
    );
    if !quiet {
        print!("{text}");
    }
    if let Some(readme) = args.readme {
        let block = if args.from.is_some() { "bench-ingest-real" } else { "bench-ingest-simulated" };
        replace_block(readme, block, &text)?;
    }
    Ok(if args.check && !met { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}

/// Writes an Oxford folder of `count` scans whose PNGs are the real ones of
/// `real`, cycled, under new increasing stamps (the ingest reads the scan stamp
/// from the file name and the azimuth times from the rows).
fn replicate_real_folder(real: &Path, to: &Path, count: usize) -> anyhow::Result<()> {
    let folder = mmtrack_ingest::oxford::OxfordFolder::open(real)?;
    std::fs::create_dir_all(to.join("radar"))?;
    let mut timestamps = String::new();
    let first_us = folder.scans[0].t_ns / 1000;
    for i in 0..count {
        let t_us = first_us + i as i64 * 250_000;
        std::fs::copy(&folder.scans[i % folder.scans.len()].path, to.join("radar").join(format!("{t_us}.png")))?;
        timestamps.push_str(&format!("{t_us} 1\n"));
    }
    std::fs::write(to.join("radar.timestamps"), timestamps)?;
    Ok(())
}

/// Total bytes of the files in `dir` (not recursive).
fn dir_bytes(dir: &Path) -> anyhow::Result<u64> {
    let mut total = 0;
    for entry in std::fs::read_dir(dir)? {
        total += entry?.metadata()?.len();
    }
    Ok(total)
}

struct IngestBench<'a> {
    scans: usize,
    repeats: usize,
    check: bool,
    dir: Option<&'a Path>,
    readme: Option<&'a Path>,
    from: Option<&'a Path>,
}

pub fn run(args: &BenchArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    match &args.kind {
        Kind::Odometry(odometry) => crate::bench_odometry::run(odometry, quiet),
        Kind::Mpc(mpc) => crate::bench_mpc::run(mpc, quiet),
        Kind::Slam(slam) => crate::slam::bench::run(slam, quiet),
        Kind::Ingest { scans, repeats, check, dir, readme, from } => ingest(
            &IngestBench {
                scans: *scans,
                repeats: *repeats,
                check: *check,
                dir: dir.as_deref(),
                readme: readme.as_deref(),
                from: from.as_deref(),
            },
            quiet,
        ),
        Kind::Io { scans, repeats, check, json, dir, readme } => io(
            &IoArgs {
                scans: *scans,
                repeats: *repeats,
                check: *check,
                json: *json,
                dir: dir.as_deref(),
                readme: readme.as_deref(),
            },
            quiet,
        ),
    }
}
