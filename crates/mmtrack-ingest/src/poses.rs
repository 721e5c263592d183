//! Trajectory files: KITTI pose files, TUM trajectories, Oxford
//! `radar_odometry.csv`, into a new recording or added to an existing one.
//!
//! - **TUM** (`timestamp tx ty tz qx qy qz qw` per line, `#` comments): the
//!   timestamp is decimal seconds (usually UNIX time), converted to
//!   nanoseconds from its digits (no float rounding; digits past the ninth
//!   decimal are dropped).
//! - **KITTI** (12 numbers per line, the first three rows of a 4x4 matrix
//!   `world_from_frame`, row-major): no time in the file, so a `times.txt`
//!   (decimal seconds per line, as the KITTI odometry devkit ships) is required,
//!   plus an offset `t0_ns` added to every time.
//!
//! Planar projection ([`Plane`]): radar-odometry tools (the Oxford and Boreas
//! devkits, CFEAR) write planar poses in the x-y plane with z up, the default;
//! KITTI's own camera trajectories are x right, y down, z forward, so their
//! ground plane is x-z: forward z, left -x, and yaw `atan2(-r13, r33)`.
//! Quaternions are `(x, y, z, w)`; yaw about z is
//! `atan2(2 (w z + x y), 1 - 2 (y^2 + z^2))`.

use std::path::Path;

use mmtrack_core::{Se2, StampedPose};
use std::collections::BTreeMap;

use mmtrack_io::RecordingOptions;
use mmtrack_io::recording::{PoseStream, WriteSummary};

use crate::IngestError;
use crate::error::os_err;

/// Which plane of a 3D trajectory is the ground.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Plane {
    /// x-y with z up (radar odometry, ROS, Oxford, Boreas).
    #[default]
    Xy,
    /// x-z of a camera frame (x right, y down, z forward): KITTI camera poses.
    XzCamera,
}

fn bad(path: &Path, line: usize, field: &str, detail: String) -> IngestError {
    IngestError::BadRecord { path: path.to_path_buf(), record: format!("line {line}"), field: field.into(), detail }
}

/// Decimal seconds (`"1305031102.175304"`) to nanoseconds, exactly.
#[must_use]
pub fn decimal_seconds_to_ns(text: &str) -> Option<i64> {
    let (whole, fraction) = text.split_once('.').unwrap_or((text, ""));
    if whole.is_empty() || !whole.bytes().all(|b| b.is_ascii_digit()) || !fraction.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let seconds: i64 = whole.parse().ok()?;
    let mut digits: String = fraction.chars().take(9).collect();
    while digits.len() < 9 {
        digits.push('0');
    }
    seconds.checked_mul(1_000_000_000)?.checked_add(digits.parse::<i64>().ok()?)
}

fn numbers<const N: usize>(path: &Path, line: usize, text: &str, names: &[&str; N]) -> Result<[f64; N], IngestError> {
    let fields: Vec<&str> = text.split_whitespace().collect();
    if fields.len() != N {
        return Err(bad(path, line, "columns", format!("{} values, expected {N} ({})", fields.len(), names.join(" "))));
    }
    let mut out = [0.0; N];
    for (i, (field, name)) in fields.iter().zip(names).enumerate() {
        out[i] = field
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(path, line, name, format!("'{field}' is not a finite number")))?;
    }
    Ok(out)
}

fn yaw_from_quaternion(q: [f64; 4]) -> f64 {
    let [x, y, z, w] = q;
    (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z))
}

fn check_increasing(path: &Path, poses: &[StampedPose], line: usize, t_ns: i64) -> Result<(), IngestError> {
    match poses.last() {
        Some(previous) if t_ns <= previous.t_ns => {
            Err(bad(path, line, "timestamp", format!("{t_ns} ns does not increase (previous {} ns)", previous.t_ns)))
        }
        _ => Ok(()),
    }
}

