//! The MPC pipeline's tables (GM-PHD tracks, long-term tracks, per-set
//! statistics, true MPCs, both sounder vehicles' poses) through Parquet and
//! back, bit-exact, with their units in the metadata.

use crate::samples;
use mmtrack_core::{Complex64, MpcDetection, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth, Se2, StampedPose};
use mmtrack_io::Overwrite;
use mmtrack_io::table::{
    GmPhdTrack, GroundTruthRxPose, GroundTruthTxPose, MPC_LONG_TERM, MPC_SETS, MPC_TRUTH, TableRow, read_table,
    read_table_dir, write_table,
};

/// Values whose decimal forms do not round-trip through a naive printer.
const AWKWARD: [f64; 6] = [0.1, -1.0 / 3.0, 5e-324, -0.0, 1.7976931348623157e308, 2.5e-10];

fn round_trip<T: TableRow + PartialEq + std::fmt::Debug>(rows: &[T]) -> Vec<T> {
    let dir = tempfile::tempdir().unwrap();
    let run = samples::run_info(r#"{"test":"mpc"}"#);
    let summary = write_table(dir.path(), "conv-tx0-rx0", rows, &run, Overwrite::Refuse).unwrap();
    assert_eq!(summary.rows, rows.len() as u64);
    let back = read_table::<T>(&summary.path).unwrap();
    assert_eq!(read_table_dir::<T>(dir.path()).unwrap()["conv-tx0-rx0"], back);
    back
}

fn long_term() -> Vec<MpcLongTermEntry> {
    (0..5u64)
        .map(|i| MpcLongTermEntry {
            long_track_id: [3, 3, 9, 3, u64::MAX][i as usize],
            set_index: i / 2,
            t_ns: -5 + i as i64 * 10_000_000,
            short_track_id: i * 7,
            mean_delay_s: 3.1e-7 + AWKWARD[i as usize] * 1e-12,
            mean_power_db: -90.0 + AWKWARD[(i as usize + 1) % 6],
            doppler_hz: AWKWARD[(i as usize + 2) % 6],
            link_error_s: (i > 0).then(|| AWKWARD[5] * i as f64),
            chi_class_s: [None, Some(1e-10), Some(2e-10), Some(5e-10), Some(1e-9)][i as usize],
        })
        .collect()
}

fn set_stats() -> Vec<MpcSetStats> {
    (0..3u64)
        .map(|i| MpcSetStats {
            set_index: i,
            t_ns: i as i64 * 10_000_000,
            snapshots: 6,
            skipped_snapshots: i as u32,
            detections: 40 + i as u32,
            short_term_tracks: 7,
            full_lifetime_tracks: 5,
            noise_floor_db: Some(-140.0 + AWKWARD[i as usize]),
            channel_gain_db: Some(-80.25),
            detected_gain_db: Some(-82.0),
            // A set without tracks has no tracked gain (null, not -inf).
            tracked_gain_db: (i != 2).then_some(-82.5),
            full_lifetime_gain_db: Some(AWKWARD[(i as usize + 3) % 6]),
            gmphd_tracked_gain_db: (i % 2 == 0).then(|| AWKWARD[(i as usize + 4) % 6]),
        })
        .collect()
}

fn truth() -> Vec<MpcTruth> {
    (0..8u64)
        .map(|i| MpcTruth {
            t_ns: 1_000 + i as i64 * 717_000,
            set_index: i / 6,
            snapshot_index: (i % 6) as u32,
            path_id: [0, 7, 1 << 40, u64::MAX][i as usize % 4],
            delay_s: 2.6e-7 + AWKWARD[i as usize % 6] * 1e-12,
            amplitude: Complex64::new(AWKWARD[(i as usize + 1) % 6], -AWKWARD[(i as usize + 4) % 6]),
            doppler_hz: [-0.0, 105.6, -3.3e3, 5e-324][i as usize % 4],
        })
        .collect()
}

fn bits(values: impl Iterator<Item = f64>) -> Vec<u64> {
    values.map(f64::to_bits).collect()
}

#[test]
fn mpc_tables_round_trip_bit_exactly() {
    let entries = long_term();
    let back = round_trip(&entries);
    assert_eq!(back, entries);
    assert_eq!(bits(back.iter().map(|e| e.doppler_hz)), bits(entries.iter().map(|e| e.doppler_hz)));
    assert_eq!(back[0].chi_class_s, None, "first entry of a long-term track has no link");

    let stats = set_stats();
    let back = round_trip(&stats);
    assert_eq!(back, stats);
    assert_eq!(
        bits(back.iter().filter_map(|s| s.full_lifetime_gain_db)),
        bits(stats.iter().filter_map(|s| s.full_lifetime_gain_db))
    );
    assert_eq!(back[2].tracked_gain_db, None);

    let truth = truth();
    let back = round_trip(&truth);
    assert_eq!(back, truth);
    assert_eq!(bits(back.iter().map(|t| t.amplitude.im)), bits(truth.iter().map(|t| t.amplitude.im)));

    let detection = |i: u32| MpcDetection {
        t_ns: i64::from(i) * 717_000,
        set_index: 4,
        snapshot_index: i,
        delay_s: 1e-7 + f64::from(i) * 1e-11,
        amplitude: Complex64::new(1e-5, -2e-5),
    };
    let gmphd = vec![
        GmPhdTrack(MpcTrack { track_id: 11, doppler_hz: Some(-12.5), detections: (0..3).map(detection).collect() }),
        GmPhdTrack(MpcTrack { track_id: 4, doppler_hz: None, detections: vec![detection(5)] }),
    ];
    assert_eq!(round_trip(&gmphd), gmphd);

    let pose = |t: i64, x: f64| StampedPose { t_ns: t, parent_from_child: Se2::new(x, -x, 0.25) };
    let tx: Vec<GroundTruthTxPose> = (0..4).map(|i| GroundTruthTxPose(pose(i, AWKWARD[i as usize]))).collect();
    let rx: Vec<GroundTruthRxPose> = (0..4).map(|i| GroundTruthRxPose(pose(i, 100.0 + i as f64))).collect();
    assert_eq!(round_trip(&tx), tx);
    assert_eq!(round_trip(&rx), rx);

    let empty: Vec<MpcLongTermEntry> = Vec::new();
    assert_eq!(round_trip(&empty), empty);
}

#[test]
fn mpc_tables_carry_units_and_keep_nulls() {
    let unit = |spec: &mmtrack_io::table::TableSpec, name: &str| {
        spec.columns.iter().find(|c| c.name == name).map(|c| (c.unit, c.nullable)).unwrap()
    };
    assert_eq!(unit(&MPC_LONG_TERM, "chi_class_s"), ("s", true));
    assert_eq!(unit(&MPC_LONG_TERM, "mean_power_db"), ("dB", false));
    assert_eq!(unit(&MPC_SETS, "channel_gain_db"), ("dB", true));
    assert_eq!(unit(&MPC_TRUTH, "doppler_hz"), ("Hz", false));
    let dir = tempfile::tempdir().unwrap();
    let run = samples::run_info("{}");
    let summary = write_table(dir.path(), "s", &long_term(), &run, Overwrite::Refuse).unwrap();
    let file = std::fs::File::open(&summary.path).unwrap();
    let reader = parquet::file::reader::SerializedFileReader::new(file).unwrap();
    let kv = parquet::file::reader::FileReader::metadata(&reader).file_metadata().key_value_metadata().unwrap().clone();
    let units = kv.iter().find(|e| e.key == "units").and_then(|e| e.value.clone()).unwrap();
    let units: serde_json::Value = serde_json::from_str(&units).unwrap();
    assert_eq!(units["link_error_s"], "s");
    assert_eq!(units["doppler_hz"], "Hz");
    assert_eq!(kv.iter().find(|e| e.key == "mmtrack.table").and_then(|e| e.value.clone()).unwrap(), "mpc_long_term");
}
