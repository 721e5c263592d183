//! Bad input gives one clear error naming the file and the problem, and never
//! leaves partial output behind.

use std::sync::Arc;

use arrow_array::{ArrayRef, Float64Array, Int64Array, RecordBatch};
use arrow_schema::{DataType, Field, Schema};
use mmtrack_core::StampedPose;
use mmtrack_io::recording::{PoseStream, inspect_recording};
use mmtrack_io::table::{read_table, write_table};
use mmtrack_io::{IoError, Overwrite, RecordingOptions, RecordingReader, RecordingWriter};

use crate::samples;

fn recording(dir: &std::path::Path) -> std::path::PathBuf {
    let path = dir.join("rec.mcap");
    let mut writer = RecordingWriter::create(&path, &samples::metadata(), &RecordingOptions::default()).unwrap();
    for p in samples::poses() {
        writer.write_radar_scan(&samples::scan(p.t_ns, 50, 500)).unwrap();
        writer.write_pose(PoseStream::GroundTruth, &p, "world").unwrap();
    }
    writer.finish().unwrap();
    path
}

#[test]
fn truncated_recording_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = recording(dir.path());
    let bytes = std::fs::read(&path).unwrap();
    for cut in [bytes.len() / 3, bytes.len() - 30, 5] {
        std::fs::write(&path, &bytes[..cut]).unwrap();
        let err = inspect_recording(&path).unwrap_err();
        assert!(matches!(err, IoError::CorruptRecording { .. }), "cut at {cut}: {err}");
        let text = err.to_string();
        assert!(text.contains("rec.mcap") && text.contains("truncated"), "{text}");
        let read: Result<Vec<_>, _> = RecordingReader::open(&path).unwrap().collect();
        assert!(read.is_err(), "cut at {cut} must not read cleanly");
    }
}

#[test]
fn corrupted_recording_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = recording(dir.path());
    let mut bytes = std::fs::read(&path).unwrap();
    // Clobber the magic: not an MCAP at all.
    bytes[..8].copy_from_slice(b"NOTMCAP!");
    std::fs::write(&path, &bytes).unwrap();
    let err = inspect_recording(&path).unwrap_err();
    assert!(matches!(err, IoError::CorruptRecording { .. }), "{err}");
}

/// Every event of a recording, or the error that ended the read.
fn read_all(path: &std::path::Path) -> Result<Vec<mmtrack_io::recording::RecordingEvent>, IoError> {
    RecordingReader::open(path)?.collect()
}

#[test]
fn a_flipped_bit_is_refused_or_changes_nothing() {
    // The chunks' CRCs are checked before any of their messages is returned
    // and the data section's at its end: a damaged recording is an error,
    // never other values (found by mutating real recordings: before, 47 of
    // 80 single-byte changes ran through `process mpc` to exit 0 with other
    // tables).
    let dir = tempfile::tempdir().unwrap();
    let path = recording(dir.path());
    let clean = read_all(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    // The footer (opcode, length, summary start, summary offset start, CRC)
    // before the closing magic says where the data section ends.
    let footer = bytes.len() - 8 - 29;
    let summary_start = u64::from_le_bytes(bytes[footer + 9..footer + 17].try_into().unwrap()) as usize;
    assert!(summary_start > bytes.len() / 2 && summary_start < footer, "{summary_start} of {}", bytes.len());
    let mut refused = 0;
    for k in 1..60 {
        let offset = 8 + k * (bytes.len() - 16) / 60;
        let mut damaged = bytes.clone();
        damaged[offset] ^= 0x10;
        std::fs::write(&path, &damaged).unwrap();
        match read_all(&path) {
            Err(err) => {
                assert!(matches!(err, IoError::CorruptRecording { .. }), "byte {offset}: {err}");
                assert!(err.to_string().contains("rec.mcap"), "{err}");
                refused += 1;
            }
            // The summary section (indexes and statistics) is not what values are read from.
            Ok(events) => {
                assert!(offset >= summary_start, "byte {offset} of the data section read without an error");
                assert_eq!(events, clean, "byte {offset} changed what was read without an error");
            }
        }
    }
    assert!(refused > 0);
}

#[test]
fn a_record_length_beyond_any_file_is_an_error_not_an_allocation() {
    // The first record (the header) after the 8-byte magic: opcode, then its
    // length as a little-endian u64. A corrupt length once made the reader
    // reserve it (1 TB: the process aborted).
    let dir = tempfile::tempdir().unwrap();
    let path = recording(dir.path());
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[9..17].copy_from_slice(&(1u64 << 40).to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let err = read_all(&path).unwrap_err();
    let text = err.to_string();
    assert!(text.contains("rec.mcap") && text.contains("limit is 256 MiB"), "{text}");
}

#[test]
fn existing_recording_is_refused_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let path = recording(dir.path());
    let before = std::fs::read(&path).unwrap();
    let err = RecordingWriter::create(&path, &samples::metadata(), &RecordingOptions::default()).err().unwrap();
    assert!(matches!(err, IoError::OutputExists { .. }));
    assert!(err.to_string().contains("--force"));
    assert_eq!(std::fs::read(&path).unwrap(), before);
}

#[test]
fn abandoned_writer_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("never.mcap");
    {
        let mut writer = RecordingWriter::create(&path, &samples::metadata(), &RecordingOptions::default()).unwrap();
        writer.write_radar_scan(&samples::scan(0, 10, 10)).unwrap();
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn negative_time_is_refused_with_the_field_named() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("neg.mcap");
    let mut writer = RecordingWriter::create(&path, &samples::metadata(), &RecordingOptions::default()).unwrap();
    let mut pose = samples::poses()[0].clone();
    pose.t_ns = -5;
    let err = writer.write_pose(PoseStream::GroundTruth, &pose, "world").unwrap_err();
    assert!(err.to_string().contains("t_ns"), "{err}");
}

fn write_raw_parquet(path: &std::path::Path, fields: Vec<Field>, columns: Vec<ArrayRef>) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let batch = RecordBatch::try_new(Arc::new(Schema::new(fields)), columns).unwrap();
    let file = std::fs::File::create(path).unwrap();
    let mut writer = parquet::arrow::ArrowWriter::try_new(file, batch.schema(), None).unwrap();
    writer.write(&batch).unwrap();
    writer.close().unwrap();
}

