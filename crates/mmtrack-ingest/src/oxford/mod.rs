//! Oxford Radar RobotCar sequence folders.
//!
//! Layout: `radar/<t_us>.png` (polar scans, see [`png_scan`]; 400 azimuth
//! rows of 11 + 3768 columns, checked from each PNG header before decoding),
//! `radar.timestamps` (`<t_us> <valid>` per scan; scans flagged 0 are skipped
//! and counted, and so are PNGs in `radar/` that it does not list), optional
//! `gt/radar_odometry.csv` (see [`odometry`]) and `gps/gps.csv` (see [`gps`])
//! and `gps/ins.csv` (see [`ins`]; its poses are the ground truth when there
//! is no `radar_odometry.csv`, its positions the GNSS fixes when there is no
//! `gps.csv`). Ground truth and GNSS fixes are kept within the time span of
//! the scans. Without `radar.timestamps`, every `radar/*.png` with a numeric
//! name is taken in time order. Scan stamps outside 2000-2100 are refused.
//!
//! An optional file that exists but is no readable regular file (a
//! directory, a broken link, a device) is an error, not an absent file.
//!
//! Attribution for the real sample used in tests: Oxford Radar RobotCar
//! Dataset (Barnes et al., ICRA 2020), CC BY-NC-SA 4.0.

pub mod gps;
pub mod ins;
pub mod odometry;
pub mod png_scan;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use mmtrack_core::{GnssFix, PolarScan, StampedPose};
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase, WriteSummary};
use mmtrack_io::{RecordingOptions, RecordingWriter};

use crate::error::os_err;
use crate::scan_folder::{
    SameSize, StampUnit, decode_in_order, folder_name, list_scan_pngs, not_a_readable_file, optional_file,
    sort_and_check, within_scan_span,
};
use crate::{IngestError, Progress};
pub use png_scan::{
    DecodedScanPng, HEADER_COLUMNS, NavtechLayout, OXFORD, decode_scan_png, decode_scan_png_file, encode_scan_png,
    shift_scan_png_times,
};

pub use crate::scan_folder::ScanFile;

/// An Oxford-layout sequence folder, listed but not yet read.
#[derive(Debug, Clone)]
pub struct OxfordFolder {
    /// The folder.
    pub root: PathBuf,
    /// Scans to ingest, in time order.
    pub scans: Vec<ScanFile>,
    /// Scans listed in `radar.timestamps` with valid flag 0 (skipped).
    pub skipped_invalid: u64,
    /// PNGs in `radar/` that `radar.timestamps` does not list (skipped), in
    /// name order.
    pub unlisted_pngs: Vec<PathBuf>,
    /// `gt/radar_odometry.csv`, when present.
    pub ground_truth: Option<PathBuf>,
    /// `gps/gps.csv`, when present.
    pub gps: Option<PathBuf>,
    /// `gps/ins.csv`, when present.
    pub ins: Option<PathBuf>,
    /// What the times count from: UNIX time (the dataset's), unless the
    /// folder was simulated ([`SIMULATION_MARKER`]).
    pub time_base: TimeBase,
}

/// The file `mmtrack simulate radar --format oxford` writes beside the
/// dataset's files: the folder's time base (`scenario_start` for the
/// simulator's clock), so that ingesting it does not label simulated times
/// as UNIX dates. The Oxford SDK ignores it; real folders do not have it.
pub const SIMULATION_MARKER: &str = "mmtrack-simulation.toml";

/// The text of [`SIMULATION_MARKER`] for a folder of `time_base`.
#[must_use]
pub fn simulation_marker_text(time_base: TimeBase) -> String {
    format!(
        "# Written by `mmtrack simulate radar --format oxford`: the scans of this folder are simulated.\n\
         # `mmtrack ingest oxford` records this time base (what the times count from).\n\
         time_base = \"{}\"\n",
        time_base.as_str()
    )
}

