//! Boreas `applanix/gps_post_process.csv`: the post-processed Applanix
//! GNSS/INS solution at 200 Hz, read here as GNSS fixes.
//!
//! Header line, columns found by name: `GPSTime` (UNIX time in seconds, with
//! a fraction), `latitude` and `longitude` in **radians** (converted to
//! degrees), `altitude` (metres); the other columns (ENU position, velocity,
//! attitude, rates) are not needed for fixes. The solution gives no accuracy,
//! satellite count or fix type: fixes are marked `Unknown` without a sigma.

use std::path::Path;

use mmtrack_core::plausible::ALTITUDE_M;
use mmtrack_core::{GnssFix, GnssFixQuality};

use crate::IngestError;
use crate::csv::CsvTable;

const COLUMNS: [&str; 4] = ["GPSTime", "latitude", "longitude", "altitude"];

/// Decimal seconds (`1606417097.528152`) to nanoseconds, exactly.
fn seconds_to_ns(text: &str) -> Option<i64> {
    let (whole, fraction) = text.split_once('.').unwrap_or((text, ""));
    if whole.is_empty() || fraction.len() > 9 || !fraction.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let seconds: i64 = whole.parse().ok().filter(|s| *s > 0)?;
    let nanos: i64 = if fraction.is_empty() { 0 } else { format!("{fraction:0<9}").parse().ok()? };
    seconds.checked_mul(1_000_000_000)?.checked_add(nanos)
}

/// Parses `gps_post_process.csv` text. Times must increase strictly.
pub fn parse_boreas_gps(path: &Path, text: &str) -> Result<Vec<GnssFix>, IngestError> {
    let table = CsvTable::parse(path, text, &COLUMNS)?;
    let mut fixes: Vec<GnssFix> = Vec::new();
    for row in table.rows() {
        let raw = row.text("GPSTime")?;
        let t_ns = seconds_to_ns(raw)
            .ok_or_else(|| row.bad("GPSTime", format!("'{raw}' is not a UNIX time in decimal seconds")))?;
        if let Some(previous) = fixes.last()
            && t_ns <= previous.t_ns
        {
            return Err(row.bad("GPSTime", format!("{raw} s does not increase (previous {} ns)", previous.t_ns)));
        }
        let (latitude_rad, longitude_rad) = (row.finite("latitude")?, row.finite("longitude")?);
        if latitude_rad.abs() > std::f64::consts::FRAC_PI_2 || longitude_rad.abs() > std::f64::consts::PI {
            return Err(row.bad(
                "latitude/longitude",
                format!("({latitude_rad}, {longitude_rad}) is not a geodetic position in radians (degrees given?)"),
            ));
        }
        fixes.push(GnssFix {
            t_ns,
            latitude_deg: latitude_rad.to_degrees(),
            longitude_deg: longitude_rad.to_degrees(),
            altitude_m: Some(row.bounded("altitude", &ALTITUDE_M)?),
            horizontal_sigma_m: None,
            num_satellites: None,
            quality: GnssFixQuality::Unknown,
        });
    }
    Ok(fixes)
}

/// Reads `gps_post_process.csv`.
pub fn read_boreas_gps(path: &Path) -> Result<Vec<GnssFix>, IngestError> {
    let text = crate::error::read_line_records(path)?;
    parse_boreas_gps(path, &text)
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "GPSTime,easting,northing,altitude,vel_east,vel_north,vel_up,roll,pitch,heading,angvel_z,angvel_y,angvel_x,accelz,accely,accelx,latitude,longitude";

    #[test]
    fn parses_radians_and_decimal_seconds_exactly() {
        let text = format!(
            "{HEADER}\n1606417097.528152,1.5,2.5,173.2,0,0,0,0,0,0,0,0,0,0,0,0,0.7641224,-1.3869569\n1606417097.533152,1.5,2.5,173.2,0,0,0,0,0,0,0,0,0,0,0,0,0.7641224,-1.3869569\n"
        );
        let fixes = parse_boreas_gps(Path::new("gps_post_process.csv"), &text).unwrap();
        assert_eq!(fixes.len(), 2);
        assert_eq!(fixes[0].t_ns, 1_606_417_097_528_152_000);
        assert_eq!(fixes[1].t_ns - fixes[0].t_ns, 5_000_000);
        assert!((fixes[0].latitude_deg - 43.780_988_551).abs() < 1e-8, "{}", fixes[0].latitude_deg);
        assert!((fixes[0].longitude_deg + 79.466_776_737).abs() < 1e-8, "{}", fixes[0].longitude_deg);
        assert_eq!(fixes[0].altitude_m, Some(173.2));
    }

    #[test]
    fn bad_rows_are_named() {
        let err = |text: String| parse_boreas_gps(Path::new("gps_post_process.csv"), &text).unwrap_err().to_string();
        let missing = err(format!("{}\n", HEADER.replace("latitude", "lat")));
        assert!(missing.contains("latitude") && missing.contains("missing column"), "{missing}");
        let degrees = err(format!("{HEADER}\n1606417097.5,0,0,173,0,0,0,0,0,0,0,0,0,0,0,0,43.78,-79.46\n"));
        assert!(degrees.contains("line 2") && degrees.contains("radians"), "{degrees}");
        let time = err(format!("{HEADER}\n1606417097.5e3,0,0,173,0,0,0,0,0,0,0,0,0,0,0,0,0.76,-1.38\n"));
        assert!(time.contains("line 2") && time.contains("GPSTime"), "{time}");
        let nan = err(format!("{HEADER}\n1606417097.5,0,0,NaN,0,0,0,0,0,0,0,0,0,0,0,0,0.76,-1.38\n"));
        assert!(nan.contains("line 2") && nan.contains("altitude"), "{nan}");
    }
}
