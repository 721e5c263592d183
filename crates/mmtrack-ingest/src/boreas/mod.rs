//! Boreas sequence folders (University of Toronto; Burnett et al., "Boreas: A
//! multi-season autonomous driving dataset", IJRR 2023; layout and conventions
//! from the pyboreas devkit's `DATA_REFERENCE.md` and `utils/radar.py`).
//!
//! Layout: `boreas-YYYY-MM-DD-HH-MM/radar/<t_us>.png` and, when present,
//! `applanix/radar_poses.csv` (or another `applanix/<sensor>_poses.csv`; see
//! [`applanix`]) and `applanix/gps_post_process.csv` (GNSS fixes, see
//! [`gps`]).
//!
//! Scans use the Oxford row header (int64 microseconds, uint16 encoder of 5600
//! counts per turn, one more byte), so they are read by the Oxford decoder
//! with a Boreas [`NavtechLayout`]:
//! - the numbers of range bins and of azimuth rows are taken from the files
//!   (the CIR204-H gives 3360 bins before the 2021 upgrade and more after it);
//!   every scan of a folder must have the same as the first;
//! - range resolution by recording date: 0.0596 m per bin before 2021-09-21 and
//!   0.04381 m from that day on (pyboreas switches at 1632182400 s, 2021-09-21
//!   00:00 UTC). The date is parsed from the folder name; a folder renamed
//!   away from `boreas-YYYY-MM-DD-HH-MM` falls back to the first scan's time,
//!   as pyboreas does; `range_resolution_m` overrides both. The metadata says
//!   which rule decided (`radar.range_resolution_source`). The folder name is
//!   the local (Toronto) start time, so the two rules could only disagree for
//!   a drive started on the evening of 2021-09-20, and no sequence was; a
//!   folder date other than the first scan's UTC date or the day before is
//!   refused, naming both (the folder name would pick the range bin);
//! - range offset -0.31 m (`range_offset_m` of every scan, and
//!   `radar.range_offset_m` in the metadata);
//! - byte 10 is documented as unused in Boreas (the Oxford valid flag), so
//!   every azimuth is marked valid.
//!
//! File names are the scan's middle azimuth time, not its first (the dataset
//! reference); each azimuth keeps its own time from the row header.

pub mod applanix;
pub mod gps;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use mmtrack_core::NS_PER_S;
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase, WriteSummary};
use mmtrack_io::{RecordingOptions, RecordingWriter};

use crate::error::os_err;
use crate::oxford::{NavtechLayout, OXFORD, write_navtech_scans};
use crate::scan_folder::{ScanFile, StampUnit, folder_name, list_scan_pngs, within_scan_span};
use crate::{IngestError, Progress};
use mmtrack_core::calendar::{civil_from_days, days_from_civil};

/// Range bin before the radar upgrade of 2021-09-21, metres.
pub const RESOLUTION_BEFORE_UPGRADE_M: f64 = 0.0596;
/// Range bin from 2021-09-21 on, metres.
pub const RESOLUTION_AFTER_UPGRADE_M: f64 = 0.04381;
/// First day with the finer range bins, (year, month, day).
pub const UPGRADE_DATE: (u32, u32, u32) = (2021, 9, 21);
/// pyboreas's switch time, UNIX seconds (2021-09-21 00:00 UTC).
pub const UPGRADE_UNIX_S: i64 = 1_632_182_400;
/// Nanoseconds per day.
const NS_PER_DAY: i64 = 86_400 * NS_PER_S;

/// Range of bin 0, metres.
pub const RANGE_OFFSET_M: f64 = -0.31;

/// A Boreas sequence folder, listed but not yet read.
#[derive(Debug, Clone)]
pub struct BoreasFolder {
    /// The folder.
    pub root: PathBuf,
    /// Scans, in time order.
    pub scans: Vec<ScanFile>,
    /// The poses file and its sensor name (`radar` for `radar_poses.csv`).
    pub poses: Option<(PathBuf, String)>,
    /// `applanix/gps_post_process.csv`, when present (see [`gps`]).
    pub gps: Option<PathBuf>,
}

/// `boreas-YYYY-MM-DD-HH-MM` to (year, month, day).
#[must_use]
pub fn sequence_date(name: &str) -> Option<(u32, u32, u32)> {
    let parts: Vec<&str> = name.strip_prefix("boreas-")?.split('-').collect();
    let [year, month, day, hour, minute] = parts.as_slice() else { return None };
    let number = |text: &str, digits: usize| {
        (text.len() == digits && text.bytes().all(|b| b.is_ascii_digit())).then(|| text.parse::<u32>().ok()).flatten()
    };
    let (y, m, d) = (number(year, 4)?, number(month, 2)?, number(day, 2)?);
    let (h, min) = (number(hour, 2)?, number(minute, 2)?);
    ((1..=12).contains(&m) && (1..=31).contains(&d) && h < 24 && min < 60).then_some((y, m, d))
}

