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

use std::collections::HashMap;
use std::path::Path;

use mmtrack_core::{Se2, StampedPose};

use crate::IngestError;
use crate::error::os_err;

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
    let mut lines = text.lines().enumerate();
    let header = lines.next().map(|(_, l)| l).ok_or_else(|| IngestError::BadLayout {
        path: path.to_path_buf(),
        detail: "empty file: no header line".into(),
    })?;
    let columns: HashMap<&str, usize> = header.split(',').map(str::trim).enumerate().map(|(i, c)| (c, i)).collect();
    for name in REQUIRED {
        if !columns.contains_key(name) {
            return Err(IngestError::BadRecord {
                path: path.to_path_buf(),
                record: "line 1 (header)".into(),
                field: name.into(),
                detail: format!("missing column; expected {}", REQUIRED.join(", ")),
            });
        }
    }
    let radar_time =
        columns.contains_key("source_radar_timestamp") && columns.contains_key("destination_radar_timestamp");
    let (source_col, destination_col) = if radar_time {
        ("source_radar_timestamp", "destination_radar_timestamp")
    } else {
        ("source_timestamp", "destination_timestamp")
    };
    let mut rows = Vec::new();
    for (index, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let record = || format!("line {}", index + 1);
        let get = |name: &str| -> Result<&str, IngestError> {
            fields.get(columns[name]).copied().ok_or_else(|| IngestError::BadRecord {
                path: path.to_path_buf(),
                record: record(),
                field: name.into(),
                detail: format!("row has {} fields, header has {}", fields.len(), columns.len()),
            })
        };
        let time = |name: &str| -> Result<i64, IngestError> {
            let raw = get(name)?;
            raw.parse::<i64>().ok().and_then(|us| us.checked_mul(1000)).ok_or_else(|| IngestError::BadRecord {
                path: path.to_path_buf(),
                record: record(),
                field: name.into(),
                detail: format!("'{raw}' is not a microsecond timestamp"),
            })
        };
        let number = |name: &str| -> Result<f64, IngestError> {
            let raw = get(name)?;
            raw.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| IngestError::BadRecord {
                path: path.to_path_buf(),
                record: record(),
                field: name.into(),
                detail: format!("'{raw}' is not a finite number"),
            })
        };
        rows.push(RelativePose {
            source_t_ns: time(source_col)?,
            destination_t_ns: time(destination_col)?,
            // x forward / y right / z down -> x forward / y left / z up.
            destination_from_source: Se2::new(number("x")?, -number("y")?, -number("yaw")?),
        });
    }
    Ok(rows)
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
    let text = std::fs::read_to_string(path).map_err(os_err(path))?;
    chain(path, &parse_radar_odometry(path, &text)?)
}
