//! NMEA 0183 GNSS logs: GGA and RMC sentences from any talker (GP, GN, GL,
//! GA, GB, ...), one fix per epoch.
//!
//! Each line is `$<talker:2><type:3>,<fields>*<checksum:2 hex>`, the checksum
//! being the XOR of the bytes between `$` and `*`. Lines with a wrong checksum
//! are skipped and counted; lines that are not sentences at all (truncated,
//! binary junk, a missing `*`) are skipped and counted separately; other
//! sentence types (GSA, GSV, VTG, GLL, TXT, ...) are counted as ignored.
//!
//! An epoch is a GGA (time of day, position, quality, satellites, altitude,
//! geoid separation) dated by the most recent RMC (`ddmmyy`; the RMC of the same
//! time of day when there is one). Time is computed from the digits, so
//! fractional seconds are exact. Epochs whose GGA quality is 0 or whose RMC
//! status is `V` are not fixes: they are counted, not emitted. Repeated epochs
//! are merged; time going backwards is an error naming the line.
//!
//! `altitude_m` is the height above the WGS-84 ellipsoid (GGA altitude above
//! mean sea level plus the geoid separation) when the geoid separation is
//! given, else the altitude above mean sea level; [`NmeaLog::altitude_datum`]
//! says which. HDOP is not a standard deviation, so `horizontal_sigma_m` stays
//! `None`.
//!
//! Written by hand rather than with the `nmea` crate: we need exact integer
//! time from the digits, any talker, and to tell bad checksums from junk with
//! line numbers; GGA and RMC are two short, fixed layouts.

use std::path::Path;

use mmtrack_core::{GnssFix, GnssFixQuality};

use crate::IngestError;
use crate::error::os_err;

/// What a log gave.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NmeaLog {
    /// Fixes in time order.
    pub fixes: Vec<GnssFix>,
    /// Lines skipped for a wrong checksum.
    pub bad_checksum_lines: u64,
    /// First line (1-based) with a wrong checksum.
    pub first_bad_checksum_line: Option<usize>,
    /// Lines that are not NMEA sentences (skipped).
    pub unparsable_lines: u64,
    /// Valid sentences of other types (GSA, GSV, VTG, ...).
    pub ignored_sentences: u64,
    /// Epochs without a fix (GGA quality 0 or RMC status V).
    pub epochs_without_fix: u64,
    /// `ellipsoid` or `mean sea level`.
    pub altitude_datum: &'static str,
}

/// Days since 1970-01-01 of a proleptic Gregorian date (Howard Hinnant's algorithm).
fn days_from_civil(year: i64, month: i64, day: i64) -> i64 {
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (month + 9) % 12;
    let doy = (153 * mp + 2) / 5 + day - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

const NS_PER_DAY: i64 = 86_400_000_000_000;

/// `hhmmss[.sss]` to nanoseconds since midnight.
fn time_of_day_ns(text: &str) -> Option<i64> {
    let (whole, fraction) = text.split_once('.').unwrap_or((text, ""));
    if whole.len() != 6 || !whole.bytes().all(|b| b.is_ascii_digit()) || !fraction.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let (h, m, s): (i64, i64, i64) = (whole[0..2].parse().ok()?, whole[2..4].parse().ok()?, whole[4..6].parse().ok()?);
    if h > 23 || m > 59 || s > 60 {
        return None;
    }
    let mut digits: String = fraction.chars().take(9).collect();
    while digits.len() < 9 {
        digits.push('0');
    }
    Some(((h * 60 + m) * 60 + s) * 1_000_000_000 + digits.parse::<i64>().ok()?)
}

/// `ddmmyy` to days since the epoch (years 80-99 are 19xx, else 20xx).
fn date_days(text: &str) -> Option<i64> {
    if text.len() != 6 || !text.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let (d, m, y): (i64, i64, i64) = (text[0..2].parse().ok()?, text[2..4].parse().ok()?, text[4..6].parse().ok()?);
    if !(1..=12).contains(&m) || !(1..=31).contains(&d) {
        return None;
    }
    Some(days_from_civil(if y >= 80 { 1900 + y } else { 2000 + y }, m, d))
}

/// `ddmm.mmmm` / `dddmm.mmmm` with hemisphere to signed degrees.
fn coordinate_deg(value: &str, hemisphere: &str, degree_digits: usize, limit_deg: f64) -> Option<f64> {
    if value.len() < degree_digits + 2 || !value.is_char_boundary(degree_digits) {
        return None;
    }
    let degrees: f64 = value[..degree_digits].parse().ok()?;
    let minutes: f64 = value[degree_digits..].parse().ok()?;
    if !(0.0..60.0).contains(&minutes) {
        return None;
    }
    let unsigned = degrees + minutes / 60.0;
    let signed = match hemisphere {
        "N" | "E" => unsigned,
        "S" | "W" => -unsigned,
        _ => return None,
    };
    (signed.is_finite() && signed.abs() <= limit_deg).then_some(signed)
}

enum Line<'a> {
    Sentence { kind: &'a str, fields: Vec<&'a str> },
    BadChecksum,
    Junk,
}

