//! MulRan sequence folders (Kim et al., "MulRan: Multimodal Range Dataset for
//! Urban Place Recognition", ICRA 2020; layout as the MulRan file player and
//! its converters read it).
//!
//! Layout: `sensor_data/radar/polar/<t_ns>.png` and, when present,
//! `global_pose.csv` (see [`global_pose`]) at the sequence root and
//! `sensor_data/gps.csv` (see [`gps`]); poses and fixes within the scans'
//! time span are written.
//!
//! Scans are plain 8-bit greyscale PNGs with **range along the rows and
//! azimuth along the columns** (a Navtech CIR204-H: 400 columns of 3360
//! rows; both are read from the files, and every scan of a folder must have
//! the size of the first) and no row header: the only time is the file name,
//! in nanoseconds (19 digits; a name that is not a time between 2000 and 2100
//! is refused). Per-azimuth times are spread evenly over
//! one scan period (0.25 s at 4 Hz) ending at the file time by default (see
//! [`crate::sweep`] for why), and column `a` of `n` is at angle `a * 2 pi / n`.
//! Range bins are 0.05952 m from 0 m.
//!
//! The canonical image is one row per azimuth, so each scan is transposed and
//! stored as a mono8 image; the PNG bytes cannot be carried unchanged. The
//! recording metadata records the timing policy (`radar.azimuth_times`).

pub mod global_pose;
pub mod gps;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use mmtrack_core::{PolarScan, PolarScanHeader};
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase, WriteSummary};
use mmtrack_io::{RecordingOptions, RecordingWriter};

use crate::scan_folder::{
    SameSize, ScanFile, StampUnit, decode_in_order, folder_name, list_scan_pngs, within_scan_span,
};
use crate::sweep::SweepTiming;
use crate::{IngestError, Progress};

/// Range bin of MulRan's CIR204-H, metres.
pub const RANGE_RESOLUTION_M: f64 = 0.05952;

/// A MulRan sequence folder, listed but not yet read.
#[derive(Debug, Clone)]
pub struct MulranFolder {
    /// The folder.
    pub root: PathBuf,
    /// Scans, in time order.
    pub scans: Vec<ScanFile>,
    /// `global_pose.csv`, when present.
    pub global_pose: Option<PathBuf>,
    /// `sensor_data/gps.csv`, when present.
    pub gps: Option<PathBuf>,
}

impl MulranFolder {
    /// Lists a folder, checking that it holds scans.
    pub fn open(root: &Path) -> Result<Self, IngestError> {
        let polar = root.join("sensor_data").join("radar").join("polar");
        if !polar.is_dir() {
            return Err(IngestError::BadLayout {
                path: root.to_path_buf(),
                detail: "no sensor_data/radar/polar/ folder; expected a MulRan sequence \
                         (sensor_data/radar/polar/<t_ns>.png, global_pose.csv)"
                    .into(),
            });
        }
        let scans = list_scan_pngs(&polar, StampUnit::Nanos)?;
        let pose = root.join("global_pose.csv");
        let gps = root.join("sensor_data").join("gps.csv");
        Ok(Self {
            root: root.to_path_buf(),
            scans,
            global_pose: crate::scan_folder::optional_file(&pose)?,
            gps: crate::scan_folder::optional_file(&gps)?,
        })
    }

    /// Sequence id: the folder name.
    #[must_use]
    pub fn sequence_id(&self) -> String {
        folder_name(&self.root)
    }
}

/// How to read and ingest a MulRan folder.
#[derive(Debug, Clone)]
pub struct MulranOptions {
    /// Range bin size, metres.
    pub range_resolution_m: f64,
    /// How azimuth times are placed against the file time.
    pub timing: SweepTiming,
    /// Sequence id; `None` takes the folder name.
    pub sequence_id: Option<String>,
}

impl Default for MulranOptions {
    fn default() -> Self {
        Self { range_resolution_m: RANGE_RESOLUTION_M, timing: SweepTiming::default(), sequence_id: None }
    }
}

fn bad(path: &Path, field: &str, detail: String) -> IngestError {
    IngestError::BadRecord { path: path.to_path_buf(), record: "image".into(), field: field.into(), detail }
}