/// The time base a [`SIMULATION_MARKER`] at `path` states.
fn read_simulation_marker(path: &Path) -> Result<TimeBase, IngestError> {
    let bad = |detail: String| IngestError::BadLayout { path: path.to_path_buf(), detail };
    let text = mmtrack_io::paths::read_config_text(path)?;
    let table: toml::Table = toml::from_str(&text).map_err(|e| bad(e.message().to_string()))?;
    if let Some(key) = table.keys().find(|k| *k != "time_base") {
        return Err(bad(format!("unknown key `{key}` (the simulator writes time_base only)")));
    }
    match table.get("time_base").and_then(toml::Value::as_str) {
        Some("scenario_start") => Ok(TimeBase::ScenarioStart),
        Some("unix_epoch") => Ok(TimeBase::UnixEpoch),
        other => {
            let found = other.map_or_else(|| "missing".to_string(), |v| format!("\"{v}\""));
            Err(bad(format!("key `time_base`: {found}, expected \"scenario_start\" or \"unix_epoch\"")))
        }
    }
}

fn parse_stamp(path: &Path, line: usize, raw: &str) -> Result<i64, IngestError> {
    StampUnit::Micros.parse(path, &format!("line {line}"), raw)
}

impl OxfordFolder {
    /// Lists a folder, checking that it holds scans.
    pub fn open(root: &Path) -> Result<Self, IngestError> {
        if !root.is_dir() {
            let what = if root.exists() { "is not a folder" } else { "does not exist" };
            return Err(IngestError::BadLayout {
                path: root.to_path_buf(),
                detail: format!(
                    "{what}; expected an Oxford Radar RobotCar sequence folder (radar/<t_us>.png, radar.timestamps)"
                ),
            });
        }
        let radar_dir = root.join("radar");
        if !radar_dir.is_dir() {
            return Err(IngestError::BadLayout {
                path: root.to_path_buf(),
                detail:
                    "no radar/ folder; expected an Oxford Radar RobotCar sequence (radar/<t_us>.png, radar.timestamps)"
                        .into(),
            });
        }
        let timestamps = root.join("radar.timestamps");
        let mut skipped_invalid = 0;
        let mut scans = Vec::new();
        let mut unlisted_pngs = Vec::new();
        if optional_file(&timestamps)?.is_some() {
            let text = crate::error::read_line_records(&timestamps)?;
            let mut listed = BTreeSet::new();
            for (index, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
                let mut parts = line.split_whitespace();
                let t_ns = parse_stamp(&timestamps, index + 1, parts.next().unwrap_or(""))?;
                let path = radar_dir.join(format!("{}.png", t_ns / 1000));
                listed.insert(path.clone());
                // The SDK's valid flag: 1 valid, 0 not; anything else (a
                // missing flag, a 7, a third field) is not this file's format.
                let valid = match (parts.next(), parts.next()) {
                    (Some("1"), None) => true,
                    (Some("0"), None) => false,
                    (flag, extra) => {
                        let found = [flag, extra].into_iter().flatten().collect::<Vec<_>>().join(" ");
                        return Err(IngestError::bad_line(
                            &timestamps,
                            index + 1,
                            "valid flag",
                            format!("`{found}`, expected 0 or 1 after the timestamp (`<t_us> <flag>`)"),
                        ));
                    }
                };
                if !valid {
                    skipped_invalid += 1;
                    continue;
                }
                if let Some(what) = not_a_readable_file(&path) {
                    return Err(IngestError::BadLayout {
                        path: timestamps.clone(),
                        detail: format!("line {} lists scan {} but {} {what}", index + 1, t_ns / 1000, path.display()),
                    });
                }
                scans.push(ScanFile { t_ns, path });
            }
            scans = sort_and_check(&radar_dir, scans)?;
            unlisted_pngs = png_files(&radar_dir)?.into_iter().filter(|p| !listed.contains(p)).collect();
        } else {
            scans = list_scan_pngs(&radar_dir, StampUnit::Micros)?;
        }
        let gt = root.join("gt").join("radar_odometry.csv");
        let gps = root.join("gps").join("gps.csv");
        let ins = root.join("gps").join("ins.csv");
        Ok(Self {
            root: root.to_path_buf(),
            scans,
            skipped_invalid,
            unlisted_pngs,
            ground_truth: optional_file(&gt)?,
            gps: optional_file(&gps)?,
            ins: optional_file(&ins)?,
            time_base: match optional_file(&root.join(SIMULATION_MARKER))? {
                Some(marker) => read_simulation_marker(&marker)?,
                None => TimeBase::UnixEpoch,
            },
        })
    }

    /// Sequence id: the folder name.
    #[must_use]
    pub fn sequence_id(&self) -> String {
        folder_name(&self.root)
    }
}