fn split_sentence(line: &str) -> Line<'_> {
    let Some(body) = line.strip_prefix('$') else { return Line::Junk };
    let Some((payload, checksum)) = body.rsplit_once('*') else { return Line::Junk };
    let Ok(expected) = u8::from_str_radix(checksum.trim(), 16) else { return Line::Junk };
    if payload.bytes().fold(0u8, |acc, b| acc ^ b) != expected {
        return Line::BadChecksum;
    }
    let fields: Vec<&str> = payload.split(',').collect();
    let id = fields[0];
    if id.len() != 5 || !id.bytes().all(|b| b.is_ascii_uppercase()) {
        return Line::Junk;
    }
    Line::Sentence { kind: &id[2..], fields }
}

struct Gga {
    time_of_day_ns: i64,
    latitude_deg: f64,
    longitude_deg: f64,
    quality: GnssFixQuality,
    num_satellites: Option<u32>,
    altitude_m: f64,
    geoid_separation_m: Option<f64>,
}

fn parse_gga(fields: &[&str]) -> Result<Gga, (&'static str, String)> {
    let get = |i: usize| fields.get(i).copied().unwrap_or("");
    let time_of_day_ns = time_of_day_ns(get(1)).ok_or(("time", format!("'{}' is not hhmmss.ss", get(1))))?;
    let quality = match get(6) {
        "0" => GnssFixQuality::NoFix,
        "1" => GnssFixQuality::Autonomous,
        "2" => GnssFixQuality::Differential,
        "4" => GnssFixQuality::RtkFixed,
        "5" => GnssFixQuality::RtkFloat,
        "6" => GnssFixQuality::DeadReckoning,
        _ => GnssFixQuality::Unknown,
    };
    if quality == GnssFixQuality::NoFix {
        return Ok(Gga {
            time_of_day_ns,
            latitude_deg: 0.0,
            longitude_deg: 0.0,
            quality,
            num_satellites: None,
            altitude_m: 0.0,
            geoid_separation_m: None,
        });
    }
    let latitude_deg = coordinate_deg(get(2), get(3), 2, 90.0)
        .ok_or(("latitude", format!("'{},{}' is not ddmm.mm,N|S", get(2), get(3))))?;
    let longitude_deg = coordinate_deg(get(4), get(5), 3, 180.0)
        .ok_or(("longitude", format!("'{},{}' is not dddmm.mm,E|W", get(4), get(5))))?;
    let altitude_m = get(9)
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or(("altitude", format!("'{}' is not a number of metres", get(9))))?;
    Ok(Gga {
        time_of_day_ns,
        latitude_deg,
        longitude_deg,
        quality,
        num_satellites: get(7).parse().ok(),
        altitude_m,
        geoid_separation_m: get(11).parse::<f64>().ok().filter(|v| v.is_finite()),
    })
}

