use proptest::prelude::*;

use mmtrack_core::GnssFixQuality;

use super::sentence::{NS_PER_DAY, days_from_civil};
use super::*;

fn sentence(payload: &str) -> String {
    format!("${payload}*{:02X}", payload.bytes().fold(0u8, |a, b| a ^ b))
}

fn rmc(talker: &str, hhmmss: &str, status: &str, ddmmyy: &str) -> String {
    sentence(&format!("{talker}RMC,{hhmmss},{status},3725.58362,N,12205.61915,W,0.028,65.13,{ddmmyy},13.06,E,F,V"))
}

fn gga(talker: &str, hhmmss: &str, quality: &str) -> String {
    sentence(&format!("{talker}GGA,{hhmmss},3725.58362,N,12205.61915,W,{quality},12,0.76,4.4,M,-30.0,M,0.0,2000"))
}

/// An epoch as a u-blox receiver writes it: RMC, then GGA, then GSA.
fn epoch(talker: &str, hhmmss: &str) -> String {
    format!(
        "{}\n{}\n{}\n",
        rmc(talker, hhmmss, "A", "070220"),
        gga(talker, hhmmss, "5"),
        sentence("GNGSA,A,3,17,02,06,28,12,13,15,24,19,,,,1.48,0.76,1.27,1")
    )
}

fn parse(text: &str) -> Result<NmeaLog, IngestError> {
    parse_nmea(Path::new("drive.nmea"), text.as_bytes())
}

/// 2020-02-07 02:14:17 UTC in UNIX seconds (`date -u -d @1581041657`).
const T0_S: i64 = 1_581_041_657;

#[test]
fn epoch_gives_exact_time_position_and_ellipsoid_height() {
    let log = parse(&epoch("GN", "021417.25")).unwrap();
    assert_eq!(log.fixes.len(), 1);
    let fix = &log.fixes[0];
    assert_eq!(fix.t_ns, T0_S * 1_000_000_000 + 250_000_000);
    assert!((fix.latitude_deg - (37.0 + 25.58362 / 60.0)).abs() < 1e-12);
    assert!((fix.longitude_deg + (122.0 + 5.61915 / 60.0)).abs() < 1e-12);
    assert!((fix.altitude_m.unwrap() - (4.4 - 30.0)).abs() < 1e-12);
    assert_eq!((fix.quality, fix.num_satellites, fix.horizontal_sigma_m), (GnssFixQuality::RtkFloat, Some(12), None));
    assert_eq!((log.altitude_datum, log.ignored_sentences), ("ellipsoid", 1));
    // Nanosecond digits are kept exactly (an f64 of seconds would not).
    let log = parse(&epoch("GN", "021417.123456789")).unwrap();
    assert_eq!(log.fixes[0].t_ns, T0_S * 1_000_000_000 + 123_456_789);
}

#[test]
fn every_talker_is_accepted_and_quality_maps() {
    let talkers = ["GP", "GN", "GL", "GA", "GB", "GQ", "BD"];
    let text: String = talkers.iter().enumerate().map(|(i, t)| epoch(t, &format!("02141{i}.00"))).collect();
    let log = parse(&text).unwrap();
    assert_eq!(log.fixes.len(), talkers.len());
    for (quality, expected) in [
        ("1", GnssFixQuality::Autonomous),
        ("2", GnssFixQuality::Differential),
        ("3", GnssFixQuality::Unknown),
        ("4", GnssFixQuality::RtkFixed),
        ("5", GnssFixQuality::RtkFloat),
        ("6", GnssFixQuality::DeadReckoning),
        ("8", GnssFixQuality::Unknown),
    ] {
        let text = format!("{}\n{}\n", rmc("GN", "021417.00", "A", "070220"), gga("GN", "021417.00", quality));
        assert_eq!(parse(&text).unwrap().fixes[0].quality, expected, "quality {quality}");
    }
}

#[test]
fn bad_checksums_junk_and_a_truncated_last_line_are_skipped_and_counted() {
    let mut text = epoch("GN", "021417.00");
    // Line 4: one digit of the GGA changed, checksum kept.
    text.push_str(&gga("GN", "021418.00", "5").replace("3725.58362", "3725.58363"));
    text.push('\n');
    // The u-blox corruption seen in the real log: the talker's G doubled.
    text.push_str("$GGPGSV,3,3,10,28,32,082,46,30,07,147,27,1*65\n");
    text.push_str(&epoch("GN", "021419.00"));
    text.push_str("\n\u{0}\u{1}\u{fffd}binary\n$PUBX,00*33\n");
    // A last line cut off in the middle, then one cut inside its checksum.
    let cut = gga("GN", "021420.00", "5");
    text.push_str(&format!("{}\n{}", &cut[..40], &cut[..cut.len() - 1]));
    let log = parse(&text).unwrap();
    assert_eq!(log.fixes.len(), 2);
    assert_eq!((log.bad_checksum_lines, log.first_bad_checksum_line), (2, Some(4)));
    // Blank line, binary line, the two truncated lines.
    assert_eq!(log.unparsable_lines, 4);
    assert_eq!(
        log.first_unparsable.as_ref().map(|s| (s.line, s.reason.as_str())),
        Some((9, "not an NMEA sentence: blank line"))
    );
    // Two GSA and the proprietary PUBX.
    assert_eq!(log.ignored_sentences, 3);
}

