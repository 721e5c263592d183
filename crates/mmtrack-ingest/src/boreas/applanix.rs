//! Boreas `applanix/<sensor>_poses.csv`: the post-processed Applanix pose of
//! one sensor frame at each of that sensor's scans.
//!
//! Header, as the dataset ships it (checked on the pyboreas demo files):
//! `GPSTime,easting,northing,altitude,vel_east,vel_north,vel_up,roll,pitch,heading,angvel_z,angvel_y,angvel_x`.
//! `GPSTime` is, despite its name, UNIX time in microseconds and equals the
//! scan file names; newer files give nanoseconds instead, which pyboreas reads
//! too. The unit is told by the number of digits (see [`unix_time_ns`]).
//! The pyboreas reference describes the same columns as
//! `t, x, y, z, ...` in its fixed ENU frame, so `timestamp`/`t` and `x, y, z`
//! are accepted as well; columns are found by name.
//!
//! Orientation: pyboreas builds the sensor's rotation (sensor to ENU) as
//! `C = roll(r) pitch(p) yaw(y)` with UTIAS's frame-rotation matrices
//! (`yaw(y) = [[cos y, sin y, 0], [-sin y, cos y, 0], [0, 0, 1]]`, and likewise
//! for roll about x and pitch about y). The planar pose keeps the direction of
//! the sensor's x axis, the first column of `C`:
//! `C00 = cos p cos y`, `C10 = -cos r sin y + sin r sin p cos y`, so
//! `yaw_rad = atan2(C10, C00)`. For the radar, whose frame has z down
//! (`roll` ~ pi in the files), this is `heading` itself; with `roll` ~ 0 it is
//! `-heading`. Checked on the demo `radar_poses.csv`: while driving, `heading`
//! agrees with the direction of travel `atan2(vel_north, vel_east)` to about
//! 0.01 rad.
//!
//! Positions: each pose is placed in a local frame whose origin is the first
//! row's position (axes east, north), so the numbers stay small; the origin is
//! returned for the recording metadata.

use std::path::Path;

use mmtrack_core::plausible::{ANGLE_RAD, COORDINATE_M};
use mmtrack_core::{Se2, StampedPose};

use crate::IngestError;
use crate::csv::{CsvRow, CsvTable};

/// Poses in a local east-north frame and where that frame's origin is.
#[derive(Debug, Clone, PartialEq)]
pub struct ApplanixPoses {
    /// `world_from_sensor`, world = east/north axes about `origin`.
    pub poses: Vec<StampedPose>,
    /// The first row's (east, north, up) position in the file's own frame, metres.
    pub origin: [f64; 3],
    /// The file's position frame: `utm` (easting/northing/altitude) or `enu_ref` (x/y/z).
    pub position_frame: &'static str,
}

const TIME_COLUMNS: [&str; 3] = ["GPSTime", "timestamp", "t"];
const UTM_COLUMNS: [&str; 3] = ["easting", "northing", "altitude"];
const ENU_COLUMNS: [&str; 3] = ["x", "y", "z"];

fn missing(path: &Path, field: &str, expected: &str) -> IngestError {
    IngestError::BadRecord {
        path: path.to_path_buf(),
        record: "line 1 (header)".into(),
        field: field.into(),
        detail: format!("missing column; expected {expected}"),
    }
}

/// A UNIX time in microseconds or nanoseconds, as nanoseconds, told apart by
/// its number of digits: up to 16 digits is microseconds (16 digits span
/// 2001-09-09 to 2286-11-20), exactly 19 digits is nanoseconds (the same
/// years). 17 or 18 digits are refused: as microseconds they would be after
/// the year 5138, as nanoseconds before 1973-03-03. Only plain positive
/// integers are accepted.
#[must_use]
pub fn unix_time_ns(text: &str) -> Option<i64> {
    if text.is_empty() || !text.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let value: i64 = text.parse().ok()?;
    let digits = text.trim_start_matches('0').len();
    let t_ns = match digits {
        0..=16 => value.checked_mul(1000)?,
        19 => value,
        _ => return None,
    };
    (t_ns > 0).then_some(t_ns)
}

fn row_time_ns(row: &CsvRow<'_>, column: &str) -> Result<i64, IngestError> {
    let raw = row.text(column)?;
    unix_time_ns(raw).ok_or_else(|| {
        row.bad(
            column,
            format!("'{raw}' is not a UNIX time in microseconds (up to 16 digits) or nanoseconds (19 digits)"),
        )
    })
}