/// Parses a TUM trajectory.
pub fn parse_tum(path: &Path, text: &str, plane: Plane) -> Result<Vec<StampedPose>, IngestError> {
    let mut poses = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let line_number = index + 1;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let stamp = line.split_whitespace().next().unwrap_or("");
        let t_ns = decimal_seconds_to_ns(stamp)
            .ok_or_else(|| bad(path, line_number, "timestamp", format!("'{stamp}' is not decimal seconds")))?;
        let rest = line[stamp.len()..].trim();
        let [tx, ty, tz, qx, qy, qz, qw] =
            numbers(path, line_number, rest, &["tx", "ty", "tz", "qx", "qy", "qz", "qw"])?;
        let pose = match plane {
            Plane::Xy => Se2::new(tx, ty, yaw_from_quaternion([qx, qy, qz, qw])),
            Plane::XzCamera => {
                // Camera forward axis (third column of R) in the planar frame (forward z, left -x).
                let r13 = 2.0 * (qx * qz + qw * qy);
                let r33 = 1.0 - 2.0 * (qx * qx + qy * qy);
                Se2::new(tz, -tx, (-r13).atan2(r33))
            }
        };
        check_increasing(path, &poses, line_number, t_ns)?;
        poses.push(StampedPose { t_ns, parent_from_child: pose });
    }
    Ok(poses)
}

/// Parses a KITTI `times.txt` (decimal seconds per line), plus `t0_ns`.
pub fn parse_times(path: &Path, text: &str, t0_ns: i64) -> Result<Vec<i64>, IngestError> {
    let mut times = Vec::new();
    for (index, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let raw = line.trim();
        // KITTI writes times like 1.036868e-01 as well as 0.103687.
        let t_ns = decimal_seconds_to_ns(raw)
            .or_else(|| {
                raw.parse::<f64>().ok().filter(|s| s.is_finite() && *s >= 0.0).map(|s| (s * 1e9).round() as i64)
            })
            .and_then(|t| t.checked_add(t0_ns))
            .ok_or_else(|| bad(path, index + 1, "time", format!("'{raw}' is not non-negative seconds")))?;
        times.push(t_ns);
    }
    Ok(times)
}

/// Parses a KITTI pose file with one time per line from `times_ns`.
pub fn parse_kitti(path: &Path, text: &str, times_ns: &[i64], plane: Plane) -> Result<Vec<StampedPose>, IngestError> {
    let names = ["r11", "r12", "r13", "tx", "r21", "r22", "r23", "ty", "r31", "r32", "r33", "tz"];
    let mut poses = Vec::new();
    for (index, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let line_number = index + 1;
        let [r11, _r12, r13, tx, r21, _r22, _r23, ty, _r31, _r32, r33, tz] = numbers(path, line_number, line, &names)?;
        let t_ns = *times_ns.get(poses.len()).ok_or_else(|| {
            bad(path, line_number, "time", format!("the times file has only {} lines for more poses", times_ns.len()))
        })?;
        let pose = match plane {
            Plane::Xy => Se2::new(tx, ty, r21.atan2(r11)),
            Plane::XzCamera => Se2::new(tz, -tx, (-r13).atan2(r33)),
        };
        check_increasing(path, &poses, line_number, t_ns)?;
        poses.push(StampedPose { t_ns, parent_from_child: pose });
    }
    if poses.len() != times_ns.len() {
        return Err(IngestError::BadLayout {
            path: path.to_path_buf(),
            detail: format!("{} poses but {} times", poses.len(), times_ns.len()),
        });
    }
    Ok(poses)
}

/// Reads a file as text.
pub fn read_text(path: &Path) -> Result<String, IngestError> {
    std::fs::read_to_string(path).map_err(os_err(path))
}