#[test]
fn bad_fields_in_a_valid_sentence_skip_the_line_and_name_it() {
    let mut text = rmc("GN", "021417.00", "A", "070220") + "\n";
    text += &sentence("GNGGA,021417.00,37x5.58,N,12205.61915,W,1,12,0.76,4.4,M,-30.0,M,,");
    text += "\n";
    for (hhmmss, field, replacement) in [
        ("021418.00", "3725.58362,N", "9125.58362,N"),
        ("021419.00", "12205.61915,W", "NaN,W"),
        ("021420.00", ",4.4,M", ",inf,M"),
        ("021421.00", "070220", "300220"),
    ] {
        let line = if field == "070220" { rmc("GN", hhmmss, "A", "070220") } else { gga("GN", hhmmss, "1") };
        let payload = line[1..line.len() - 3].replace(field, replacement);
        text += &(sentence(&payload) + "\n");
    }
    text += &epoch("GN", "021422.00");
    let log = parse(&text).unwrap();
    // The first epoch's GGA does not parse, so its valid RMC gives the fix.
    assert_eq!((log.fixes.len(), log.unparsable_lines, log.rmc_only_fixes), (2, 5, 1));
    assert_eq!(log.fixes.iter().map(|f| f.altitude_m.is_some()).collect::<Vec<_>>(), vec![false, true]);
    let first = log.first_unparsable.unwrap();
    assert_eq!(first.line, 2);
    assert!(first.reason.contains("GNGGA: latitude:") && first.reason.contains("'37x5.58,N'"), "{}", first.reason);
}

#[test]
fn gga_without_rmc_is_an_error() {
    let text = [gga("GN", "021417.00", "1"), gga("GN", "021418.00", "1")].join("\n");
    let err = parse(&text).unwrap_err().to_string();
    assert!(err.contains("drive.nmea") && err.contains("no RMC") && err.contains("line 1"), "{err}");
    // Without any fix there is nothing to date: not an error.
    let log = parse(&gga("GN", "021417.00", "0")).unwrap();
    assert_eq!((log.fixes.len(), log.epochs_without_fix), (0, 1));
}

fn zda(talker: &str, hhmmss: &str, dd_mm_yyyy: &str) -> String {
    sentence(&format!("{talker}ZDA,{hhmmss},{dd_mm_yyyy},00,00"))
}

#[test]
fn gga_with_zda_and_no_rmc_gives_fixes() {
    // GGA then ZDA of the same epoch, across midnight; then a GGA whose
    // epoch has no ZDA (dated from the previous fix).
    let lines = [
        gga("GP", "235959.00", "1"),
        zda("GP", "235959.00", "31,01,2020"),
        gga("GP", "000000.00", "4"),
        zda("GP", "000000.00", "01,02,2020"),
        gga("GP", "000001.00", "4"),
        // Before the receiver knows the time: ignored.
        sentence("GPZDA,,,,,00,00"),
    ];
    let log = parse(&lines.join("\n")).unwrap();
    let midnight_s = days_from_civil(2020, 2, 1) * 86_400;
    let times: Vec<i64> = log.fixes.iter().map(|f| f.t_ns / 1_000_000_000 - midnight_s).collect();
    assert_eq!(times, vec![-1, 0, 1]);
    assert_eq!((log.rmc_only_fixes, log.unparsable_lines, log.ignored_sentences), (0, 0, 1));
    assert!(log.fixes.iter().all(|f| f.altitude_m.is_some() && f.num_satellites == Some(12)));
    // ZDA first, and at 1 Hz beside 5 Hz GGAs: the ZDA dates the GGAs before and after it.
    let lines = [
        gga("GN", "021416.80", "1"),
        zda("GN", "021417.00", "07,02,2020"),
        gga("GN", "021417.00", "1"),
        gga("GN", "021417.20", "1"),
    ];
    let log = parse(&lines.join("\n")).unwrap();
    let times: Vec<i64> = log.fixes.iter().map(|f| f.t_ns / 1_000_000 - T0_S * 1000).collect();
    assert_eq!(times, vec![-200, 0, 200]);
    // A ZDA with a date that is not a calendar date is counted, not used.
    let text = gga("GN", "021417.00", "1") + "\n" + &zda("GN", "021417.00", "30,02,2020");
    let err = parse(&text).unwrap_err().to_string();
    assert!(err.contains("no RMC or ZDA sentence with a date"), "{err}");
}

