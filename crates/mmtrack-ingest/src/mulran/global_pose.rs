//! MulRan `global_pose.csv`: no header; per line the UNIX time in
//! nanoseconds, then the first three rows of the 4x4 pose matrix
//! `world_from_vehicle`, row-major (`r11,r12,r13,tx,r21,r22,r23,ty,r31,r32,r33,tz`),
//! 13 comma-separated numbers in all (as the MulRan file player reads it).
//!
//! Projected to SE(2): `x = tx`, `y = ty`, `yaw = atan2(r21, r11)` (the
//! direction of the vehicle's x axis in the world's x-y plane; z is up in
//! MulRan's global frame). Positions are placed in a local frame whose origin
//! is the first line's translation, so the numbers stay small; the origin is
//! returned for the recording metadata.

use std::path::Path;

use mmtrack_core::plausible::{self, COORDINATE_M};
use mmtrack_core::{Se2, StampedPose};

use crate::IngestError;
use crate::error::check_plausible;

/// Poses in a local frame and where that frame's origin is.
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalPoses {
    /// `world_from_vehicle`, world = the file's axes about `origin`.
    pub poses: Vec<StampedPose>,
    /// The first line's translation (tx, ty, tz), metres.
    pub origin: [f64; 3],
}

const NAMES: [&str; 13] = ["t_ns", "r11", "r12", "r13", "tx", "r21", "r22", "r23", "ty", "r31", "r32", "r33", "tz"];

/// Parses one line into its time and 12 matrix entries.
fn parse_line(path: &Path, line: usize, text: &str) -> Result<(i64, [f64; 12]), IngestError> {
    let fields: Vec<&str> = text.split(',').map(str::trim).collect();
    if fields.len() != NAMES.len() {
        return Err(IngestError::bad_line(
            path,
            line,
            "columns",
            format!("{} values, expected 13 (t_ns and a 3x4 row-major pose matrix)", fields.len()),
        ));
    }
    let t_ns = fields[0].parse::<i64>().ok().filter(|t| *t > 0).ok_or_else(|| {
        IngestError::bad_line(path, line, "t_ns", format!("'{}' is not a nanosecond UNIX timestamp", fields[0]))
    })?;
    let mut m = [0.0; 12];
    for (k, (value, name)) in fields[1..].iter().zip(&NAMES[1..]).enumerate() {
        m[k] = value
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| IngestError::bad_line(path, line, name, format!("'{value}' is not a finite number")))?;
    }
    for k in [3, 7, 11] {
        check_plausible(path, || format!("line {line}"), NAMES[k + 1], &COORDINATE_M, m[k])?;
    }
    plausible::check_rotation(&[[m[0], m[1], m[2]], [m[4], m[5], m[6]], [m[8], m[9], m[10]]])
        .map_err(|detail| IngestError::bad_line(path, line, "rotation", detail))?;
    Ok((t_ns, m))
}

/// Parses `global_pose.csv` text. Lines must be in strictly increasing time.
pub fn parse_global_pose(path: &Path, text: &str) -> Result<GlobalPoses, IngestError> {
    let mut poses: Vec<StampedPose> = Vec::new();
    let mut origin = None;
    for (index, raw) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let line = index + 1;
        let (t_ns, m) = parse_line(path, line, raw)?;
        if let Some(previous) = poses.last()
            && t_ns <= previous.t_ns
        {
            return Err(IngestError::bad_line(
                path,
                line,
                "t_ns",
                format!("{t_ns} ns does not increase (previous {} ns)", previous.t_ns),
            ));
        }
        let (r11, r21) = (m[0], m[4]);
        if !(0.5..=1.5).contains(&r11.hypot(r21)) {
            return Err(IngestError::bad_line(
                path,
                line,
                "r11/r21",
                format!("({r11}, {r21}) is not the planar part of a rotation of a level vehicle"),
            ));
        }
        let [ox, oy, _] = *origin.get_or_insert([m[3], m[7], m[11]]);
        poses.push(StampedPose { t_ns, parent_from_child: Se2::new(m[3] - ox, m[7] - oy, r21.atan2(r11)) });
    }
    let origin = origin.ok_or_else(|| IngestError::BadLayout {
        path: path.to_path_buf(),
        detail: "no pose lines (empty file?)".into(),
    })?;
    Ok(GlobalPoses { poses, origin })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(t_ns: i64, x: f64, y: f64, yaw: f64) -> String {
        let (s, c) = yaw.sin_cos();
        format!("{t_ns},{c},{},0,{x},{s},{c},0,{y},0,0,1,19.5\n", -s)
    }

    #[test]
    fn lines_become_local_planar_poses() {
        let text = format!(
            "{}{}",
            line(1_561_000_000_000_000_000, 353_000.5, 4_026_000.25, 0.3),
            line(1_561_000_000_100_000_000, 353_001.5, 4_026_000.75, -2.0)
        );
        let parsed = parse_global_pose(Path::new("global_pose.csv"), &text).unwrap();
        assert_eq!(parsed.origin, [353_000.5, 4_026_000.25, 19.5]);
        let second = parsed.poses[1].parent_from_child;
        assert_eq!((second.x_m, second.y_m), (1.0, 0.5));
        assert!((second.yaw_rad + 2.0).abs() < 1e-12);
        assert!((parsed.poses[0].parent_from_child.yaw_rad - 0.3).abs() < 1e-12);
    }

    #[test]
    fn bad_lines_are_named() {
        let path = Path::new("global_pose.csv");
        let err = parse_global_pose(path, "5,1,0,0,1,0,1,0,2,0,0,1\n").unwrap_err().to_string();
        assert!(err.contains("global_pose.csv: line 1: columns") && err.contains("12 values"), "{err}");
        let err =
            parse_global_pose(path, &line(5, 1.0, 2.0, 0.0).replacen("5,1,", "5,NaN,", 1)).unwrap_err().to_string();
        assert!(err.contains("line 1: r11") && err.contains("finite"), "{err}");
        let text = format!("{}{}", line(10, 0.0, 0.0, 0.0), line(9, 0.0, 0.0, 0.0));
        let err = parse_global_pose(path, &text).unwrap_err().to_string();
        assert!(err.contains("line 2: t_ns") && err.contains("does not increase"), "{err}");
        let err = parse_global_pose(path, "timestamp,r11\n").unwrap_err().to_string();
        assert!(err.contains("line 1: columns"), "{err}");
        // A rotation whose x axis points straight up (90 deg about y): no planar heading.
        let err = parse_global_pose(path, "5,0,0,1,1,0,1,0,2,-1,0,0,0\n").unwrap_err().to_string();
        assert!(err.contains("r11/r21"), "{err}");
        // Not a rotation at all (before: accepted, its yaw taken from r11/r21).
        let err = parse_global_pose(path, "5,2,0,0,1,0,2,0,2,0,0,2,0\n").unwrap_err().to_string();
        assert!(err.starts_with("global_pose.csv: line 1: rotation: the rotation is not orthonormal"), "{err}");
        let err = parse_global_pose(path, "5,1,0,0,1e300,0,1,0,2,0,0,1,0\n").unwrap_err().to_string();
        assert!(err.starts_with("global_pose.csv: line 1: tx: 1e300 is not a coordinate"), "{err}");
        assert!(parse_global_pose(path, "\n").unwrap_err().to_string().contains("no pose lines"));
    }
}
