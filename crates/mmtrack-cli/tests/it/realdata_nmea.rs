//! Ingest of a real u-blox F9K drive (google/gps-measurement-tools, Apache-2.0).

use mmtrack_io::{RecordingEvent, RecordingReader};

use super::common::{mmtrack, text};

#[test]
fn nmea_drive_gives_1653_fixes_and_reports_bad_checksums() {
    let Some(realdata) = super::common::realdata("nmea_drive") else { return };
    let log = realdata.join("nmea-ublox-f9k/MTV.Local1.ublox-F9K.20200206-181434.nmea");
    let dir = tempfile::tempdir().unwrap();
    assert!(mmtrack(dir.path(), &["demo", "--out", "d", "--quiet"]).status.success());
    let rec = "d/recording.mcap";
    let out = mmtrack(dir.path(), &["ingest", "nmea", log.to_str().unwrap(), "--add-to", rec, "-o", rec]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    // 13 lines fail their checksum: counted independently with a Python XOR over each line.
    assert!(stdout.contains("1653 GNSS fixes") && stdout.contains("13 lines with bad checksums"), "{stdout}");
    let mut fixes = 0;
    let mut scans = 0;
    for event in RecordingReader::open(&dir.path().join(rec)).unwrap() {
        match event.unwrap() {
            RecordingEvent::Gnss(_) => fixes += 1,
            RecordingEvent::RadarScan(_) => scans += 1,
            _ => {}
        }
    }
    assert_eq!((fixes, scans), (1653, 8));
    let meta = mmtrack(dir.path(), &["inspect", "--json", rec]);
    let summary: serde_json::Value = serde_json::from_slice(&meta.stdout).unwrap();
    let m = &summary["metadata"]["mmtrack.recording"];
    assert_eq!(m["gnss.altitude_datum"], "ellipsoid");
    assert!(m["gnss.enu_origin_latitude_deg"].as_str().unwrap().starts_with("37.4"));
}
