//! 5G mmWave SLAM epochs (path measurements, UE truth, sources) through a
//! recording and back, bit-exactly, an empty epoch and a NaN included;
//! malformed messages are errors naming the topic, the message and the field.

use std::collections::BTreeMap;
use std::sync::Arc;

use mmtrack_core::slam::{PathMeasurement, PathOrigin, SlamEpoch, SourceType, UeState};
use mmtrack_io::proto::{self, SpecMessage};
use mmtrack_io::recording::{ChannelInfo, RawMessage, inspect_recording};
use mmtrack_io::{IoError, RecordingEvent, RecordingOptions, RecordingReader, RecordingWriter};

use crate::samples;

fn epochs() -> Vec<SlamEpoch> {
    let path = |k: f64| PathMeasurement {
        toa_m: 80.1 + k,
        doa_az_rad: -3.1 + 0.1 * k,
        doa_el_rad: 1.0 / 3.0,
        dod_az_rad: -0.0,
        dod_el_rad: -std::f64::consts::FRAC_PI_2,
    };
    vec![
        SlamEpoch { t_ns: 0, paths: vec![path(0.0), path(1.0), path(2.0)] },
        SlamEpoch { t_ns: 200_000_000, paths: Vec::new() },
        SlamEpoch { t_ns: 400_000_000, paths: vec![PathMeasurement { doa_el_rad: f64::NAN, ..path(3.0) }] },
    ]
}

fn ue(k: f64) -> UeState {
    UeState {
        position_m: [70.73 - k, 0.1 * k, 1.5],
        heading_rad: std::f64::consts::FRAC_PI_2,
        speed_mps: 22.22,
        turn_rate_radps: std::f64::consts::PI / 10.0,
        clock_bias_m: 300.0 + 5e-324,
    }
}

#[test]
fn slam_epochs_truth_and_sources_round_trip_bit_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("slam.mcap");
    let mut writer = RecordingWriter::create(&path, &samples::metadata(), &RecordingOptions::default()).unwrap();
    let sources = [
        (SourceType::BaseStation, 0, [0.0, 0.0, 40.0]),
        (SourceType::VirtualAnchor, 0, [200.0, 0.0, 40.0]),
        (SourceType::ScatteringPoint, 7, [51.2, -3.0, 2.5]),
    ];
    for (kind, index, at) in sources {
        writer.write_slam_source(0, kind, index, at).unwrap();
    }
    let origins = [
        vec![PathOrigin::LineOfSight, PathOrigin::VirtualAnchor(3), PathOrigin::ScatteringPoint(9)],
        vec![],
        vec![PathOrigin::Clutter],
    ];
    for (k, (epoch, o)) in epochs().iter().zip(&origins).enumerate() {
        writer.write_slam_paths(epoch).unwrap();
        writer.write_slam_ue_truth(epoch.t_ns, &ue(k as f64), o).unwrap();
    }
    let summary = writer.finish().unwrap();
    assert_eq!(summary.message_counts["/slam/paths"], 3);
    assert_eq!(summary.message_counts["/slam/ue_truth"], 3);
    assert_eq!(summary.message_counts["/slam/sources"], 3);

    let events: Vec<RecordingEvent> = RecordingReader::open(&path).unwrap().collect::<Result<_, _>>().unwrap();
    let got: Vec<&SlamEpoch> =
        events.iter().filter_map(|e| if let RecordingEvent::SlamPaths(p) = e { Some(p) } else { None }).collect();
    let bits = |e: &SlamEpoch| (e.t_ns, e.paths.iter().map(|p| p.to_array().map(f64::to_bits)).collect::<Vec<_>>());
    assert_eq!(got.iter().map(|e| bits(e)).collect::<Vec<_>>(), epochs().iter().map(bits).collect::<Vec<_>>());
    let truths: Vec<(i64, UeState, Vec<PathOrigin>)> = events
        .iter()
        .filter_map(|e| match e {
            RecordingEvent::SlamUeTruth { t_ns, ue, origins } => Some((*t_ns, *ue, origins.clone())),
            _ => None,
        })
        .collect();
    assert_eq!(truths.len(), 3);
    for (k, (t_ns, state, o)) in truths.iter().enumerate() {
        assert_eq!(*t_ns, epochs()[k].t_ns);
        assert_eq!(state.clock_bias_m.to_bits(), ue(k as f64).clock_bias_m.to_bits());
        assert_eq!(*state, ue(k as f64));
        assert_eq!(*o, origins[k]);
    }
    let got_sources: Vec<(SourceType, usize, [f64; 3])> = events
        .iter()
        .filter_map(|e| match e {
            RecordingEvent::SlamSource { kind, index, position_m, .. } => Some((*kind, *index, *position_m)),
            _ => None,
        })
        .collect();
    assert_eq!(got_sources, sources.to_vec());
    let inspected = inspect_recording(&path).unwrap();
    let paths = inspected.channels.iter().find(|c| c.topic == "/slam/paths").unwrap();
    assert_eq!((paths.schema_name.as_str(), paths.message_count), ("mmtrack.PathMeasurements", 3));
}