/// Every `*.png` file of `dir`, in name order.
fn png_files(dir: &Path) -> Result<Vec<PathBuf>, IngestError> {
    let mut pngs = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(os_err(dir))? {
        let path = entry.map_err(os_err(dir))?.path();
        if path.extension().is_some_and(|e| e == "png") && path.is_file() {
            pngs.push(path);
        }
    }
    pngs.sort();
    Ok(pngs)
}

/// How to ingest an Oxford folder.
#[derive(Debug, Clone)]
pub struct OxfordOptions {
    /// PNG layout and range scaling.
    pub layout: NavtechLayout,
    /// Carry the PNG bytes unchanged (`true`) or store decoded mono8 images.
    pub carry_png: bool,
    /// Sequence id; `None` takes the folder name.
    pub sequence_id: Option<String>,
}

impl Default for OxfordOptions {
    fn default() -> Self {
        Self { layout: OXFORD, carry_png: true, sequence_id: None }
    }
}

/// What an ingest did.
#[derive(Debug, Clone)]
pub struct IngestReport {
    /// Scans written.
    pub scans: u64,
    /// Scans skipped because `radar.timestamps` flags them invalid.
    pub skipped_invalid_scans: u64,
    /// PNGs in `radar/` skipped because `radar.timestamps` does not list
    /// them, in name order.
    pub unlisted_pngs: Vec<PathBuf>,
    /// Ground-truth poses written (those within the scans' time span).
    pub ground_truth_poses: u64,
    /// GNSS fixes written (those within the scans' time span).
    pub gnss_fixes: u64,
    /// What `gps/ins.csv` was used as (`ground truth`, `GNSS fixes`, both, or
    /// nothing when the other files take precedence); `None` without one.
    pub ins_used_as: Option<String>,
    /// `ins.csv` rows skipped because their status is not `INS_SOLUTION_GOOD`.
    pub ins_rows_not_good: u64,
    /// The recording.
    pub output: WriteSummary,
}

/// Ground truth and GNSS fixes of a folder, from whichever files it has.
struct Auxiliary {
    ground_truth: Vec<StampedPose>,
    fixes: Vec<GnssFix>,
    ins_used_as: Option<String>,
    ins_rows_not_good: u64,
}

/// Reads `radar_odometry.csv`, `gps.csv` and `ins.csv` (each when present);
/// `ins.csv` fills in for whichever of the other two is missing.
fn read_auxiliary(folder: &OxfordFolder, extra: &mut BTreeMap<String, String>) -> Result<Auxiliary, IngestError> {
    let mut aux = Auxiliary { ground_truth: Vec::new(), fixes: Vec::new(), ins_used_as: None, ins_rows_not_good: 0 };
    if let Some(path) = &folder.ground_truth {
        extra.insert("ground_truth.source".into(), mmtrack_io::paths::canonical(path));
        extra.insert("ground_truth.frame".into(), "radar".into());
        aux.ground_truth = odometry::read_radar_odometry(path)?;
    }
    if let Some(path) = &folder.gps {
        extra.insert("gnss.source".into(), mmtrack_io::paths::canonical(path));
        extra.insert("gnss.altitude_datum".into(), "as in the Oxford gps.csv (NovAtel)".into());
        aux.fixes = gps::read_gps_csv(path)?.into_iter().map(|row| row.fix).collect();
    }
    let Some(path) = &folder.ins else { return Ok(aux) };
    let solution = ins::read_ins_csv(path)?;
    let mut used = Vec::new();
    if folder.ground_truth.is_none() {
        extra.insert("ground_truth.source".into(), mmtrack_io::paths::canonical(path));
        extra.insert("ground_truth.frame".into(), "ins (local east-north frame about the origin)".into());
        for (axis, value) in ["east", "north", "up"].iter().zip(solution.origin) {
            extra.insert(format!("ground_truth.origin_{axis}_m"), value.to_string());
        }
        extra.insert("ground_truth.origin_utm_zone".into(), solution.utm_zone.clone());
        aux.ground_truth = solution.poses;
        used.push("ground truth");
    }
    if folder.gps.is_none() {
        extra.insert("gnss.source".into(), mmtrack_io::paths::canonical(path));
        extra.insert("gnss.altitude_datum".into(), "as in the Oxford ins.csv (NovAtel)".into());
        aux.fixes = solution.fixes;
        used.push("GNSS fixes");
    }
    let used_as = if used.is_empty() {
        "nothing (radar_odometry.csv and gps.csv take precedence)".to_string()
    } else {
        used.join(" and ")
    };
    extra.insert("ins.source".into(), mmtrack_io::paths::canonical(path));
    extra.insert("ins.used_as".into(), used_as.clone());
    aux.ins_used_as = Some(used_as);
    aux.ins_rows_not_good = solution.skipped_not_good;
    Ok(aux)
}