/// Planar yaw of the sensor's x axis from pyboreas's (roll, pitch, heading);
/// `None` when the x axis points straight up or down.
#[must_use]
pub fn planar_yaw_rad(roll_rad: f64, pitch_rad: f64, heading_rad: f64) -> Option<f64> {
    let (sr, cr) = roll_rad.sin_cos();
    let (sp, cp) = pitch_rad.sin_cos();
    let (sy, cy) = heading_rad.sin_cos();
    let (c00, c10) = (cp * cy, -cr * sy + sr * sp * cy);
    (c00.hypot(c10) > 1e-9).then(|| c10.atan2(c00))
}

fn row_pose(row: &CsvRow<'_>, position: &[&str; 3]) -> Result<([f64; 3], f64), IngestError> {
    let xyz = [
        row.bounded(position[0], &COORDINATE_M)?,
        row.bounded(position[1], &COORDINATE_M)?,
        row.bounded(position[2], &COORDINATE_M)?,
    ];
    let (roll, pitch) = (row.bounded("roll", &ANGLE_RAD)?, row.bounded("pitch", &ANGLE_RAD)?);
    let heading = row.bounded("heading", &ANGLE_RAD)?;
    let yaw_rad = planar_yaw_rad(roll, pitch, heading).ok_or_else(|| {
        row.bad("pitch", format!("{pitch} rad points the x axis straight up or down: no planar heading"))
    })?;
    Ok((xyz, yaw_rad))
}

