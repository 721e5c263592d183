//! One target per byte-level reader: a function from bytes to the reader's
//! public entry point, and the seeds it starts from.
//!
//! | target | entry point |
//! |---|---|
//! | `png` | `oxford::decode_scan_png`, with any width and with Oxford's 3768 bins |
//! | `nmea` | `nmea::parse_nmea` on the bytes, streamed as `read_nmea` streams a file |
//! | `cdr` | `ros2::decode_odometry`, `decode_pose_with_covariance_stamped`, `decode_nav_sat_fix`, `ros2_image::decode_image` + `image_to_scan` |
//! | `decawave` | `cir::parse_decawave_log_detailed`, timed by the RX timestamp and by a frame period |
//! | `npy` | `cir::read_cir_file` as `npy`, or as `npz` when the file starts with `PK`; `cir::parse_npy_matrix` (DeepSense beam arrays) |
//! | `mat` | `cir::read_cir_file` as `mat`, and `cir::read_mat_cir` on the bytes |
//! | `sigmf` | `cir::read_cir_file` as `sigmf` |
//! | `csv` | `cir::read_cir_file` as `csv` (CIRs one snapshot per row) |
//!
//! The CIR targets parse a sidecar first: their input is `sidecar TOML, NUL,
//! file` (SigMF: `sidecar, NUL, meta, NUL, data`), split at the first NUL(s).
//! `read_cir_file` takes a path, so these targets write the file into a
//! scratch directory (the same file each time) and go the way
//! `mmtrack ingest cir` goes, sidecar checks and snapshot cutting included.
//!
//! A target returns a short outcome ("ok", or the record and field of the
//! error; one per entry point, joined by ` | `) that the fuzz loop uses to
//! grow its corpus; an outcome starting with "ok" is an accepted input.

use std::path::{Path, PathBuf};

use mmtrack_ingest::IngestError;
use mmtrack_ingest::cir::{
    CirFormat, CirSidecar, DecawaveConfig, DecawaveDelayReference, DecawaveTimeBase, MatCirLayout,
    parse_decawave_log_detailed, parse_npy_matrix, read_cir_file, read_mat_cir,
};
use mmtrack_ingest::nmea::parse_nmea;
use mmtrack_ingest::oxford::{OXFORD, decode_scan_png};
use mmtrack_ingest::ros2::{decode_nav_sat_fix, decode_odometry, decode_pose_with_covariance_stamped};
use mmtrack_ingest::ros2_image::{decode_image, image_to_scan};
use mmtrack_ingest::sweep::SweepTiming;

use crate::seeds;

/// A reader under test.
pub struct Target {
    /// Name on the command line.
    pub name: &'static str,
    /// The reader, for messages.
    pub reader: &'static str,
    /// Runs the reader on one input; returns its outcome.
    pub run: fn(&Scratch, &[u8]) -> String,
    /// The seed corpus, from the real-data folder when given.
    pub seeds: fn(Option<&Path>) -> Vec<Vec<u8>>,
    /// Repairs checksums after mutation, so that inputs get past them.
    pub fixup: fn(&mut [u8]),
}

/// Every target, in the order `all` runs them.
pub const TARGETS: [Target; 8] = [
    Target {
        name: "png",
        reader: "Navtech polar PNG (Oxford/Boreas row header)",
        run: png,
        seeds: seeds::png,
        fixup: png_chunk_crcs,
    },
    Target { name: "nmea", reader: "NMEA 0183 log", run: nmea, seeds: seeds::nmea, fixup: keep },
    Target { name: "cdr", reader: "ROS 2 CDR messages", run: cdr, seeds: seeds::cdr, fixup: keep },
    Target { name: "decawave", reader: "DecaWave DecaRanging log", run: decawave, seeds: seeds::decawave, fixup: keep },
    Target { name: "npy", reader: "NumPy .npy / .npz", run: npy, seeds: seeds::npy_files, fixup: keep },
    Target { name: "mat", reader: "MATLAB v5 .mat", run: mat, seeds: seeds::mat, fixup: keep },
    Target { name: "sigmf", reader: "SigMF meta + data", run: sigmf, seeds: seeds::sigmf, fixup: keep },
    Target { name: "csv", reader: "CIR CSV", run: csv, seeds: seeds::csv, fixup: keep },
];

/// The target called `name`.
#[must_use]
pub fn find(name: &str) -> Option<&'static Target> {
    TARGETS.iter().find(|t| t.name == name)
}

/// A private directory for targets whose reader takes a path.
pub struct Scratch {
    dir: tempfile::TempDir,
}

