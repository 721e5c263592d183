//! Navtech polar PNGs with the Oxford/Boreas 11-byte row header.
//!
//! Each image row is one azimuth: bytes 0-7 the azimuth's UNIX time in
//! microseconds (int64 little-endian), bytes 8-9 the encoder count (uint16
//! little-endian, `counts_per_turn` per revolution), byte 10 the valid flag
//! (255 = a real measurement, as the Oxford SDK tests it; Boreas documents the
//! byte as unused, see [`NavtechLayout::valid_byte_is_flag`]), then the range
//! bins.

use std::f64::consts::TAU;
use std::path::Path;

use mmtrack_core::{AzimuthSample, PolarScan, PolarScanHeader, plausible};

use crate::IngestError;

/// Image columns before the first range bin.
pub const HEADER_COLUMNS: usize = 11;

/// How a dataset lays out and scales its polar PNGs.
#[derive(Debug, Clone, PartialEq)]
pub struct NavtechLayout {
    /// Encoder counts per revolution.
    pub counts_per_turn: u16,
    /// Range bin size, metres.
    pub range_resolution_m: f64,
    /// Range of bin 0, metres.
    pub range_offset_m: f64,
    /// Required number of range bins, or `None` to take it from each file.
    pub expected_bins: Option<usize>,
    /// Required number of azimuth rows, or `None` to take it from each file.
    pub expected_azimuths: Option<usize>,
    /// Whether byte 10 flags the row (255 = valid). `false` marks every row
    /// valid: Boreas documents the byte as unused.
    pub valid_byte_is_flag: bool,
}

/// Oxford Radar RobotCar (Navtech CTS350-X): 400 azimuths of 3768 bins of
/// 0.0432 m, as the dataset SDK states (CFEAR's code uses 0.0438 m;
/// `--range-resolution-m` overrides it).
pub const OXFORD: NavtechLayout = NavtechLayout {
    counts_per_turn: 5600,
    range_resolution_m: 0.0432,
    range_offset_m: 0.0,
    expected_bins: Some(3768),
    expected_azimuths: Some(400),
    valid_byte_is_flag: true,
};

/// A decoded scan PNG: the header and the full image (header columns included).
#[derive(Debug, Clone, PartialEq)]
pub struct DecodedScanPng {
    /// Timing and geometry parsed from the row headers.
    pub header: PolarScanHeader,
    /// Image width (header columns + bins).
    pub width: usize,
    /// Row-major pixels.
    pub pixels: Vec<u8>,
}

impl DecodedScanPng {
    /// The scan with header columns removed from the power.
    #[must_use]
    pub fn into_scan(self) -> PolarScan {
        // In place: row r's bins move left by the header columns of rows 0..=r.
        let Self { header, width, mut pixels } = self;
        let bins = width - HEADER_COLUMNS;
        let rows = pixels.len() / width;
        for row in 0..rows {
            pixels.copy_within(row * width + HEADER_COLUMNS..(row + 1) * width, row * bins);
        }
        pixels.truncate(rows * bins);
        PolarScan { header, power: pixels }
    }
}

fn bad(path: &Path, record: String, field: &str, detail: String) -> IngestError {
    IngestError::BadRecord { path: path.to_path_buf(), record, field: field.to_string(), detail }
}

/// Checks an image's size from its PNG header against the layout, before
/// anything is decoded.
fn check_size(path: &Path, width: usize, height: usize, layout: &NavtechLayout) -> Result<(), IngestError> {
    if width <= HEADER_COLUMNS {
        return Err(bad(
            path,
            "image".into(),
            "width",
            format!("{width} columns; expected {HEADER_COLUMNS} header columns plus range bins"),
        ));
    }
    let bins = width - HEADER_COLUMNS;
    if let Some(expected) = layout.expected_bins
        && bins != expected
    {
        return Err(bad(
            path,
            "image".into(),
            "width",
            format!("{width} columns ({bins} range bins); expected {HEADER_COLUMNS} + {expected} for this dataset"),
        ));
    }
    if let Some(expected) = layout.expected_azimuths
        && height != expected
    {
        return Err(bad(
            path,
            "image".into(),
            "height",
            format!("{height} rows; expected {expected} azimuth rows (one per azimuth) for this dataset"),
        ));
    }
    Ok(())
}

