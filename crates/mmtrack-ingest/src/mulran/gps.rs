//! MulRan `sensor_data/gps.csv`: the GPS fixes of a sequence.
//!
//! No header; 13 comma-separated fields per line, as the MulRan file player
//! publishes them as `sensor_msgs/NavSatFix`: time (UNIX nanoseconds),
//! latitude and longitude (degrees), altitude (metres), then the 3 x 3
//! position covariance (m^2, row major, east-north-up as in `NavSatFix`).
//!
//! `horizontal_sigma_m` is `sqrt((c_ee + c_nn) / 2)`, the per-axis 1-sigma of
//! an isotropic horizontal covariance; it is left out when the covariance is
//! all zero (unknown). The file gives no fix quality or satellite count.

use std::path::Path;

use mmtrack_core::plausible::{ALTITUDE_M, LATITUDE_DEG, LONGITUDE_DEG};
use mmtrack_core::{GnssFix, GnssFixQuality};

use crate::IngestError;
use crate::error::check_plausible;

/// Fields per line.
const FIELDS: usize = 13;
/// Field names, for errors.
const NAMES: [&str; 4] = ["timestamp", "latitude", "longitude", "altitude"];

/// Parses `gps.csv` text. Times must increase strictly; an empty file is an
/// error.
pub fn parse_mulran_gps(path: &Path, text: &str) -> Result<Vec<GnssFix>, IngestError> {
    let mut fixes: Vec<GnssFix> = Vec::new();
    for (index, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let number = index + 1;
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != FIELDS {
            return Err(IngestError::bad_line(
                path,
                number,
                "line",
                format!(
                    "{} fields; expected {FIELDS} (t_ns, latitude, longitude, altitude, 9 covariance values)",
                    fields.len()
                ),
            ));
        }
        let t_ns = fields[0].parse::<i64>().ok().filter(|t| *t > 0).ok_or_else(|| {
            IngestError::bad_line(path, number, NAMES[0], format!("'{}' is not a nanosecond UNIX time", fields[0]))
        })?;
        if let Some(previous) = fixes.last()
            && t_ns <= previous.t_ns
        {
            return Err(IngestError::bad_line(
                path,
                number,
                NAMES[0],
                format!("{t_ns} ns does not increase (previous {} ns)", previous.t_ns),
            ));
        }
        let value = |i: usize, name: &str| {
            fields[i].parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                IngestError::bad_line(path, number, name, format!("'{}' is not a finite number", fields[i]))
            })
        };
        let record = || format!("line {number}");
        let latitude_deg = check_plausible(path, record, NAMES[1], &LATITUDE_DEG, value(1, NAMES[1])?)?;
        let longitude_deg = check_plausible(path, record, NAMES[2], &LONGITUDE_DEG, value(2, NAMES[2])?)?;
        let altitude_m = check_plausible(path, record, NAMES[3], &ALTITUDE_M, value(3, NAMES[3])?)?;
        let mut covariance = [0.0; 9];
        for (k, c) in covariance.iter_mut().enumerate() {
            *c = value(4 + k, &format!("covariance[{k}]"))?;
        }
        let horizontal = (covariance[0] + covariance[4]) / 2.0;
        if horizontal < 0.0 {
            return Err(IngestError::bad_line(
                path,
                number,
                "covariance",
                format!("negative horizontal variance {horizontal} m^2"),
            ));
        }
        fixes.push(GnssFix {
            t_ns,
            latitude_deg,
            longitude_deg,
            altitude_m: Some(altitude_m),
            horizontal_sigma_m: covariance.iter().any(|c| *c != 0.0).then(|| horizontal.sqrt()),
            num_satellites: None,
            quality: GnssFixQuality::Unknown,
        });
    }
    if fixes.is_empty() {
        return Err(IngestError::BadLayout { path: path.to_path_buf(), detail: "no fixes (empty file)".into() });
    }
    Ok(fixes)
}

/// Reads `gps.csv`.
pub fn read_mulran_gps(path: &Path) -> Result<Vec<GnssFix>, IngestError> {
    let text = crate::error::read_line_records(path)?;
    parse_mulran_gps(path, &text)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ROW: &str = "1566279371523590000,37.4,127.1,82.5,4.0,0,0,0,2.25,0,0,0,9.0";

    #[test]
    fn parses_a_fix_and_its_horizontal_sigma() {
        let fixes = parse_mulran_gps(Path::new("gps.csv"), &format!("{ROW}\n")).unwrap();
        assert_eq!(fixes.len(), 1);
        assert_eq!(fixes[0].t_ns, 1_566_279_371_523_590_000);
        assert_eq!((fixes[0].latitude_deg, fixes[0].longitude_deg, fixes[0].altitude_m), (37.4, 127.1, Some(82.5)));
        // sqrt((4 + 2.25) / 2)
        assert!((fixes[0].horizontal_sigma_m.unwrap() - 3.125f64.sqrt()).abs() < 1e-12);
        let unknown = parse_mulran_gps(Path::new("gps.csv"), "5,37.4,127.1,82.5,0,0,0,0,0,0,0,0,0\n").unwrap();
        assert_eq!(unknown[0].horizontal_sigma_m, None);
    }

    #[test]
    fn bad_lines_are_named() {
        let err = |text: &str| parse_mulran_gps(Path::new("gps.csv"), text).unwrap_err().to_string();
        let short = err("1566279371523590000,37.4,127.1\n");
        assert!(short.contains("line 1") && short.contains("3 fields"), "{short}");
        let nan = err(&format!("{ROW}\n1566279371623590000,NaN,127.1,82.5,0,0,0,0,0,0,0,0,0\n"));
        assert!(nan.contains("line 2") && nan.contains("latitude"), "{nan}");
        let backwards = err(&format!("{ROW}\n{ROW}\n"));
        assert!(backwards.contains("line 2") && backwards.contains("does not increase"), "{backwards}");
        let radians = err("5,0.65,2.2,82.5,0,0,0,0,0,0,0,0,0\n6,91,2.2,82.5,0,0,0,0,0,0,0,0,0\n");
        assert!(radians.contains("line 2: latitude: 91 is not a latitude within [-90, 90] deg"), "{radians}");
        for empty in ["", "\n \n"] {
            let message = err(empty);
            assert!(message.contains("gps.csv") && message.contains("no fixes"), "{message}");
        }
    }
}