#[test]
fn a_leap_second_epoch_is_counted_and_skipped() {
    // 2016-12-31 23:59:60 UTC was a leap second. UNIX time gives 23:59:60.f
    // the time of 00:00:00.f, which belongs to the next epoch: the leap
    // second's fix is skipped and counted, every other fix kept.
    let lines = [
        gga("GP", "235959.00", "1"),
        rmc("GP", "235959.00", "A", "311216"),
        gga("GP", "235960.00", "1"),
        rmc("GP", "235960.00", "A", "311216"),
        gga("GP", "000000.00", "1"),
        rmc("GP", "000000.00", "A", "010117"),
    ];
    let log = parse(&lines.join("\n")).unwrap();
    let midnight_s = days_from_civil(2017, 1, 1) * 86_400;
    let times: Vec<i64> = log.fixes.iter().map(|f| f.t_ns / 1_000_000_000 - midnight_s).collect();
    assert_eq!(times, vec![-1, 0]);
    assert_eq!((log.leap_second_epochs, log.first_leap_second_line, log.duplicate_epochs), (1, Some(3), 0));
    // At 10 Hz, GGA + ZDA: the ten epochs of the leap second are counted; the
    // ZDA of the leap second dates the GGAs after it.
    let mut text = String::new();
    for tenth in 0..10 {
        text += &(gga("GN", &format!("235960.{tenth}0"), "1") + "\n");
    }
    text += &(zda("GN", "235960.90", "31,12,2016") + "\n" + &gga("GN", "000000.00", "1") + "\n");
    let log = parse(&text).unwrap();
    assert_eq!(log.fixes.iter().map(|f| f.t_ns).collect::<Vec<_>>(), vec![midnight_s * 1_000_000_000]);
    assert_eq!((log.leap_second_epochs, log.first_leap_second_line), (10, Some(1)));
}

#[test]
fn a_long_line_or_a_file_without_sentences_is_refused_with_its_line() {
    // /dev/zero, a binary file without line ends: refused at line 1 after
    // reading at most one line's cap.
    let err = parse_nmea(Path::new("zero.nmea"), std::io::BufReader::new(std::io::repeat(0))).unwrap_err().to_string();
    assert!(err.starts_with("zero.nmea: line 1: line: longer than 4096 bytes"), "{err}");
    let long =
        format!("{}\n{}\n$GPTXT,{}*00\n", epoch("GN", "021417.00"), gga("GN", "021418.00", "1"), "x".repeat(5000));
    let err = parse(&long).unwrap_err().to_string();
    assert!(err.starts_with("drive.nmea: line 6: line: longer than 4096 bytes"), "{err}");
    // A line of exactly the cap (line end included) is a line like another.
    let at_cap = format!("{}\n{}", "x".repeat(MAX_LINE_BYTES - 1), epoch("GN", "021417.00"));
    assert_eq!(parse(&at_cap).unwrap().fixes.len(), 1);
    // Binary data with line ends (bytes of a xorshift generator): no
    // sentence in the first 1000 lines.
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let noise: Vec<u8> = (0..400_000)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 56) as u8
        })
        .filter(|&b| b != b'$')
        .collect();
    let err = parse_nmea(Path::new("noise.bin"), noise.as_slice()).unwrap_err().to_string();
    assert!(err.starts_with("noise.bin: line 1000: line: no NMEA sentence"), "{err}");
    // Junk lines before the first sentence, fewer than the cap, are counted.
    let text = "header\n".repeat(MAX_LINES_BEFORE_FIRST_SENTENCE - 1) + &epoch("GN", "021417.00");
    let log = parse(&text).unwrap();
    assert_eq!((log.fixes.len(), log.unparsable_lines), (1, 999));
}

#[test]
fn an_epoch_earlier_than_the_previous_fix_is_skipped_and_counted() {
    // 5 Hz, one epoch stamped 0.3 s back (a receiver's clock correction): it
    // is skipped, the log is not rejected, and the epochs after it are kept.
    let text = ["021417.00", "021417.20", "021417.40", "021417.10", "021417.60", "021417.80"]
        .iter()
        .map(|t| epoch("GN", t))
        .collect::<String>();
    let log = parse(&text).unwrap();
    let t0_ns = T0_S * 1_000_000_000;
    let times: Vec<i64> = log.fixes.iter().map(|f| (f.t_ns - t0_ns) / 1_000_000).collect();
    assert_eq!(times, vec![0, 200, 400, 600, 800]);
    assert_eq!(log.out_of_order_epochs, 1);
    let first = log.first_out_of_order.as_ref().unwrap();
    // Lines are those of each epoch's first sentence.
    assert_eq!(first.line, 10);
    assert!(
        first.reason.contains("021417.100000000 UTC")
            && first.reason.contains("0.300000000 s before")
            && first.reason.contains("line 7"),
        "{}",
        first.reason
    );
    // The same epoch twice (and a GPGGA beside the GNGGA) is merged, not counted as out of order.
    let text = epoch("GN", "021417.00") + &gga("GP", "021417.00", "5") + "\n" + &epoch("GN", "021417.00");
    let log = parse(&text).unwrap();
    assert_eq!((log.fixes.len(), log.duplicate_epochs, log.out_of_order_epochs), (1, 2, 0));
}

