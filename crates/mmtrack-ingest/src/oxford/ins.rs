//! Oxford `gps/ins.csv`: the NovAtel GNSS/INS solution of a sequence.
//!
//! Columns (found by name): `timestamp` (UNIX microseconds), `ins_status`,
//! `latitude`, `longitude` (degrees), `altitude` (metres), `northing`,
//! `easting`, `down` (metres, UTM), `utm_zone`, `velocity_north`,
//! `velocity_east`, `velocity_down` (m/s), `roll`, `pitch`, `yaw` (radians).
//!
//! Each row gives two things the recording can hold:
//! - a GNSS fix (latitude, longitude, altitude; no sigma or satellite count in
//!   the file, quality `Unknown`);
//! - a planar pose: the SDK builds the INS pose in north-east-down
//!   (`[northing, easting, down, roll, pitch, yaw]`), so yaw turns clockwise
//!   from north seen from above. mmtrack is z up: the pose is placed in a
//!   local east-north frame about the first kept row's UTM position, with
//!   `x = easting - e0`, `y = northing - n0` and `yaw = pi/2 - yaw_ned`
//!   (counter-clockwise from east).
//!
//! Only rows whose `ins_status` is `INS_SOLUTION_GOOD` are kept; the others
//! (aligning, inactive, bad GPS agreement) are counted, not used.

use std::f64::consts::FRAC_PI_2;
use std::path::Path;

use mmtrack_core::plausible::{ALTITUDE_M, ANGLE_RAD, COORDINATE_M, LATITUDE_DEG, LONGITUDE_DEG};
use mmtrack_core::{GnssFix, GnssFixQuality, Se2, StampedPose};

use crate::IngestError;
use crate::csv::CsvTable;

/// The usable rows of an `ins.csv`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct InsSolution {
    /// Position fixes.
    pub fixes: Vec<GnssFix>,
    /// `world_from_vehicle` in a local east-north frame about `origin`.
    pub poses: Vec<StampedPose>,
    /// The first kept row's UTM (easting, northing, up = -down), metres.
    pub origin: [f64; 3],
    /// The first kept row's UTM zone.
    pub utm_zone: String,
    /// Rows skipped because their status is not `INS_SOLUTION_GOOD`.
    pub skipped_not_good: u64,
}

const COLUMNS: [&str; 9] =
    ["timestamp", "ins_status", "latitude", "longitude", "altitude", "northing", "easting", "down", "yaw"];

/// Parses `ins.csv` text. Rows must be in strictly increasing time.
pub fn parse_ins_csv(path: &Path, text: &str) -> Result<InsSolution, IngestError> {
    let table = CsvTable::parse(path, text, &COLUMNS)?;
    let mut out = InsSolution::default();
    let mut last_t_ns = None;
    for row in table.rows() {
        let t_ns = row.micros_ns("timestamp")?;
        if let Some(previous) = last_t_ns
            && t_ns <= previous
        {
            return Err(
                row.bad("timestamp", format!("{} us does not increase (previous {} us)", t_ns / 1000, previous / 1000))
            );
        }
        last_t_ns = Some(t_ns);
        if row.text("ins_status")? != "INS_SOLUTION_GOOD" {
            out.skipped_not_good += 1;
            continue;
        }
        let (latitude_deg, longitude_deg) =
            (row.bounded("latitude", &LATITUDE_DEG)?, row.bounded("longitude", &LONGITUDE_DEG)?);
        out.fixes.push(GnssFix {
            t_ns,
            latitude_deg,
            longitude_deg,
            altitude_m: Some(row.bounded("altitude", &ALTITUDE_M)?),
            horizontal_sigma_m: None,
            num_satellites: None,
            quality: GnssFixQuality::Unknown,
        });
        let (east, north, up) = (
            row.bounded("easting", &COORDINATE_M)?,
            row.bounded("northing", &COORDINATE_M)?,
            -row.bounded("down", &COORDINATE_M)?,
        );
        if out.poses.is_empty() {
            out.origin = [east, north, up];
            out.utm_zone = if table.has("utm_zone") { row.text("utm_zone")?.to_string() } else { String::new() };
        }
        let yaw_ned = row.bounded("yaw", &ANGLE_RAD)?;
        out.poses.push(StampedPose {
            t_ns,
            parent_from_child: Se2::new(east - out.origin[0], north - out.origin[1], FRAC_PI_2 - yaw_ned),
        });
    }
    Ok(out)
}

