//! Every core type through MCAP and Parquet and back, bit-exact.

use mmtrack_core::{CirSnapshot, GnssFix, MpcDetection, MpcTrack, PolarScan, Se2, StampedPose};
use mmtrack_io::recording::{Compression, PoseStream, inspect_recording};
use mmtrack_io::table::{TableRow, TrajectoryMetrics, read_table, read_table_dir, table_path, write_table};
use mmtrack_io::{Overwrite, RecordingEvent, RecordingOptions, RecordingReader, RecordingWriter};
use proptest::prelude::*;

use crate::samples;

/// Bitwise equality of floats inside Debug output is what `==` misses for
/// -0.0 vs 0.0; compare the bit patterns of every pose component.
fn pose_bits(p: &StampedPose) -> (i64, u64, u64, u64) {
    let t = p.parent_from_child;
    (p.t_ns, t.x_m.to_bits(), t.y_m.to_bits(), t.yaw_rad.to_bits())
}

fn cir_bits(c: &CirSnapshot) -> Vec<u64> {
    c.taps.iter().flat_map(|t| [t.re.to_bits(), t.im.to_bits()]).collect()
}

fn write_everything(path: &std::path::Path, options: &RecordingOptions) -> mmtrack_io::recording::WriteSummary {
    let mut writer = RecordingWriter::create(path, &samples::metadata(), options).unwrap();
    for (i, pose) in samples::poses().iter().enumerate() {
        writer.write_radar_scan(&samples::scan(pose.t_ns, 40, 64 + i)).unwrap();
        writer.write_pose(PoseStream::GroundTruth, pose, "world").unwrap();
    }
    writer.write_pose(PoseStream::Estimate, &samples::poses()[0], "world").unwrap();
    for fix in samples::gnss_fixes() {
        writer.write_gnss_fix(&fix).unwrap();
    }
    for set in 0..3 {
        for snapshot in 0..6 {
            writer.write_cir(&samples::cir(set, snapshot, 101)).unwrap();
        }
    }
    writer.finish().unwrap()
}

fn read_everything(path: &std::path::Path) -> Vec<RecordingEvent> {
    RecordingReader::open(path).unwrap().collect::<Result<Vec<_>, _>>().unwrap()
}

#[test]
fn recording_round_trips_every_type_bit_exactly() {
    for compression in [Compression::None, Compression::Zstd { level: 1 }, Compression::Lz4] {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rec.mcap");
        let options = RecordingOptions { compression, ..Default::default() };
        let summary = write_everything(&path, &options);
        assert_eq!(summary.message_counts["/radar/image"], 7);
        assert_eq!(summary.message_counts["/viz/ground_truth"], 7);

        let events = read_everything(&path);
        let scans: Vec<&PolarScan> =
            events.iter().filter_map(|e| if let RecordingEvent::RadarScan(s) = e { Some(s) } else { None }).collect();
        let expected_scans: Vec<PolarScan> =
            samples::poses().iter().enumerate().map(|(i, p)| samples::scan(p.t_ns, 40, 64 + i)).collect();
        assert_eq!(scans.len(), expected_scans.len());
        for (got, want) in scans.iter().zip(&expected_scans) {
            assert_eq!(*got, want);
        }

        let truth: Vec<&StampedPose> = events
            .iter()
            .filter_map(|e| match e {
                RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } => Some(pose),
                _ => None,
            })
            .collect();
        let want: Vec<_> = samples::poses().iter().map(pose_bits).collect();
        assert_eq!(truth.iter().map(|p| pose_bits(p)).collect::<Vec<_>>(), want);

        let fixes: Vec<&GnssFix> =
            events.iter().filter_map(|e| if let RecordingEvent::Gnss(f) = e { Some(f) } else { None }).collect();
        assert_eq!(fixes.into_iter().cloned().collect::<Vec<_>>(), samples::gnss_fixes());

        let cirs: Vec<&CirSnapshot> =
            events.iter().filter_map(|e| if let RecordingEvent::Cir(c) = e { Some(c) } else { None }).collect();
        assert_eq!(cirs.len(), 18);
        let want = samples::cir(2, 5, 101);
        assert_eq!(*cirs[17], want);
        assert_eq!(cir_bits(cirs[17]), cir_bits(&want));
    }
}

