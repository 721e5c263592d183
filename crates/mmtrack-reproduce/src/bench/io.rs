//! MCAP write and read of Oxford-size radar scans (400 x 3768 bytes = 1.5 MB
//! per message) against `std::fs::copy` of the same bytes. Each measurement
//! is the best of `repeats` runs (the least disturbed by the rest of the
//! machine). Target: write at least [`WRITE_TARGET_RATIO`] x the copy speed
//! with zstd level 1 or no compression.

use std::path::{Path, PathBuf};
use std::time::Duration;

use mmtrack_core::{PolarScan, limits};
use mmtrack_io::recording::{Compression, RecordingMetadata, TimeBase};
use mmtrack_io::{Durability, Overwrite, RecordingEvent, RecordingOptions, RecordingReader, RecordingWriter};
use mmtrack_sim::radar::{
    ConstantTurn, GeneratorConfig, RadarSimulator, ScanLimits, Sensor, SimOptions, Trajectory, World, generate_world,
};
use serde_json::json;

use super::measure::best_of;
use super::{check_count, verdict_cell};

/// MCAP write at least this fraction of the speed of copying the same bytes.
pub const WRITE_TARGET_RATIO: f64 = 0.5;

/// The README block that [`markdown`] fills.
pub const README_BLOCK: &str = "bench-io";

/// What to measure.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IoBenchOptions {
    /// Number of scans (1.5 MB each).
    pub scans: usize,
    /// Runs per measurement; the best is reported.
    pub repeats: usize,
    /// Directory for the temporary files (`None`: the system temp dir).
    pub dir: Option<PathBuf>,
}

impl Default for IoBenchOptions {
    fn default() -> Self {
        Self { scans: 60, repeats: 3, dir: None }
    }
}

impl IoBenchOptions {
    /// Refuses absurd counts before any scan is made.
    ///
    /// # Errors
    /// `scans` or `repeats` outside [`limits::BENCH_SCANS_IN_MEMORY`] or
    /// [`limits::BENCH_RUNS`].
    pub fn validate(&self) -> anyhow::Result<()> {
        check_count("--scans", self.scans, 1, limits::BENCH_SCANS_IN_MEMORY)?;
        check_count("--repeats", self.repeats, 1, limits::BENCH_RUNS)
    }
}

/// One chunk compression.
#[derive(Debug, Clone, PartialEq)]
pub struct IoRow {
    /// `none`, `zstd-1` or `lz4`.
    pub compression: &'static str,
    /// Size of the recording written.
    pub file_mb: f64,
    /// Payload written per second (page cache).
    pub write_mb_per_s: f64,
    /// `write_mb_per_s` over the copy baseline's.
    pub write_ratio_to_copy: f64,
    /// Payload written per second, fsync before close.
    pub write_fsync_mb_per_s: f64,
    /// `write_fsync_mb_per_s` over the copy + fsync baseline's.
    pub write_fsync_ratio_to_copy_fsync: f64,
    /// Payload read back per second.
    pub read_mb_per_s: f64,
    /// `read_mb_per_s` over the copy baseline's.
    pub read_ratio_to_copy: f64,
    /// [`WRITE_TARGET_RATIO`] for the compressions the target names (none
    /// and zstd level 1), `None` for the others.
    pub write_target_ratio: Option<f64>,
    /// `write_ratio_to_copy >= write_target_ratio`, when there is a target.
    pub target_met: Option<bool>,
}

/// The measurements of one `bench io` run.
#[derive(Debug, Clone, PartialEq)]
pub struct IoBench {
    /// Scans written per recording.
    pub scans: usize,
    /// Runs per measurement (the best is reported).
    pub repeats: usize,
    /// Power bytes per scan message.
    pub message_mb: f64,
    /// Power bytes of all the scans.
    pub payload_mb: f64,
    /// Baselines: `std::fs::copy` of the same bytes, without and with fsync.
    pub copy_mb_per_s: f64,
    /// Baseline: copy, then fsync.
    pub copy_fsync_mb_per_s: f64,
    /// One row per chunk compression: none, zstd level 1, lz4.
    pub rows: Vec<IoRow>,
}

impl IoBench {
    /// The compressions that meet the target.
    #[must_use]
    pub fn target_met_by(&self) -> Vec<&'static str> {
        self.rows.iter().filter(|r| r.target_met == Some(true)).map(|r| r.compression).collect()
    }

    /// Some compression meets the target.
    #[must_use]
    pub fn target_met(&self) -> bool {
        !self.target_met_by().is_empty()
    }
}