#[test]
fn parquet_with_a_missing_column_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("poses.parquet");
    write_raw_parquet(
        &path,
        vec![
            Field::new("t_ns", DataType::Int64, false),
            Field::new("x_m", DataType::Float64, false),
            Field::new("yaw_rad", DataType::Float64, false),
        ],
        vec![
            Arc::new(Int64Array::from(vec![1])),
            Arc::new(Float64Array::from(vec![1.0])),
            Arc::new(Float64Array::from(vec![0.0])),
        ],
    );
    let err = read_table::<StampedPose>(&path).unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, IoError::MissingColumn { .. }));
    assert!(text.contains("poses.parquet") && text.contains("'y_m'"), "{text}");
}

#[test]
fn parquet_with_wrong_type_or_unknown_column_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("poses.parquet");
    let base_fields = || {
        vec![
            Field::new("t_ns", DataType::Int64, false),
            Field::new("x_m", DataType::Float64, false),
            Field::new("yaw_rad", DataType::Float64, false),
        ]
    };
    let base_columns = || -> Vec<ArrayRef> {
        vec![
            Arc::new(Int64Array::from(vec![1])),
            Arc::new(Float64Array::from(vec![1.0])),
            Arc::new(Float64Array::from(vec![0.0])),
        ]
    };
    let mut fields = base_fields();
    fields.push(Field::new("y_m", DataType::Int64, false));
    let mut columns = base_columns();
    columns.push(Arc::new(Int64Array::from(vec![3])));
    write_raw_parquet(&path, fields, columns);
    let err = read_table::<StampedPose>(&path).unwrap_err();
    assert!(matches!(err, IoError::WrongColumnType { ref column, .. } if column == "y_m"), "{err}");

    let mut fields = base_fields();
    fields.push(Field::new("y_m", DataType::Float64, false));
    fields.push(Field::new("speed", DataType::Float64, false));
    let mut columns = base_columns();
    columns.push(Arc::new(Float64Array::from(vec![3.0])));
    columns.push(Arc::new(Float64Array::from(vec![3.0])));
    write_raw_parquet(&path, fields, columns);
    let err = read_table::<StampedPose>(&path).unwrap_err();
    assert!(matches!(err, IoError::UnknownColumn { ref column, .. } if column == "speed"), "{err}");
}

