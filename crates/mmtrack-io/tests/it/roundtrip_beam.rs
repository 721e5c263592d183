//! Beam sweeps and both units' GNSS fixes (the vehicle on `/gnss/fix`, the
//! sweeping array on `/gnss/array`) through a recording and back, bit-exact;
//! a malformed sweep is an error naming the topic and message.

use std::collections::BTreeMap;
use std::sync::Arc;

use mmtrack_core::{BeamSweep, GnssFix, GnssFixQuality};
use mmtrack_io::proto::{self, SpecMessage};
use mmtrack_io::recording::{ChannelInfo, Compression, RawMessage, inspect_recording};
use mmtrack_io::{IoError, RecordingEvent, RecordingOptions, RecordingReader, RecordingWriter};
use prost::Message;

use crate::samples;

/// Powers whose decimal forms do not round-trip through a naive printer.
const AWKWARD: [f64; 6] = [0.1, 1.0 / 3.0, 5e-324, 0.0, 1.7976931348623157e308, 2.5e-10];

/// Full sweeps of 64 beams, a partial sweep (unmeasured beams hold 0, as
/// the reader gives them back) and a one-beam codebook.
fn sweeps() -> Vec<(BeamSweep, Option<&'static str>)> {
    let mut out = Vec::new();
    for k in 0..4i64 {
        let power = (0..64).map(|b| AWKWARD[(b + k as usize) % AWKWARD.len()] / (1.0 + b as f64)).collect();
        out.push((BeamSweep::full(k * 100_000_000, power).unwrap(), Some("deepsense-60ghz-64")));
    }
    let measured: Vec<bool> = (0..64).map(|b| (30..35).contains(&b)).collect();
    let power = measured.iter().enumerate().map(|(b, &m)| if m { 0.25 + b as f64 } else { 0.0 }).collect();
    out.push((BeamSweep::new(400_000_000, power, measured).unwrap(), None));
    out.push((BeamSweep::full(500_000_000, vec![7.5]).unwrap(), Some("")));
    out
}

fn fix(t_ns: i64, latitude_deg: f64, longitude_deg: f64) -> GnssFix {
    GnssFix {
        t_ns,
        latitude_deg,
        longitude_deg,
        altitude_m: None,
        horizontal_sigma_m: None,
        num_satellites: None,
        quality: GnssFixQuality::Unknown,
    }
}

#[test]
fn beam_sweeps_and_both_units_fixes_round_trip_bit_exactly() {
    for (compression, views) in
        [(Compression::None, true), (Compression::Zstd { level: 3 }, false), (Compression::Lz4, true)]
    {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("beams.mcap");
        let options = RecordingOptions { compression, foxglove_views: views, ..Default::default() };
        let mut writer = RecordingWriter::create(&path, &samples::metadata(), &options).unwrap();
        let car: Vec<GnssFix> = (0..6)
            .map(|k| fix(k * 100_000_000, 33.42 + AWKWARD[k as usize] * 1e-6, -111.93 - 1e-7 * k as f64))
            .collect();
        let array = fix(0, 33.420_347_222_222_22, -111.929_152_777_777_79);
        for ((sweep, codebook), car_fix) in sweeps().iter().zip(&car) {
            writer.write_beam_sweep(sweep, *codebook).unwrap();
            writer.write_gnss_fix(car_fix).unwrap();
            writer.write_array_gnss_fix(&GnssFix { t_ns: sweep.t_ns(), ..array.clone() }).unwrap();
        }
        let summary = writer.finish().unwrap();
        assert_eq!(summary.message_counts["/beam/sweeps"], 6);
        assert_eq!(summary.message_counts["/gnss/fix"], 6);
        assert_eq!(summary.message_counts["/gnss/array"], 6);
        assert_eq!(summary.message_counts.get("/viz/gnss_array").copied(), views.then_some(6));

        let events: Vec<RecordingEvent> = RecordingReader::open(&path).unwrap().collect::<Result<_, _>>().unwrap();
        let got_sweeps: Vec<(BeamSweep, Option<String>)> = events
            .iter()
            .filter_map(|e| match e {
                RecordingEvent::BeamSweep { sweep, codebook } => Some((sweep.clone(), codebook.clone())),
                _ => None,
            })
            .collect();
        let want: Vec<(BeamSweep, Option<String>)> =
            sweeps().into_iter().map(|(s, c)| (s, c.map(str::to_string))).collect();
        assert_eq!(got_sweeps, want);
        // `==` on floats misses -0.0 vs 0.0 and NaN payloads: compare bits.
        for ((got, _), (sent, _)) in got_sweeps.iter().zip(&want) {
            let bits = |s: &BeamSweep| (0..s.beam_count()).map(|b| s.power(b).map(f64::to_bits)).collect::<Vec<_>>();
            assert_eq!(bits(got), bits(sent));
        }
        let cars: Vec<&GnssFix> =
            events.iter().filter_map(|e| if let RecordingEvent::Gnss(f) = e { Some(f) } else { None }).collect();
        let arrays: Vec<&GnssFix> =
            events.iter().filter_map(|e| if let RecordingEvent::ArrayGnss(f) = e { Some(f) } else { None }).collect();
        assert_eq!(cars, car.iter().collect::<Vec<_>>(), "the vehicle's fixes stay on /gnss/fix");
        assert_eq!(arrays.len(), 6);
        assert!(arrays.iter().all(|f| f.latitude_deg.to_bits() == array.latitude_deg.to_bits()));

        let inspected = inspect_recording(&path).unwrap();
        let beam = inspected.channels.iter().find(|c| c.topic == "/beam/sweeps").unwrap();
        assert_eq!((beam.schema_name.as_str(), beam.message_count), ("mmtrack.BeamSweep", 6));
    }
}