#[test]
fn sounder_truth_and_both_vehicles_round_trip_bit_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sounder.mcap");
    let mut writer = RecordingWriter::create(&path, &samples::metadata(), &RecordingOptions::default()).unwrap();
    let poses = samples::poses();
    for (i, truth) in samples::mpc_truth().iter().enumerate() {
        if truth.snapshot_index == 0 {
            writer.write_pose(PoseStream::GroundTruthTx, &poses[i / 6], "world").unwrap();
            writer.write_pose(PoseStream::GroundTruthRx, &poses[i / 6 + 2], "world").unwrap();
        }
        writer.write_mpc_truth(truth).unwrap();
    }
    let summary = writer.finish().unwrap();
    assert_eq!(summary.message_counts["/channel/mpc_truth"], 12);
    assert_eq!(summary.message_counts["/viz/ground_truth_tx"], 2);
    let events = read_everything(&path);
    let truth: Vec<&mmtrack_core::MpcTruth> =
        events.iter().filter_map(|e| if let RecordingEvent::MpcTruth(t) = e { Some(t) } else { None }).collect();
    let want = samples::mpc_truth();
    assert_eq!(truth.len(), want.len());
    let bits = |t: &mmtrack_core::MpcTruth| {
        (
            t.t_ns,
            t.set_index,
            t.snapshot_index,
            t.path_id,
            t.delay_s.to_bits(),
            t.amplitude.re.to_bits(),
            t.amplitude.im.to_bits(),
            t.doppler_hz.to_bits(),
        )
    };
    assert_eq!(truth.iter().map(|t| bits(t)).collect::<Vec<_>>(), want.iter().map(bits).collect::<Vec<_>>());
    let stream = |wanted: PoseStream| -> Vec<(i64, u64, u64, u64)> {
        events
            .iter()
            .filter_map(|e| match e {
                RecordingEvent::Pose { stream, pose } if *stream == wanted => Some(pose_bits(pose)),
                _ => None,
            })
            .collect()
    };
    assert_eq!(stream(PoseStream::GroundTruthTx), vec![pose_bits(&poses[0]), pose_bits(&poses[1])]);
    assert_eq!(stream(PoseStream::GroundTruthRx), vec![pose_bits(&poses[2]), pose_bits(&poses[3])]);
    // Readers of the single-platform ground truth see none of the two cars' poses.
    assert!(stream(PoseStream::GroundTruth).is_empty());
    assert!(PoseStream::GroundTruthRx.is_ground_truth() && !PoseStream::Estimate.is_ground_truth());
    for s in PoseStream::ALL {
        assert_eq!(PoseStream::from_topic(s.topic()), Some(s));
    }
}

#[test]
fn inspect_reports_channels_counts_and_metadata() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rec.mcap");
    write_everything(&path, &RecordingOptions::default());
    let summary = inspect_recording(&path).unwrap();
    let find = |topic: &str| summary.channels.iter().find(|c| c.topic == topic).unwrap();
    assert_eq!(find("/radar/image").schema_name, "foxglove.RawImage");
    assert_eq!(find("/radar/scan_meta").message_count, 7);
    assert_eq!(find("/channel/cir").message_count, 18);
    assert_eq!(find("/gnss/fix").schema_name, "mmtrack.GnssFix");
    assert_eq!(find("/viz/gnss").schema_name, "foxglove.LocationFix");
    let gt = find("/ground_truth/pose");
    let poses = samples::poses();
    assert_eq!((gt.start_ns, gt.end_ns), (poses[0].t_ns as u64, poses[6].t_ns as u64));
    let meta = &summary.metadata["mmtrack.recording"];
    assert_eq!(meta["sequence_id"], "test-seq");
    assert_eq!(meta["radar.model"], "CTS350-X");
    assert_eq!(meta["time_base"], "unix_epoch");
}

#[test]
fn carried_png_is_stored_unchanged_and_decodes_to_the_scan() {
    let scan = samples::scan(5_000, 12, 30);
    // An Oxford-style PNG: 11 header columns before the bins.
    let width = 11 + 30;
    let mut pixels = Vec::new();
    for a in 0..12 {
        pixels.extend_from_slice(&[0xAB; 11]);
        pixels.extend_from_slice(scan.row(a).unwrap());
    }
    let mut png_bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut png_bytes, width as u32, 12);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.write_header().unwrap().write_image_data(&pixels).unwrap();
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("png.mcap");
    let mut writer = RecordingWriter::create(&path, &samples::metadata(), &RecordingOptions::default()).unwrap();
    writer.write_radar_png(&scan.header, &png_bytes, 11).unwrap();
    writer.finish().unwrap();

    let events = read_everything(&path);
    assert_eq!(events, vec![RecordingEvent::RadarScan(scan)]);
    let summary = inspect_recording(&path).unwrap();
    assert!(summary.channels.iter().any(|c| c.schema_name == "foxglove.CompressedImage"));
}