#[test]
fn a_misdated_first_fix_is_an_error_not_a_one_fix_drive() {
    // The first RMC dated 2068 instead of 2020 (checksum valid): every later
    // epoch is "before the previous fix". Before, ingest kept the one
    // misdated fix, skipped the other 1652 of the real log and exited 0.
    let misdated = format!("{}\n{}\n", rmc("GN", "021417.00", "A", "070268"), gga("GN", "021417.00", "5"));
    let text = misdated + &["021418.00", "021419.00", "021420.00"].iter().map(|t| epoch("GN", t)).collect::<String>();
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("drive.nmea"), dir.path().join("drive.mcap"));
    std::fs::write(&input, &text).unwrap();
    let err = ingest_nmea(&input, &out, None, &mmtrack_io::RecordingOptions::default()).unwrap_err().to_string();
    assert!(
        err.contains("drive.nmea: line 3: date: fix at 2020-02-07 021418.000000000 UTC is 17531 days before")
            && err.contains("2068-02-07 021417.000000000 UTC, line 1): one of them is likely misdated"),
        "{err}"
    );
    assert!(!out.exists());
    // Misdated into the past (the drive became 22 years long, its times then
    // labelled relative), the last fix misdated, a two-fix log: the same.
    let past = format!("{}\n{}\n", rmc("GN", "021417.00", "A", "070298"), gga("GN", "021417.00", "5"));
    let last = format!("{}\n{}\n", rmc("GN", "021421.00", "A", "070268"), gga("GN", "021421.00", "5"));
    let good = |times: &[&str]| times.iter().map(|t| epoch("GN", t)).collect::<String>();
    for (text, days) in [
        (past + &good(&["021418.00", "021419.00"]), "days after the previous fix (1998-02-07"),
        (good(&["021418.00", "021419.00"]) + &last, "days after the previous fix (2020-02-07 021419"),
        (
            format!("{}\n{}\n", rmc("GN", "021417.00", "A", "070268"), gga("GN", "021417.00", "5"))
                + &good(&["021418.00"]),
            "days before",
        ),
    ] {
        std::fs::write(&input, &text).unwrap();
        let err = ingest_nmea(&input, &out, None, &mmtrack_io::RecordingOptions::default()).unwrap_err().to_string();
        assert!(err.contains(days) && err.contains("likely misdated"), "{err}");
        assert!(!out.exists());
    }
    // One epoch stepped back among many is still skipped, not refused.
    let text = ["021417.00", "021418.00", "021416.00", "021419.00"].iter().map(|t| epoch("GN", t)).collect::<String>();
    std::fs::write(&input, &text).unwrap();
    let report = ingest_nmea(&input, &out, None, &mmtrack_io::RecordingOptions::default()).unwrap();
    assert_eq!((report.log.fix_count, report.log.out_of_order_epochs), (3, 1));
}

#[test]
fn an_rmc_without_a_usable_gga_is_a_fix_without_altitude() {
    let t0_ns = T0_S * 1_000_000_000;
    // RMC alone: position, date and the mode indicator's quality; no height
    // and no satellite count.
    let log = parse(&(rmc("GN", "021417.00", "A", "070220") + "\n")).unwrap();
    assert_eq!(log.fixes.len(), 1);
    let fix = &log.fixes[0];
    assert_eq!((fix.t_ns, fix.altitude_m, fix.num_satellites), (t0_ns, None, None));
    assert!((fix.latitude_deg - (37.0 + 25.58362 / 60.0)).abs() < 1e-12);
    assert!((fix.longitude_deg + (122.0 + 5.61915 / 60.0)).abs() < 1e-12);
    assert_eq!((fix.quality, log.rmc_only_fixes, log.altitude_datum), (GnssFixQuality::RtkFloat, 1, ""));
    // Mode indicators map like GGA qualities; N (not valid) and status V are no fix.
    for (mode, expected) in [
        ("A", Some(GnssFixQuality::Autonomous)),
        ("D", Some(GnssFixQuality::Differential)),
        ("E", Some(GnssFixQuality::DeadReckoning)),
        ("R", Some(GnssFixQuality::RtkFixed)),
        ("", Some(GnssFixQuality::Unknown)),
        ("N", None),
    ] {
        let line = sentence(&format!("GNRMC,021417.00,A,3725.58362,N,12205.61915,W,0.0,0.0,070220,,,{mode}"));
        let log = parse(&line).unwrap();
        assert_eq!(log.fixes.first().map(|f| f.quality), expected, "mode {mode}");
        assert_eq!(log.epochs_without_fix, u64::from(expected.is_none()), "mode {mode}");
    }
    let log = parse(&rmc("GN", "021417.00", "V", "070220")).unwrap();
    assert_eq!((log.fixes.len(), log.epochs_without_fix), (0, 1));
    // A GGA with an empty altitude still gives its position and satellites.
    let no_height = sentence("GNGGA,021418.00,3725.58362,N,12205.61915,W,1,12,0.76,,M,,M,,");
    let text = epoch("GN", "021417.00") + &rmc("GN", "021418.00", "A", "070220") + "\n" + &no_height + "\n";
    let log = parse(&text).unwrap();
    assert_eq!(log.fixes.iter().map(|f| f.altitude_m.is_some()).collect::<Vec<_>>(), vec![true, false]);
    assert_eq!((log.fixes[1].num_satellites, log.fixes[1].quality), (Some(12), GnssFixQuality::Autonomous));
    assert_eq!((log.unparsable_lines, log.rmc_only_fixes, log.altitude_datum), (0, 0, "ellipsoid"));
    // A GGA that does not parse leaves its epoch to the RMC (and is counted).
    let bad_gga = gga("GN", "021418.00", "4").replace("3725.58362", "37x5.58362");
    let text = epoch("GN", "021417.00")
        + &rmc("GN", "021418.00", "A", "070220")
        + "\n"
        + &sentence(&bad_gga[1..bad_gga.len() - 3]);
    let log = parse(&text).unwrap();
    assert_eq!((log.fixes.len(), log.unparsable_lines, log.rmc_only_fixes), (2, 1, 1));
    assert_eq!(log.fixes[1].altitude_m, None);
    // A valid RMC must say where.
    let err = parse(&sentence("GNRMC,021417.00,A,,,,,0.0,0.0,070220,,,A")).unwrap();
    assert_eq!((err.fixes.len(), err.unparsable_lines), (0, 1));
    assert!(err.first_unparsable.unwrap().reason.contains("GNRMC: latitude"));
}