/// Ingests an Oxford folder into a new recording at `out`, one scan at a time.
pub fn ingest_oxford(
    folder: &OxfordFolder,
    out: &Path,
    options: &OxfordOptions,
    recording: &RecordingOptions,
    progress: Progress<'_>,
) -> Result<IngestReport, IngestError> {
    let sequence_id = crate::scan_folder::checked_sequence_id(&folder.root, options.sequence_id.as_deref())?;
    let layout = &options.layout;
    let mut extra = BTreeMap::from([
        ("radar.format".to_string(), "oxford-navtech-png".to_string()),
        ("radar.range_resolution_m".to_string(), layout.range_resolution_m.to_string()),
        ("radar.encoder_counts_per_turn".to_string(), layout.counts_per_turn.to_string()),
        ("radar.carried_png".to_string(), options.carry_png.to_string()),
    ]);
    let aux = read_auxiliary(folder, &mut extra)?;
    // Checked before anything is written.
    let source = |key: &str| extra.get(key).cloned().unwrap_or_default();
    let in_span =
        within_scan_span(&folder.scans, "poses", &source("ground_truth.source"), &aux.ground_truth, |p| p.t_ns)?;
    let fixes_in_span = within_scan_span(&folder.scans, "fixes", &source("gnss.source"), &aux.fixes, |f| f.t_ns)?;
    let metadata = RecordingMetadata {
        sequence_id,
        source: format!("oxford:{}", mmtrack_io::paths::canonical(&folder.root)),
        time_base: folder.time_base,
        extra,
    };
    let mut writer = RecordingWriter::create(out, &metadata, recording)?;
    let total = folder.scans.len() as u64;
    write_navtech_scans(&mut writer, &folder.scans, layout, options.carry_png, progress)?;
    for pose in &in_span {
        writer.write_pose(PoseStream::GroundTruth, pose, "world")?;
    }
    for fix in &fixes_in_span {
        writer.write_gnss_fix(fix)?;
    }
    let output = writer.finish()?;
    Ok(IngestReport {
        scans: total,
        skipped_invalid_scans: folder.skipped_invalid,
        unlisted_pngs: folder.unlisted_pngs.clone(),
        ground_truth_poses: in_span.len() as u64,
        gnss_fixes: fixes_in_span.len() as u64,
        ins_used_as: aux.ins_used_as,
        ins_rows_not_good: aux.ins_rows_not_good,
        output,
    })
}

/// A scan PNG as read and decoded on a worker thread: the PNG bytes to
/// carry, or the decoded scan (never both).
struct DecodedScan {
    payload: ScanPayload,
    cartesian: Option<Vec<u8>>,
}

enum ScanPayload {
    Png { header: mmtrack_core::PolarScanHeader, png: Vec<u8> },
    Scan(PolarScan),
}