/// Parses a whole log.
pub fn parse_nmea(path: &Path, text: &str) -> Result<NmeaLog, IngestError> {
    let mut log = NmeaLog::default();
    // Latest RMC: (days since epoch, time of day, status valid).
    let mut rmc: Option<(i64, i64, bool)> = None;
    let mut saw_gga_without_date = false;
    let mut ellipsoid = true;
    for (index, raw) in text.lines().enumerate() {
        let line_number = index + 1;
        let line = raw.trim();
        if line.is_empty() {
            continue;
        }
        let (kind, fields) = match split_sentence(line) {
            Line::Sentence { kind, fields } => (kind, fields),
            Line::BadChecksum => {
                log.bad_checksum_lines += 1;
                log.first_bad_checksum_line.get_or_insert(line_number);
                continue;
            }
            Line::Junk => {
                log.unparsable_lines += 1;
                continue;
            }
        };
        let bad = |field: &str, detail: String| IngestError::BadRecord {
            path: path.to_path_buf(),
            record: format!("line {line_number} ({})", fields[0]),
            field: field.into(),
            detail,
        };
        match kind {
            "RMC" => {
                let get = |i: usize| fields.get(i).copied().unwrap_or("");
                let tod =
                    time_of_day_ns(get(1)).ok_or_else(|| bad("time", format!("'{}' is not hhmmss.ss", get(1))))?;
                let days = date_days(get(9)).ok_or_else(|| bad("date", format!("'{}' is not ddmmyy", get(9))))?;
                rmc = Some((days, tod, get(2) == "A"));
            }
            "GGA" => {
                let gga = parse_gga(&fields).map_err(|(field, detail)| bad(field, detail))?;
                let Some((days, rmc_tod, rmc_valid)) = rmc else {
                    saw_gga_without_date = true;
                    continue;
                };
                // A GGA just past midnight dated by the previous day's RMC.
                let day_offset = if gga.time_of_day_ns + NS_PER_DAY / 2 < rmc_tod { 1 } else { 0 };
                let t_ns = (days + day_offset) * NS_PER_DAY + gga.time_of_day_ns;
                let same_epoch_invalid = rmc_tod == gga.time_of_day_ns && !rmc_valid;
                if gga.quality == GnssFixQuality::NoFix || same_epoch_invalid {
                    log.epochs_without_fix += 1;
                    continue;
                }
                if let Some(last) = log.fixes.last() {
                    if t_ns == last.t_ns {
                        continue;
                    }
                    if t_ns < last.t_ns {
                        return Err(bad(
                            "time",
                            format!("{t_ns} ns goes back in time (previous fix {} ns)", last.t_ns),
                        ));
                    }
                }
                ellipsoid &= gga.geoid_separation_m.is_some();
                log.fixes.push(GnssFix {
                    t_ns,
                    latitude_deg: gga.latitude_deg,
                    longitude_deg: gga.longitude_deg,
                    altitude_m: gga.altitude_m + gga.geoid_separation_m.unwrap_or(0.0),
                    horizontal_sigma_m: None,
                    num_satellites: gga.num_satellites,
                    quality: gga.quality,
                });
            }
            _ => log.ignored_sentences += 1,
        }
    }
    if log.fixes.is_empty() && saw_gga_without_date {
        return Err(IngestError::BadLayout {
            path: path.to_path_buf(),
            detail: "GGA sentences but no RMC: the log has no date, so fixes cannot be given UNIX times".into(),
        });
    }
    log.altitude_datum = if ellipsoid { "ellipsoid" } else { "mean sea level" };
    Ok(log)
}

/// Reads and parses a log file.
pub fn read_nmea(path: &Path) -> Result<NmeaLog, IngestError> {
    let bytes = std::fs::read(path).map_err(os_err(path))?;
    // Junk bytes are tolerated line by line; invalid UTF-8 becomes unparsable lines.
    parse_nmea(path, &String::from_utf8_lossy(&bytes))
}

/// What an NMEA ingest did.
#[derive(Debug, Clone)]
pub struct NmeaReport {
    /// The parsed log (fixes and skip counts).
    pub log: NmeaLog,
    /// The recording.
    pub output: mmtrack_io::recording::WriteSummary,
}

/// Writes the fixes of an NMEA log into `out` (new, or a copy of `extend` plus
/// the fixes). The metadata records the altitude datum and the origin of the
/// local ENU frame (the first fix) that analyses use, e.g. for distance
/// travelled.
pub fn ingest_nmea(
    input: &Path,
    out: &Path,
    extend: Option<&Path>,
    recording: &mmtrack_io::RecordingOptions,
) -> Result<NmeaReport, IngestError> {
    use mmtrack_io::recording::channels::{GNSS_TOPIC, GNSS_VIZ_TOPIC};
    let log = read_nmea(input)?;
    let first = log.fixes.first().ok_or_else(|| IngestError::BadLayout {
        path: input.to_path_buf(),
        detail: format!(
            "no fixes (bad checksums {}, unparsable lines {}, epochs without fix {})",
            log.bad_checksum_lines, log.unparsable_lines, log.epochs_without_fix
        ),
    })?;
    let extra = std::collections::BTreeMap::from([
        ("gnss.source".to_string(), format!("nmea:{}", input.display())),
        ("gnss.altitude_datum".to_string(), log.altitude_datum.to_string()),
        ("gnss.enu_origin_latitude_deg".to_string(), first.latitude_deg.to_string()),
        ("gnss.enu_origin_longitude_deg".to_string(), first.longitude_deg.to_string()),
        ("gnss.enu_origin_altitude_m".to_string(), first.altitude_m.to_string()),
    ]);
    let source = format!("nmea:{}", input.display());
    let mut writer = crate::target::open_writer(out, extend, &source, extra, &[GNSS_TOPIC, GNSS_VIZ_TOPIC], recording)?;
    for fix in &log.fixes {
        writer.write_gnss_fix(fix)?;
    }
    let output = writer.finish()?;
    Ok(NmeaReport { log, output })
}