#[test]
fn gga_before_rmc_and_midnight_rollover_are_dated_right() {
    // GGA first (as many receivers write it): the first epoch is kept and the
    // RMC status V of an epoch applies to its GGA.
    let lines = [
        gga("GP", "235958.00", "1"),
        rmc("GP", "235958.00", "A", "310120"),
        gga("GP", "235959.00", "1"),
        rmc("GP", "235959.00", "V", "310120"),
        gga("GP", "000000.00", "1"),
        rmc("GP", "000000.00", "A", "010220"),
        // No RMC after midnight: dated from the previous fix.
        gga("GP", "000001.00", "1"),
    ];
    let log = parse(&lines.join("\n")).unwrap();
    let midnight_s = days_from_civil(2020, 2, 1) * 86_400;
    let times: Vec<i64> = log.fixes.iter().map(|f| f.t_ns / 1_000_000_000 - midnight_s).collect();
    assert_eq!(times, vec![-2, 0, 1]);
    assert_eq!(log.epochs_without_fix, 1);
    // GGAs before the first RMC, across midnight, dated by that RMC (which
    // is a fix of its own, without altitude).
    let lines = [gga("GN", "235959.00", "1"), gga("GN", "000000.00", "1"), rmc("GN", "000001.00", "A", "010220")];
    let log = parse(&lines.join("\n")).unwrap();
    let times: Vec<i64> = log.fixes.iter().map(|f| f.t_ns / 1_000_000_000 - midnight_s).collect();
    assert_eq!(times, vec![-1, 0, 1]);
    assert_eq!((log.rmc_only_fixes, log.fixes[2].altitude_m), (1, None));
}

#[test]
fn cold_start_no_fix_and_gst_sigma() {
    let text = [
        "$GPRMC,,V,,,,,,,,,,N*53".to_string(),
        "$GPGGA,,,,,,0,00,99.99,,,,,,*48".to_string(),
        rmc("GP", "021417.00", "V", "070220"),
        gga("GP", "021417.00", "0"),
        rmc("GP", "021418.00", "A", "070220"),
        gga("GP", "021418.00", "1"),
        sentence("GPGST,021418.00,1.2,0.5,0.3,45.0,0.3,0.4,0.9"),
    ]
    .join("\r\n");
    let log = parse(&text).unwrap();
    assert_eq!((log.fixes.len(), log.epochs_without_fix, log.unparsable_lines), (1, 2, 0));
    assert!((log.fixes[0].horizontal_sigma_m.unwrap() - 0.125f64.sqrt()).abs() < 1e-12);
}

#[test]
fn altitude_is_above_mean_sea_level_unless_every_fix_gives_the_geoid() {
    let without_geoid = sentence("GNGGA,021418.00,3725.58362,N,12205.61915,W,1,12,0.76,4.4,M,,M,,");
    let text = epoch("GN", "021417.00") + &rmc("GN", "021418.00", "A", "070220") + "\n" + &without_geoid;
    let log = parse(&text).unwrap();
    assert_eq!(log.altitude_datum, "mean sea level");
    assert!(log.fixes.iter().all(|f| (f.altitude_m.unwrap() - 4.4).abs() < 1e-12));
    assert_eq!(parse("").unwrap(), NmeaLog::default());
}

