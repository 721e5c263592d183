//! Ingest of a real u-blox F9K drive (google/gps-measurement-tools, Apache-2.0),
//! and of written GGA + ZDA logs.

use mmtrack_io::{RecordingEvent, RecordingReader};

use super::common::{mmtrack, text};

#[test]
fn nmea_drive_gives_1653_fixes_and_reports_bad_checksums() {
    let Some(realdata) = super::common::realdata("nmea_drive") else { return };
    let log = realdata.join("nmea-ublox-f9k/MTV.Local1.ublox-F9K.20200206-181434.nmea");
    let dir = tempfile::tempdir().unwrap();
    assert!(mmtrack(dir.path(), &["demo", "--out", "d", "--quiet"]).status.success());
    // The demo's scans are of 2023; the drive of 2020-02-06: adding its fixes
    // to the demo is refused, and the demo left as it was.
    let demo = "d/recording.mcap";
    let before = std::fs::read(dir.path().join(demo)).unwrap();
    let out = mmtrack(dir.path(), &["ingest", "nmea", log.to_str().unwrap(), "--add-to", demo, "-o", demo]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("none of its 1653 GNSS fixes falls within the time span of d/recording.mcap"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert_eq!(std::fs::read(dir.path().join(demo)).unwrap(), before);
    let rec = "nmea.mcap";
    let out = mmtrack(dir.path(), &["ingest", "nmea", log.to_str().unwrap(), "-o", rec]);
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
    assert_eq!((fixes, scans), (1653, 0));
    let meta = mmtrack(dir.path(), &["inspect", "--json", rec]);
    let summary: serde_json::Value = serde_json::from_slice(&meta.stdout).unwrap();
    let m = &summary["metadata"]["mmtrack.recording"];
    assert_eq!(m["gnss.altitude_datum"], "ellipsoid");
    assert!(m["gnss.enu_origin_latitude_deg"].as_str().unwrap().starts_with("37.4"));
}

/// `$payload*XX` with the NMEA checksum.
fn signed(payload: &str) -> String {
    format!("${payload}*{:02X}", payload.bytes().fold(0u8, |a, b| a ^ b))
}

/// Each sentence of `text` through `edit` (given its payload; `None` drops
/// it); changed sentences are re-signed, the others kept byte for byte.
fn edit_sentences(text: &str, edit: impl Fn(&str) -> Option<String>) -> String {
    text.lines()
        .filter_map(|line| match line.strip_prefix('$').and_then(|b| b.rsplit_once('*')) {
            Some((payload, _)) => {
                edit(payload).map(|p| if p == payload { format!("{line}\n") } else { signed(&p) + "\n" })
            }
            None => Some(format!("{line}\n")),
        })
        .collect()
}

#[test]
fn nmea_rmc_only_epochs_and_a_backward_step_are_reported_not_lost() {
    let Some(realdata) = super::common::realdata("nmea_rmc_only") else { return };
    let log = realdata.join("nmea-ublox-f9k/MTV.Local1.ublox-F9K.20200206-181434.nmea");
    let nmea = String::from_utf8_lossy(&std::fs::read(log).unwrap()).into_owned();
    let dir = tempfile::tempdir().unwrap();

    // The first 34 epochs with their GGA sentences gone: 34 RMC fixes, as a
    // receiver that writes RMC alone logs them.
    let epoch_34 = nmea.lines().position(|l| l.starts_with("$GNRMC,021451.00,")).unwrap();
    let head: String = nmea.lines().take(epoch_34).map(|l| format!("{l}\n")).collect();
    let rmc_only = edit_sentences(&head, |p| (!p.contains("GGA,")).then(|| p.to_string()));
    std::fs::write(dir.path().join("rmc.nmea"), rmc_only).unwrap();
    let out = mmtrack(dir.path(), &["ingest", "nmea", "rmc.nmea", "-o", "rmc.mcap"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("34 GNSS fixes (34 from RMC alone, 34 without altitude)"), "{stdout}");
    let fixes: Vec<_> = RecordingReader::open(&dir.path().join("rmc.mcap"))
        .unwrap()
        .filter_map(|e| match e.unwrap() {
            RecordingEvent::Gnss(fix) => Some(fix),
            _ => None,
        })
        .collect();
    assert_eq!(fixes.len(), 34);
    assert!(fixes.iter().all(|f| f.altitude_m.is_none() && f.num_satellites.is_none()), "{:?}", fixes[0]);
    let meta = mmtrack(dir.path(), &["inspect", "--json", "rmc.mcap"]);
    let summary: serde_json::Value = serde_json::from_slice(&meta.stdout).unwrap();
    assert_eq!(summary["metadata"]["mmtrack.recording"]["gnss.altitude_datum"], "none (no fix gives an altitude)");

    // The epoch of 02:15:57 stamped 0.3 s before the one of 02:15:56: that
    // epoch is skipped and reported, the 1652 others kept.
    let back = edit_sentences(&nmea, |p| Some(p.replace(",021557.00,", ",021555.70,")));
    std::fs::write(dir.path().join("back.nmea"), back).unwrap();
    let out = mmtrack(dir.path(), &["ingest", "nmea", "back.nmea", "-o", "back.mcap"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stdout.contains("1652 GNSS fixes")
            && stdout.contains(
                "1 epoch out of time order (first at line 2892: fix at 2020-02-07 021555.700000000 UTC is \
                 0.300000000 s before"
            ),
        "{stdout}"
    );

    // The first RMC dated 2068 (checksum valid): every later epoch is before
    // it. Refused, naming the misdated fix, instead of a one-fix recording.
    let first_rmc = std::cell::Cell::new(true);
    let misdated = edit_sentences(&nmea, |p| {
        if p.contains("RMC,") && first_rmc.replace(false) {
            Some(p.replace(",070220,", ",070268,"))
        } else {
            Some(p.to_string())
        }
    });
    std::fs::write(dir.path().join("misdated.nmea"), misdated).unwrap();
    let out = mmtrack(dir.path(), &["ingest", "nmea", "misdated.nmea", "-o", "misdated.mcap"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("misdated.nmea")
            && stderr.contains("days before the previous fix (2068-02-07")
            && stderr.contains("likely misdated"),
        "{stderr}"
    );
    assert!(!dir.path().join("misdated.mcap").exists());
}

#[test]
fn nmea_gga_with_zda_gives_fixes_and_the_summary_counts_leap_seconds() {
    // A receiver logging GGA + ZDA (no RMC) through the leap second at the
    // end of 2016: three fixes, the epoch at 23:59:60 counted.
    let mut log = String::new();
    for (time, date) in [
        ("235959.00", "31,12,2016"),
        ("235960.00", "31,12,2016"),
        ("000000.00", "01,01,2017"),
        ("000001.00", "01,01,2017"),
    ] {
        log += &(signed(&format!("GNGGA,{time},4807.0380,N,01131.0000,E,4,12,0.7,545.4,M,46.9,M,,")) + "\n");
        log += &(signed(&format!("GNZDA,{time},{date},00,00")) + "\n");
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("zda.nmea"), log).unwrap();
    let out = mmtrack(dir.path(), &["ingest", "nmea", "zda.nmea", "-o", "zda.mcap"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stdout.contains("3 GNSS fixes;")
            && stdout.contains("1 leap-second epoch (23:59:60 UTC has no UNIX time of its own; first at line 3)"),
        "{stdout}"
    );
    let times: Vec<i64> = RecordingReader::open(&dir.path().join("zda.mcap"))
        .unwrap()
        .filter_map(|e| match e.unwrap() {
            RecordingEvent::Gnss(fix) => Some(fix.t_ns / 1_000_000_000),
            _ => None,
        })
        .collect();
    // 2017-01-01 00:00:00 UTC is UNIX second 1483228800 (`date -u -d 2017-01-01 +%s`).
    assert_eq!(times, vec![1_483_228_799, 1_483_228_800, 1_483_228_801]);
}