/// Origin of a local East-North-Up frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnuOrigin {
    /// Geodetic latitude, degrees.
    pub latitude_deg: f64,
    /// Geodetic longitude, degrees.
    pub longitude_deg: f64,
    /// Ellipsoidal height, metres.
    pub altitude_m: f64,
}

const WGS84_A_M: f64 = 6_378_137.0;
const WGS84_F: f64 = 1.0 / 298.257_223_563;

/// WGS-84 geodetic to Earth-centred Earth-fixed, metres:
/// `X = (N + h) cos(phi) cos(lambda)`, `Y = (N + h) cos(phi) sin(lambda)`,
/// `Z = (N (1 - e^2) + h) sin(phi)`, with `N = a / sqrt(1 - e^2 sin^2(phi))`.
fn ecef_m(latitude_deg: f64, longitude_deg: f64, altitude_m: f64) -> [f64; 3] {
    let e2 = WGS84_F * (2.0 - WGS84_F);
    let (sin_phi, cos_phi) = latitude_deg.to_radians().sin_cos();
    let (sin_lambda, cos_lambda) = longitude_deg.to_radians().sin_cos();
    let n = WGS84_A_M / (1.0 - e2 * sin_phi * sin_phi).sqrt();
    [
        (n + altitude_m) * cos_phi * cos_lambda,
        (n + altitude_m) * cos_phi * sin_lambda,
        (n * (1.0 - e2) + altitude_m) * sin_phi,
    ]
}