#[test]
fn real_ublox_drive_gives_1653_fixes() {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/realdata/nmea-ublox-f9k/MTV.Local1.ublox-F9K.20200206-181434.nmea"
    ));
    if !path.is_file() {
        eprintln!("skipped: real data not found at {}", path.display());
        return;
    }
    // google/gps-measurement-tools, Apache-2.0. 45498 lines: 1653 epochs of
    // RMC, VTG, GGA, 4 GSA, 17-20 GSV and GLL from talkers GN, GP, GL, GA, GB.
    let log = read_nmea(path).unwrap();
    assert_eq!(log.fixes.len(), 1653);
    assert!(log.fixes.windows(2).all(|w| w[1].t_ns > w[0].t_ns));
    // 2020-02-07 02:14:17 to 02:43:04 UTC: the file name's 2020-02-06 18:14
    // is Pacific local time.
    assert_eq!(log.fixes[0].t_ns / NS_PER_DAY, days_from_civil(2020, 2, 7));
    assert_eq!(log.fixes[0].t_ns, T0_S * 1_000_000_000);
    assert_eq!(log.fixes[1652].t_ns, (T0_S + 28 * 60 + 47) * 1_000_000_000);
    assert!(
        log.fixes
            .iter()
            .all(|f| (37.41..37.43).contains(&f.latitude_deg) && (-122.10..-122.06).contains(&f.longitude_deg))
    );
    // Counted independently with a Python XOR over each line: 13 corrupted
    // GSV/VTG lines ("$GGPGSV..."), no other junk; GSV 32260 + GSA 6612 +
    // GLL 1654 + VTG 1652 + TXT 1 ignored.
    assert_eq!((log.bad_checksum_lines, log.first_bad_checksum_line), (13, Some(7181)));
    assert_eq!((log.unparsable_lines, log.ignored_sentences), (0, 42_179));
    assert_eq!((log.epochs_without_fix, log.duplicate_epochs, log.altitude_datum), (0, 0, "ellipsoid"));
    let count = |q: GnssFixQuality| log.fixes.iter().filter(|f| f.quality == q).count();
    assert_eq!(
        (count(GnssFixQuality::RtkFixed), count(GnssFixQuality::RtkFloat), count(GnssFixQuality::Differential)),
        (967, 632, 54)
    );
}

fn real_log() -> Option<String> {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/realdata/nmea-ublox-f9k/MTV.Local1.ublox-F9K.20200206-181434.nmea"
    ));
    if !path.is_file() {
        eprintln!("skipped: real data not found at {}", path.display());
        return None;
    }
    Some(String::from_utf8_lossy(&std::fs::read(path).unwrap()).into_owned())
}

#[test]
fn real_drive_without_usable_gga_still_gives_every_fix() {
    let Some(text) = real_log() else { return };
    let with_gga = parse(&text).unwrap();
    // Every GGA dropped: the 1653 RMCs (status A) give the same times and
    // positions, the quality from the RMC mode (it matches the GGA quality
    // in every epoch of this log), no altitude.
    let rmc_only: String = text.lines().filter(|l| !l.contains("GGA,")).map(|l| format!("{l}\n")).collect();
    let log = parse(&rmc_only).unwrap();
    assert_eq!((log.fixes.len(), log.rmc_only_fixes, log.altitude_datum), (1653, 1653, ""));
    for (a, b) in log.fixes.iter().zip(&with_gga.fixes) {
        assert_eq!(
            (a.t_ns, a.latitude_deg, a.longitude_deg, a.quality),
            (b.t_ns, b.latitude_deg, b.longitude_deg, b.quality)
        );
        assert_eq!((a.altitude_m, a.num_satellites), (None, None));
    }
    // Every GGA's altitude emptied (and re-signed): counted as fixes, not unparsable lines.
    let no_height: String = text
        .lines()
        .map(|l| match l.strip_prefix('$').and_then(|b| b.rsplit_once('*')) {
            Some((payload, _)) if payload.contains("GGA,") => {
                let mut fields: Vec<&str> = payload.split(',').collect();
                fields[9] = "";
                sentence(&fields.join(",")) + "\n"
            }
            _ => format!("{l}\n"),
        })
        .collect();
    let log = parse(&no_height).unwrap();
    assert_eq!((log.fixes.len(), log.unparsable_lines, log.rmc_only_fixes), (1653, 0, 0));
    assert!(log.fixes.iter().all(|f| f.altitude_m.is_none() && f.num_satellites.is_some()));
}

#[test]
fn real_drive_as_gga_and_zda_gives_the_same_fixes() {
    let Some(text) = real_log() else { return };
    let with_rmc = parse(&text).unwrap();
    // Each RMC replaced by a ZDA of the same time and date, written after the
    // GGA (as receivers that log GGA + ZDA do): the same 1653 fixes, field
    // for field.
    let mut zda_log = String::new();
    let mut pending_zda = None;
    for line in text.lines() {
        let payload = line.strip_prefix('$').and_then(|b| b.rsplit_once('*')).map(|(p, _)| p);
        match payload.map(|p| p.split(',').collect::<Vec<_>>()) {
            Some(fields) if fields[0].ends_with("RMC") && fields.len() > 9 => {
                let date = fields[9];
                let dd_mm_yyyy = format!("{},{},20{}", &date[0..2], &date[2..4], &date[4..6]);
                pending_zda = Some(zda("GN", fields[1], &dd_mm_yyyy));
                continue;
            }
            Some(fields) if fields[0].ends_with("GGA") => {
                zda_log += &format!("{line}\n");
                zda_log += &(pending_zda.take().unwrap() + "\n");
                continue;
            }
            _ => zda_log += &format!("{line}\n"),
        }
    }
    let log = parse(&zda_log).unwrap();
    assert_eq!(log.fixes, with_rmc.fixes);
    assert_eq!((log.rmc_only_fixes, log.bad_checksum_lines, log.unparsable_lines), (0, 13, 0));
}