/// Decodes one scan PNG and parses its row headers. `scan_t_ns` is the scan's
/// own stamp (the file name); every row time must lie within
/// [`plausible::SCAN_ROW_TIME_TOLERANCE_NS`] of it. The size in the PNG header is checked against
/// the layout before any pixel is decoded. Errors name the file, the row and
/// the field.
pub fn decode_scan_png(
    path: &Path,
    png: &[u8],
    scan_t_ns: i64,
    layout: &NavtechLayout,
) -> Result<DecodedScanPng, IngestError> {
    let image = mmtrack_io::Gray8Png::open(png).map_err(|detail| bad(path, "image".into(), "PNG data", detail))?;
    decode_scan_image(path, image, scan_t_ns, layout)
}

/// [`decode_scan_png`] on the open PNG file of `path`, read piece by piece:
/// the file is never held whole beside its image.
pub fn decode_scan_png_file(
    path: &Path,
    file: &std::fs::File,
    scan_t_ns: i64,
    layout: &NavtechLayout,
) -> Result<DecodedScanPng, IngestError> {
    let image =
        mmtrack_io::Gray8Png::open_file(file).map_err(|detail| bad(path, "image".into(), "PNG data", detail))?;
    decode_scan_image(path, image, scan_t_ns, layout)
}

fn decode_scan_image(
    path: &Path,
    image: mmtrack_io::Gray8Png<'_>,
    scan_t_ns: i64,
    layout: &NavtechLayout,
) -> Result<DecodedScanPng, IngestError> {
    let png_error = |detail| bad(path, "image".into(), "PNG data", detail);
    let (width, height) = (image.width(), image.height());
    check_size(path, width, height, layout)?;
    let bins = width - HEADER_COLUMNS;
    let pixels = image.decode().map_err(png_error)?;
    let mut azimuths = Vec::with_capacity(height);
    for (row_index, row) in pixels.chunks_exact(width).enumerate() {
        let record = || format!("azimuth row {row_index}");
        let mut t_bytes = [0u8; 8];
        t_bytes.copy_from_slice(&row[0..8]);
        let t_us = i64::from_le_bytes(t_bytes);
        let t_ns = t_us.checked_mul(1000).filter(|t| *t > 0).ok_or_else(|| {
            bad(path, record(), "timestamp (bytes 0-7)", format!("{t_us} us is not a valid UNIX time"))
        })?;
        if !plausible::time_near(t_ns, scan_t_ns, plausible::SCAN_ROW_TIME_TOLERANCE_NS) {
            return Err(bad(
                path,
                record(),
                "timestamp (bytes 0-7)",
                format!(
                    "{t_us} us is {:.3} s from the scan's own stamp {} us (the file name); a sweep lasts 0.25 s, \
                     so its row times must lie within {} s of it",
                    (t_ns as f64 - scan_t_ns as f64) * 1e-9,
                    scan_t_ns / 1000,
                    plausible::SCAN_ROW_TIME_TOLERANCE_NS / 1_000_000_000
                ),
            ));
        }
        let counts = u16::from_le_bytes([row[8], row[9]]);
        if counts >= layout.counts_per_turn {
            return Err(bad(
                path,
                record(),
                "encoder (bytes 8-9)",
                format!("count {counts} is not below {} per turn", layout.counts_per_turn),
            ));
        }
        if let Some(previous) = azimuths.last().map(|a: &AzimuthSample| a.t_ns)
            && t_ns <= previous
        {
            return Err(bad(
                path,
                record(),
                "timestamp (bytes 0-7)",
                format!("{t_us} us does not increase (previous row {} us)", previous / 1000),
            ));
        }
        azimuths.push(AzimuthSample {
            t_ns,
            azimuth_rad: f64::from(counts) / f64::from(layout.counts_per_turn) * TAU,
            valid: !layout.valid_byte_is_flag || row[10] == 255,
        });
    }
    let header = PolarScanHeader {
        t_ns: scan_t_ns,
        range_resolution_m: layout.range_resolution_m,
        range_offset_m: layout.range_offset_m,
        bins_per_azimuth: bins,
        azimuths,
    };
    header.validate().map_err(|e| bad(path, "scan".into(), "geometry", e.to_string()))?;
    Ok(DecodedScanPng { header, width, pixels })
}