/// Decodes Oxford/Boreas-style scan PNGs (one worker per core) and writes them
/// in order: the PNG bytes carried unchanged, or decoded mono8 images. Every
/// scan must have the size of the first.
///
/// Memory: a PNG is decoded from its file piece by piece (never held whole
/// beside its image); a carried PNG is read whole after its image is
/// dropped. What one scan holds, the larger of the two plus its Cartesian
/// view, counts against [`crate::scan_folder::SCAN_MEMORY_BUDGET_BYTES`]
/// until the writer has taken it.
pub(crate) fn write_navtech_scans(
    writer: &mut RecordingWriter,
    scans: &[ScanFile],
    layout: &NavtechLayout,
    carry_png: bool,
    progress: Progress<'_>,
) -> Result<(), IngestError> {
    let total = scans.len() as u64;
    // The Cartesian view is resampled on the decoding threads, from the
    // decoded image with its header columns skipped.
    let resampler = writer.cartesian_resampler().cloned();
    let view_bytes = resampler.as_ref().map_or(0, |r| (r.grid().size_px as usize).pow(2));
    let cost = |scan: &ScanFile| {
        let image = crate::scan_folder::png_image_bytes(&scan.path);
        let carried = if carry_png { crate::scan_folder::file_bytes(&scan.path) } else { 0 };
        image.max(carried).saturating_add(view_bytes)
    };
    let decode = |scan: &ScanFile| -> Result<DecodedScan, IngestError> {
        let (file, _) = crate::error::open_capped(&scan.path, &mmtrack_core::limits::SCAN_PNG_BYTES)?;
        let decoded = decode_scan_png_file(&scan.path, &file, scan.t_ns, layout)?;
        drop(file);
        let cartesian =
            match &resampler {
                Some(r) => Some(r.resample(&decoded.header, &decoded.pixels, decoded.width, HEADER_COLUMNS).map_err(
                    |detail| IngestError::BadRecord {
                        path: scan.path.clone(),
                        record: "scan image".into(),
                        field: "cartesian view".into(),
                        detail,
                    },
                )?),
                None => None,
            };
        let payload = if carry_png {
            let DecodedScanPng { header, pixels, .. } = decoded;
            drop(pixels); // before the file is read
            ScanPayload::Png {
                header,
                png: crate::error::read_capped(&scan.path, &mmtrack_core::limits::SCAN_PNG_BYTES)?,
            }
        } else {
            ScanPayload::Scan(decoded.into_scan())
        };
        Ok(DecodedScan { payload, cartesian })
    };
    let mut same_size = SameSize::default();
    let mut write = |index: usize, scan: DecodedScan| -> Result<(), IngestError> {
        let DecodedScan { payload, cartesian } = scan;
        let header = match &payload {
            ScanPayload::Png { header, .. } => header,
            ScanPayload::Scan(scan) => &scan.header,
        };
        same_size.check(&scans[index].path, header.azimuths.len(), header.bins_per_azimuth)?;
        match &payload {
            ScanPayload::Png { header, png } => {
                writer.write_radar_png_and_view(header, png, HEADER_COLUMNS as u32, cartesian.as_deref())?;
            }
            ScanPayload::Scan(scan) => writer.write_radar_scan_and_view(scan, cartesian.as_deref())?,
        }
        progress(index as u64 + 1, total);
        Ok(())
    };
    decode_in_order(scans, &cost, &decode, &mut write)
}

/// Writes scans (and optional relative-pose ground truth) as an Oxford-layout
/// folder: the inverse of [`OxfordFolder::open`], for fixtures and benchmarks.
pub fn write_oxford_folder(
    root: &Path,
    scans: &[PolarScan],
    ground_truth: &[StampedPose],
    layout: &NavtechLayout,
) -> Result<(), IngestError> {
    let radar_dir = root.join("radar");
    mmtrack_io::create_output_dirs(&radar_dir).map_err(os_err(&radar_dir))?;
    let mut timestamps = String::new();
    for scan in scans {
        let t_us = scan.header.t_ns / 1000;
        let path = radar_dir.join(format!("{t_us}.png"));
        let png =
            encode_scan_png(scan, layout).map_err(|detail| IngestError::BadLayout { path: path.clone(), detail })?;
        std::fs::write(&path, png).map_err(os_err(&path))?;
        timestamps.push_str(&format!("{t_us} 1\n"));
    }
    let path = root.join("radar.timestamps");
    std::fs::write(&path, timestamps).map_err(os_err(&path))?;
    if ground_truth.len() >= 2 {
        let gt_dir = root.join("gt");
        mmtrack_io::create_output_dirs(&gt_dir).map_err(os_err(&gt_dir))?;
        let mut csv = String::from(
            "source_timestamp,destination_timestamp,x,y,z,roll,pitch,yaw,source_radar_timestamp,destination_radar_timestamp\n",
        );
        for w in ground_truth.windows(2) {
            let relative = w[0].parent_from_child.inverse() * w[1].parent_from_child;
            let (source_us, destination_us) = (w[1].t_ns / 1000, w[0].t_ns / 1000);
            csv.push_str(&format!(
                "{source_us},{destination_us},{:.6},{:.6},0.000000,0.000000,0.000000,{:.6},{source_us},{destination_us}\n",
                // Back to the dataset's x forward / y right / z down frame (see `odometry`).
                relative.x_m, -relative.y_m, -relative.yaw_rad
            ));
        }
        let path = gt_dir.join("radar_odometry.csv");
        std::fs::write(&path, csv).map_err(os_err(&path))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests;