#[test]
fn truncated_parquet_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let summary = write_table(dir.path(), "s", &samples::poses(), &samples::run_info("{}"), Overwrite::Refuse).unwrap();
    let bytes = std::fs::read(&summary.path).unwrap();
    std::fs::write(&summary.path, &bytes[..bytes.len() / 2]).unwrap();
    let err = read_table::<StampedPose>(&summary.path).unwrap_err();
    assert!(matches!(err, IoError::CorruptTable { .. }), "{err}");
    assert!(err.to_string().contains("part-0.parquet"));
}

#[test]
fn existing_table_is_refused_unless_replace() {
    let dir = tempfile::tempdir().unwrap();
    let first = write_table(dir.path(), "s", &samples::poses(), &samples::run_info("{}"), Overwrite::Refuse).unwrap();
    let before = std::fs::read(&first.path).unwrap();
    let err =
        write_table(dir.path(), "s", &samples::poses()[..2], &samples::run_info("{}"), Overwrite::Refuse).unwrap_err();
    assert!(matches!(err, IoError::OutputExists { .. }));
    assert_eq!(std::fs::read(&first.path).unwrap(), before);
    let second =
        write_table(dir.path(), "s", &samples::poses()[..2], &samples::run_info("{}"), Overwrite::Replace).unwrap();
    assert_eq!(read_table::<StampedPose>(&second.path).unwrap().len(), 2);
    let leftovers: Vec<_> =
        std::fs::read_dir(first.path.parent().unwrap()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(leftovers, vec![std::ffi::OsString::from("part-0.parquet")]);
}

#[test]
fn unsafe_sequence_names_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for bad in ["", "..", "a/b", "x y"] {
        let err =
            write_table(dir.path(), bad, &samples::poses(), &samples::run_info("{}"), Overwrite::Refuse).unwrap_err();
        assert!(err.to_string().contains("sequence_id"), "{bad}: {err}");
    }
}

/// Before: `__HIVE_DEFAULT_PARTITION__` was accepted as a sequence id, and
/// DuckDB, polars and pyarrow read its rows with a null sequence. Now it is
/// refused like any name that cannot be a partition; ordinary ids pass.
#[test]
fn the_hive_null_partition_is_not_a_sequence_id() {
    let error = mmtrack_io::table::check_partition_name("__HIVE_DEFAULT_PARTITION__").unwrap_err();
    assert!(error.contains("missing value"), "{error}");
    assert!(
        mmtrack_io::table::table_path(std::path::Path::new("t"), "odometry", "__HIVE_DEFAULT_PARTITION__").is_err()
    );
    for fine in ["007", "2019-01-10", "__HIVE_DEFAULT_PARTITION__x", "oxford-demo"] {
        mmtrack_io::table::check_partition_name(fine).unwrap();
    }
}

/// `path`'s messages, without the `/radar/image` messages whose index among
/// them is in `dropped`, written to `out` (metadata records are not copied).
fn copy_without_images(path: &std::path::Path, out: &std::path::Path, dropped: &[usize]) {
    let bytes = std::fs::read(path).unwrap();
    let mut writer = mcap::Writer::new(std::io::BufWriter::new(std::fs::File::create(out).unwrap())).unwrap();
    let mut images = 0;
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        if message.channel.topic == "/radar/image" {
            images += 1;
            if dropped.contains(&(images - 1)) {
                continue;
            }
        }
        writer.write(&message).unwrap();
    }
    writer.finish().unwrap();
    assert!(images > 2, "{images} images");
}

#[test]
fn radar_metadata_without_its_image_is_an_error_naming_the_scan() {
    let dir = tempfile::tempdir().unwrap();
    let path = recording(dir.path());
    let scans = read_all(&path).unwrap().len() / 2;
    let last = scans - 1;
    let t_ns = |i: usize| samples::poses()[i].t_ns;
    for (dropped, why) in [(0, "the next scan's metadata came first"), (last, "the file ends first")] {
        let bad = dir.path().join(format!("without-{dropped}.mcap"));
        copy_without_images(&path, &bad, &[dropped]);
        let err = read_all(&bad).unwrap_err().to_string();
        assert!(err.contains(&format!("without-{dropped}.mcap")) && err.contains("/radar/scan_meta"), "{err}");
        assert!(
            err.contains(&format!("the radar scan at t_ns {} has no /radar/image message: {why}", t_ns(dropped))),
            "{err}"
        );
    }
    // The copy itself reads as the original does.
    let copy = dir.path().join("copy.mcap");
    copy_without_images(&path, &copy, &[]);
    assert_eq!(read_all(&copy).unwrap().len(), read_all(&path).unwrap().len());
}