/// The scan PNG of `path` (its own stamp `scan_t_ns`) with every row time
/// moved by `shift_us` microseconds, re-encoded (balanced compression): the
/// same scan as if recorded `shift_us` later. Used to repeat real scans under
/// later stamps, whose row times must lie near the new stamp.
///
/// # Errors
/// As [`decode_scan_png`]; a shift that takes a row time out of range; an
/// encoder error.
pub fn shift_scan_png_times(
    path: &Path,
    png: &[u8],
    scan_t_ns: i64,
    shift_us: i64,
    layout: &NavtechLayout,
) -> Result<Vec<u8>, IngestError> {
    let DecodedScanPng { width, mut pixels, header } = decode_scan_png(path, png, scan_t_ns, layout)?;
    for (row_index, row) in pixels.chunks_exact_mut(width).enumerate() {
        let t_us = i64::from_le_bytes(row[0..8].try_into().unwrap_or([0; 8]));
        let shifted = t_us.checked_add(shift_us).ok_or_else(|| {
            bad(
                path,
                format!("azimuth row {row_index}"),
                "timestamp (bytes 0-7)",
                format!("{t_us} us + {shift_us} us overflows"),
            )
        })?;
        row[0..8].copy_from_slice(&shifted.to_le_bytes());
    }
    let encode = || -> Result<Vec<u8>, png::EncodingError> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, width as u32, header.azimuths.len() as u32);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Balanced);
        let mut writer = encoder.write_header()?;
        writer.write_image_data(&pixels)?;
        writer.finish()?;
        Ok(out)
    };
    encode().map_err(|e| bad(path, "image".into(), "PNG data", format!("re-encoding: {e}")))
}

