//! One line: framing and checksum, then the fields of GGA, RMC, GST and ZDA.
//!
//! Every parser here is total: it returns a value or says which field is
//! wrong and what was expected, and never panics, whatever the bytes.

use mmtrack_core::GnssFixQuality;

pub(super) use mmtrack_core::calendar::days_from_civil;
use mmtrack_core::plausible::{ALTITUDE_M, LATITUDE_DEG, LONGITUDE_DEG};

/// Nanoseconds in a day.
pub(super) const NS_PER_DAY: i64 = 86_400_000_000_000;

/// What a line is.
pub(super) enum Line<'a> {
    /// A standard sentence with a valid checksum: `$<talker:2><kind:3>,...`.
    Sentence {
        /// The address, e.g. `GNGGA`.
        id: &'a str,
        /// The sentence type, e.g. `GGA`.
        kind: &'a str,
        /// Comma-separated fields; `fields[0]` is the address.
        fields: Vec<&'a str>,
    },
    /// A proprietary sentence (`$P<maker>...`, e.g. u-blox `$PUBX`) with a valid checksum.
    Proprietary,
    /// Framed as a sentence, but the checksum does not match.
    BadChecksum,
    /// Not a sentence at all, and why.
    Junk(String),
}

/// Splits and checks one line (already trimmed of surrounding whitespace).
pub(super) fn split_sentence(line: &str) -> Line<'_> {
    if line.is_empty() {
        return Line::Junk("blank line".into());
    }
    let Some(body) = line.strip_prefix('$') else {
        return Line::Junk("does not start with '$'".into());
    };
    let Some((payload, checksum)) = body.rsplit_once('*') else {
        return Line::Junk("no '*' before a checksum (truncated?)".into());
    };
    let expected = match checksum.as_bytes() {
        [high, low] => match (hex_digit(*high), hex_digit(*low)) {
            (Some(high), Some(low)) => high << 4 | low,
            _ => return Line::Junk(format!("checksum '{}' is not two hex digits", checksum.escape_debug())),
        },
        _ => return Line::Junk(format!("checksum '{}' is not two hex digits", checksum.escape_debug())),
    };
    if payload.bytes().fold(0u8, |acc, b| acc ^ b) != expected {
        return Line::BadChecksum;
    }
    let fields: Vec<&str> = payload.split(',').collect();
    let id = fields.first().copied().unwrap_or("");
    if id.len() >= 2 && id.starts_with('P') && id.bytes().all(|b| b.is_ascii_alphanumeric()) {
        return Line::Proprietary;
    }
    if id.len() != 5 || !id.bytes().all(|b| b.is_ascii_uppercase()) {
        return Line::Junk(format!("address '{}' is not <talker:2><type:3> letters", id.escape_debug()));
    }
    Line::Sentence { id, kind: &id[2..], fields }
}

fn hex_digit(b: u8) -> Option<u8> {
    match b {
        b'0'..=b'9' => Some(b - b'0'),
        b'A'..=b'F' => Some(b - b'A' + 10),
        b'a'..=b'f' => Some(b - b'a' + 10),
        _ => None,
    }
}

/// A field that does not parse: which one, and what was expected.
#[derive(Debug)]
pub(super) struct FieldError {
    pub field: &'static str,
    pub detail: String,
}

fn field_error(field: &'static str, detail: String) -> FieldError {
    FieldError { field, detail }
}

/// Decimal value of a run of ASCII digits (at most 18, so it cannot overflow).
fn digits_value(text: &str) -> Option<i64> {
    if text.is_empty() || text.len() > 18 || !text.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    Some(text.bytes().fold(0i64, |acc, b| acc * 10 + i64::from(b - b'0')))
}

/// `hhmmss[.f...]` to nanoseconds since midnight, from the digits (exact to
/// the nanosecond; digits past the ninth are dropped). Second 60 is accepted
/// at 23:59 only (a leap second; its time of day is then a day or more).
pub(super) fn time_of_day_ns(text: &str) -> Option<i64> {
    let (whole, fraction) = text.split_once('.').unwrap_or((text, ""));
    if whole.len() != 6 {
        return None;
    }
    let (h, m, s) = (digits_value(whole.get(0..2)?)?, digits_value(whole.get(2..4)?)?, digits_value(whole.get(4..6)?)?);
    if h > 23 || m > 59 || s > 60 || (s == 60 && (h, m) != (23, 59)) {
        return None;
    }
    let mut sub_ns = 0i64;
    if !fraction.is_empty() {
        if !fraction.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let kept = fraction.get(..fraction.len().min(9))?;
        sub_ns = digits_value(kept)? * 10i64.pow(9 - kept.len() as u32);
    }
    Some(((h * 60 + m) * 60 + s) * 1_000_000_000 + sub_ns)
}