/// Reads `ins.csv`.
pub fn read_ins_csv(path: &Path) -> Result<InsSolution, IngestError> {
    let text = crate::error::read_line_records(path)?;
    parse_ins_csv(path, &text)
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "timestamp,ins_status,latitude,longitude,altitude,northing,easting,down,utm_zone,velocity_north,velocity_east,velocity_down,roll,pitch,yaw";

    /// A row driving at 10 m/s on a NED yaw `yaw` (clockwise from north), so
    /// its velocity is (north, east) = 10 (cos yaw, sin yaw).
    fn row(t_us: i64, status: &str, north: f64, east: f64, yaw: f64) -> String {
        let (vn, ve) = (10.0 * yaw.cos(), 10.0 * yaw.sin());
        format!("{t_us},{status},51.76,-1.26,110.5,{north},{east},-110.5,30U,{vn},{ve},0,0.01,0.02,{yaw}\n")
    }

    #[test]
    fn good_rows_become_fixes_and_enu_poses_whose_yaw_follows_the_velocity() {
        let text = format!(
            "{HEADER}\n{}{}{}",
            row(1_547_131_000_000_000, "INS_ALIGNING", 5_735_990.0, 619_880.0, 0.0),
            row(1_547_131_000_020_000, "INS_SOLUTION_GOOD", 5_736_000.0, 619_890.0, 0.5),
            row(1_547_131_000_040_000, "INS_SOLUTION_GOOD", 5_736_000.2, 619_890.1, 0.5),
        );
        let ins = parse_ins_csv(Path::new("ins.csv"), &text).unwrap();
        assert_eq!((ins.fixes.len(), ins.poses.len(), ins.skipped_not_good), (2, 2, 1));
        assert_eq!(ins.origin, [619_890.0, 5_736_000.0, 110.5]);
        assert_eq!(ins.utm_zone, "30U");
        assert_eq!(ins.fixes[0].t_ns, 1_547_131_000_020_000_000);
        let p = ins.poses[1].parent_from_child;
        // UTM differences of the literals, to float rounding of 6e6-sized numbers.
        assert!((p.x_m - 0.1).abs() < 1e-6 && (p.y_m - 0.2).abs() < 1e-6, "{p:?}");
        // The ENU yaw points along the ENU velocity (east, north) = 10 (sin 0.5, cos 0.5).
        let travel = (10.0 * 0.5f64.cos()).atan2(10.0 * 0.5f64.sin());
        assert!((p.yaw_rad - travel).abs() < 1e-12, "{} vs {travel}", p.yaw_rad);
    }

    #[test]
    fn missing_column_nan_and_backwards_time_are_named() {
        let path = Path::new("ins.csv");
        let err = parse_ins_csv(path, &format!("{}\n", HEADER.replace("yaw", "heading"))).unwrap_err().to_string();
        assert!(err.contains("ins.csv") && err.contains("yaw") && err.contains("missing column"), "{err}");
        let nan = format!("{HEADER}\n{}", row(5, "INS_SOLUTION_GOOD", 1.0, 2.0, 0.1).replace("51.76", "NaN"));
        let err = parse_ins_csv(path, &nan).unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains("latitude"), "{err}");
        let backwards = format!(
            "{HEADER}\n{}{}",
            row(5, "INS_SOLUTION_GOOD", 1.0, 2.0, 0.1),
            row(4, "INS_SOLUTION_GOOD", 1.0, 2.0, 0.1)
        );
        let err = parse_ins_csv(path, &backwards).unwrap_err().to_string();
        assert!(err.contains("line 3") && err.contains("does not increase"), "{err}");
        let inf = format!("{HEADER}\n{}", row(5, "INS_SOLUTION_GOOD", 1.0, 2.0, f64::INFINITY));
        let err = parse_ins_csv(path, &inf).unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains("yaw"), "{err}");
    }

    #[test]
    fn an_oxford_folder_takes_ins_for_whatever_it_lacks() {
        use mmtrack_io::recording::PoseStream;
        use mmtrack_io::{RecordingEvent, RecordingOptions, RecordingReader};

        use super::super::tests::{T0_US, scan_folder};

        let dir = tempfile::tempdir().unwrap();
        let layout = scan_folder(dir.path(), 3);
        std::fs::create_dir(dir.path().join("gps")).unwrap();
        let mut text = format!("{HEADER}\n");
        for i in 0..5 {
            let status = if i == 0 { "INS_ALIGNING" } else { "INS_SOLUTION_GOOD" };
            text.push_str(&row(T0_US + i * 125_000, status, 5_736_000.0 + i as f64, 619_890.0, 0.0));
        }
        std::fs::write(dir.path().join("gps/ins.csv"), text).unwrap();

        let folder = super::super::OxfordFolder::open(dir.path()).unwrap();
        let options = super::super::OxfordOptions { layout, ..super::super::OxfordOptions::default() };
        let out = dir.path().join("rec.mcap");
        let report =
            super::super::ingest_oxford(&folder, &out, &options, &RecordingOptions::default(), &mut |_, _| {}).unwrap();
        assert_eq!(report.ins_used_as.as_deref(), Some("ground truth and GNSS fixes"));
        assert_eq!((report.ground_truth_poses, report.gnss_fixes, report.ins_rows_not_good), (4, 4, 1));
        let mut reader = RecordingReader::open(&out).unwrap();
        let poses: Vec<_> = reader
            .by_ref()
            .filter_map(|e| match e.unwrap() {
                RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } => Some(pose),
                _ => None,
            })
            .collect();
        // Driving north (NED yaw 0): ENU yaw pi/2, one metre of northing per row.
        assert_eq!(poses[3].parent_from_child.y_m, 3.0);
        assert!((poses[3].parent_from_child.yaw_rad - FRAC_PI_2).abs() < 1e-12);
        assert_eq!(reader.metadata().unwrap()["ground_truth.origin_north_m"], "5736001");
    }
}