#[test]
fn real_drive_with_one_epoch_stamped_back_keeps_the_rest() {
    let Some(text) = real_log() else { return };
    // The epoch of 02:15:57 restamped 0.3 s before the one of 02:15:56 (its
    // sentences re-signed).
    let text: String = text
        .lines()
        .map(|l| match l.strip_prefix('$').and_then(|b| b.rsplit_once('*')) {
            Some((payload, _)) if payload.contains(",021557.00,") => {
                sentence(&payload.replace(",021557.00,", ",021555.70,")) + "\n"
            }
            _ => format!("{l}\n"),
        })
        .collect();
    let log = parse(&text).unwrap();
    assert_eq!((log.fixes.len(), log.out_of_order_epochs), (1652, 1));
    assert!(log.first_out_of_order.unwrap().reason.contains("0.300000000 s before"));
}

/// A valid multi-epoch log to mutate.
fn valid_log() -> String {
    epoch("GN", "235958.50") + &epoch("GP", "235959.99") + &gga("GL", "000000.00", "4") + "\n"
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn parser_never_panics_on_arbitrary_text(text in "\\PC{0,300}", bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        let _ = parse(&text);
        let _ = parse(&String::from_utf8_lossy(&bytes));
    }

    /// Byte edits of a valid log; the payload edits re-sign the line so they
    /// reach the field parsers instead of stopping at the checksum.
    #[test]
    fn parser_never_panics_on_mutated_sentences(
        edits in proptest::collection::vec((0usize..400, any::<u8>(), 0u8..3), 1..6),
        resign in any::<bool>(),
        cut in 0usize..400,
    ) {
        let mut bytes = valid_log().into_bytes();
        for (at, value, op) in edits {
            let at = at % (bytes.len() + 1);
            match op {
                0 if at < bytes.len() => bytes[at] = value,
                1 => bytes.insert(at, value),
                _ if at < bytes.len() => { bytes.remove(at); }
                _ => {}
            }
        }
        bytes.truncate(cut.max(1));
        let text = String::from_utf8_lossy(&bytes).into_owned();
        let text = if resign {
            text.lines()
                .map(|l| match l.strip_prefix('$').and_then(|b| b.rsplit_once('*')) {
                    Some((payload, _)) => sentence(payload),
                    None => l.to_string(),
                })
                .collect::<Vec<_>>()
                .join("\n")
        } else {
            text
        };
        if let Ok(log) = parse(&text) {
            prop_assert!(log.fixes.windows(2).all(|w| w[1].t_ns > w[0].t_ns));
            prop_assert!(log.fixes.iter().all(|f| f.latitude_deg.abs() <= 90.0 && f.altitude_m.is_none_or(f64::is_finite)));
        }
    }

    /// A fix written as GGA + RMC (positions to 7 decimals of a minute, time to
    /// the centisecond) parses back to the same time exactly and the same
    /// position within the printing's rounding.
    #[test]
    fn fixes_round_trip_through_gga_and_rmc(
        lat_deg in -89.999_999f64..89.999_999,
        lon_deg in -179.999_999f64..179.999_999,
        alt_dm in -5_000i32..50_000,
        second_of_day in 0u32..86_400,
        centis in 0u32..100,
        (year, month, day) in (2000i64..2080, 1i64..=12, 1i64..=28),
    ) {
        let hhmmss = format!(
            "{:02}{:02}{:02}.{centis:02}",
            second_of_day / 3600,
            second_of_day / 60 % 60,
            second_of_day % 60
        );
        let ddmmyy = format!("{day:02}{month:02}{:02}", year % 100);
        let angle = |value: f64, degree_digits: usize, hemispheres: [char; 2]| {
            let degrees = value.abs().trunc();
            let minutes = (value.abs() - degrees) * 60.0;
            // Printing minutes to 7 decimals can round up to 60.0000000; carry it.
            let (degrees, minutes) = if format!("{minutes:.7}").starts_with("60") { (degrees + 1.0, 0.0) } else { (degrees, minutes) };
            let hemisphere = if value < 0.0 { hemispheres[1] } else { hemispheres[0] };
            format!("{:0width$}{minutes:010.7},{hemisphere}", degrees as u32, width = degree_digits)
        };
        let (lat, lon) = (angle(lat_deg, 2, ['N', 'S']), angle(lon_deg, 3, ['E', 'W']));
        let altitude_m = f64::from(alt_dm) / 10.0;
        let text = format!(
            "{}\n{}\n",
            sentence(&format!("GNRMC,{hhmmss},A,{lat},{lon},0.0,0.0,{ddmmyy},,,A")),
            sentence(&format!("GNGGA,{hhmmss},{lat},{lon},1,9,0.9,{altitude_m:.1},M,,M,,")),
        );
        let log = parse(&text).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(log.fixes.len(), 1, "{}", text);
        let fix = &log.fixes[0];
        // Days since 1970-01-01 counted naively, independent of the parser's arithmetic.
        let leap = |y: i64| (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
        let month_days = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
        let days: i64 = (1970..year).map(|y| if leap(y) { 366 } else { 365 }).sum::<i64>()
            + (1..month).map(|m| month_days[(m - 1) as usize] + i64::from(m == 2 && leap(year))).sum::<i64>()
            + day - 1;
        let t_ns = (days * 86_400 + i64::from(second_of_day)) * 1_000_000_000 + i64::from(centis) * 10_000_000;
        prop_assert_eq!(fix.t_ns, t_ns);
        // 7 decimals of a minute round by at most 5e-8 min = 8.3e-10 deg.
        prop_assert!((fix.latitude_deg - lat_deg).abs() < 1e-9, "{} vs {}", fix.latitude_deg, lat_deg);
        prop_assert!((fix.longitude_deg - lon_deg).abs() < 1e-9, "{} vs {}", fix.longitude_deg, lon_deg);
        prop_assert!((fix.altitude_m.unwrap() - altitude_m).abs() < 1e-9);
    }
}

/// Before: a GGA altitude of 1e300 was taken, and as the first fix's
/// altitude it became the recording's map origin. Now the GGA is skipped and
/// reported like any unparsable line; its epoch keeps the RMC's position.
#[test]
fn an_implausible_altitude_is_skipped_and_reported() {
    let huge = gga("GN", "021417.00", "1").replace(",4.4,M,", ",1e300,M,");
    let text = rmc("GN", "021417.00", "A", "070220") + "\n" + &sentence(&huge[1..huge.len() - 3]) + "\n";
    let log = parse(&text).unwrap();
    assert_eq!((log.fixes.len(), log.unparsable_lines), (1, 1));
    assert_eq!(log.fixes[0].altitude_m, None);
    let reason = log.first_unparsable.unwrap().reason;
    assert!(reason.contains("altitude") && reason.contains("1e300 is not an altitude within"), "{reason}");
}

/// The fixes of the recording at `path`.
fn recorded_fixes(path: &Path) -> Vec<mmtrack_core::GnssFix> {
    use mmtrack_io::recording::{RecordingEvent, RecordingReader};
    let mut reader = RecordingReader::open(path).unwrap();
    reader
        .by_ref()
        .filter_map(|event| match event.unwrap() {
            RecordingEvent::Gnss(fix) => Some(fix),
            _ => None,
        })
        .collect()
}

/// Before: `ingest_nmea` kept every fix in memory (about 90 bytes each)
/// until the last had decided the altitude datum. A file is now read twice
/// (the datum, then the writing) and no fix is kept; the recording is the
/// same, with GGAs before the first RMC dated by it, altitudes on either
/// datum, and the ENU origin's height on the datum. A pipe is read once.
#[test]
fn a_file_is_ingested_in_two_passes_keeping_no_fix() {
    let dir = tempfile::tempdir().unwrap();
    let without_geoid = sentence("GNGGA,021419.00,3725.58362,N,12205.61915,W,1,12,0.76,9.9,M,,M,,");
    let undated = [gga("GN", "021415.00", "1"), gga("GN", "021416.00", "1")].join("\n") + "\n";
    let ellipsoid = undated.clone() + &epoch("GN", "021417.00") + &epoch("GN", "021418.00");
    let msl = ellipsoid.clone() + &rmc("GN", "021419.00", "A", "070220") + "\n" + &without_geoid + "\n";
    for (name, text, datum, origin_m) in
        [("e.nmea", &ellipsoid, "ellipsoid", 4.4 - 30.0), ("m.nmea", &msl, "mean sea level", 4.4)]
    {
        let input = dir.path().join(name);
        std::fs::write(&input, text).unwrap();
        let expected = parse(text).unwrap();
        assert_eq!(expected.altitude_datum, datum);
        let out = dir.path().join(format!("{name}.mcap"));
        let report = ingest_nmea(&input, &out, None, &mmtrack_io::RecordingOptions::default()).unwrap();
        assert!(report.log.fixes.is_empty(), "{} fixes kept", report.log.fixes.len());
        assert_eq!(report.log, NmeaLog { fixes: Vec::new(), ..expected.clone() });
        assert_eq!(recorded_fixes(&out), expected.fixes);
        assert_eq!(expected.fixes.len(), 4 + usize::from(datum == "mean sea level"));
        let mut reader = mmtrack_io::recording::RecordingReader::open(&out).unwrap();
        let _ = reader.next();
        let metadata = reader.metadata().unwrap().clone();
        let origin: f64 = metadata["gnss.enu_origin_altitude_m"].parse().unwrap();
        assert!((origin - origin_m).abs() < 1e-9, "{origin}");
        assert_eq!(metadata["gnss.altitude_datum"], datum);
    }
    #[cfg(unix)]
    {
        let fifo = dir.path().join("pipe");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let feeder = {
            let (fifo, text) = (fifo.clone(), msl.clone());
            std::thread::spawn(move || std::fs::write(fifo, text).unwrap())
        };
        let out = dir.path().join("pipe.mcap");
        let report = ingest_nmea(&fifo, &out, None, &mmtrack_io::RecordingOptions::default()).unwrap();
        feeder.join().unwrap();
        assert_eq!(report.log.fix_count, 5);
        assert_eq!(recorded_fixes(&out), parse(&msl).unwrap().fixes);
    }
}