fn days_in_month(year: i64, month: i64) -> i64 {
    match month {
        2 if (year % 4 == 0 && year % 100 != 0) || year % 400 == 0 => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// RMC `ddmmyy` to days since the UNIX epoch; years 80-99 are 19xx, 00-79 are 20xx.
pub(super) fn date_days(text: &str) -> Option<i64> {
    if text.len() != 6 {
        return None;
    }
    let (d, m, y) = (digits_value(text.get(0..2)?)?, digits_value(text.get(2..4)?)?, digits_value(text.get(4..6)?)?);
    let year = if y >= 80 { 1900 + y } else { 2000 + y };
    if !(1..=12).contains(&m) || d < 1 || d > days_in_month(year, m) {
        return None;
    }
    Some(days_from_civil(year, m, d))
}

/// `ddmm.mmmm` (latitude, 2 degree digits) or `dddmm.mmmm` (longitude, 3)
/// with its hemisphere to signed degrees. Only digits and one point are
/// accepted, minutes must be below 60 and the result within `limit_deg`.
pub(super) fn coordinate_deg(value: &str, hemisphere: &str, degree_digits: usize, limit_deg: f64) -> Option<f64> {
    let degrees = digits_value(value.get(..degree_digits)?)?;
    let minutes_text = value.get(degree_digits..)?;
    let (minutes_whole, minutes_fraction) = minutes_text.split_once('.').unwrap_or((minutes_text, ""));
    if minutes_whole.len() != 2
        || !minutes_whole.bytes().all(|b| b.is_ascii_digit())
        || !minutes_fraction.bytes().all(|b| b.is_ascii_digit())
    {
        return None;
    }
    // Digits and at most one point: this parse cannot yield NaN or infinity.
    let minutes: f64 = minutes_text.parse().ok()?;
    if minutes >= 60.0 {
        return None;
    }
    let unsigned = degrees as f64 + minutes / 60.0;
    let signed = match hemisphere {
        "N" | "E" => unsigned,
        "S" | "W" => -unsigned,
        _ => return None,
    };
    (signed.is_finite() && signed.abs() <= limit_deg).then_some(signed)
}

/// A finite decimal number, or `None`.
fn finite(text: &str) -> Option<f64> {
    text.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Position part of a GGA that reports a fix.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct GgaPosition {
    pub latitude_deg: f64,
    pub longitude_deg: f64,
    /// Altitude above mean sea level (GGA field 9); `None` when the field is
    /// empty.
    pub altitude_msl_m: Option<f64>,
    /// Geoid separation (GGA field 11), ellipsoid minus mean sea level.
    pub geoid_separation_m: Option<f64>,
    pub num_satellites: Option<u32>,
}

/// A GGA sentence.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Gga {
    /// Time of day; may be empty only when there is no fix (receivers print
    /// `$GPGGA,,,,,,0,...` before they know the time).
    pub time_of_day_ns: Option<i64>,
    pub quality: GnssFixQuality,
    /// `None` exactly when `quality` is `NoFix`.
    pub position: Option<GgaPosition>,
}

fn get<'a>(fields: &[&'a str], index: usize) -> &'a str {
    fields.get(index).copied().unwrap_or("")
}

