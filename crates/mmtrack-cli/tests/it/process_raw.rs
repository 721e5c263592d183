//! `mmtrack process raw`: a recording's measurements as tables, value for
//! value what the recording holds, on the real Oxford radar sample and the
//! real UWB channel log.

use mmtrack_core::{CirSnapshot, GnssFix, PolarScan, Se2, StampedPose};
use mmtrack_io::recording::{PoseStream, RecordingItem, RecordingMetadata, TimeBase};
use mmtrack_io::table::{GroundTruthPose, read_table};
use mmtrack_io::{RecordingEvent, RecordingOptions, RecordingWriter};

use super::common::{mmtrack, mmtrack_ok, realdata, text};

/// Every message of the recording, scans decoded.
fn events(recording: &std::path::Path) -> Vec<RecordingEvent> {
    let mut reader = mmtrack_io::RecordingReader::open(recording).unwrap();
    let mut events = Vec::new();
    while let Some(item) = reader.next_item() {
        events.push(match item.unwrap() {
            RecordingItem::Event(event) => event,
            RecordingItem::Scan(scan) => RecordingEvent::RadarScan(scan.decode().unwrap()),
        });
    }
    events
}

#[test]
fn the_oxford_sample_s_scans_fixes_and_ground_truth_come_out_as_recorded() {
    let Some(realdata) = realdata("process_raw_oxford") else { return };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = realdata.join("oxford-radar-tiny");
    mmtrack_ok(d, &["ingest", "oxford", input.to_str().unwrap(), "-o", "ox.mcap", "-q"]);
    let stdout = mmtrack_ok(d, &["process", "raw", "ox.mcap", "-o", "raw"]);
    let recorded = events(&d.join("ox.mcap"));
    let scans: Vec<PolarScan> = recorded
        .iter()
        .filter_map(|e| if let RecordingEvent::RadarScan(s) = e { Some(s.clone()) } else { None })
        .collect();
    let fixes: Vec<GnssFix> =
        recorded.iter().filter_map(|e| if let RecordingEvent::Gnss(f) = e { Some(f.clone()) } else { None }).collect();
    let truth: Vec<GroundTruthPose> = recorded
        .iter()
        .filter_map(|e| match e {
            RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } => Some(GroundTruthPose(pose.clone())),
            _ => None,
        })
        .collect();
    assert_eq!(scans.len(), 11);
    assert!(!fixes.is_empty() && !truth.is_empty(), "{} fixes, {} poses", fixes.len(), truth.len());
    assert!(
        stdout.contains(&format!(
            "raw (oxford-radar-tiny): 11 radar scans, 0 CIR snapshots, {} GNSS fixes, {} ground-truth poses",
            fixes.len(),
            truth.len()
        )),
        "{stdout}"
    );
    let part = |table: &str| d.join(format!("raw/{table}/sequence=oxford-radar-tiny/part-0.parquet"));
    assert_eq!(read_table::<PolarScan>(&part("radar_scans")).unwrap(), scans);
    assert_eq!(read_table::<GnssFix>(&part("gnss_fixes")).unwrap(), fixes);
    assert_eq!(read_table::<GroundTruthPose>(&part("ground_truth")).unwrap(), truth);
    assert!(!d.join("raw/cir_snapshots").exists());

    // Again without --force: refused before anything is read, naming the table.
    let out = mmtrack(d, &["process", "raw", "ox.mcap", "-o", "raw"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out).1.contains("radar_scans/sequence=oxford-radar-tiny"), "{}", text(&out).1);
    // The scans' odometry from the table equals the odometry from the recording.
    mmtrack_ok(d, &["process", "raw", "ox.mcap", "-o", "raw", "--force", "-q"]);
    assert_eq!(read_table::<PolarScan>(&part("radar_scans")).unwrap(), scans);
}

#[test]
fn the_uwb_log_s_cirs_come_out_as_recorded_and_a_recording_without_measurements_is_refused() {
    let Some(realdata) = realdata("process_raw_uwb") else { return };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let log = realdata.join("uwb-cirs-2018/1.log");
    mmtrack_ok(d, &["ingest", "cir", log.to_str().unwrap(), "--format", "decawave", "-o", "uwb.mcap", "-q"]);
    let stdout = mmtrack_ok(d, &["process", "raw", "uwb.mcap", "-o", "raw", "--run-id", "r1"]);
    let cirs: Vec<CirSnapshot> = events(&d.join("uwb.mcap"))
        .into_iter()
        .filter_map(|e| if let RecordingEvent::Cir(c) = e { Some(c) } else { None })
        .collect();
    assert_eq!(cirs.len(), 252);
    assert!(stdout.contains("252 CIR snapshots"), "{stdout}");
    let table = d.join("raw/run=r1/cir_snapshots/sequence=uwb/part-0.parquet");
    assert_eq!(read_table::<CirSnapshot>(&table).unwrap(), cirs);

    // A recording holding only an estimate has none of these messages:
    // refused, nothing left behind.
    let metadata = RecordingMetadata {
        sequence_id: "estimate-only".into(),
        source: "process raw test".into(),
        time_base: TimeBase::Relative,
        extra: Default::default(),
    };
    let mut writer = RecordingWriter::create(&d.join("est.mcap"), &metadata, &RecordingOptions::default()).unwrap();
    let pose = StampedPose { t_ns: 5, parent_from_child: Se2::new(1.0, 2.0, 0.5) };
    writer.write_pose(PoseStream::Estimate, &pose, "world").unwrap();
    writer.finish().unwrap();
    let out = mmtrack(d, &["process", "raw", "est.mcap", "-o", "empty"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out)
            .1
            .contains("the recording has no radar scans, CIR snapshots, GNSS fixes or ground truth; nothing written"),
        "{}",
        text(&out).1
    );
    assert!(!d.join("empty").exists() || std::fs::read_dir(d.join("empty")).unwrap().next().is_none());
}
