//! Oxford-folder ingest (PNG bytes carried, no chunk compression) in scans/s
//! against copying the same folder, and the ingest's peak memory at two
//! folder sizes (a quarter and the whole), on real PNG bytes repeated or on
//! simulated scans.

use std::path::{Path, PathBuf};
use std::process::Command;

use mmtrack_core::limits;
use mmtrack_ingest::oxford::{self, OxfordFolder, OxfordOptions};
use mmtrack_io::recording::Compression;
use mmtrack_io::{Durability, Overwrite, RecordingOptions};

use super::measure::{best_of, dir_bytes, peak_rss_bytes, reset_peak_rss};
use super::{check_count, verdict_cell};

/// Ingest of an Oxford folder, bytes carried, on this 2-core machine.
pub const INGEST_TARGET_SCANS_PER_S: f64 = 200.0;

/// The README block that [`markdown`] fills for real PNG bytes.
pub const README_BLOCK_REAL: &str = "bench-ingest-real";
/// The README block that [`markdown`] fills for simulated scans.
pub const README_BLOCK_SIMULATED: &str = "bench-ingest-simulated";

/// What to measure.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IngestBenchOptions {
    /// Scans in the large folder (400 x 3768 each); the small one has a quarter.
    pub scans: usize,
    /// Runs per measurement; the best is reported.
    pub repeats: usize,
    /// Directory for the temporary files (`None`: the system temp dir).
    pub dir: Option<PathBuf>,
    /// Build the folders from this Oxford folder's real PNG bytes, repeated
    /// under new stamps; `None`: simulated scans.
    pub from: Option<PathBuf>,
}

impl Default for IngestBenchOptions {
    fn default() -> Self {
        Self { scans: 200, repeats: 3, dir: None, from: None }
    }
}

impl IngestBenchOptions {
    /// Refuses absurd counts before any folder is written.
    ///
    /// # Errors
    /// `scans` or `repeats` outside [`limits::BENCH_SCANS_ON_DISK`] or
    /// [`limits::BENCH_RUNS`].
    pub fn validate(&self) -> anyhow::Result<()> {
        check_count("--scans", self.scans, 4, limits::BENCH_SCANS_ON_DISK)?;
        check_count("--repeats", self.repeats, 1, limits::BENCH_RUNS)
    }
}

/// How to run `simulate radar --format oxford` on a scenario file into a
/// folder in a child process: scans rendered in the measuring process
/// would leave their freed memory with its allocator and hide the ingest's
/// own peak. The front end knows how to start itself.
pub type SimulateOxfordCommand<'a> = &'a dyn Fn(&Path, &Path) -> Command;

/// The measurements of one `bench ingest` run.
#[derive(Debug, Clone, PartialEq)]
pub struct IngestBench {
    /// Scans of the large folder.
    pub scans: usize,
    /// Scans of the small folder (a quarter, at least 1).
    pub small_scans: usize,
    /// Runs per timing (the best is reported).
    pub repeats: usize,
    /// Whether the PNGs are real (`from`) or simulated.
    pub real: bool,
    /// Where the PNGs came from, in words.
    pub source: String,
    /// Bytes of the large folder's `radar/`, MB.
    pub folder_mb: f64,
    /// Ingest of the large folder, best run.
    pub scans_per_s: f64,
    /// The baseline: copying the large folder.
    pub copy_scans_per_s: f64,
    /// `scans_per_s` over `copy_scans_per_s`.
    pub ratio_to_copy: f64,
    /// The target: [`INGEST_TARGET_SCANS_PER_S`].
    pub target_scans_per_s: f64,
    /// `scans_per_s >= target_scans_per_s`.
    pub target_met: bool,
    /// Peak resident memory of this process ingesting the small folder
    /// (`None` without `/proc`).
    pub peak_small_mb: Option<f64>,
    /// Peak resident memory ingesting the large folder.
    pub peak_large_mb: Option<f64>,
    /// Peak resident memory just before ingesting the small folder.
    pub memory_before_mb: Option<f64>,
}