/// GGA: `time, lat, N|S, lon, E|W, quality, satellites, HDOP, altitude, M, separation, M, ...`.
pub(super) fn parse_gga(fields: &[&str]) -> Result<Gga, FieldError> {
    let quality = match get(fields, 6) {
        "0" => GnssFixQuality::NoFix,
        "1" => GnssFixQuality::Autonomous,
        "2" => GnssFixQuality::Differential,
        "4" => GnssFixQuality::RtkFixed,
        "5" => GnssFixQuality::RtkFloat,
        "6" => GnssFixQuality::DeadReckoning,
        _ => GnssFixQuality::Unknown,
    };
    let time_of_day_ns = utc_time_field(fields, quality == GnssFixQuality::NoFix)?;
    if quality == GnssFixQuality::NoFix {
        return Ok(Gga { time_of_day_ns, quality, position: None });
    }
    let latitude_deg = coordinate_deg(get(fields, 2), get(fields, 3), 2, LATITUDE_DEG.max).ok_or_else(|| {
        field_error("latitude", format!("'{},{}' is not ddmm.mm,N|S within 90 degrees", get(fields, 2), get(fields, 3)))
    })?;
    let longitude_deg = coordinate_deg(get(fields, 4), get(fields, 5), 3, LONGITUDE_DEG.max).ok_or_else(|| {
        field_error(
            "longitude",
            format!("'{},{}' is not dddmm.mm,E|W within 180 degrees", get(fields, 4), get(fields, 5)),
        )
    })?;
    // The first fix's altitude becomes the recording's map origin: bounded.
    let metres = |index: usize, field: &'static str| -> Result<Option<f64>, FieldError> {
        match get(fields, index) {
            "" => Ok(None),
            text => {
                let value = finite(text)
                    .ok_or_else(|| field_error(field, format!("'{text}' is not a finite number of metres")))?;
                ALTITUDE_M.check(value).map(Some).map_err(|e| field_error(field, e.to_string()))
            }
        }
    };
    let altitude_msl_m = metres(9, "altitude")?;
    let geoid_separation_m = metres(11, "geoid separation")?;
    Ok(Gga {
        time_of_day_ns,
        quality,
        position: Some(GgaPosition {
            latitude_deg,
            longitude_deg,
            altitude_msl_m,
            geoid_separation_m,
            num_satellites: get(fields, 7).parse().ok(),
        }),
    })
}

/// Position part of a valid RMC.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct RmcPosition {
    pub latitude_deg: f64,
    pub longitude_deg: f64,
    /// From the mode indicator (field 12, NMEA 2.3 and later): A autonomous,
    /// D differential, E dead reckoning, F RTK float, R RTK fixed; anything
    /// else, or no field, unknown.
    pub quality: GnssFixQuality,
}

/// An RMC sentence: what dating, validity and a fix without GGA need.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Rmc {
    /// Time of day; may be empty only without a fix.
    pub time_of_day_ns: Option<i64>,
    /// Status `A` (valid) and a mode other than `N` (not valid).
    pub valid: bool,
    /// Date, days since the UNIX epoch; may be empty only without a fix.
    pub days: Option<i64>,
    /// Where, exactly when `valid`.
    pub position: Option<RmcPosition>,
}

/// RMC: `time, status, lat, N|S, lon, E|W, speed, course, date, magnetic
/// variation, E|W, mode, ...`. Status `A` with mode `N` is no fix.
pub(super) fn parse_rmc(fields: &[&str]) -> Result<Rmc, FieldError> {
    let mode = get(fields, 12);
    let valid = match get(fields, 2) {
        "A" => mode != "N",
        "V" => false,
        other => return Err(field_error("status", format!("'{other}' is not A (valid) or V (no fix)"))),
    };
    let time_of_day_ns = utc_time_field(fields, !valid)?;
    let date_text = get(fields, 9);
    let days = match date_text {
        "" if !valid => None,
        _ => Some(date_days(date_text).ok_or_else(|| field_error("date", format!("'{date_text}' is not ddmmyy")))?),
    };
    if !valid {
        return Ok(Rmc { time_of_day_ns, valid, days, position: None });
    }
    let latitude_deg = coordinate_deg(get(fields, 3), get(fields, 4), 2, LATITUDE_DEG.max).ok_or_else(|| {
        field_error("latitude", format!("'{},{}' is not ddmm.mm,N|S within 90 degrees", get(fields, 3), get(fields, 4)))
    })?;
    let longitude_deg = coordinate_deg(get(fields, 5), get(fields, 6), 3, LONGITUDE_DEG.max).ok_or_else(|| {
        field_error(
            "longitude",
            format!("'{},{}' is not dddmm.mm,E|W within 180 degrees", get(fields, 5), get(fields, 6)),
        )
    })?;
    let quality = match mode {
        "A" => GnssFixQuality::Autonomous,
        "D" => GnssFixQuality::Differential,
        "E" => GnssFixQuality::DeadReckoning,
        "F" => GnssFixQuality::RtkFloat,
        "R" => GnssFixQuality::RtkFixed,
        _ => GnssFixQuality::Unknown,
    };
    Ok(Rmc { time_of_day_ns, valid, days, position: Some(RmcPosition { latitude_deg, longitude_deg, quality }) })
}

