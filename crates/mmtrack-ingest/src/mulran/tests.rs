use std::path::Path;

use mmtrack_io::recording::PoseStream;
use mmtrack_io::{RecordingEvent, RecordingOptions, RecordingReader};

use super::*;
use crate::sweep::StampAt;

/// A MulRan-style PNG: `columns` azimuths by `rows` range bins, pixel value
/// `(3 * azimuth + range) % 256` so a transposition error shows.
fn polar_png(columns: u32, rows: u32) -> Vec<u8> {
    let pixels: Vec<u8> = (0..rows).flat_map(|r| (0..columns).map(move |a| ((3 * a + r) % 256) as u8)).collect();
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, columns, rows);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header().unwrap().write_image_data(&pixels).unwrap();
    out
}

const STAMPS_NS: [i64; 3] = [1_561_000_000_000_000_000, 1_561_000_000_250_000_000, 1_561_000_000_500_000_000];

fn folder(parent: &Path) -> PathBuf {
    let root = parent.join("KAIST01");
    let polar = root.join("sensor_data/radar/polar");
    std::fs::create_dir_all(&polar).unwrap();
    let mut poses = String::new();
    for (i, t_ns) in STAMPS_NS.iter().enumerate() {
        std::fs::write(polar.join(format!("{t_ns}.png")), polar_png(8, 20)).unwrap();
        poses.push_str(&format!("{t_ns},0,-1,0,{},1,0,0,4026000.0,0,0,1,19\n", 353_000.0 + i as f64));
    }
    // A pose outside the scans' span is left out.
    poses.push_str("1561000009000000000,1,0,0,0,0,1,0,0,0,0,1,0\n");
    std::fs::write(root.join("global_pose.csv"), poses).unwrap();
    // GPS at 4 Hz around the scans: the 3 rows within their span are kept.
    let gps: String = [-250_000_000i64, 0, 250_000_000, 500_000_000, 750_000_000]
        .iter()
        .map(|dt| format!("{},36.37,127.36,80.0,4.0,0,0,0,4.0,0,0,0,16.0\n", STAMPS_NS[0] + dt))
        .collect();
    std::fs::write(root.join("sensor_data/gps.csv"), gps).unwrap();
    root
}

fn ingest(root: &Path, out: &Path, options: &MulranOptions) -> Result<MulranReport, IngestError> {
    ingest_mulran(&MulranFolder::open(root)?, out, options, &RecordingOptions::default(), &mut |_, _| {})
}

#[test]
fn folder_gives_transposed_scans_with_spread_times_and_local_poses() {
    let dir = tempfile::tempdir().unwrap();
    let root = folder(dir.path());
    let out = dir.path().join("kaist.mcap");
    let report = ingest(&root, &out, &MulranOptions::default()).unwrap();
    assert_eq!((report.scans, report.ground_truth_poses, report.gnss_fixes), (3, 3, 3));
    let mut reader = RecordingReader::open(&out).unwrap();
    let (mut scans, mut poses) = (Vec::new(), Vec::new());
    for event in reader.by_ref() {
        match event.unwrap() {
            RecordingEvent::RadarScan(s) => scans.push(s),
            RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } => poses.push(pose),
            _ => {}
        }
    }
    let scan = &scans[1];
    assert_eq!((scan.header.azimuths.len(), scan.header.bins_per_azimuth), (8, 20));
    assert_eq!(scan.header.range_resolution_m, 0.05952);
    // Row of azimuth 5 holds column 5: (3 * 5 + r) for r = 0..20.
    assert_eq!(scan.row(5).unwrap(), (15..35).map(|v| v as u8).collect::<Vec<_>>().as_slice());
    // Last azimuth at the file time, 250 ms / 8 apart, angles a * 2 pi / 8.
    assert_eq!(scan.header.azimuths[7].t_ns, STAMPS_NS[1]);
    assert_eq!(scan.header.azimuths[0].t_ns, STAMPS_NS[1] - 7 * 31_250_000);
    assert_eq!(scan.header.azimuths[2].azimuth_rad, std::f64::consts::FRAC_PI_2);
    let metadata = reader.metadata().unwrap();
    assert_eq!(metadata["radar.stamp_at"], "end");
    assert_eq!(metadata["ground_truth.origin_x_m"], "353000");
    let last = poses[2].parent_from_child;
    assert_eq!((last.x_m, last.y_m), (2.0, 0.0));
    // r11 = 0, r21 = 1: heading north, yaw pi / 2.
    assert!((last.yaw_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);

    let start = MulranOptions {
        timing: SweepTiming { stamp_at: StampAt::Start, ..SweepTiming::default() },
        ..MulranOptions::default()
    };
    let scan = decode_mulran_png(Path::new("s.png"), &polar_png(8, 20), 1000, &start).unwrap();
    assert_eq!(scan.header.azimuths[0].t_ns, 1000);
    // The encoder is the decoder's inverse on the pixels.
    assert_eq!(encode_mulran_png(&scan).unwrap(), polar_png(8, 20));
}