fn table_round_trip<T: TableRow + PartialEq + std::fmt::Debug + Clone>(rows: &[T]) -> Vec<T> {
    let dir = tempfile::tempdir().unwrap();
    let run = samples::run_info(r#"{"test":true}"#);
    let summary = write_table(dir.path(), "seq-1", rows, &run, Overwrite::Refuse).unwrap();
    assert_eq!(summary.path, table_path(dir.path(), T::SPEC.name, "seq-1").unwrap());
    assert_eq!(summary.rows, rows.len() as u64);
    let back = read_table::<T>(&summary.path).unwrap();
    let by_dir = read_table_dir::<T>(dir.path()).unwrap();
    assert_eq!(by_dir.keys().collect::<Vec<_>>(), vec!["seq-1"]);
    assert_eq!(by_dir["seq-1"], back);
    back
}

#[test]
fn tables_round_trip_every_type_bit_exactly() {
    let poses = samples::poses();
    let back = table_round_trip(&poses);
    assert_eq!(back.iter().map(pose_bits).collect::<Vec<_>>(), poses.iter().map(pose_bits).collect::<Vec<_>>());

    assert_eq!(table_round_trip(&samples::gnss_fixes()), samples::gnss_fixes());
    let scans = vec![samples::scan(1, 40, 64), samples::scan(2, 3, 5)];
    assert_eq!(table_round_trip(&scans), scans);
    let cirs: Vec<CirSnapshot> = (0..4).map(|i| samples::cir(i, 1, 33)).collect();
    let back = table_round_trip(&cirs);
    assert_eq!(back, cirs);
    assert_eq!(back.iter().map(cir_bits).collect::<Vec<_>>(), cirs.iter().map(cir_bits).collect::<Vec<_>>());
    assert_eq!(table_round_trip(&samples::detections()), samples::detections());
    assert_eq!(table_round_trip(&samples::tracks()), samples::tracks());
    let empty: Vec<MpcDetection> = Vec::new();
    assert_eq!(table_round_trip(&empty), empty);
    let _: Vec<MpcTrack> = table_round_trip(&Vec::new());
}

/// The derived writer and reader of a result table with lists and nullable
/// integers and floats give back every value, nulls included.
#[test]
fn trajectory_metrics_round_trip_with_and_without_nulls() {
    let full = TrajectoryMetrics {
        estimate_poses: u64::MAX,
        associated_poses: 7,
        interpolated_poses: 3,
        dropped_poses: 0,
        first_t_ns: i64::MIN,
        last_t_ns: i64::MAX,
        path_length_m: 812.5,
        estimate_path_length_m: -0.0,
        segment_lengths_m: vec![100.0, 200.0],
        step_frames: Some(10),
        step_m: None,
        kitti_segments: 12,
        kitti_translational_pct: Some(1.25),
        kitti_rotational_deg_per_100m: Some(0.2),
        ate_rmse_m: 1.0,
        ate_max_m: 2.0,
        x_rmse_m: 0.5,
        y_rmse_m: 0.25,
        position_rmse_m: f64::INFINITY,
        yaw_rmse_rad: 1e-300,
        final_position_error_m: 3.0,
        rpe_translation_rmse_m: 0.1,
        rpe_yaw_rmse_rad: 0.01,
    };
    let empty = TrajectoryMetrics {
        segment_lengths_m: Vec::new(),
        step_frames: None,
        step_m: Some(5.0),
        kitti_translational_pct: None,
        kitti_rotational_deg_per_100m: None,
        ..full.clone()
    };
    assert_eq!(table_round_trip(&[full.clone(), empty.clone()]), vec![full, empty]);
}

/// A track's points are rows of `mpc_tracks`; the Parquet reader hands a
/// file back in batches of 1024 rows, and a track straddling a batch boundary
/// must still come back as one track.
#[test]
fn records_spanning_reader_batches_come_back_whole() {
    let detection = |i: u64| MpcDetection {
        t_ns: i as i64,
        set_index: i / 6,
        snapshot_index: (i % 6) as u32,
        delay_s: 1e-8 + i as f64 * 1e-13,
        amplitude: mmtrack_core::Complex64::new(1e-6, 0.0),
    };
    let tracks = vec![
        MpcTrack { track_id: 0, doppler_hz: Some(12.5), detections: (0..1000).map(detection).collect() },
        MpcTrack { track_id: 1, doppler_hz: None, detections: (1000..3100).map(detection).collect() },
        MpcTrack { track_id: 2, doppler_hz: Some(-3.0), detections: (3100..3105).map(detection).collect() },
    ];
    assert_eq!(table_round_trip(&tracks), tracks);
}

#[test]
fn parquet_metadata_carries_units_and_run_config() {
    let dir = tempfile::tempdir().unwrap();
    let run = samples::run_info(r#"{"k":3}"#);
    let summary = write_table(dir.path(), "s", &samples::poses(), &run, Overwrite::Refuse).unwrap();
    let file = std::fs::File::open(&summary.path).unwrap();
    let reader = parquet::file::reader::SerializedFileReader::new(file).unwrap();
    let kv = parquet::file::reader::FileReader::metadata(&reader).file_metadata().key_value_metadata().unwrap().clone();
    let get = |k: &str| kv.iter().find(|e| e.key == k).and_then(|e| e.value.clone()).unwrap();
    let units: serde_json::Value = serde_json::from_str(&get("units")).unwrap();
    assert_eq!(units["x_m"], "m");
    assert_eq!(units["yaw_rad"], "rad");
    assert_eq!(get("mmtrack.run_config"), r#"{"k":3}"#);
    assert_eq!(get("mmtrack.table"), "poses");
}

fn any_f64() -> impl Strategy<Value = f64> {
    // Every bit pattern but NaN (NaN != NaN would make the assertion vacuous;
    // NaN payloads are covered by the bit comparison below anyway).
    any::<u64>().prop_map(f64::from_bits).prop_filter("not NaN", |v| !v.is_nan())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn poses_round_trip_both_formats(values in proptest::collection::vec((0i64..i64::MAX, any_f64(), any_f64(), any_f64()), 1..20)) {
        let poses: Vec<StampedPose> = values.iter().map(|&(t_ns, x, y, yaw)| StampedPose { t_ns, parent_from_child: Se2::new(x, y, yaw) }).collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.mcap");
        let mut writer = RecordingWriter::create(&path, &samples::metadata(), &RecordingOptions::default()).unwrap();
        for p in &poses {
            writer.write_pose(PoseStream::Estimate, p, "world").unwrap();
        }
        writer.finish().unwrap();
        let back: Vec<StampedPose> = read_everything(&path).into_iter().filter_map(|e| match e {
            RecordingEvent::Pose { pose, .. } => Some(pose),
            _ => None,
        }).collect();
        prop_assert_eq!(back.iter().map(pose_bits).collect::<Vec<_>>(), poses.iter().map(pose_bits).collect::<Vec<_>>());

        let summary = write_table(dir.path(), "p", &poses, &samples::run_info("{}"), Overwrite::Refuse).unwrap();
        let back = read_table::<StampedPose>(&summary.path).unwrap();
        prop_assert_eq!(back.iter().map(pose_bits).collect::<Vec<_>>(), poses.iter().map(pose_bits).collect::<Vec<_>>());
    }
}

/// A table written in many calls (radar scans of a whole drive) goes to the
/// file a row group at a time, about every `ROW_GROUP_BYTES`, instead of
/// buffering every row until the end; it reads back whole, in order.
#[test]
fn a_table_written_in_many_calls_is_flushed_in_row_groups_and_reads_back_whole() {
    use mmtrack_core::{AzimuthSample, PolarScanHeader};
    use mmtrack_io::table::{RADAR_SCANS, ROW_GROUP_BYTES, RunInfo, TableWriter};
    let (azimuths, bins) = (400, 3768);
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut scan = |k: i64| {
        let power = (0..azimuths * bins)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 56) as u8
            })
            .collect();
        let azimuths = (0..azimuths)
            .map(|a| AzimuthSample { t_ns: k * 250_000_000 + a as i64, azimuth_rad: a as f64 * 0.0157, valid: true })
            .collect();
        let header = PolarScanHeader {
            t_ns: k * 250_000_000,
            range_resolution_m: 0.0438,
            range_offset_m: 0.0,
            bins_per_azimuth: bins,
            azimuths,
        };
        PolarScan::new(header, power).unwrap()
    };
    let scans_per_group = ROW_GROUP_BYTES / (azimuths * bins) + 1;
    let dir = tempfile::tempdir().unwrap();
    let run = RunInfo::new("{}", mmtrack_io::recording::TimeBase::Relative);
    let mut writer = TableWriter::create(dir.path(), &RADAR_SCANS, "s", &run, Overwrite::Refuse).unwrap();
    let mut written = Vec::new();
    for k in 0..(scans_per_group + 3) as i64 {
        let s = scan(k);
        writer.write(std::slice::from_ref(&s)).unwrap();
        written.push(s);
    }
    let summary = writer.finish().unwrap();
    let file = std::fs::File::open(&summary.path).unwrap();
    let row_groups = parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(file)
        .unwrap()
        .metadata()
        .num_row_groups();
    assert_eq!(row_groups, 2, "{} scans of {} bytes", written.len(), azimuths * bins);
    assert_eq!(read_table::<PolarScan>(&summary.path).unwrap(), written);
}
