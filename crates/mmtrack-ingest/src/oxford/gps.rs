//! Oxford `gps/gps.csv`: the NovAtel GNSS fixes of a sequence.
//!
//! Columns: `timestamp` (UNIX microseconds), `num_satellites`, `latitude`,
//! `longitude` (degrees), `altitude` (metres), `latitude_sigma`,
//! `longitude_sigma`, `altitude_sigma` (metres, 1 sigma), `northing`,
//! `easting`, `down` (metres, UTM), `utm_zone`. Columns are found by name, so
//! their order does not matter; a missing one is an error naming it.
//!
//! `horizontal_sigma_m` is the RMS of the two horizontal sigmas,
//! `sqrt((sigma_lat^2 + sigma_lon^2) / 2)`: the per-axis 1-sigma a reader
//! would use for an isotropic horizontal covariance. Fix quality is not in the
//! file: fixes are marked `Unknown`.

use std::path::Path;

use mmtrack_core::plausible::{ALTITUDE_M, COORDINATE_M, LATITUDE_DEG, LONGITUDE_DEG};
use mmtrack_core::{GnssFix, GnssFixQuality};

use crate::IngestError;
use crate::csv::CsvTable;

/// One row: the fix and the UTM position the file also gives.
#[derive(Debug, Clone, PartialEq)]
pub struct OxfordGpsRow {
    /// The fix.
    pub fix: GnssFix,
    /// UTM northing, metres.
    pub northing_m: f64,
    /// UTM easting, metres.
    pub easting_m: f64,
}

const COLUMNS: [&str; 10] = [
    "timestamp",
    "num_satellites",
    "latitude",
    "longitude",
    "altitude",
    "latitude_sigma",
    "longitude_sigma",
    "altitude_sigma",
    "northing",
    "easting",
];

/// Parses `gps.csv` text. Rows must be in strictly increasing time.
pub fn parse_gps_csv(path: &Path, text: &str) -> Result<Vec<OxfordGpsRow>, IngestError> {
    let table = CsvTable::parse(path, text, &COLUMNS)?;
    let mut rows: Vec<OxfordGpsRow> = Vec::new();
    for row in table.rows() {
        let t_ns = row.micros_ns("timestamp")?;
        if let Some(previous) = rows.last()
            && t_ns <= previous.fix.t_ns
        {
            return Err(row.bad(
                "timestamp",
                format!("{} us does not increase (previous {} us)", t_ns / 1000, previous.fix.t_ns / 1000),
            ));
        }
        let satellites = row.text("num_satellites")?;
        let latitude_deg = row.bounded("latitude", &LATITUDE_DEG)?;
        let longitude_deg = row.bounded("longitude", &LONGITUDE_DEG)?;
        let (sigma_lat_m, sigma_lon_m) = (row.finite("latitude_sigma")?, row.finite("longitude_sigma")?);
        rows.push(OxfordGpsRow {
            fix: GnssFix {
                t_ns,
                latitude_deg,
                longitude_deg,
                altitude_m: Some(row.bounded("altitude", &ALTITUDE_M)?),
                horizontal_sigma_m: Some(((sigma_lat_m * sigma_lat_m + sigma_lon_m * sigma_lon_m) / 2.0).sqrt()),
                num_satellites: Some(
                    satellites
                        .parse()
                        .map_err(|_| row.bad("num_satellites", format!("'{satellites}' is not a count")))?,
                ),
                quality: GnssFixQuality::Unknown,
            },
            northing_m: row.bounded("northing", &COORDINATE_M)?,
            easting_m: row.bounded("easting", &COORDINATE_M)?,
        });
    }
    Ok(rows)
}

/// Reads `gps.csv`.
pub fn read_gps_csv(path: &Path) -> Result<Vec<OxfordGpsRow>, IngestError> {
    let text = crate::error::read_line_records(path)?;
    parse_gps_csv(path, &text)
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "timestamp,num_satellites,latitude,longitude,altitude,latitude_sigma,longitude_sigma,altitude_sigma,northing,easting,down,utm_zone";

    #[test]
    fn parses_a_row_and_combines_sigmas() {
        let text = format!(
            "{HEADER}\n0001547131010502681,7,51.762042,-1.262751,65.176138,0.6,0.8,0.955170,5736000.13,619890.11,-65.17,30U\n"
        );
        let rows = parse_gps_csv(Path::new("gps.csv"), &text).unwrap();
        assert_eq!(rows.len(), 1);
        assert_eq!(rows[0].fix.t_ns, 1_547_131_010_502_681_000);
        assert_eq!(rows[0].fix.num_satellites, Some(7));
        // sqrt((0.36 + 0.64) / 2) = sqrt(0.5)
        assert!((rows[0].fix.horizontal_sigma_m.unwrap() - 0.5f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn missing_column_nan_and_backwards_time_are_named() {
        let renamed = HEADER.replace("latitude_sigma", "lat_sigma");
        let err = parse_gps_csv(Path::new("gps.csv"), &format!("{renamed}\n")).unwrap_err().to_string();
        assert!(err.contains("latitude_sigma") && err.contains("missing column"), "{err}");

        let nan = format!("{HEADER}\n1,7,NaN,-1.2,65,0.6,0.8,0.9,1,2,3,30U\n");
        let err = parse_gps_csv(Path::new("gps.csv"), &nan).unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains("latitude"), "{err}");

        let backwards = format!("{HEADER}\n5,7,51,-1,65,0.6,0.8,0.9,1,2,3,30U\n4,7,51,-1,65,0.6,0.8,0.9,1,2,3,30U\n");
        let err = parse_gps_csv(Path::new("gps.csv"), &backwards).unwrap_err().to_string();
        assert!(err.contains("line 3") && err.contains("does not increase"), "{err}");
    }

    /// Before: latitude 200 and an altitude of 1e300 (which becomes the
    /// recording's map origin) were ingested.
    #[test]
    fn implausible_latitude_altitude_and_northing_are_refused() {
        let good = "1,7,51.76,-1.26,65,0.6,0.8,0.9,5736000,619890,-65,30U";
        for (bad, field) in [
            (good.replace("51.76", "200"), "latitude: 200 is not a latitude within [-90, 90] deg"),
            (good.replace(",65,", ",1e300,"), "altitude: 1e300 is not an altitude"),
            (good.replace("5736000", "1e300"), "northing: 1e300 is not a coordinate"),
        ] {
            let err = parse_gps_csv(Path::new("gps.csv"), &format!("{HEADER}\n{bad}\n")).unwrap_err().to_string();
            assert!(err.starts_with(&format!("gps.csv: line 2: {field}")), "{err}");
        }
        assert!(parse_gps_csv(Path::new("gps.csv"), &format!("{HEADER}\n{good}\n")).is_ok());
    }
}