/// Parses a poses CSV. Rows must be in strictly increasing time.
pub fn parse_applanix_poses(path: &Path, text: &str) -> Result<ApplanixPoses, IngestError> {
    let table = CsvTable::parse(path, text, &["roll", "pitch", "heading"])?;
    let time = *TIME_COLUMNS
        .iter()
        .find(|c| table.has(c))
        .ok_or_else(|| missing(path, "GPSTime", "GPSTime (or timestamp, t) in UNIX microseconds or nanoseconds"))?;
    let (position, position_frame) = if UTM_COLUMNS.iter().all(|c| table.has(c)) {
        (UTM_COLUMNS, "utm")
    } else if ENU_COLUMNS.iter().all(|c| table.has(c)) {
        (ENU_COLUMNS, "enu_ref")
    } else {
        let absent = UTM_COLUMNS.iter().find(|c| !table.has(c)).copied().unwrap_or("easting");
        return Err(missing(path, absent, "easting, northing, altitude (or x, y, z)"));
    };
    let mut poses: Vec<StampedPose> = Vec::new();
    let mut origin = None;
    for row in table.rows() {
        let t_ns = row_time_ns(&row, time)?;
        if let Some(previous) = poses.last()
            && t_ns <= previous.t_ns
        {
            return Err(row.bad(time, format!("{t_ns} ns does not increase (previous {} ns)", previous.t_ns)));
        }
        let (xyz, yaw_rad) = row_pose(&row, &position)?;
        let origin = *origin.get_or_insert(xyz);
        poses.push(StampedPose { t_ns, parent_from_child: Se2::new(xyz[0] - origin[0], xyz[1] - origin[1], yaw_rad) });
    }
    let origin = origin.ok_or_else(|| IngestError::BadLayout {
        path: path.to_path_buf(),
        detail: "no pose rows after the header".into(),
    })?;
    Ok(ApplanixPoses { poses, origin, position_frame })
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str =
        "GPSTime,easting,northing,altitude,vel_east,vel_north,vel_up,roll,pitch,heading,angvel_z,angvel_y,angvel_x";

    #[test]
    fn rows_become_local_poses_with_the_first_as_origin() {
        // A radar frame (z down, roll ~ pi) driving east-north-east: heading
        // 0.17 rad, velocity (3.9, 0.67) m/s points at atan2(0.67, 3.9) = 0.17 rad.
        let text = format!(
            "{HEADER}\n1630597345560134,623450.5,4848823.0,154.5,3.9,0.67,0.1,3.1248,0.029,0.17,0,0,0\n\
             1630597345810747,623451.5,4848823.25,154.6,3.9,0.67,0.1,3.1278,0.029,0.17,0,0,0\n"
        );
        let parsed = parse_applanix_poses(Path::new("radar_poses.csv"), &text).unwrap();
        assert_eq!(parsed.position_frame, "utm");
        assert_eq!(parsed.origin, [623450.5, 4848823.0, 154.5]);
        assert_eq!(parsed.poses[0].t_ns, 1_630_597_345_560_134_000);
        let second = parsed.poses[1].parent_from_child;
        assert_eq!((second.x_m, second.y_m), (1.0, 0.25));
        // With roll near pi and a small pitch, the x axis yaw is the heading up
        // to sin(roll) sin(pitch) cos(heading) ~ 5e-4 rad.
        assert!((second.yaw_rad - 0.17).abs() < 1e-3, "{}", second.yaw_rad);
        assert!((second.yaw_rad - 0.67f64.atan2(3.9)).abs() < 0.01);
    }

    #[test]
    fn nanosecond_gps_time_is_read_by_its_magnitude() {
        let row = ",623450.5,4848823.0,154.5,3.9,0.67,0.1,3.1248,0.029,0.17,0,0,0";
        let path = Path::new("radar_poses.csv");
        let parse = |t: &str| parse_applanix_poses(path, &format!("{HEADER}\n{t}{row}\n"));
        // 16 digits: microseconds; 19 digits: nanoseconds (as pyboreas reads newer files).
        assert_eq!(parse("1630597345560134").unwrap().poses[0].t_ns, 1_630_597_345_560_134_000);
        assert_eq!(parse("1630597345560134123").unwrap().poses[0].t_ns, 1_630_597_345_560_134_123);
        // 17 and 18 digits are neither a microsecond time before the year
        // 5138 nor a nanosecond time after 1973: refused, naming the rule.
        for t in ["16305973455601341", "163059734556013412", "-1630597345560134", "1.5e15"] {
            let err = parse(t).unwrap_err().to_string();
            assert!(err.contains("line 2: GPSTime") && err.contains("16 digits") && err.contains("19 digits"), "{err}");
        }
    }

    #[test]
    fn yaw_follows_the_x_axis_for_either_roll() {
        assert!((planar_yaw_rad(std::f64::consts::PI, 0.0, 0.4).unwrap() - 0.4).abs() < 1e-12);
        assert!((planar_yaw_rad(0.0, 0.0, 0.4).unwrap() + 0.4).abs() < 1e-12);
        assert_eq!(planar_yaw_rad(0.0, std::f64::consts::FRAC_PI_2, 0.0), None);
        let text = "t,x,y,z,roll,pitch,heading\n5,1,2,3,0,0,0.25\n";
        let parsed = parse_applanix_poses(Path::new("p.csv"), text).unwrap();
        assert_eq!(parsed.position_frame, "enu_ref");
        assert!((parsed.poses[0].parent_from_child.yaw_rad + 0.25).abs() < 1e-12);
    }

    #[test]
    fn bad_rows_are_named() {
        let path = Path::new("radar_poses.csv");
        let err = parse_applanix_poses(path, &format!("{}\n1,2\n", HEADER.replace("heading", "yaw")))
            .unwrap_err()
            .to_string();
        assert!(err.contains("radar_poses.csv") && err.contains("heading") && err.contains("missing column"), "{err}");
        let err = parse_applanix_poses(path, &format!("{}\n1,2\n", HEADER.replace("northing", "north")))
            .unwrap_err()
            .to_string();
        assert!(err.contains("northing") && err.contains("missing column"), "{err}");
        let err = parse_applanix_poses(path, &format!("{}\n1,2\n", HEADER.replace("GPSTime", "time")))
            .unwrap_err()
            .to_string();
        assert!(err.contains("GPSTime") && err.contains("missing column"), "{err}");
        let nan = format!("{HEADER}\n10,1,2,3,0,0,0,3.1,0,NaN,0,0,0\n");
        let err = parse_applanix_poses(path, &nan).unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains("heading") && err.contains("finite"), "{err}");
        let backwards = format!("{HEADER}\n10,1,2,3,0,0,0,3.1,0,0,0,0,0\n9,1,2,3,0,0,0,3.1,0,0,0,0,0\n");
        let err = parse_applanix_poses(path, &backwards).unwrap_err().to_string();
        assert!(err.contains("line 3") && err.contains("GPSTime") && err.contains("does not increase"), "{err}");
        let err = parse_applanix_poses(path, &format!("{HEADER}\n")).unwrap_err().to_string();
        assert!(err.contains("no data rows"), "{err}");
    }
}