#[test]
fn bad_input_names_file_and_field_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let root = folder(dir.path());
    let out = dir.path().join("out.mcap");
    let scans = list_scan_pngs(&root.join("sensor_data/radar/polar"), StampUnit::Nanos).unwrap();
    let good = std::fs::read(&scans[2].path).unwrap();

    std::fs::write(&scans[2].path, &good[..good.len() - 20]).unwrap();
    let err = ingest(&root, &out, &MulranOptions::default()).unwrap_err().to_string();
    assert!(err.contains(&scans[2].path.display().to_string()) && err.contains("PNG"), "{err}");
    assert!(!out.exists(), "no partial output");

    // Oxford-shaped (wide) image.
    std::fs::write(&scans[2].path, polar_png(30, 4)).unwrap();
    let err = ingest(&root, &out, &MulranOptions::default()).unwrap_err().to_string();
    assert!(err.contains("width/height") && err.contains("azimuths along the columns"), "{err}");

    // 16-bit image.
    let mut sixteen = Vec::new();
    let mut encoder = png::Encoder::new(&mut sixteen, 2, 4);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::Sixteen);
    encoder.write_header().unwrap().write_image_data(&[0; 16]).unwrap();
    std::fs::write(&scans[2].path, sixteen).unwrap();
    let err = ingest(&root, &out, &MulranOptions::default()).unwrap_err().to_string();
    assert!(err.contains("16-bit") && err.contains("8-bit greyscale"), "{err}");
    std::fs::write(&scans[2].path, &good).unwrap();

    // NaN and time going backwards in the poses.
    let poses = root.join("global_pose.csv");
    let text = std::fs::read_to_string(&poses).unwrap();
    std::fs::write(&poses, text.replacen(",4026000.0,", ",nan,", 1)).unwrap();
    let err = ingest(&root, &out, &MulranOptions::default()).unwrap_err().to_string();
    assert!(err.contains("global_pose.csv: line 1: ty") && err.contains("finite"), "{err}");
    let swapped: Vec<&str> = text.lines().collect();
    std::fs::write(&poses, format!("{}\n{}\n", swapped[1], swapped[0])).unwrap();
    let err = ingest(&root, &out, &MulranOptions::default()).unwrap_err().to_string();
    assert!(err.contains("line 2: t_ns") && err.contains("does not increase"), "{err}");
    assert!(!out.exists(), "no partial output");
    std::fs::write(&poses, &text).unwrap();

    // A GPS line cut short.
    let gps = root.join("sensor_data/gps.csv");
    let text = std::fs::read_to_string(&gps).unwrap();
    std::fs::write(&gps, text.replacen(",16.0\n", "\n", 1)).unwrap();
    let err = ingest(&root, &out, &MulranOptions::default()).unwrap_err().to_string();
    assert!(err.contains("gps.csv") && err.contains("line 1") && err.contains("12 fields"), "{err}");
    assert!(!out.exists(), "no partial output");

    let empty = dir.path().join("empty");
    std::fs::create_dir_all(empty.join("sensor_data/radar/polar")).unwrap();
    assert!(MulranFolder::open(&empty).unwrap_err().to_string().contains("no scans found"));
    assert!(MulranFolder::open(dir.path()).unwrap_err().to_string().contains("no sensor_data/radar/polar/"));
}

/// Before, `000001.png` became a scan at t = 1 ns; MulRan names scans by
/// 19-digit UNIX nanoseconds. A scan of another size than the first is
/// refused too, naming the file.
#[test]
fn implausible_file_stamp_and_odd_scan_size_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let root = folder(dir.path());
    let polar = root.join("sensor_data/radar/polar");
    let odd = polar.join(format!("{}.png", STAMPS_NS[2]));
    std::fs::write(&odd, polar_png(8, 19)).unwrap();
    let out = dir.path().join("out.mcap");
    let err = ingest(&root, &out, &MulranOptions::default()).unwrap_err().to_string();
    assert!(err.contains(&odd.display().to_string()) && err.contains("8 azimuths x 19 range bins"), "{err}");
    assert!(!out.exists(), "no partial output");
    std::fs::write(&odd, polar_png(8, 20)).unwrap();

    let stray = polar.join("000001.png");
    std::fs::write(&stray, polar_png(8, 20)).unwrap();
    let err = MulranFolder::open(&root).unwrap_err().to_string();
    assert!(
        err.contains(&stray.display().to_string())
            && err.contains("'000001' is not a plausible nanosecond UNIX timestamp")
            && err.contains("19 digits"),
        "{err}"
    );
}

/// Before: `global_pose.csv` or `sensor_data/gps.csv` as a directory was
/// taken as absent (no ground truth, no GNSS, exit 0).
#[test]
fn an_optional_file_that_is_a_directory_is_an_error_naming_it() {
    for optional in ["global_pose.csv", "sensor_data/gps.csv"] {
        let dir = tempfile::tempdir().unwrap();
        let root = folder(dir.path());
        let path = root.join(optional);
        std::fs::remove_file(&path).unwrap();
        MulranFolder::open(&root).unwrap();
        std::fs::create_dir(&path).unwrap();
        let err = MulranFolder::open(&root).unwrap_err().to_string();
        assert!(err.contains(optional) && err.contains("is a directory, not a regular file"), "{err}");
    }
}