/// Decodes one MulRan polar PNG (columns = azimuths, rows = range bins) into
/// a scan with one row per azimuth. The image's shape is checked from its PNG
/// header before any pixel is decoded.
pub fn decode_mulran_png(
    path: &Path,
    png: &[u8],
    scan_t_ns: i64,
    options: &MulranOptions,
) -> Result<PolarScan, IngestError> {
    let image = mmtrack_io::Gray8Png::open(png).map_err(|detail| bad(path, "PNG data", detail))?;
    decode_mulran_image(path, image, scan_t_ns, options)
}

/// [`decode_mulran_png`] on the open PNG file of `path`, read piece by
/// piece: the file is never held whole beside its image.
pub fn decode_mulran_png_file(
    path: &Path,
    file: &std::fs::File,
    scan_t_ns: i64,
    options: &MulranOptions,
) -> Result<PolarScan, IngestError> {
    let image = mmtrack_io::Gray8Png::open_file(file).map_err(|detail| bad(path, "PNG data", detail))?;
    decode_mulran_image(path, image, scan_t_ns, options)
}

fn decode_mulran_image(
    path: &Path,
    image: mmtrack_io::Gray8Png<'_>,
    scan_t_ns: i64,
    options: &MulranOptions,
) -> Result<PolarScan, IngestError> {
    let (azimuths, bins) = (image.width(), image.height());
    if azimuths == 0 || bins == 0 {
        return Err(bad(path, "width/height", format!("{azimuths} x {bins} image has no pixels")));
    }
    if azimuths > bins {
        return Err(bad(
            path,
            "width/height",
            format!(
                "{azimuths} columns x {bins} rows: expected azimuths along the columns and range bins along \
                 the rows (MulRan: 400 x 3360); is this an Oxford-style image?"
            ),
        ));
    }
    let pixels = image.decode().map_err(|detail| bad(path, "PNG data", detail))?;
    let mut power = vec![0u8; azimuths * bins];
    for (range_bin, row) in pixels.chunks_exact(azimuths).enumerate() {
        for (azimuth, value) in row.iter().enumerate() {
            power[azimuth * bins + range_bin] = *value;
        }
    }
    let samples = options.timing.azimuths(scan_t_ns, azimuths).map_err(|detail| bad(path, "azimuth times", detail))?;
    let header = PolarScanHeader {
        t_ns: scan_t_ns,
        range_resolution_m: options.range_resolution_m,
        range_offset_m: 0.0,
        bins_per_azimuth: bins,
        azimuths: samples,
    };
    PolarScan::new(header, power).map_err(|e| bad(path, "geometry", e.to_string()))
}

/// Encodes a scan as a MulRan polar PNG (range rows x azimuth columns, no
/// header): the inverse of [`decode_mulran_png`] for the power, used to make
/// fixtures. Azimuth times and angles are not stored, as in the dataset.
pub fn encode_mulran_png(scan: &PolarScan) -> Result<Vec<u8>, String> {
    let (azimuths, bins) = (scan.header.azimuths.len(), scan.header.bins_per_azimuth);
    let mut pixels = vec![0u8; azimuths * bins];
    for azimuth in 0..azimuths {
        let row = scan.row(azimuth).ok_or("power shorter than the header says")?;
        for (range_bin, value) in row.iter().enumerate() {
            pixels[range_bin * azimuths + azimuth] = *value;
        }
    }
    let width = u32::try_from(azimuths).map_err(|e| e.to_string())?;
    let height = u32::try_from(bins).map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(&pixels).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
    Ok(out)
}

/// What a MulRan ingest did.
#[derive(Debug, Clone)]
pub struct MulranReport {
    /// Scans written.
    pub scans: u64,
    /// Ground-truth poses written (those within the scans' time span).
    pub ground_truth_poses: u64,
    /// GNSS fixes written (those within the scans' time span).
    pub gnss_fixes: u64,
    /// The recording.
    pub output: WriteSummary,
}