/// Geodetic position to local East-North-Up metres about `origin`: the ECEF
/// difference `d` rotated by
/// `e = -sin(l0) dx + cos(l0) dy`,
/// `n = -sin(p0) cos(l0) dx - sin(p0) sin(l0) dy + cos(p0) dz`,
/// `u = cos(p0) cos(l0) dx + cos(p0) sin(l0) dy + sin(p0) dz`.
#[must_use]
pub fn geodetic_to_enu_m(origin: &EnuOrigin, latitude_deg: f64, longitude_deg: f64, altitude_m: f64) -> [f64; 3] {
    let p0 = ecef_m(origin.latitude_deg, origin.longitude_deg, origin.altitude_m);
    let p = ecef_m(latitude_deg, longitude_deg, altitude_m);
    let d = [p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]];
    let (sp, cp) = origin.latitude_deg.to_radians().sin_cos();
    let (sl, cl) = origin.longitude_deg.to_radians().sin_cos();
    [-sl * d[0] + cl * d[1], -sp * cl * d[0] - sp * sl * d[1] + cp * d[2], cp * cl * d[0] + cp * sl * d[1] + sp * d[2]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn sentence(payload: &str) -> String {
        format!("${payload}*{:02X}", payload.bytes().fold(0u8, |a, b| a ^ b))
    }

    fn epoch(talker: &str, hhmmss: &str) -> String {
        format!(
            "{}\n{}\n",
            sentence(&format!("{talker}RMC,{hhmmss},A,3725.58362,N,12205.61915,W,0.028,65.13,070220,13.06,E,F,V")),
            sentence(&format!("{talker}GGA,{hhmmss},3725.58362,N,12205.61915,W,5,12,0.76,4.4,M,-30.0,M,0.0,2000"))
        )
    }

    #[test]
    fn epoch_gives_exact_time_position_and_ellipsoid_height() {
        let log = parse_nmea(Path::new("a.nmea"), &epoch("GN", "021417.25")).unwrap();
        assert_eq!(log.fixes.len(), 1);
        let fix = &log.fixes[0];
        // 2020-02-07 02:14:17.25 UTC = 1581041657.25 s (date -d @1581041657).
        assert_eq!(fix.t_ns, 1_581_041_657_250_000_000);
        assert!((fix.latitude_deg - (37.0 + 25.58362 / 60.0)).abs() < 1e-12);
        assert!((fix.longitude_deg + (122.0 + 5.61915 / 60.0)).abs() < 1e-12);
        assert!((fix.altitude_m - (4.4 - 30.0)).abs() < 1e-12);
        assert_eq!((fix.quality, fix.num_satellites), (GnssFixQuality::RtkFloat, Some(12)));
        assert_eq!(log.altitude_datum, "ellipsoid");
    }

    #[test]
    fn every_talker_and_bad_checksums_and_junk_are_handled() {
        let mut text = String::new();
        for (i, talker) in ["GP", "GN", "GL", "GA", "GB"].iter().enumerate() {
            text.push_str(&epoch(talker, &format!("02141{i}.00")));
        }
        text.push_str("$GNGGA,021419.00,3725.58362,N,12205.61915,W,5,12,0.76,4.4,M,-30.0,M,0.0,2000*00\n");
        text.push_str("$GGPGS,garbage\n\u{0}\u{1}binary\n$GNGSA,A,3,17");
        let log = parse_nmea(Path::new("a.nmea"), &text).unwrap();
        assert_eq!(log.fixes.len(), 5);
        assert_eq!((log.bad_checksum_lines, log.first_bad_checksum_line), (1, Some(11)));
        assert_eq!(log.unparsable_lines, 3);
    }

    #[test]
    fn bad_fields_and_backwards_time_name_the_line() {
        let text = sentence("GNRMC,021417.00,A,3725.5,N,12205.6,W,0,0,070220,,,A")
            + "\n"
            + &sentence("GNGGA,021417.00,37x5.58,N,12205.61915,W,1,12,0.76,4.4,M,-30.0,M,,");
        let err = parse_nmea(Path::new("a.nmea"), &text).unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains("latitude"), "{err}");
        let text = epoch("GN", "021417.00") + &epoch("GN", "021416.00");
        let err = parse_nmea(Path::new("a.nmea"), &text).unwrap_err().to_string();
        assert!(err.contains("line 4") && err.contains("back in time"), "{err}");
        let only_gga = sentence("GNGGA,021417.00,3725.58362,N,12205.61915,W,1,12,0.76,4.4,M,-30.0,M,,");
        let err = parse_nmea(Path::new("a.nmea"), &only_gga).unwrap_err().to_string();
        assert!(err.contains("no RMC"), "{err}");
    }

    #[test]
    fn enu_matches_known_distances() {
        let origin = EnuOrigin { latitude_deg: 0.0, longitude_deg: 0.0, altitude_m: 0.0 };
        assert_eq!(geodetic_to_enu_m(&origin, 0.0, 0.0, 0.0), [0.0, 0.0, 0.0]);
        // Meridian arc at the equator: M = a (1 - e^2) / (1 - e^2 sin^2 phi)^(3/2)
        // = 6335439.33 m per radian, so 0.001 deg = 110.574 m; 1 mm covers the
        // chord-versus-arc difference over 110 m.
        let [e, n, u] = geodetic_to_enu_m(&origin, 0.001, 0.0, 0.0);
        assert!(e.abs() < 1e-9 && (n - 110.574).abs() < 1e-3 && u.abs() < 1e-3, "{e} {n} {u}");
        let [e, n, u] = geodetic_to_enu_m(&origin, 0.0, 0.0, 100.0);
        assert!(e.abs() < 1e-9 && n.abs() < 1e-9 && (u - 100.0).abs() < 1e-9);
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
        // google/gps-measurement-tools, Apache-2.0.
        let log = read_nmea(path).unwrap();
        assert_eq!(log.fixes.len(), 1653);
        assert!(log.fixes.windows(2).all(|w| w[1].t_ns > w[0].t_ns));
        // 2020-02-07 UTC (the file name's 2020-02-06 18:14 is local time in California).
        let first_day = log.fixes[0].t_ns / NS_PER_DAY;
        assert_eq!(first_day, days_from_civil(2020, 2, 7));
        assert!(
            log.fixes
                .iter()
                .all(|f| (37.0..38.0).contains(&f.latitude_deg) && (-123.0..-122.0).contains(&f.longitude_deg))
        );
        // The file holds a handful of corrupted lines ($GGPGS...), skipped, not fatal.
        assert!(log.unparsable_lines + log.bad_checksum_lines > 0);
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]
        #[test]
        fn parser_never_panics(text in "\\\\PC{0,200}", cut in 0usize..160, flip in 0usize..160) {
            let _ = parse_nmea(Path::new("p.nmea"), &text);
            let mut valid = epoch("GN", "235959.99").into_bytes();
            if let Some(b) = valid.get_mut(flip) {
                *b = b.wrapping_add(1);
            }
            valid.truncate(cut.min(valid.len()));
            let _ = parse_nmea(Path::new("p.nmea"), &String::from_utf8_lossy(&valid));
        }
    }
}