impl Scratch {
    /// A new scratch directory: in `/dev/shm` where there is one (memory,
    /// no disk writes per input), else in the system's temporary directory.
    pub fn new() -> std::io::Result<Self> {
        let mut builder = tempfile::Builder::new();
        builder.prefix("mmtrack-fuzz-");
        let shm = Path::new("/dev/shm");
        let dir = if shm.is_dir() { builder.tempdir_in(shm).or_else(|_| builder.tempdir()) } else { builder.tempdir() };
        Ok(Self { dir: dir? })
    }

    /// Writes `bytes` as `name` in the directory. The old file is removed
    /// first: ext4 flushes a file truncated and rewritten in place on
    /// close, which costs milliseconds per input.
    fn write(&self, name: &str, bytes: &[u8]) -> Result<PathBuf, String> {
        let path = self.dir.path().join(name);
        let _ = std::fs::remove_file(&path);
        std::fs::write(&path, bytes).map_err(|e| format!("scratch file {}: {e}", path.display()))?;
        Ok(path)
    }
}

/// The outcome of a reader: "ok", or where the error is (record, field and
/// the start of the detail). Never a path: outcomes steer the corpus, and
/// the same seed must give the same inputs in every run.
fn outcome<T>(result: &Result<T, IngestError>) -> String {
    match result {
        Ok(_) => "ok".into(),
        Err(IngestError::BadRecord { record, field, detail, .. }) => {
            format!("{record}/{field}/{}", unquoted(detail))
        }
        Err(IngestError::BadSidecar { key, .. }) => format!("sidecar {key}"),
        Err(IngestError::BadLayout { detail, .. }) => format!("layout {}", unquoted(detail)),
        Err(IngestError::Os { source, .. }) => format!("os {:?}", source.kind()),
        // Never the message: it starts with the scratch file's path, which
        // differs from run to run and would make runs differ.
        Err(_) => "other error".into(),
    }
}

/// The outcome of a reader whose errors start with the field name.
fn text_outcome<T>(result: &Result<T, String>) -> String {
    match result {
        Ok(_) => "ok".into(),
        Err(e) => e.split(':').next().unwrap_or("").chars().take(40).collect(),
    }
}

/// No checksums to repair.
fn keep(_: &mut [u8]) {}

/// Recomputes the CRC of every whole chunk after the PNG signature: the
/// decoder checks them first, and a mutated chunk would never be read.
/// (The zlib stream's Adler-32 inside the image data is left as it is.)
pub fn png_chunk_crcs(png: &mut [u8]) {
    if !png.starts_with(b"\x89PNG\r\n\x1a\n") {
        return;
    }
    let mut at = 8;
    while let Some(length) = png.get(at..at + 4).map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]) as usize) {
        let Some(crc_at) = (at + 8).checked_add(length).filter(|&end| end + 4 <= png.len()) else { break };
        let crc = crc32fast::hash(&png[at + 4..crc_at]);
        png[crc_at..crc_at + 4].copy_from_slice(&crc.to_be_bytes());
        at = crc_at + 4;
    }
}

fn png(_: &Scratch, input: &[u8]) -> String {
    let path = Path::new("fuzz.png");
    // The seeds' scans are stamped at the real sample's first scan: row times
    // near it pass the plausibility check and reach the checks after it.
    let any = decode_scan_png(path, input, seeds::SCAN_T0_NS, &seeds::ANY_SIZE).map(|d| d.into_scan().power.len());
    let oxford = decode_scan_png(path, input, seeds::SCAN_T0_NS, &OXFORD).map(|d| d.width);
    format!("{} | {}", outcome(&any), outcome(&oxford))
}

/// The text before the first quote (what follows often echoes the input).
fn unquoted(text: &str) -> String {
    text.chars().take_while(|c| !matches!(c, '`' | '"' | '\'')).take(32).collect()
}

/// NMEA: a log with bad lines is still read (they are counted), so the
/// outcome of an accepted log says what was skipped and why.
fn nmea(_: &Scratch, input: &[u8]) -> String {
    match parse_nmea(Path::new("fuzz.nmea"), input) {
        Ok(log) => {
            let flags = [
                log.fixes.is_empty(),
                log.rmc_only_fixes > 0,
                log.first_out_of_order.is_some(),
                log.duplicate_epochs > 0,
                log.epochs_without_fix > 0,
                log.leap_second_epochs > 0,
            ];
            let flags: String = flags.iter().map(|&f| if f { 'x' } else { '-' }).collect();
            let skipped = log.first_unparsable.map(|s| unquoted(&s.reason)).unwrap_or_default();
            format!("ok {flags} {skipped}")
        }
        Err(e) => outcome(&Err::<(), _>(e)),
    }
}