/// Builds the two folders, then times the ingest against copying and
/// measures its peak memory.
///
/// # Errors
/// `from` is not an Oxford folder with scans, the simulation child fails, or
/// a file cannot be written or ingested.
pub fn run(options: &IngestBenchOptions, simulate_oxford: SimulateOxfordCommand<'_>) -> anyhow::Result<IngestBench> {
    options.validate()?;
    let temp = match &options.dir {
        Some(d) => tempfile::tempdir_in(d)?,
        None => tempfile::tempdir()?,
    };
    let scans = options.scans;
    let small_scans = (scans / 4).max(1);
    let (large, small) = (temp.path().join("large"), temp.path().join("small"));
    let source = match &options.from {
        Some(real) => {
            replicate_real_folder(real, &large, scans)?;
            replicate_real_folder(real, &small, small_scans)?;
            format!("real PNG bytes of {}, repeated; the repeats moved in time and re-encoded", real.display())
        }
        None => {
            simulated_oxford_folder(&large, scans, temp.path(), simulate_oxford)?;
            simulated_oxford_folder(&small, small_scans, temp.path(), simulate_oxford)?;
            "simulated scans of the radar simulator in a generated street".to_string()
        }
    };
    let folder_mb = dir_bytes(&large.join("radar"))? as f64 / 1e6;

    let copy_target = temp.path().join("copy");
    let copy = best_of(options.repeats, || {
        // Absent on the first run.
        let _ = std::fs::remove_dir_all(&copy_target);
        copy_dir(&large, &copy_target)
    })?;
    let out = temp.path().join("out.mcap");
    let ingest_time = best_of(options.repeats, || {
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

    let scans_per_s = scans as f64 / ingest_time.as_secs_f64();
    let copy_scans_per_s = scans as f64 / copy.as_secs_f64();
    let mb = |b: Option<u64>| b.map(|b| b as f64 / 1e6);
    Ok(IngestBench {
        scans,
        small_scans,
        repeats: options.repeats,
        real: options.from.is_some(),
        source,
        folder_mb,
        scans_per_s,
        copy_scans_per_s,
        ratio_to_copy: scans_per_s / copy_scans_per_s,
        target_scans_per_s: INGEST_TARGET_SCANS_PER_S,
        target_met: scans_per_s >= INGEST_TARGET_SCANS_PER_S,
        peak_small_mb: mb(peak_small),
        peak_large_mb: mb(peak_large),
        memory_before_mb: mb(before),
    })
}

/// The README block `bench` belongs in: real or simulated PNGs.
#[must_use]
pub fn readme_block(bench: &IngestBench) -> &'static str {
    if bench.real { README_BLOCK_REAL } else { README_BLOCK_SIMULATED }
}

/// The Markdown table of `bench` (also the README block's body).
#[must_use]
pub fn markdown(bench: &IngestBench) -> String {
    let mb = |v: Option<f64>| v.unwrap_or(f64::NAN);
    format!(
        "`mmtrack bench ingest`: Oxford folder of {} scans (400 x 3779 PNG, {:.0} MB; {}), PNG bytes carried, no chunk compression, best of {} runs.\n\n\
         | measure | value |\n|---|---|\n\
         | ingest | {:.0} scans/s |\n\
         | baseline: copy the folder | {:.0} scans/s |\n\
         | ingest / copy | {:.2} |\n\
         | target: >= {} scans/s | {} |\n\
         | peak memory, {} scans | {:.0} MB |\n\
         | peak memory, {} scans | {:.0} MB |\n\
         | memory before ingest | {:.0} MB |\n",
        bench.scans,
        bench.folder_mb,
        bench.source,
        bench.repeats,
        bench.scans_per_s,
        bench.copy_scans_per_s,
        bench.ratio_to_copy,
        bench.target_scans_per_s,
        verdict_cell(bench.target_met),
        bench.small_scans,
        mb(bench.peak_small_mb),
        bench.scans,
        mb(bench.peak_large_mb),
        mb(bench.memory_before_mb),
    )
}

/// An Oxford folder of `count` Oxford-size scans (400 x 3768) of a simulated
/// drive through a generated street, written by `simulate_oxford` in a child
/// process (scenario file in `scratch`).
fn simulated_oxford_folder(
    folder: &Path,
    count: usize,
    scratch: &Path,
    simulate_oxford: SimulateOxfordCommand<'_>,
) -> anyhow::Result<()> {
    let scenario = scratch.join("bench-scenario.toml");
    std::fs::write(
        &scenario,
        format!(
            "seed = 1\nstart_t_ns = 1_547_131_046_353_776_000\nmax_scans = {count}\n[motion]\nspeed_mps = 10.0\n\
             yaw_rate_radps = 0.02\nduration_s = {}\n[generator]\n",
            count as f64 * 0.25 + 1.0
        ),
    )?;
    let status = simulate_oxford(&scenario, folder).status()?;
    anyhow::ensure!(status.success(), "{}: simulating the bench scans failed", folder.display());
    Ok(())
}

/// Writes an Oxford folder of `count` scans whose PNGs are the real ones of
/// `real`, cycled, under increasing stamps: the first cycle keeps each
/// scan's own stamp and bytes; each later cycle moves the stamp and every
/// row time (the ingest checks the rows against the file name's stamp) by
/// the first cycle's span, so its PNGs are re-encoded
/// ([`oxford::shift_scan_png_times`]).
fn replicate_real_folder(real: &Path, to: &Path, count: usize) -> anyhow::Result<()> {
    let folder = OxfordFolder::open(real)?;
    let (Some(first), Some(last)) = (folder.scans.first(), folder.scans.last()) else {
        anyhow::bail!("{}: no radar scans", real.display());
    };
    std::fs::create_dir_all(to.join("radar"))?;
    let mut timestamps = String::new();
    // One scan period past the last scan: cycles follow each other like scans.
    let period_us = if folder.scans.len() > 1 {
        (last.t_ns - first.t_ns) / 1000 / (folder.scans.len() as i64 - 1)
    } else {
        250_000
    };
    let cycle_us = (last.t_ns - first.t_ns) / 1000 + period_us;
    for (i, scan) in (0..count).zip(folder.scans.iter().cycle()) {
        let shift_us = (i / folder.scans.len()) as i64 * cycle_us;
        let t_us = scan.t_ns / 1000 + shift_us;
        let target = to.join("radar").join(format!("{t_us}.png"));
        if shift_us == 0 {
            std::fs::copy(&scan.path, &target)?;
        } else {
            let png = std::fs::read(&scan.path)?;
            let shifted = oxford::shift_scan_png_times(&scan.path, &png, scan.t_ns, shift_us, &oxford::OXFORD)?;
            std::fs::write(&target, shifted)?;
        }
        timestamps.push_str(&format!("{t_us} 1\n"));
    }
    std::fs::write(to.join("radar.timestamps"), timestamps)?;
    Ok(())
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

/// Ingests `folder` into `out` as `ingest oxford` does by default, without
/// chunk compression or the final fsync; returns the scans ingested.
fn ingest_folder(folder: &Path, out: &Path) -> anyhow::Result<u64> {
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