/// Writes `poses` as `stream` into `out`: a new recording, or, with `extend`,
/// a copy of that recording plus the poses (see [`crate::target`]).
pub fn write_poses(
    poses: &[StampedPose],
    stream: PoseStream,
    source: &str,
    extend: Option<&Path>,
    out: &Path,
    recording: &RecordingOptions,
) -> Result<WriteSummary, IngestError> {
    let extra = BTreeMap::from([(format!("{}.source", stream.topic().trim_start_matches('/')), source.to_string())]);
    let mut writer =
        crate::target::open_writer(out, extend, source, extra, &[stream.topic(), stream.viz_topic()], recording)?;
    for pose in poses {
        writer.write_pose(stream, pose, "world", "vehicle")?;
    }
    Ok(writer.finish()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_seconds_are_exact() {
        assert_eq!(decimal_seconds_to_ns("1305031102.175304"), Some(1_305_031_102_175_304_000));
        assert_eq!(decimal_seconds_to_ns("7"), Some(7_000_000_000));
        assert_eq!(decimal_seconds_to_ns("0.1234567891"), Some(123_456_789));
        assert_eq!(decimal_seconds_to_ns("-1.0"), None);
        assert_eq!(decimal_seconds_to_ns("1e3"), None);
    }

    #[test]
    fn tum_reads_position_and_yaw() {
        let half = 0.3f64;
        let text = format!("# comment\n1.5 1.0 2.0 0.0 0 0 {} {}\n2.5 3.0 4.0 0.0 0 0 0 1\n", half.sin(), half.cos());
        let poses = parse_tum(Path::new("t.txt"), &text, Plane::Xy).unwrap();
        assert_eq!(poses.len(), 2);
        assert_eq!(poses[0].t_ns, 1_500_000_000);
        assert!((poses[0].parent_from_child.yaw_rad - 0.6).abs() < 1e-12);
        assert_eq!(poses[1].parent_from_child.x_m, 3.0);
    }

    #[test]
    fn kitti_planes_agree_on_a_turning_camera() {
        // Camera turned left by 0.4 rad about its (down) y axis, i.e. yaw +0.4 about up:
        // forward axis (r13, r23, r33) = (-sin 0.4, 0, cos 0.4).
        let (s, c) = 0.4f64.sin_cos();
        let line = format!("{c} 0 {} 1.0 0 1 0 0 {s} 0 {c} 5.0\n", -s);
        let poses = parse_kitti(Path::new("p.txt"), &line, &[10], Plane::XzCamera).unwrap();
        let p = poses[0].parent_from_child;
        assert!((p.x_m - 5.0).abs() < 1e-12 && (p.y_m + 1.0).abs() < 1e-12 && (p.yaw_rad - 0.4).abs() < 1e-12);
        let xy = format!("{c} {} 0 1.0 {s} {c} 0 2.0 0 0 1 0\n", -s);
        let p = parse_kitti(Path::new("p.txt"), &xy, &[10], Plane::Xy).unwrap()[0].parent_from_child;
        assert!((p.yaw_rad - 0.4).abs() < 1e-12 && p.y_m == 2.0);
    }

    #[test]
    fn bad_lines_are_named() {
        let err = parse_tum(Path::new("t.txt"), "1.0 1 2 3 0 0 0\n", Plane::Xy).unwrap_err().to_string();
        assert!(err.contains("line 1") && err.contains("expected 7"), "{err}");
        let err =
            parse_tum(Path::new("t.txt"), "1.0 1 2 3 0 0 0 1\n0.5 1 2 3 0 0 0 1\n", Plane::Xy).unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains("does not increase"), "{err}");
        let err = parse_tum(Path::new("t.txt"), "1.0 NaN 2 3 0 0 0 1\n", Plane::Xy).unwrap_err().to_string();
        assert!(err.contains("tx") && err.contains("finite"), "{err}");
        let err =
            parse_kitti(Path::new("p.txt"), "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0\n", &[1], Plane::Xy)
                .unwrap_err()
                .to_string();
        assert!(err.contains("line 2") && err.contains("times file has only 1"), "{err}");
    }
}