/// Encodes a scan as an Oxford-style PNG (the inverse of [`decode_scan_png`],
/// up to the microsecond and encoder-count quantisation of the format). Used
/// to make fixtures and benchmark folders.
pub fn encode_scan_png(scan: &PolarScan, layout: &NavtechLayout) -> Result<Vec<u8>, String> {
    let bins = scan.header.bins_per_azimuth;
    let width = HEADER_COLUMNS + bins;
    let mut pixels = Vec::with_capacity(width * scan.header.azimuths.len());
    for (index, azimuth) in scan.header.azimuths.iter().enumerate() {
        let counts = (azimuth.azimuth_rad / TAU * f64::from(layout.counts_per_turn)).round() as i64;
        let counts = u16::try_from(counts.rem_euclid(i64::from(layout.counts_per_turn))).map_err(|e| e.to_string())?;
        pixels.extend_from_slice(&(azimuth.t_ns / 1000).to_le_bytes());
        pixels.extend_from_slice(&counts.to_le_bytes());
        pixels.push(if azimuth.valid { 255 } else { 0 });
        pixels.extend_from_slice(scan.row(index).ok_or("power shorter than the header says")?);
    }
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width as u32, scan.header.azimuths.len() as u32);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(&pixels).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The first real scan's stamp (Oxford sample), ns.
    const T0_NS: i64 = 1_547_131_046_353_776_000;

    fn scan(azimuths: usize, bins: usize) -> PolarScan {
        let azimuths: Vec<AzimuthSample> = (0..azimuths)
            .map(|a| AzimuthSample {
                t_ns: T0_NS + a as i64 * 625_000,
                azimuth_rad: a as f64 * TAU / 400.0,
                valid: a != 3,
            })
            .collect();
        let power = (0..azimuths.len() * bins).map(|i| (i % 251) as u8).collect();
        let header = PolarScanHeader {
            t_ns: T0_NS,
            range_resolution_m: 0.0432,
            range_offset_m: 0.0,
            bins_per_azimuth: bins,
            azimuths,
        };
        PolarScan::new(header, power).unwrap()
    }

    fn layout(bins: usize) -> NavtechLayout {
        NavtechLayout { expected_bins: Some(bins), expected_azimuths: None, ..OXFORD }
    }

    fn gray_png(width: u32, height: u32, depth: png::BitDepth, pixels: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, width, height);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(depth);
        encoder.write_header().unwrap().write_image_data(pixels).unwrap();
        out
    }

    #[test]
    fn encode_decode_round_trip_keeps_rows_and_headers() {
        let original = scan(20, 30);
        let png = encode_scan_png(&original, &layout(30)).unwrap();
        let decoded = decode_scan_png(Path::new("s.png"), &png, T0_NS, &layout(30)).unwrap().into_scan();
        assert_eq!(decoded.power, original.power);
        for (a, b) in decoded.header.azimuths.iter().zip(&original.header.azimuths) {
            // The format keeps microseconds and encoder counts (2 pi / 5600 rad).
            assert_eq!(a.t_ns, b.t_ns / 1000 * 1000);
            assert!((a.azimuth_rad - b.azimuth_rad).abs() <= TAU / 5600.0 / 2.0 + 1e-12);
            assert_eq!(a.valid, b.valid);
        }
    }

    #[test]
    fn wrong_width_depth_and_time_are_named() {
        let png = encode_scan_png(&scan(4, 30), &layout(30)).unwrap();
        let err = decode_scan_png(Path::new("s.png"), &png, T0_NS, &layout(3768)).unwrap_err().to_string();
        assert!(err.contains("s.png") && err.contains("width") && err.contains("3768"), "{err}");

        let sixteen = gray_png(41, 4, png::BitDepth::Sixteen, &vec![0; 41 * 4 * 2]);
        let err = decode_scan_png(Path::new("s.png"), &sixteen, T0_NS, &layout(30)).unwrap_err().to_string();
        assert!(err.contains("16-bit") && err.contains("8-bit greyscale"), "{err}");

        let mut backwards = scan(4, 30);
        backwards.header.azimuths[2].t_ns = backwards.header.azimuths[1].t_ns - 1000;
        let png = encode_scan_png(&backwards, &layout(30)).unwrap();
        let err = decode_scan_png(Path::new("s.png"), &png, T0_NS, &layout(30)).unwrap_err().to_string();
        assert!(
            err.contains("azimuth row 2") && err.contains("timestamp") && err.contains("does not increase"),
            "{err}"
        );

        let mut pixels = vec![0u8; 41 * 2];
        pixels[..8].copy_from_slice(&1_000_000i64.to_le_bytes());
        pixels[8..10].copy_from_slice(&6000u16.to_le_bytes());
        let err = decode_scan_png(
            Path::new("s.png"),
            &gray_png(41, 2, png::BitDepth::Eight, &pixels),
            1_000_000_000,
            &layout(30),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("azimuth row 0") && err.contains("encoder") && err.contains("5600"), "{err}");
    }

    /// Before: row times in 1970, in 2200 or an hour off the file name were
    /// ingested, and odometry reported a 10.3 m path instead of 19.2 m.
    #[test]
    fn row_times_far_from_the_file_stamp_are_refused() {
        let png = encode_scan_png(&scan(4, 30), &layout(30)).unwrap();
        // The last row is 1.875 ms after the first: within a sweep of the stamp.
        assert!(decode_scan_png(Path::new("s.png"), &png, T0_NS + 200_000_000, &layout(30)).is_ok());
        for (stamp_ns, offset) in [(T0_NS + 3_600_000_000_000, "-3600.000 s"), (T0_NS - 2_000_000_000, "2.000 s")] {
            let err = decode_scan_png(Path::new("s.png"), &png, stamp_ns, &layout(30)).unwrap_err().to_string();
            assert!(err.contains("s.png: azimuth row 0: timestamp (bytes 0-7)") && err.contains(offset), "{err}");
        }
        let mut old = scan(4, 30);
        old.header.azimuths[2].t_ns = 1_000_000_000;
        old.header.azimuths[3].t_ns = 2_000_000_000;
        let png = encode_scan_png(&old, &layout(30)).unwrap();
        let err = decode_scan_png(Path::new("s.png"), &png, T0_NS, &layout(30)).unwrap_err().to_string();
        assert!(err.contains("azimuth row 2") && err.contains("from the scan's own stamp"), "{err}");
    }

    /// The data of a PNG's IDAT chunks, concatenated (the zlib stream).
    fn idat(png: &[u8]) -> Vec<u8> {
        let (mut at, mut data) = (8, Vec::new());
        while at + 8 <= png.len() {
            let length = u32::from_be_bytes(png[at..at + 4].try_into().unwrap()) as usize;
            if &png[at + 4..at + 8] == b"IDAT" {
                data.extend_from_slice(&png[at + 8..at + 8 + length]);
            }
            at += 12 + length;
        }
        data
    }

    /// A greyscale PNG with this header and `zlib` as its image data, every
    /// chunk CRC correct (the png writer computes them).
    fn png_with_image_data(width: u32, height: u32, zlib: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, width, height);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().unwrap();
        writer.write_chunk(png::chunk::IDAT, zlib).unwrap();
        drop(writer);
        out
    }

    /// Before: a 74-byte PNG claiming 100000 x 100000 made the decoder ask for
    /// 10 GB (and abort) before its width was looked at; a 399-row image was
    /// taken as an Oxford scan. Now the header is checked first.
    #[test]
    fn size_is_checked_from_the_header_before_decoding() {
        let tiny = idat(&gray_png(1, 1, png::BitDepth::Eight, &[0]));
        let huge = png_with_image_data(100_000, 100_000, &tiny);
        assert!(huge.len() < 100);
        let err =
            decode_scan_png(Path::new("radar/1547131046353776.png"), &huge, T0_NS, &OXFORD).unwrap_err().to_string();
        assert!(
            err.contains("radar/1547131046353776.png: image: width: 100000 columns") && err.contains("11 + 3768"),
            "{err}"
        );
        // Right width, 100000 rows: the height is refused, still from the header.
        let tall = png_with_image_data(3779, 100_000, &tiny);
        let err = decode_scan_png(Path::new("t.png"), &tall, T0_NS, &OXFORD).unwrap_err().to_string();
        assert!(err.contains("t.png: image: height: 100000 rows; expected 400 azimuth rows"), "{err}");
        // A layout that takes the size from the file: the reader's cap.
        let auto = NavtechLayout { expected_bins: None, expected_azimuths: None, ..OXFORD };
        let err = decode_scan_png(Path::new("t.png"), &huge, T0_NS, &auto).unwrap_err().to_string();
        assert!(err.contains("t.png: image: PNG data: 100000 x 100000 pixels is over the 64 MiB"), "{err}");

        let full = NavtechLayout { expected_bins: Some(30), ..OXFORD };
        let png = encode_scan_png(&scan(399, 30), &full).unwrap();
        let err = decode_scan_png(Path::new("s.png"), &png, T0_NS, &full).unwrap_err().to_string();
        assert!(err.contains("s.png: image: height: 399 rows; expected 400 azimuth rows"), "{err}");
        assert!(
            decode_scan_png(Path::new("s.png"), &encode_scan_png(&scan(400, 30), &full).unwrap(), T0_NS, &full).is_ok()
        );
    }

    /// Before: one flipped byte of image data under a corrected chunk CRC was
    /// ingested as a good scan (the zlib Adler-32 was not checked).
    #[test]
    fn corrupted_image_data_under_a_good_crc_is_refused() {
        let layout = layout(30);
        let good = encode_scan_png(&scan(20, 30), &layout).unwrap();
        let mut zlib = idat(&good);
        let middle = zlib.len() / 2;
        zlib[middle] ^= 0x04;
        let bad = png_with_image_data(41, 20, &zlib);
        let err = decode_scan_png(Path::new("s.png"), &bad, T0_NS, &layout).unwrap_err().to_string();
        assert!(err.contains("s.png: image: PNG data") && err.contains("corrupt"), "{err}");
    }

    /// An Oxford folder: `radar.timestamps` lists 1 of 11 PNGs; the other 10
    /// are reported, not silently dropped. With `--bins auto`, a scan of
    /// another size than the first is refused.
    #[test]
    fn unlisted_pngs_are_counted_and_sizes_agree() {
        let dir = tempfile::tempdir().unwrap();
        let auto = NavtechLayout { expected_bins: None, expected_azimuths: None, ..OXFORD };
        let scans: Vec<PolarScan> = (0..11)
            .map(|i| {
                let mut s = scan(8, 30);
                let t0_ns = 1_547_131_046_353_776_000 + i * 250_000_000;
                for (a, azimuth) in s.header.azimuths.iter_mut().enumerate() {
                    azimuth.t_ns = t0_ns + a as i64 * 625_000;
                }
                s.header.t_ns = t0_ns;
                s
            })
            .collect();
        super::super::write_oxford_folder(dir.path(), &scans, &[], &auto).unwrap();
        let timestamps = dir.path().join("radar.timestamps");
        let all = std::fs::read_to_string(&timestamps).unwrap();
        std::fs::write(&timestamps, format!("{}\n", all.lines().nth(4).unwrap())).unwrap();
        let folder = super::super::OxfordFolder::open(dir.path()).unwrap();
        assert_eq!((folder.scans.len(), folder.unlisted_pngs.len()), (1, 10));
        assert!(folder.unlisted_pngs[0].ends_with("radar/1547131046353776.png"), "{:?}", folder.unlisted_pngs);
        let options = super::super::OxfordOptions { layout: auto.clone(), ..Default::default() };
        let out = dir.path().join("out.mcap");
        let recording = mmtrack_io::RecordingOptions::default();
        let report = super::super::ingest_oxford(&folder, &out, &options, &recording, &mut |_, _| {}).unwrap();
        assert_eq!((report.scans, report.unlisted_pngs.len()), (1, 10));

        // Every scan listed again, the last one a row short.
        std::fs::write(&timestamps, &all).unwrap();
        let last = dir.path().join(format!("radar/{}.png", scans[10].header.t_ns / 1000));
        let mut short = scans[10].clone();
        short.header.azimuths.pop();
        short.power.truncate(7 * 30);
        std::fs::write(&last, encode_scan_png(&short, &auto).unwrap()).unwrap();
        let folder = super::super::OxfordFolder::open(dir.path()).unwrap();
        assert!(folder.unlisted_pngs.is_empty());
        let out = dir.path().join("short.mcap");
        let err =
            super::super::ingest_oxford(&folder, &out, &options, &recording, &mut |_, _| {}).unwrap_err().to_string();
        assert!(err.contains(&last.display().to_string()) && err.contains("7 azimuths x 30 range bins"), "{err}");
        assert!(!out.exists(), "no partial output");
    }

    #[test]
    fn empty_folder_is_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("radar")).unwrap();
        let err = super::super::OxfordFolder::open(dir.path()).unwrap_err().to_string();
        assert!(err.contains("no scans found"), "{err}");
        let err = super::super::OxfordFolder::open(&dir.path().join("radar")).unwrap_err().to_string();
        assert!(err.contains("no radar/ folder"), "{err}");
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]
        /// Arbitrary row headers and arbitrary bytes never panic the decoder.
        #[test]
        fn row_header_parser_never_panics(rows in proptest::collection::vec(proptest::collection::vec(any::<u8>(), 14), 1..6),
                                          junk in proptest::collection::vec(any::<u8>(), 0..300)) {
            let pixels: Vec<u8> = rows.concat();
            let png = gray_png(14, rows.len() as u32, png::BitDepth::Eight, &pixels);
            let _ = decode_scan_png(Path::new("p.png"), &png, T0_NS, &layout(3));
            let _ = decode_scan_png(Path::new("p.png"), &junk, T0_NS, &layout(3));
            let mut cut = png.clone();
            cut.truncate(junk.len().min(png.len()));
            let _ = decode_scan_png(Path::new("p.png"), &cut, T0_NS, &layout(3));
        }

        /// Any scan the format can hold (increasing microsecond times within
        /// a second of the scan's stamp, angles in [0, 2 pi), any valid flags
        /// and power) decodes to itself, up to the encoder-count quantisation
        /// of the angle.
        #[test]
        fn row_headers_round_trip(
            rows in proptest::collection::vec((1i64..40_000, 0.0f64..TAU, any::<bool>()), 1..24),
            bins in 1usize..9,
            t0_us in 1i64..4_000_000_000_000_000,
            seed in any::<u8>(),
        ) {
            let mut t_us = t0_us;
            let azimuths: Vec<AzimuthSample> = rows
                .iter()
                .map(|&(step_us, azimuth_rad, valid)| {
                    t_us += step_us;
                    AzimuthSample { t_ns: t_us * 1000, azimuth_rad, valid }
                })
                .collect();
            let power: Vec<u8> = (0..azimuths.len() * bins).map(|i| (i as u8).wrapping_mul(31) ^ seed).collect();
            let header = PolarScanHeader { t_ns: t0_us * 1000, range_resolution_m: 0.0432, range_offset_m: 0.0, bins_per_azimuth: bins, azimuths };
            let original = PolarScan::new(header, power).unwrap();
            let png = encode_scan_png(&original, &layout(bins)).unwrap();
            let decoded = decode_scan_png(Path::new("p.png"), &png, t0_us * 1000, &layout(bins)).unwrap().into_scan();
            prop_assert_eq!(&decoded.power, &original.power);
            for (a, b) in decoded.header.azimuths.iter().zip(&original.header.azimuths) {
                prop_assert_eq!(a.t_ns, b.t_ns);
                prop_assert_eq!(a.valid, b.valid);
                // Nearest encoder count: within half a count (2 pi / 5600 / 2), or
                // a whole turn less when the angle rounds up to 5600 counts = 0.
                let error = (a.azimuth_rad - b.azimuth_rad).rem_euclid(TAU);
                prop_assert!(error.min(TAU - error) <= TAU / 5600.0 / 2.0 + 1e-12, "{} vs {}", a.azimuth_rad, b.azimuth_rad);
            }
        }
    }
}