fn find_poses(root: &Path) -> Result<Option<(PathBuf, String)>, IngestError> {
    let dir = root.join("applanix");
    let radar = dir.join("radar_poses.csv");
    if let Some(radar) = crate::scan_folder::optional_file(&radar)? {
        return Ok(Some((radar, "radar".into())));
    }
    if !dir.is_dir() {
        return Ok(None);
    }
    let mut others = Vec::new();
    for entry in std::fs::read_dir(&dir).map_err(os_err(&dir))? {
        let path = entry.map_err(os_err(&dir))?.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if let Some(sensor) = name.strip_suffix("_poses.csv") {
            others.push((path.clone(), sensor.to_string()));
        }
    }
    others.sort();
    Ok(others.into_iter().next())
}

impl BoreasFolder {
    /// Lists a folder, checking that it holds scans.
    pub fn open(root: &Path) -> Result<Self, IngestError> {
        let radar_dir = root.join("radar");
        if !radar_dir.is_dir() {
            return Err(IngestError::BadLayout {
                path: root.to_path_buf(),
                detail: "no radar/ folder; expected a Boreas sequence (radar/<t_us>.png, applanix/radar_poses.csv)"
                    .into(),
            });
        }
        let scans = list_scan_pngs(&radar_dir, StampUnit::Micros)?;
        let gps = root.join("applanix").join("gps_post_process.csv");
        Ok(Self {
            root: root.to_path_buf(),
            scans,
            poses: find_poses(root)?,
            gps: crate::scan_folder::optional_file(&gps)?,
        })
    }

    /// Sequence id: the folder name.
    #[must_use]
    pub fn sequence_id(&self) -> String {
        folder_name(&self.root)
    }

    /// Range resolution by recording date, and the rule that chose it.
    ///
    /// The folder name is the drive's local (Toronto) start time, so its
    /// date is the first scan's UTC date or the day before. A folder date
    /// further from the scans than that contradicts the data, and since the
    /// date picks the range bin, the folder is refused naming both dates.
    pub fn range_resolution(&self) -> Result<(f64, String), IngestError> {
        let name = self.sequence_id();
        let pick = |after: bool| if after { RESOLUTION_AFTER_UPGRADE_M } else { RESOLUTION_BEFORE_UPGRADE_M };
        let first_ns = self.scans.first().map_or(0, |s| s.t_ns);
        match sequence_date(&name) {
            Some(date) => {
                let (y, m, d) = date;
                let folder_day = days_from_civil(i64::from(y), i64::from(m), i64::from(d));
                let scan_day = first_ns.div_euclid(NS_PER_DAY);
                if !(0..=1).contains(&(scan_day - folder_day)) {
                    let (sy, sm, sd) = civil_from_days(scan_day);
                    return Err(IngestError::BadLayout {
                        path: self.root.clone(),
                        detail: format!(
                            "the folder name says the drive started on {y:04}-{m:02}-{d:02} (local time), but the \
                             first scan is stamped {} us, on {sy:04}-{sm:02}-{sd:02} UTC; the date picks the range \
                             bin ({RESOLUTION_BEFORE_UPGRADE_M} m before 2021-09-21, {RESOLUTION_AFTER_UPGRADE_M} m \
                             from then on): rename the folder or give --range-resolution-m",
                            first_ns / 1000
                        ),
                    });
                }
                Ok((pick(date >= UPGRADE_DATE), format!("folder date {y:04}-{m:02}-{d:02} (upgrade 2021-09-21)")))
            }
            None => Ok((
                pick(first_ns >= UPGRADE_UNIX_S * 1_000_000_000),
                format!("first scan time {} us (folder name '{name}' is not boreas-YYYY-MM-DD-HH-MM)", first_ns / 1000),
            )),
        }
    }
}

/// How to ingest a Boreas folder.
#[derive(Debug, Clone, Default)]
pub struct BoreasOptions {
    /// Range bin size; `None` chooses it by recording date.
    pub range_resolution_m: Option<f64>,
    /// Store decoded mono8 images instead of carrying the PNG bytes unchanged.
    pub decode: bool,
    /// Sequence id; `None` takes the folder name.
    pub sequence_id: Option<String>,
}