/// `count` Oxford-size scans (400 x 3768) of a simulated drive through a
/// generated street (the full radar simulator, default sensor and scene),
/// so that compression sees data like the real sensor's rather than zeros.
fn oxford_size_scans(count: usize) -> anyhow::Result<Vec<PolarScan>> {
    let motion = ConstantTurn { speed_mps: 10.0, yaw_rate_radps: 0.02 };
    let trajectory = Trajectory::constant_turn(motion, 1_547_131_046_353_776_000, count as f64 * 0.25 + 1.0)?;
    let world = World::new(&generate_world(&GeneratorConfig::default(), &trajectory, 1)?)?;
    let sensor = Sensor::default();
    let options = SimOptions { seed: 1, limits: ScanLimits { max_scans: Some(count), max_distance_m: None } };
    Ok(RadarSimulator::new(&world, &sensor, &trajectory, options)?.map(|(scan, _)| scan).collect())
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

/// Bytes of power read back from the recording at `path`.
fn read_recording(path: &Path) -> anyhow::Result<usize> {
    let mut count = 0;
    for event in RecordingReader::open(path)? {
        if let RecordingEvent::RadarScan(scan) = event? {
            count += scan.power.len();
        }
    }
    Ok(count)
}

/// Measures the copy baselines and each compression's write and read.
///
/// # Errors
/// The scans cannot be simulated, a temporary file cannot be written, or a
/// recording reads back other bytes than were written.
pub fn run(options: &IoBenchOptions) -> anyhow::Result<IoBench> {
    options.validate()?;
    let IoBenchOptions { scans, repeats, ref dir } = *options;
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
    let (copy_mb_per_s, copy_fsync_mb_per_s) = (mbps(copy), mbps(copy_sync));

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
        let write_target_ratio = (name != "lz4").then_some(WRITE_TARGET_RATIO);
        let write_ratio_to_copy = mbps(write) / copy_mb_per_s;
        rows.push(IoRow {
            compression: name,
            file_mb,
            write_mb_per_s: mbps(write),
            write_ratio_to_copy,
            write_fsync_mb_per_s: mbps(write_sync),
            write_fsync_ratio_to_copy_fsync: mbps(write_sync) / copy_fsync_mb_per_s,
            read_mb_per_s: mbps(read),
            read_ratio_to_copy: mbps(read) / copy_mb_per_s,
            write_target_ratio,
            target_met: write_target_ratio.map(|t| write_ratio_to_copy >= t),
        });
    }
    Ok(IoBench {
        scans,
        repeats,
        message_mb: payload_mb / scans as f64,
        payload_mb,
        copy_mb_per_s,
        copy_fsync_mb_per_s,
        rows,
    })
}

/// `bench` as one JSON object (`bench io --json`).
#[must_use]
pub fn json(bench: &IoBench) -> serde_json::Value {
    let rows: Vec<serde_json::Value> = bench
        .rows
        .iter()
        .map(|r| {
            json!({
                "compression": r.compression, "file_mb": r.file_mb,
                "write_mb_per_s": r.write_mb_per_s, "write_ratio_to_copy": r.write_ratio_to_copy,
                "write_fsync_mb_per_s": r.write_fsync_mb_per_s,
                "write_fsync_ratio_to_copy_fsync": r.write_fsync_ratio_to_copy_fsync,
                "read_mb_per_s": r.read_mb_per_s, "read_ratio_to_copy": r.read_ratio_to_copy,
                "write_target_ratio": r.write_target_ratio, "target_met": r.target_met,
            })
        })
        .collect();
    json!({
        "benchmark": "io", "scans": bench.scans, "message_mb": bench.message_mb, "payload_mb": bench.payload_mb,
        "repeats": bench.repeats, "copy_mb_per_s": bench.copy_mb_per_s, "copy_fsync_mb_per_s": bench.copy_fsync_mb_per_s,
        "results": rows, "target_met_by": bench.target_met_by(),
    })
}

/// The Markdown table of `bench` (also the README block's body).
#[must_use]
pub fn markdown(bench: &IoBench) -> String {
    let mut out = format!(
        "`mmtrack bench io`: {} radar scans of {:.2} MB, best of {} runs. Baselines in the same run: \
         `std::fs::copy` of the same bytes {:.0} MB/s; copy + fsync {:.0} MB/s.\n\n\
         | compression | file MB | write MB/s | / copy | write+fsync MB/s | / copy+fsync | read MB/s | / copy | target: write >= {WRITE_TARGET_RATIO} x copy |\n\
         |---|---|---|---|---|---|---|---|---|\n",
        bench.scans, bench.message_mb, bench.repeats, bench.copy_mb_per_s, bench.copy_fsync_mb_per_s,
    );
    for r in &bench.rows {
        let target = r.target_met.map_or("-", verdict_cell);
        out.push_str(&format!(
            "| {} | {:.0} | {:.0} | {:.2} | {:.0} | {:.2} | {:.0} | {:.2} | {target} |\n",
            r.compression,
            r.file_mb,
            r.write_mb_per_s,
            r.write_ratio_to_copy,
            r.write_fsync_mb_per_s,
            r.write_fsync_ratio_to_copy_fsync,
            r.read_mb_per_s,
            r.read_ratio_to_copy,
        ));
    }
    out
}