/// The UTC time of day of field 1 (`hhmmss[.ss]`, every sentence type
/// here), nanoseconds; `None` when the field is empty and `may_be_empty`
/// (a receiver without a fix, or before it knows the time).
fn utc_time_field(fields: &[&str], may_be_empty: bool) -> Result<Option<i64>, FieldError> {
    let time_text = get(fields, 1);
    if time_text.is_empty() && may_be_empty {
        return Ok(None);
    }
    time_of_day_ns(time_text)
        .map(Some)
        .ok_or_else(|| field_error("time", format!("'{time_text}' is not hhmmss[.ss] (UTC)")))
}

/// A GST sentence (pseudorange error statistics).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Gst {
    pub time_of_day_ns: Option<i64>,
    /// `sqrt((sigma_lat^2 + sigma_lon^2) / 2)`, when both are given.
    pub horizontal_sigma_m: Option<f64>,
}

/// GST: `time, rms, semi-major, semi-minor, orientation, sigma lat, sigma lon, sigma alt`.
pub(super) fn parse_gst(fields: &[&str]) -> Result<Gst, FieldError> {
    let time_of_day_ns = utc_time_field(fields, true)?;
    let sigma = |index: usize, field: &'static str| match get(fields, index) {
        "" => Ok(None),
        text => finite(text)
            .filter(|v| *v >= 0.0)
            .map(Some)
            .ok_or_else(|| field_error(field, format!("'{text}' is not a non-negative number of metres"))),
    };
    let horizontal_sigma_m = match (sigma(6, "latitude sigma")?, sigma(7, "longitude sigma")?) {
        (Some(lat), Some(lon)) => Some(((lat * lat + lon * lon) / 2.0).sqrt()),
        _ => None,
    };
    Ok(Gst { time_of_day_ns, horizontal_sigma_m })
}

/// A ZDA sentence (UTC time and date).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Zda {
    /// Time of day; empty before the receiver knows the time.
    pub time_of_day_ns: Option<i64>,
    /// Date, days since the UNIX epoch; `None` when the day, month and year
    /// fields are all empty.
    pub days: Option<i64>,
}