/// Writes one hand-encoded message on `topic` and returns the reader's error.
fn read_bad<M: SpecMessage>(topic: &str, message: &M) -> IoError {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.mcap");
    let mut writer = RecordingWriter::create(&path, &samples::metadata(), &RecordingOptions::default()).unwrap();
    let channel = Arc::new(ChannelInfo {
        topic: topic.into(),
        schema_name: M::SPEC.full_name.into(),
        message_encoding: "protobuf".into(),
        schema_encoding: "protobuf".into(),
        schema_data: Arc::from(M::SPEC.file_descriptor_set()),
        metadata: BTreeMap::new(),
    });
    let data = bytes::Bytes::from(message.encode_to_vec());
    writer.copy_message(&RawMessage { channel, sequence: 4, log_time_ns: 5, data }).unwrap();
    writer.finish().unwrap();
    RecordingReader::open(&path).unwrap().collect::<Result<Vec<_>, _>>().unwrap_err()
}

#[test]
fn malformed_slam_messages_are_errors_naming_topic_message_and_field() {
    let paths = proto::PathMeasurements {
        t_ns: 5,
        toa_m: vec![1.0, 2.0],
        doa_az_rad: vec![0.0, 0.1],
        doa_el_rad: vec![0.0],
        dod_az_rad: vec![0.0, 0.1],
        dod_el_rad: vec![0.0, 0.1],
    };
    let truth = proto::SlamUeTruth {
        t_ns: 5,
        x_m: 0.0,
        y_m: 0.0,
        z_m: 0.0,
        heading_rad: 0.0,
        speed_mps: 0.0,
        turn_rate_radps: 0.0,
        clock_bias_m: 0.0,
        path_source: vec!["bs".into(), "wall".into()],
        path_source_index: vec![0, 1],
    };
    let source = proto::SlamSource { t_ns: 5, kind: "tree".into(), index: 0, x_m: 0.0, y_m: 0.0, z_m: 0.0 };
    let cases = [
        (read_bad("/slam/paths", &paths), "/slam/paths", "doa_el_rad"),
        (read_bad("/slam/ue_truth", &truth), "/slam/ue_truth", "path 1: path_source 'wall'"),
        (
            read_bad("/slam/ue_truth", &proto::SlamUeTruth { path_source_index: vec![0], ..truth.clone() }),
            "/slam/ue_truth",
            "path_source_index has 1",
        ),
        (read_bad("/slam/sources", &source), "/slam/sources", "kind 'tree'"),
    ];
    for (err, topic, expected) in cases {
        let text = err.to_string();
        assert!(matches!(err, IoError::BadMessage { sequence: 4, .. }), "{text}");
        assert!(text.contains("bad.mcap") && text.contains(topic) && text.contains(expected), "{text}");
    }
}