/// Writes one hand-encoded `mmtrack.BeamSweep` message and returns the
/// reader's error.
fn read_bad(message: &proto::BeamSweep) -> IoError {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.mcap");
    let mut writer = RecordingWriter::create(&path, &samples::metadata(), &RecordingOptions::default()).unwrap();
    let channel = Arc::new(ChannelInfo {
        topic: "/beam/sweeps".into(),
        schema_name: proto::BeamSweep::SPEC.full_name.into(),
        message_encoding: "protobuf".into(),
        schema_encoding: "protobuf".into(),
        schema_data: Arc::from(proto::BeamSweep::SPEC.file_descriptor_set()),
        metadata: BTreeMap::new(),
    });
    let data = bytes::Bytes::from(message.encode_to_vec());
    writer.copy_message(&RawMessage { channel, sequence: 3, log_time_ns: 5, data }).unwrap();
    writer.finish().unwrap();
    RecordingReader::open(&path).unwrap().collect::<Result<Vec<_>, _>>().unwrap_err()
}

#[test]
fn malformed_beam_sweeps_are_errors_naming_topic_message_and_problem() {
    let good = proto::BeamSweep {
        t_ns: 5,
        beam_count: 3,
        power_linear: vec![0.1, 0.2, 0.3],
        measured: vec![true; 3],
        codebook: None,
    };
    let cases = [
        (proto::BeamSweep { beam_count: 4, ..good.clone() }, "beam_count 4 but 3 power_linear values"),
        (proto::BeamSweep { measured: vec![true; 2], ..good.clone() }, "2 measured flags"),
        (proto::BeamSweep { power_linear: vec![0.1, f64::NAN, 0.3], ..good.clone() }, "not finite"),
        (proto::BeamSweep { power_linear: vec![0.1, -0.2, 0.3], ..good.clone() }, "non-negative"),
        (
            proto::BeamSweep { beam_count: 0, power_linear: vec![], measured: vec![], ..good.clone() },
            "at least one beam",
        ),
        (proto::BeamSweep { measured: vec![false; 3], ..good.clone() }, "at least one measured beam"),
    ];
    for (message, expected) in cases {
        let err = read_bad(&message);
        let text = err.to_string();
        assert!(matches!(err, IoError::BadMessage { sequence: 3, .. }), "{text}");
        assert!(text.contains("bad.mcap") && text.contains("/beam/sweeps") && text.contains(expected), "{text}");
    }
}

#[test]
fn beam_sweeps_tracked_table_round_trips_with_and_without_gnss_beam() {
    use mmtrack_io::Overwrite;
    use mmtrack_io::table::{BEAM_SWEEPS_TRACKED, BeamSweepTracked, read_table, write_table};
    let rows: Vec<BeamSweepTracked> = (0..6u32)
        .map(|k| BeamSweepTracked {
            tracker: if k < 3 { "window".into() } else { "gnss-map".into() },
            site: "deepsense-scenario1".into(),
            t_ns: i64::from(k) * 100_000_000 - 1,
            sweep: u64::from(k % 3),
            beam_count: 64,
            chosen_beam: 63 - k,
            best_beam: k,
            beams_measured: [64, 3, 0, u32::MAX, 5, 1][k as usize],
            reinitialised: k == 0,
            loss_db: AWKWARD[k as usize],
            gnss_beam: (k >= 3).then(|| -AWKWARD[k as usize] - 1.5),
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let run = samples::run_info(r#"{"test":"beam"}"#);
    let summary = write_table(dir.path(), "scenario1-pass01", &rows, &run, Overwrite::Refuse).unwrap();
    assert!(summary.path.ends_with("beam_sweeps_tracked/sequence=scenario1-pass01/part-0.parquet"));
    let back = read_table::<BeamSweepTracked>(&summary.path).unwrap();
    assert_eq!(back, rows);
    let bits = |r: &[BeamSweepTracked]| {
        r.iter().map(|r| (r.loss_db.to_bits(), r.gnss_beam.map(f64::to_bits))).collect::<Vec<_>>()
    };
    assert_eq!(bits(&back), bits(&rows));
    assert_eq!(BEAM_SWEEPS_TRACKED.columns.iter().find(|c| c.name == "loss_db").unwrap().unit, "dB");
}