fn cdr(_: &Scratch, input: &[u8]) -> String {
    let image = decode_image(input).and_then(|image| image_to_scan(&image, &SweepTiming::default(), 0.0438));
    [
        text_outcome(&decode_odometry(input)),
        text_outcome(&decode_pose_with_covariance_stamped(input)),
        text_outcome(&decode_nav_sat_fix(input)),
        text_outcome(&image),
    ]
    .join(" | ")
}

fn decawave(_: &Scratch, input: &[u8]) -> String {
    let path = Path::new("fuzz.log");
    let text = String::from_utf8_lossy(input);
    let by_timestamp = parse_decawave_log_detailed(path, &text, &DecawaveConfig::default());
    let by_period = DecawaveConfig {
        time_base: DecawaveTimeBase::FramePeriod { period_ns: 10_000_000 },
        delay_reference: DecawaveDelayReference::FirstPath,
        ..DecawaveConfig::default()
    };
    let by_period = parse_decawave_log_detailed(path, &text, &by_period);
    format!("{} | {}", outcome(&by_timestamp), outcome(&by_period))
}

/// Splits `sidecar, NUL, rest` and parses the sidecar (`None` when empty).
fn split_sidecar(input: &[u8]) -> Result<(Option<CirSidecar>, &[u8]), String> {
    let (text, rest) = match input.iter().position(|&b| b == 0) {
        Some(nul) => (&input[..nul], &input[nul + 1..]),
        None => (input, &[][..]),
    };
    if text.is_empty() {
        return Ok((None, rest));
    }
    let sidecar = CirSidecar::parse(Path::new("fuzz.toml"), &String::from_utf8_lossy(text));
    sidecar.map(|s| (Some(s), rest)).map_err(|e| outcome::<()>(&Err(e)))
}

fn npy(scratch: &Scratch, input: &[u8]) -> String {
    let (sidecar, file) = match split_sidecar(input) {
        Ok(split) => split,
        Err(outcome) => return outcome,
    };
    let (format, name) =
        if file.starts_with(b"PK") { (CirFormat::Npz, "fuzz.npz") } else { (CirFormat::Npy, "fuzz.npy") };
    let cir = match scratch.write(name, file) {
        Ok(path) => outcome(&read_cir_file(format, &path, sidecar.as_ref())),
        Err(e) => e,
    };
    let matrix = parse_npy_matrix(Path::new("fuzz.npy"), file);
    format!("{cir} | {}", outcome(&matrix))
}

fn mat(scratch: &Scratch, input: &[u8]) -> String {
    let (sidecar, file) = match split_sidecar(input) {
        Ok(split) => split,
        Err(outcome) => return outcome,
    };
    let via_sidecar = match scratch.write("fuzz.mat", file) {
        Ok(path) => outcome(&read_cir_file(CirFormat::Mat, &path, sidecar.as_ref())),
        Err(e) => e,
    };
    let layout = MatCirLayout {
        variable: sidecar.as_ref().and_then(|s| s.variable.clone()).unwrap_or_else(|| "CIR_mat".into()),
        carrier_hz: 60e9,
        tap_spacing_s: 1e-10,
        delay_offset_s: 0.0,
        t_ns: 0,
        tap_axis: 2,
        tx_axis: Some(1),
        rx_axis: Some(0),
        allow_real: sidecar.as_ref().is_some_and(|s| s.allow_real),
    };
    let in_memory = read_mat_cir(Path::new("fuzz.mat"), file, &layout);
    format!("{via_sidecar} | {}", outcome(&in_memory))
}

fn sigmf(scratch: &Scratch, input: &[u8]) -> String {
    let (sidecar, rest) = match split_sidecar(input) {
        Ok(split) => split,
        Err(outcome) => return outcome,
    };
    let (meta, data) = match rest.iter().position(|&b| b == 0) {
        Some(nul) => (&rest[..nul], &rest[nul + 1..]),
        None => (rest, &[][..]),
    };
    let written =
        scratch.write("fuzz.sigmf-meta", meta).and_then(|meta| Ok((meta, scratch.write("fuzz.sigmf-data", data)?)));
    match written {
        Ok((meta, _)) => outcome(&read_cir_file(CirFormat::Sigmf, &meta, sidecar.as_ref())),
        Err(e) => e,
    }
}

fn csv(scratch: &Scratch, input: &[u8]) -> String {
    let (sidecar, file) = match split_sidecar(input) {
        Ok(split) => split,
        Err(outcome) => return outcome,
    };
    match scratch.write("fuzz.csv", file) {
        Ok(path) => outcome(&read_cir_file(CirFormat::Csv, &path, sidecar.as_ref())),
        Err(e) => e,
    }
}
