//! Oxford `gt/radar_odometry.csv`: relative poses between consecutive radar
//! scans, chained into absolute poses.
//!
//! Each row holds the pose of the *source* scan (later) in the frame of the
//! *destination* scan (earlier), `destination_from_source`. As the dataset SDK
//! does (`abs = abs * T(x, y, z, roll, pitch, yaw)`), the chain starts at the
//! identity at the first row's destination and composes on the right:
//! `world_from_source = world_from_destination * destination_from_source`.
//! We keep the planar part; the vehicle is level to within the dataset's own
//! precision.
//!
//! Frames: the dataset's vehicle frame is x forward, y right, z down, so its
//! yaw is clockwise-positive seen from above. mmtrack is z up (y left, yaw
//! counter-clockwise), so each row becomes `Se2(x, -y, -yaw)`. The yaw sign is
//! pinned by a test against the sample's own GPS track: chained this way, the
//! path fits the GPS (UTM easting/northing) to about 2 m RMS after a rigid
//! alignment, while keeping the CSV's yaw sign gives over 100 m. The sign of y
//! cannot be told apart by GPS (lateral steps are centimetres); it follows the
//! SDK's frame convention. Poses are stamped with the radar timestamps
//! (`source_radar_timestamp`, which equal the scan file names) when present,
//! else with `source_timestamp`.

use std::path::Path;

use mmtrack_core::plausible::{ANGLE_RAD, COORDINATE_M};
use mmtrack_core::{Se2, StampedPose};

use crate::IngestError;
use crate::csv::CsvTable;

/// One parsed row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelativePose {
    /// Time of the later scan, nanoseconds.
    pub source_t_ns: i64,
    /// Time of the earlier scan, nanoseconds.
    pub destination_t_ns: i64,
    /// Pose of the source scan in the destination scan's frame.
    pub destination_from_source: Se2,
}

const REQUIRED: [&str; 5] = ["source_timestamp", "destination_timestamp", "x", "y", "yaw"];

/// Parses the CSV text. Errors name the line and column.
pub fn parse_radar_odometry(path: &Path, text: &str) -> Result<Vec<RelativePose>, IngestError> {
    let table = CsvTable::parse(path, text, &REQUIRED)?;
    let (source_col, destination_col) =
        if table.has("source_radar_timestamp") && table.has("destination_radar_timestamp") {
            ("source_radar_timestamp", "destination_radar_timestamp")
        } else {
            ("source_timestamp", "destination_timestamp")
        };
    table
        .rows()
        .map(|row| {
            Ok(RelativePose {
                source_t_ns: row.micros_ns(source_col)?,
                destination_t_ns: row.micros_ns(destination_col)?,
                // x forward / y right / z down -> x forward / y left / z up.
                destination_from_source: Se2::new(
                    row.bounded("x", &COORDINATE_M)?,
                    -row.bounded("y", &COORDINATE_M)?,
                    -row.bounded("yaw", &ANGLE_RAD)?,
                ),
            })
        })
        .collect()
}

/// Chains relative poses into absolute `world_from_vehicle` poses, the first
/// at the identity. Fails when a row's destination is not the previous row's
/// source (a gap in the chain would silently corrupt every later pose).
pub fn chain(path: &Path, rows: &[RelativePose]) -> Result<Vec<StampedPose>, IngestError> {
    let Some(first) = rows.first() else {
        return Ok(Vec::new());
    };
    let mut poses = Vec::with_capacity(rows.len() + 1);
    poses.push(StampedPose { t_ns: first.destination_t_ns, parent_from_child: Se2::IDENTITY });
    for (index, row) in rows.iter().enumerate() {
        let previous = poses[poses.len() - 1].clone();
        if row.destination_t_ns != previous.t_ns {
            return Err(IngestError::BadRecord {
                path: path.to_path_buf(),
                record: format!("line {}", index + 2),
                field: "destination timestamp".into(),
                detail: format!(
                    "{} us does not continue the chain (previous source {} us)",
                    row.destination_t_ns / 1000,
                    previous.t_ns / 1000
                ),
            });
        }
        if row.source_t_ns <= row.destination_t_ns {
            return Err(IngestError::BadRecord {
                path: path.to_path_buf(),
                record: format!("line {}", index + 2),
                field: "source timestamp".into(),
                detail: "not later than the destination timestamp".into(),
            });
        }
        poses.push(StampedPose {
            t_ns: row.source_t_ns,
            parent_from_child: previous.parent_from_child * row.destination_from_source,
        });
    }
    Ok(poses)
}

/// Reads and chains a `radar_odometry.csv` file.
pub fn read_radar_odometry(path: &Path) -> Result<Vec<StampedPose>, IngestError> {
    let text = crate::error::read_line_records(path)?;
    chain(path, &parse_radar_odometry(path, &text)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "source_timestamp,destination_timestamp,x,y,z,roll,pitch,yaw,source_radar_timestamp,destination_radar_timestamp";

    #[test]
    fn rows_chain_in_the_z_up_frame() {
        let text = format!("{HEADER}\n20,10,1.0,0.5,0,0,0,0.1,21,11\n30,20,2.0,0,0,0,0,0,31,21\n");
        let path = Path::new("radar_odometry.csv");
        let poses = chain(path, &parse_radar_odometry(path, &text).unwrap()).unwrap();
        // Keyed on the radar timestamps; the first pose is the identity.
        assert_eq!(poses.iter().map(|p| p.t_ns).collect::<Vec<_>>(), vec![11_000, 21_000, 31_000]);
        let second = poses[1].parent_from_child;
        assert_eq!((second.x_m, second.y_m, second.yaw_rad), (1.0, -0.5, -0.1));
    }

    #[test]
    fn renamed_column_nan_and_broken_chain_are_named() {
        let path = Path::new("radar_odometry.csv");
        let err = parse_radar_odometry(path, &HEADER.replace(",yaw,", ",heading,")).unwrap_err().to_string();
        assert!(err.contains("yaw") && err.contains("missing column"), "{err}");
        let err =
            parse_radar_odometry(path, &format!("{HEADER}\n20,10,NaN,0,0,0,0,0,21,11\n")).unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains(": x:"), "{err}");
        let rows = parse_radar_odometry(path, &format!("{HEADER}\n20,10,1,0,0,0,0,0,21,11\n40,30,1,0,0,0,0,0,41,31\n"))
            .unwrap();
        let err = chain(path, &rows).unwrap_err().to_string();
        assert!(err.contains("line 3") && err.contains("does not continue the chain"), "{err}");
        // A header alone is not an empty trajectory but an error.
        let err = parse_radar_odometry(path, &format!("{HEADER}\n")).unwrap_err().to_string();
        assert!(err.contains("radar_odometry.csv") && err.contains("no data rows"), "{err}");
    }
}