/// ZDA: `time, day (dd), month (mm), year (yyyy), local zone hours, local
/// zone minutes`. The time and date are UTC; the local zone is not used.
pub(super) fn parse_zda(fields: &[&str]) -> Result<Zda, FieldError> {
    let time_of_day_ns = utc_time_field(fields, true)?;
    let (day, month, year) = (get(fields, 2), get(fields, 3), get(fields, 4));
    let days = match (day, month, year) {
        ("", "", "") => None,
        _ => {
            let parsed = (day.len() == 2 && month.len() == 2 && year.len() == 4)
                .then(|| Some((digits_value(day)?, digits_value(month)?, digits_value(year)?)))
                .flatten()
                .filter(|&(d, m, y)| (1..=12).contains(&m) && d >= 1 && d <= days_in_month(y, m));
            let (d, m, y) = parsed.ok_or_else(|| {
                field_error("date", format!("'{day},{month},{year}' is not dd,mm,yyyy (a calendar date)"))
            })?;
            Some(days_from_civil(y, m, d))
        }
    };
    Ok(Zda { time_of_day_ns, days })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn framing_tells_checksums_from_junk() {
        assert!(matches!(split_sentence("$GNGLL,3725.58362,N,12205.61915,W,021417.00,A,D*66"), Line::Sentence { .. }));
        assert!(matches!(split_sentence("$GNGLL,3725.58362,N,12205.61915,W,021417.00,A,D*67"), Line::BadChecksum));
        // Lower-case hex is accepted; one digit, a sign or three digits are not a checksum.
        assert!(matches!(split_sentence("$GPRMC,,V,,,,,,,,,,N*53"), Line::Sentence { .. }));
        for junk in ["$GPRMC,,V,,,,,,,,,,N*5", "$GPRMC,,V,,,,,,,,,,N*+5", "$GPRMC,,V,,,,,,,,,,N*053", "GPRMC*53", ""] {
            assert!(matches!(split_sentence(junk), Line::Junk(_)), "{junk}");
        }
        // u-blox PUBX is proprietary, not junk.
        assert!(matches!(split_sentence("$PUBX,00*33"), Line::Proprietary));
    }

    #[test]
    fn time_date_and_coordinates_parse_from_digits() {
        assert_eq!(time_of_day_ns("000000"), Some(0));
        assert_eq!(time_of_day_ns("235959.999999999"), Some(NS_PER_DAY - 1));
        assert_eq!(time_of_day_ns("021417.1"), Some((2 * 3600 + 14 * 60 + 17) * 1_000_000_000 + 100_000_000));
        // An empty fraction ("021417.") is whole seconds.
        assert_eq!(time_of_day_ns("021417."), time_of_day_ns("021417"));
        assert_eq!(time_of_day_ns("235960.5"), Some(NS_PER_DAY + 500_000_000));
        for bad in ["", "2414", "240000", "026000", "021460", "0214+7", "021417.x", "021417.-1", "02141\u{ff17}"] {
            assert_eq!(time_of_day_ns(bad), None, "{bad}");
        }
        assert_eq!(date_days("010170"), Some(days_from_civil(2070, 1, 1)));
        assert_eq!(date_days("070220"), Some(18_299));
        assert_eq!(date_days("290224"), Some(days_from_civil(2024, 2, 29)));
        assert_eq!(date_days("290223"), None);
        assert_eq!(date_days("310499"), None);
        let lat = coordinate_deg("3725.58362", "N", 2, 90.0).unwrap();
        assert!((lat - (37.0 + 25.58362 / 60.0)).abs() < 1e-12);
        assert_eq!(coordinate_deg("00130.0", "W", 3, 180.0), Some(-1.5));
        assert_eq!(coordinate_deg("0030", "S", 2, 90.0), Some(-0.5));
        for (value, hemisphere) in
            [("37x5.58", "N"), ("-125.5", "N"), ("3760.0", "N"), ("9100.0", "N"), ("NaN", "N"), ("3725.5", "X")]
        {
            assert_eq!(coordinate_deg(value, hemisphere, 2, 90.0), None, "{value}");
        }
        assert_eq!(coordinate_deg("inf00.0", "E", 3, 180.0), None);
    }

    #[test]
    fn cold_start_sentences_without_time_are_no_fix() {
        let gga = parse_gga(&"GPGGA,,,,,,0,00,99.99,,,,,,".split(',').collect::<Vec<_>>()).unwrap();
        assert_eq!((gga.time_of_day_ns, gga.quality, gga.position), (None, GnssFixQuality::NoFix, None));
        let rmc = parse_rmc(&"GPRMC,,V,,,,,,,,,,N".split(',').collect::<Vec<_>>()).unwrap();
        assert_eq!(rmc, Rmc { time_of_day_ns: None, valid: false, days: None, position: None });
        // A valid RMC must carry its date.
        let err = parse_rmc(&"GPRMC,021417.00,A,3725.5,N,12205.6,W,0,0,,,,A".split(',').collect::<Vec<_>>());
        assert_eq!(err.unwrap_err().field, "date");
    }

    #[test]
    fn zda_gives_the_utc_date() {
        let fields = |text: &'static str| text.split(',').collect::<Vec<_>>();
        let zda = parse_zda(&fields("GNZDA,021417.00,07,02,2020,00,00")).unwrap();
        assert_eq!(zda, Zda { time_of_day_ns: time_of_day_ns("021417.00"), days: Some(days_from_civil(2020, 2, 7)) });
        // Before the receiver knows the time: nothing, not an error.
        assert_eq!(parse_zda(&fields("GNZDA,,,,,00,00")).unwrap(), Zda { time_of_day_ns: None, days: None });
        for bad in ["GNZDA,021417.00,30,02,2020,,", "GNZDA,021417.00,7,2,2020,,", "GNZDA,021417.00,07,02,20,,"] {
            assert_eq!(parse_zda(&fields(bad)).unwrap_err().field, "date", "{bad}");
        }
        assert_eq!(parse_zda(&fields("GNZDA,021460.00,07,02,2020,,")).unwrap_err().field, "time");
    }

    #[test]
    fn gst_gives_the_per_axis_rms_sigma() {
        let gst = parse_gst(&"GPGST,021417.00,1.2,0.5,0.3,45.0,0.3,0.4,0.9".split(',').collect::<Vec<_>>()).unwrap();
        assert!((gst.horizontal_sigma_m.unwrap() - (0.125f64).sqrt()).abs() < 1e-12);
        let gst = parse_gst(&"GPGST,021417.00,,,,,,,".split(',').collect::<Vec<_>>()).unwrap();
        assert_eq!(gst.horizontal_sigma_m, None);
        let err = parse_gst(&"GPGST,021417.00,1,1,1,0,-1,1,1".split(',').collect::<Vec<_>>()).unwrap_err();
        assert_eq!(err.field, "latitude sigma");
    }
}