/// What a Boreas ingest did.
#[derive(Debug, Clone)]
pub struct BoreasReport {
    /// Scans written.
    pub scans: u64,
    /// Ground-truth poses written (those within the scans' time span).
    pub ground_truth_poses: u64,
    /// GNSS fixes written from `gps_post_process.csv` (within the scans' time span).
    pub gnss_fixes: u64,
    /// The range resolution used, metres.
    pub range_resolution_m: f64,
    /// Why that resolution.
    pub range_resolution_source: String,
    /// The recording.
    pub output: WriteSummary,
}

/// Ingests a Boreas folder into a new recording at `out`, one scan at a time.
pub fn ingest_boreas(
    folder: &BoreasFolder,
    out: &Path,
    options: &BoreasOptions,
    recording: &RecordingOptions,
    progress: Progress<'_>,
) -> Result<BoreasReport, IngestError> {
    let sequence_id = crate::scan_folder::checked_sequence_id(&folder.root, options.sequence_id.as_deref())?;
    let (range_resolution_m, source) = match options.range_resolution_m {
        Some(given) => (given, "given by the caller".to_string()),
        None => folder.range_resolution()?,
    };
    let layout = NavtechLayout {
        range_resolution_m,
        range_offset_m: RANGE_OFFSET_M,
        expected_bins: None,
        expected_azimuths: None,
        valid_byte_is_flag: false,
        ..OXFORD
    };
    let mut extra = BTreeMap::from([
        ("radar.format".to_string(), "boreas-navtech-png".to_string()),
        ("radar.range_resolution_m".to_string(), range_resolution_m.to_string()),
        ("radar.range_resolution_source".to_string(), source.clone()),
        ("radar.range_offset_m".to_string(), RANGE_OFFSET_M.to_string()),
        ("radar.encoder_counts_per_turn".to_string(), layout.counts_per_turn.to_string()),
        ("radar.valid_byte".to_string(), "ignored (unused in Boreas); every azimuth valid".to_string()),
        ("radar.scan_stamp".to_string(), "file name = middle azimuth time".to_string()),
        ("radar.carried_png".to_string(), (!options.decode).to_string()),
    ]);
    let truth = match &folder.poses {
        Some((path, sensor)) => {
            let text = crate::error::read_line_records(path)?;
            let parsed = applanix::parse_applanix_poses(path, &text)?;
            extra.insert("ground_truth.source".into(), mmtrack_io::paths::canonical(path));
            extra.insert("ground_truth.frame".into(), sensor.clone());
            extra.insert("ground_truth.origin_frame".into(), parsed.position_frame.into());
            for (axis, value) in ["east", "north", "up"].iter().zip(parsed.origin) {
                extra.insert(format!("ground_truth.origin_{axis}_m"), value.to_string());
            }
            Some((parsed.poses, sensor.as_str()))
        }
        None => None,
    };
    let fixes = match &folder.gps {
        Some(path) => {
            extra.insert("gnss.source".into(), mmtrack_io::paths::canonical(path));
            extra.insert("gnss.kind".into(), "Applanix post-processed GNSS/INS solution (200 Hz)".into());
            gps::read_boreas_gps(path)?
        }
        None => Vec::new(),
    };
    // Checked before anything is written.
    let truth = match &truth {
        Some((poses, sensor)) => {
            let source = folder.poses.as_ref().map(|(path, _)| path.display().to_string()).unwrap_or_default();
            Some((within_scan_span(&folder.scans, "poses", &source, poses, |p| p.t_ns)?, *sensor))
        }
        None => None,
    };
    let gps_source = folder.gps.as_ref().map(|path| path.display().to_string()).unwrap_or_default();
    let fixes = within_scan_span(&folder.scans, "fixes", &gps_source, &fixes, |f| f.t_ns)?;
    let metadata = RecordingMetadata {
        sequence_id,
        source: format!("boreas:{}", mmtrack_io::paths::canonical(&folder.root)),
        time_base: TimeBase::UnixEpoch,
        extra,
    };
    let mut writer = RecordingWriter::create(out, &metadata, recording)?;
    write_navtech_scans(&mut writer, &folder.scans, &layout, !options.decode, progress)?;
    let mut ground_truth_poses = 0;
    if let Some((poses, _)) = &truth {
        for pose in poses {
            writer.write_pose(PoseStream::GroundTruth, pose, "world")?;
        }
        ground_truth_poses = poses.len() as u64;
    }
    for fix in &fixes {
        writer.write_gnss_fix(fix)?;
    }
    Ok(BoreasReport {
        scans: folder.scans.len() as u64,
        ground_truth_poses,
        gnss_fixes: fixes.len() as u64,
        range_resolution_m,
        range_resolution_source: source,
        output: writer.finish()?,
    })
}

#[cfg(test)]
mod tests;