fn metadata(
    folder: &MulranFolder,
    options: &MulranOptions,
) -> Result<(BTreeMap<String, String>, Vec<mmtrack_core::StampedPose>), IngestError> {
    let timing = &options.timing;
    let mut extra = BTreeMap::from([
        ("radar.format".to_string(), "mulran-polar-png (range rows x azimuth columns, transposed)".to_string()),
        ("radar.range_resolution_m".to_string(), options.range_resolution_m.to_string()),
        ("radar.carried_png".to_string(), "false".to_string()),
        (
            "radar.azimuth_times".to_string(),
            format!("spread evenly over {} ns, file time at the sweep's {}", timing.period_ns, timing.stamp_at.name()),
        ),
        ("radar.scan_period_ns".to_string(), timing.period_ns.to_string()),
        ("radar.stamp_at".to_string(), timing.stamp_at.name().to_string()),
    ]);
    let Some(path) = &folder.global_pose else { return Ok((extra, Vec::new())) };
    let text = crate::error::read_line_records(path)?;
    let parsed = global_pose::parse_global_pose(path, &text)?;
    extra.insert("ground_truth.source".into(), mmtrack_io::paths::canonical(path));
    extra.insert("ground_truth.frame".into(), "vehicle".into());
    for (axis, value) in ["x", "y", "z"].iter().zip(parsed.origin) {
        extra.insert(format!("ground_truth.origin_{axis}_m"), value.to_string());
    }
    Ok((extra, parsed.poses))
}

/// Ingests a MulRan folder into a new recording at `out`, one scan at a time.
pub fn ingest_mulran(
    folder: &MulranFolder,
    out: &Path,
    options: &MulranOptions,
    recording: &RecordingOptions,
    progress: Progress<'_>,
) -> Result<MulranReport, IngestError> {
    let sequence_id = crate::scan_folder::checked_sequence_id(&folder.root, options.sequence_id.as_deref())?;
    let (mut extra, truth) = metadata(folder, options)?;
    let fixes = match &folder.gps {
        Some(path) => {
            extra.insert("gnss.source".into(), mmtrack_io::paths::canonical(path));
            gps::read_mulran_gps(path)?
        }
        None => Vec::new(),
    };
    // Checked before anything is written.
    let source = |path: &Option<std::path::PathBuf>| path.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
    let truth = within_scan_span(&folder.scans, "poses", &source(&folder.global_pose), &truth, |p| p.t_ns)?;
    let fixes = within_scan_span(&folder.scans, "fixes", &source(&folder.gps), &fixes, |f| f.t_ns)?;
    let metadata = RecordingMetadata {
        sequence_id,
        source: format!("mulran:{}", mmtrack_io::paths::canonical(&folder.root)),
        time_base: TimeBase::UnixEpoch,
        extra,
    };
    let mut writer = RecordingWriter::create(out, &metadata, recording)?;
    let total = folder.scans.len() as u64;
    // The Cartesian view is resampled on the decoding threads too.
    let resampler = writer.cartesian_resampler().cloned();
    // The image and its transpose (the scan) are held at once.
    let view_bytes = resampler.as_ref().map_or(0, |r| (r.grid().size_px as usize).pow(2));
    let cost = |scan: &ScanFile| (2 * crate::scan_folder::png_image_bytes(&scan.path)).saturating_add(view_bytes);
    let decode = |scan: &ScanFile| -> Result<(PolarScan, Option<Vec<u8>>), IngestError> {
        let (file, _) = crate::error::open_capped(&scan.path, &mmtrack_core::limits::SCAN_PNG_BYTES)?;
        let polar = decode_mulran_png_file(&scan.path, &file, scan.t_ns, options)?;
        let view =
            match &resampler {
                Some(r) => Some(r.resample(&polar.header, &polar.power, polar.header.bins_per_azimuth, 0).map_err(
                    |detail| IngestError::BadRecord {
                        path: scan.path.clone(),
                        record: "scan image".into(),
                        field: "cartesian view".into(),
                        detail,
                    },
                )?),
                None => None,
            };
        Ok((polar, view))
    };
    let mut same_size = SameSize::default();
    decode_in_order(&folder.scans, &cost, &decode, &mut |index, (scan, view): (PolarScan, Option<Vec<u8>>)| {
        same_size.check(&folder.scans[index].path, scan.header.azimuths.len(), scan.header.bins_per_azimuth)?;
        writer.write_radar_scan_and_view(&scan, view.as_deref())?;
        progress(index as u64 + 1, total);
        Ok(())
    })?;
    for pose in &truth {
        writer.write_pose(PoseStream::GroundTruth, pose, "world")?;
    }
    for fix in &fixes {
        writer.write_gnss_fix(fix)?;
    }
    Ok(MulranReport {
        scans: total,
        ground_truth_poses: truth.len() as u64,
        gnss_fixes: fixes.len() as u64,
        output: writer.finish()?,
    })
}

#[cfg(test)]
mod tests;
