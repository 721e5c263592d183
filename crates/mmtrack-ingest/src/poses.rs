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
//! `atan2(2 (w z + x y), 1 - 2 (y^2 + z^2))`. A quaternion whose norm is not
//! 1 within [`QUATERNION_NORM_TOLERANCE`] (a zero quaternion, a column read
//! from the wrong place) is an error naming the line; within it, the
//! quaternion is normalised first.
//!
//! A file without a single pose is an error, and so is a plane that leaves
//! the motion on the dropped axis (see [`check_plane`]), a coordinate beyond
//! [`COORDINATE_M`] or a KITTI rotation that is not orthonormal
//! ([`plausible::check_rotation`]).

use std::path::Path;

use mmtrack_core::plausible::{self, COORDINATE_M};
use mmtrack_core::{Se2, StampedPose};
use std::collections::BTreeMap;

use mmtrack_io::RecordingOptions;
use mmtrack_io::recording::{PoseStream, WriteSummary};

use crate::IngestError;
use crate::error::check_plausible;

/// Which plane of a 3D trajectory is the ground.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Plane {
    /// x-y with z up (radar odometry, ROS, Oxford, Boreas).
    #[default]
    Xy,
    /// x-z of a camera frame (x right, y down, z forward): KITTI camera poses.
    XzCamera,
}

impl Plane {
    /// The axis dropped by the projection (the one taken as vertical): 2 (z)
    /// for x-y, 1 (y) for a camera's x-z.
    fn vertical_axis(self) -> usize {
        match self {
            Self::Xy => 2,
            Self::XzCamera => 1,
        }
    }

    /// The `--plane` value that names this plane.
    fn flag(self) -> &'static str {
        match self {
            Self::Xy => "xy",
            Self::XzCamera => "xz-camera",
        }
    }

    /// The plane a `--plane` value names.
    ///
    /// # Errors
    /// Another value (the message lists the values).
    pub fn parse(flag: &str) -> Result<Self, String> {
        [Self::Xy, Self::XzCamera]
            .into_iter()
            .find(|p| p.flag() == flag)
            .ok_or_else(|| format!("--plane '{flag}': expected xy or xz-camera"))
    }
}

/// How far from 1 the norm of an orientation quaternion may be: printing a
/// unit quaternion to 4 decimals is off by about 1e-4, and a quaternion
/// further off than 1 % is not a rotation written out.
pub const QUATERNION_NORM_TOLERANCE: f64 = 0.01;

/// `(x, y, z, w)` scaled to unit norm, or why it is not a rotation: its norm
/// differs from 1 by more than [`QUATERNION_NORM_TOLERANCE`] (a zero
/// quaternion among them).
pub fn unit_quaternion(q: [f64; 4]) -> Result<[f64; 4], String> {
    let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    if (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(format!(
            "quaternion ({}, {}, {}, {}) has norm {norm:.3}; a rotation has norm 1 (within {QUATERNION_NORM_TOLERANCE})",
            q[0], q[1], q[2], q[3]
        ));
    }
    Ok(q.map(|c| c / norm))
}

/// Smallest extent of the dropped axis, metres, for [`check_plane`] to judge:
/// below it a trajectory is too small for its vertical axis to matter.
const PLANE_CHECK_MIN_EXTENT_M: f64 = 1.0;

/// Refuses a plane that drops the axis the motion happens along.
///
/// With `e_v` the extent (max - min) of the positions along the dropped
/// (vertical) axis and `e_big`, `e_small` the larger and smaller extents of
/// the two kept axes, the trajectory is refused when all of
/// - `e_v >= 1 m` (smaller trajectories are left alone),
/// - `e_v >= 0.25 e_big`: the dropped axis carries a good share of the motion;
///   a ground vehicle climbing at a 25 % average grade along a straight road
///   would be needed to reach it,
/// - `e_small <= 0.1 e_v`: one kept axis is nearly constant, as the height
///   of a vehicle is,
///
/// hold: then the kept axis that stays constant is the real vertical. KITTI
/// camera poses (y down) read with `--plane xy` are caught this way (their
/// z spans hundreds of metres, y a few), as is a z-up trajectory read as a
/// camera's x-z.
pub fn check_plane(path: &Path, positions_m: &[[f64; 3]], plane: Plane) -> Result<(), IngestError> {
    let extent_m: [f64; 3] = std::array::from_fn(|axis| {
        let values = positions_m.iter().map(|p| p[axis]);
        values.clone().fold(f64::NEG_INFINITY, f64::max) - values.fold(f64::INFINITY, f64::min)
    });
    let vertical = plane.vertical_axis();
    let [first, second] = match plane {
        Plane::Xy => [0, 1],
        Plane::XzCamera => [0, 2],
    };
    // Ties go to the second kept axis: y of a camera, y of a z-up frame.
    let (small, big) = if extent_m[second] <= extent_m[first] { (second, first) } else { (first, second) };
    let e_v = extent_m[vertical];
    if !(e_v >= PLANE_CHECK_MIN_EXTENT_M && e_v >= 0.25 * extent_m[big] && extent_m[small] <= 0.1 * e_v) {
        return Ok(());
    }
    let names = ["x", "y", "z"];
    let suggestion = [Plane::Xy, Plane::XzCamera]
        .into_iter()
        .find(|p| p.vertical_axis() == small)
        .map(|p| format!("use --plane {}", p.flag()))
        .unwrap_or_else(|| format!("no --plane choice takes {} as vertical", names[small]));
    Err(IngestError::BadLayout {
        path: path.to_path_buf(),
        detail: format!(
            "positions span x {:.1} m, y {:.1} m, z {:.1} m: --plane {} drops {}, which carries the motion, \
             while {} stays within {:.1} m, so {} looks vertical; {suggestion}",
            extent_m[0],
            extent_m[1],
            extent_m[2],
            plane.flag(),
            names[vertical],
            names[small],
            extent_m[small],
            names[small],
        ),
    })
}

/// The error for a file without a single pose.
fn no_poses(path: &Path, what: &str) -> IngestError {
    IngestError::BadLayout { path: path.to_path_buf(), detail: format!("no poses ({what})") }
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
        return Err(IngestError::bad_line(
            path,
            line,
            "columns",
            format!("{} values, expected {N} ({})", fields.len(), names.join(" ")),
        ));
    }
    let mut out = [0.0; N];
    for (i, (field, name)) in fields.iter().zip(names).enumerate() {
        out[i] = field
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| IngestError::bad_line(path, line, name, format!("'{field}' is not a finite number")))?;
    }
    Ok(out)
}

/// Checks a position's coordinates against [`COORDINATE_M`].
fn check_position(path: &Path, line: usize, names: [&str; 3], position_m: [f64; 3]) -> Result<(), IngestError> {
    for (name, value) in names.into_iter().zip(position_m) {
        check_plausible(path, || format!("line {line}"), name, &COORDINATE_M, value)?;
    }
    Ok(())
}

fn yaw_from_quaternion(q: [f64; 4]) -> f64 {
    let [x, y, z, w] = q;
    (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z))
}

fn check_increasing(path: &Path, poses: &[StampedPose], line: usize, t_ns: i64) -> Result<(), IngestError> {
    match poses.last() {
        Some(previous) if t_ns <= previous.t_ns => Err(IngestError::bad_line(
            path,
            line,
            "timestamp",
            format!("{t_ns} ns does not increase (previous {} ns)", previous.t_ns),
        )),
        _ => Ok(()),
    }
}

/// Parses a TUM trajectory: at least one pose, unit quaternions, a plane that
/// keeps the motion ([`check_plane`]).
pub fn parse_tum(path: &Path, text: &str, plane: Plane) -> Result<Vec<StampedPose>, IngestError> {
    let mut poses = Vec::new();
    let mut positions_m = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let line_number = index + 1;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let stamp = line.split_whitespace().next().unwrap_or("");
        let t_ns = decimal_seconds_to_ns(stamp).ok_or_else(|| {
            IngestError::bad_line(path, line_number, "timestamp", format!("'{stamp}' is not decimal seconds"))
        })?;
        let rest = line[stamp.len()..].trim();
        let [tx, ty, tz, qx, qy, qz, qw] =
            numbers(path, line_number, rest, &["tx", "ty", "tz", "qx", "qy", "qz", "qw"])?;
        check_position(path, line_number, ["tx", "ty", "tz"], [tx, ty, tz])?;
        let [qx, qy, qz, qw] = unit_quaternion([qx, qy, qz, qw])
            .map_err(|detail| IngestError::bad_line(path, line_number, "qx qy qz qw", detail))?;
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
        positions_m.push([tx, ty, tz]);
    }
    if poses.is_empty() {
        return Err(no_poses(path, "the file is empty or only comments"));
    }
    check_plane(path, &positions_m, plane)?;
    Ok(poses)
}

/// Parses a KITTI `times.txt` (decimal seconds per line, increasing), plus
/// `t0_ns` (`--t0-ns` of `mmtrack ingest poses`). A time that does not
/// increase is the times file's fault, named by its line. A time that is not non-negative
/// seconds within the i64 nanosecond range is the file's fault; a time that
/// only overflows once `t0_ns` is added is `t0_ns`'s, and the error says so.
pub fn parse_times(path: &Path, text: &str, t0_ns: i64) -> Result<Vec<i64>, IngestError> {
    // Largest f64 seconds whose nanoseconds fit an i64 (2^63 ns is about 292 years).
    const MAX_SECONDS: f64 = 9.2e9;
    let mut times = Vec::new();
    for (index, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let raw = line.trim();
        // KITTI writes times like 1.036868e-01 as well as 0.103687.
        let time_ns = decimal_seconds_to_ns(raw)
            .or_else(|| {
                raw.parse::<f64>()
                    .ok()
                    .filter(|s| s.is_finite() && (0.0..MAX_SECONDS).contains(s))
                    .map(|s| (s * 1e9).round() as i64)
            })
            .ok_or_else(|| {
                IngestError::bad_line(
                    path,
                    index + 1,
                    "time",
                    format!("'{raw}' is not non-negative seconds below {MAX_SECONDS:e}"),
                )
            })?;
        let t_ns = time_ns.checked_add(t0_ns).ok_or_else(|| {
            IngestError::bad_line(
                path,
                index + 1,
                "t0_ns (--t0-ns)",
                format!("{raw} s plus the offset {t0_ns} ns overflows i64 nanoseconds: the offset is too large"),
            )
        })?;
        if let Some(&previous) = times.last()
            && t_ns <= previous
        {
            return Err(IngestError::bad_line(
                path,
                index + 1,
                "time",
                format!("{raw} s does not increase (previous {} ns after the offset)", previous),
            ));
        }
        times.push(t_ns);
    }
    Ok(times)
}

/// Refuses a KITTI times file with fewer or more times than the pose file
/// has poses (non-blank lines), naming the times file and its last time's
/// line: the poses cannot be matched to times.
fn check_times_count(
    times_path: &Path,
    times_text: &str,
    times: usize,
    poses_path: &Path,
    poses_text: &str,
) -> Result<(), IngestError> {
    let poses = poses_text.lines().filter(|l| !l.trim().is_empty()).count();
    if poses == times || poses == 0 {
        return Ok(()); // an empty pose file is reported by its parser
    }
    let last_line =
        times_text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()).last().map_or(0, |(i, _)| i + 1);
    let detail = format!(
        "{times} times for the {poses} poses of {}: expected one time per pose ({})",
        poses_path.display(),
        if times < poses { "the times file is short" } else { "the times file is long" }
    );
    Err(match last_line {
        0 => IngestError::BadLayout { path: times_path.to_path_buf(), detail },
        line => IngestError::bad_line(times_path, line, "time", detail),
    })
}

/// Parses a KITTI pose file with one time per line from `times_ns`: at
/// least one pose, a plane that keeps the motion ([`check_plane`]).
pub fn parse_kitti(path: &Path, text: &str, times_ns: &[i64], plane: Plane) -> Result<Vec<StampedPose>, IngestError> {
    let names = ["r11", "r12", "r13", "tx", "r21", "r22", "r23", "ty", "r31", "r32", "r33", "tz"];
    let mut poses = Vec::new();
    let mut positions_m = Vec::new();
    for (index, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let line_number = index + 1;
        let [r11, r12, r13, tx, r21, r22, r23, ty, r31, r32, r33, tz] = numbers(path, line_number, line, &names)?;
        check_position(path, line_number, ["tx", "ty", "tz"], [tx, ty, tz])?;
        plausible::check_rotation(&[[r11, r12, r13], [r21, r22, r23], [r31, r32, r33]])
            .map_err(|detail| IngestError::bad_line(path, line_number, "r11..r33", detail))?;
        let t_ns = *times_ns.get(poses.len()).ok_or_else(|| {
            IngestError::bad_line(
                path,
                line_number,
                "time",
                format!("the times file has only {} lines for more poses", times_ns.len()),
            )
        })?;
        let pose = match plane {
            Plane::Xy => Se2::new(tx, ty, r21.atan2(r11)),
            Plane::XzCamera => Se2::new(tz, -tx, (-r13).atan2(r33)),
        };
        check_increasing(path, &poses, line_number, t_ns)?;
        poses.push(StampedPose { t_ns, parent_from_child: pose });
        positions_m.push([tx, ty, tz]);
    }
    if poses.is_empty() {
        return Err(no_poses(path, "the file is empty"));
    }
    if poses.len() != times_ns.len() {
        return Err(IngestError::BadLayout {
            path: path.to_path_buf(),
            detail: format!("{} poses but {} times", poses.len(), times_ns.len()),
        });
    }
    check_plane(path, &positions_m, plane)?;
    Ok(poses)
}

/// A trajectory file's format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrajectoryFormat {
    /// Oxford `gt/radar_odometry.csv` (relative poses, chained).
    Oxford,
    /// TUM: `t x y z qx qy qz qw` per line.
    Tum,
    /// KITTI: 3x4 matrices per line, times from a separate file.
    Kitti,
}

impl TrajectoryFormat {
    /// The name on the command line (`--format`, `--trajectory-format`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Oxford => "oxford",
            Self::Tum => "tum",
            Self::Kitti => "kitti",
        }
    }

    /// The format of a name, as [`TrajectoryFormat::name`] writes it.
    ///
    /// # Errors
    /// Another name (the message lists the names).
    pub fn parse(name: &str) -> Result<Self, String> {
        [Self::Oxford, Self::Tum, Self::Kitti]
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| format!("'{name}': expected oxford, tum or kitti"))
    }
}

/// Reads a trajectory file as `world_from_vehicle` poses: TUM and KITTI in
/// the ground `plane`, Oxford's chained relative poses; KITTI's times from
/// `times` (decimal seconds per line) plus `t0_ns`.
///
/// # Errors
/// The file (or KITTI's times file, or its absence) cannot be read or parsed.
pub fn read_trajectory(
    path: &Path,
    format: TrajectoryFormat,
    times: Option<&Path>,
    t0_ns: i64,
    plane: Plane,
) -> Result<Vec<StampedPose>, IngestError> {
    match format {
        TrajectoryFormat::Oxford => crate::oxford::odometry::read_radar_odometry(path),
        TrajectoryFormat::Tum => parse_tum(path, &read_text(path)?, plane),
        TrajectoryFormat::Kitti => {
            let Some(times_path) = times else {
                return Err(IngestError::BadLayout {
                    path: path.to_path_buf(),
                    detail: "KITTI pose files carry no time: give --times <times.txt>".into(),
                });
            };
            let times_text = read_text(times_path)?;
            let times = parse_times(times_path, &times_text, t0_ns)?;
            let text = read_text(path)?;
            check_times_count(times_path, &times_text, times.len(), path, &text)?;
            parse_kitti(path, &text, &times, plane)
        }
    }
}

/// Reads a file of line records as text; a last line without its newline
/// (a cut-off file) is an error naming it.
pub fn read_text(path: &Path) -> Result<String, IngestError> {
    crate::error::read_line_records(path)
}

/// Writes `poses` as `stream` into `out`: a new recording, or, with `extend`,
/// a copy of that recording plus the poses (see [`crate::target`]; poses
/// none of which falls within that recording's time span are refused).
/// `input` is the file they came from, `source` how the metadata names it.
pub fn write_poses(
    poses: &[StampedPose],
    stream: PoseStream,
    input: &Path,
    source: &str,
    extend: Option<&Path>,
    out: &Path,
    recording: &RecordingOptions,
) -> Result<WriteSummary, IngestError> {
    let extra = BTreeMap::from([(format!("{}.source", stream.topic().trim_start_matches('/')), source.to_string())]);
    let mut target = crate::target::open_writer(
        out,
        extend,
        source,
        extra,
        poses.first().map(|p| p.t_ns),
        &[stream.topic(), stream.viz_topic()],
        recording,
    )?;
    for pose in poses {
        target.writer().write_pose(stream, pose, "world")?;
        target.added(pose.t_ns);
    }
    target.finish(input, "poses")
}

/// A trajectory file to ingest (`mmtrack ingest poses`).
#[derive(Debug, Clone)]
pub struct PoseFile<'a> {
    /// The file.
    pub path: &'a Path,
    /// Its format.
    pub format: TrajectoryFormat,
    /// KITTI: the times file and the nanoseconds added to each time.
    pub times: Option<&'a Path>,
    /// KITTI: nanoseconds added to every time of `times`.
    pub t0_ns: i64,
    /// The ground plane.
    pub plane: Plane,
}

/// `mmtrack ingest poses`: reads `file` and writes its poses as `stream`
/// into `out` (a new recording, or a copy of `extend` plus the poses), the
/// source named by its canonical path. Returns the recording and the
/// number of poses.
///
/// # Errors
/// The file cannot be read or parsed, or the recording cannot be written.
pub fn ingest_poses(
    file: &PoseFile<'_>,
    stream: PoseStream,
    extend: Option<&Path>,
    out: &Path,
    recording: &RecordingOptions,
) -> Result<(WriteSummary, usize), IngestError> {
    let trajectory = read_trajectory(file.path, file.format, file.times, file.t0_ns, file.plane)?;
    let source = format!("{}:{}", file.format.name(), mmtrack_io::paths::canonical(file.path));
    let summary = write_poses(&trajectory, stream, file.path, &source, extend, out, recording)?;
    Ok((summary, trajectory.len()))
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

    /// Before: a KITTI rotation of 2 x identity and TUM coordinates of 1e300
    /// were ingested (exit 0) and broke every metric downstream.
    #[test]
    fn implausible_coordinates_and_rotations_are_refused() {
        let err = parse_tum(Path::new("t.txt"), "1.0 1e300 2 3 0 0 0 1\n", Plane::Xy).unwrap_err().to_string();
        assert!(err.starts_with("t.txt: line 1: tx: 1e300 is not a coordinate within +-1e8 m"), "{err}");
        let twice = "2 0 0 0 0 2 0 0 0 0 2 0\n";
        let err = parse_kitti(Path::new("p.txt"), twice, &[1], Plane::Xy).unwrap_err().to_string();
        assert!(err.starts_with("p.txt: line 1: r11..r33: the rotation is not orthonormal"), "{err}");
        let mirror = "1 0 0 0 0 -1 0 0 0 0 1 0\n";
        let err = parse_kitti(Path::new("p.txt"), mirror, &[1], Plane::Xy).unwrap_err().to_string();
        assert!(err.contains("reflection"), "{err}");
        let far = "1 0 0 0 0 1 0 -2e8 0 0 1 0\n";
        let err = parse_kitti(Path::new("p.txt"), far, &[1], Plane::Xy).unwrap_err().to_string();
        assert!(err.starts_with("p.txt: line 1: ty: -200000000 is not a coordinate"), "{err}");
    }

    /// Before: a times file going backwards or too short was blamed on the
    /// pose file ("p.txt: line 2: timestamp: ... does not increase").
    #[test]
    fn a_bad_times_file_is_named_with_its_line_not_the_pose_file() {
        let dir = tempfile::tempdir().unwrap();
        let poses = dir.path().join("gt.kitti.txt");
        let times = dir.path().join("times.txt");
        std::fs::write(&poses, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n1 0 0 2 0 1 0 0 0 0 1 0\n").unwrap();
        let read = |times_text: &str| {
            std::fs::write(&times, times_text).unwrap();
            read_trajectory(&poses, TrajectoryFormat::Kitti, Some(&times), 0, Plane::Xy)
        };
        assert_eq!(read("0.0\n0.1\n0.2\n").unwrap().len(), 3);
        let err = read("0.0\n0.2\n0.1\n").unwrap_err().to_string();
        assert!(err.starts_with(&format!("{}: line 3: time: 0.1 s does not increase", times.display())), "{err}");
        let err = read("0.0\n\n0.1\n").unwrap_err().to_string();
        assert!(
            err.starts_with(&format!(
                "{}: line 3: time: 2 times for the 3 poses of {}",
                times.display(),
                poses.display()
            )) && err.contains("the times file is short"),
            "{err}"
        );
        let err = read("0.0\n0.1\n0.2\n0.3\n").unwrap_err().to_string();
        assert!(err.contains("times.txt: line 4: time: 4 times for the 3 poses") && err.contains("long"), "{err}");
    }

    #[test]
    fn a_time_offset_that_overflows_is_named_not_the_times_file() {
        let times = Path::new("times.txt");
        assert_eq!(parse_times(times, "0.5\n1.5\n", 1_000).unwrap(), vec![500_001_000, 1_500_001_000]);
        // 1.5 s plus an offset 1 s below i64::MAX overflows: the offset's fault.
        let err = parse_times(times, "0.5\n1.5\n", i64::MAX - 1_000_000_000).unwrap_err().to_string();
        assert!(err.starts_with("times.txt: line 2: t0_ns (--t0-ns): 1.5 s plus the offset"), "{err}");
        assert!(err.contains("the offset is too large"), "{err}");
        // A time beyond the i64 nanosecond range is the file's fault (it
        // was saturated to i64::MAX and accepted).
        for huge in ["1e300", "9300000000", "-1"] {
            let err = parse_times(times, huge, 0).unwrap_err().to_string();
            assert!(err.starts_with("times.txt: line 1: time:"), "{huge}: {err}");
        }
    }

    #[test]
    fn empty_trajectories_are_errors() {
        for text in ["", "# only a comment\n\n"] {
            let err = parse_tum(Path::new("t.txt"), text, Plane::Xy).unwrap_err().to_string();
            assert!(err.contains("t.txt") && err.contains("no poses"), "{err}");
        }
        let err = parse_kitti(Path::new("p.txt"), "\n", &[], Plane::Xy).unwrap_err().to_string();
        assert!(err.contains("p.txt") && err.contains("no poses"), "{err}");
    }

    #[test]
    fn zero_and_unnormalised_quaternions_are_refused() {
        let err =
            parse_tum(Path::new("t.txt"), "1.0 1 2 3 0 0 0 1\n2.0 1 2 3 0 0 0 0\n", Plane::Xy).unwrap_err().to_string();
        assert!(err.contains("t.txt: line 2: qx qy qz qw") && err.contains("norm 0"), "{err}");
        let err = parse_tum(Path::new("t.txt"), "1.0 1 2 3 0 0 0.5 0.5\n", Plane::XzCamera).unwrap_err().to_string();
        assert!(err.contains("line 1") && err.contains("norm 0.707"), "{err}");
        // Printed to 4 decimals a unit quaternion is off by ~1e-4: accepted,
        // and its yaw is that of the normalised quaternion.
        let (s, c) = 0.35f64.sin_cos();
        let text = format!("1.0 0 0 0 0 0 {s:.4} {c:.4}\n");
        let yaw = parse_tum(Path::new("t.txt"), &text, Plane::Xy).unwrap()[0].parent_from_child.yaw_rad;
        assert!((yaw - 0.7).abs() < 1e-3, "{yaw}");
    }

    /// A KITTI-like camera drive: forward along z, a left turn onto -x, the
    /// camera height (y) within 0.3 m; as TUM lines with the camera's
    /// quaternion (x right, y down, z forward).
    fn camera_drive_tum() -> String {
        let mut text = String::new();
        for i in 0..200 {
            let (x, y, z, turn) = if i < 100 {
                (0.0, 0.1 * (i as f64 * 0.3).sin(), i as f64 * 2.0, 0.0)
            } else {
                (-(i - 100) as f64 * 2.0, -0.2, 200.0, std::f64::consts::FRAC_PI_2)
            };
            // Yaw left about the up axis is a rotation about the camera's -y.
            let (s, c) = (turn / 2.0f64).sin_cos();
            text += &format!("{}.0 {x} {y} {z} 0 {} 0 {c}\n", 100 + i, -s);
        }
        text
    }

    #[test]
    fn a_vertical_axis_carrying_the_motion_is_refused() {
        let path = Path::new("camera.txt");
        let text = camera_drive_tum();
        let err = parse_tum(path, &text, Plane::Xy).unwrap_err().to_string();
        assert!(
            err.contains("camera.txt")
                && err.contains("--plane xy")
                && err.contains("y looks vertical")
                && err.contains("--plane xz-camera"),
            "{err}"
        );
        let poses = parse_tum(path, &text, Plane::XzCamera).unwrap();
        let last = poses[199].parent_from_child;
        assert!((last.x_m - 200.0).abs() < 1e-9 && (last.y_m - 198.0).abs() < 1e-9, "{last:?}");
        // The same drive written z up (x, y ground; z the height), read as a
        // camera frame, is refused the other way round.
        let z_up: String = text
            .lines()
            .map(|l| {
                let f: Vec<&str> = l.split_whitespace().collect();
                format!("{} {} {} {} 0 0 0 1\n", f[0], f[3], f[1], f[2])
            })
            .collect();
        let err = parse_tum(path, &z_up, Plane::XzCamera).unwrap_err().to_string();
        assert!(err.contains("z looks vertical") && err.contains("use --plane xy"), "{err}");
        assert_eq!(parse_tum(path, &z_up, Plane::Xy).unwrap().len(), 200);
        // A KITTI pose file likewise.
        let kitti: String = (0..50).map(|i| format!("1 0 0 0.5 0 1 0 1.6 0 0 1 {}\n", i as f64 * 3.0)).collect();
        let times: Vec<i64> = (0..50).map(|i| i * 100_000_000).collect();
        let err = parse_kitti(Path::new("00.txt"), &kitti, &times, Plane::Xy).unwrap_err().to_string();
        assert!(err.contains("00.txt") && err.contains("--plane xz-camera"), "{err}");
    }

    #[test]
    fn a_ground_vehicle_climbing_a_hill_is_accepted() {
        // 1 km east with 10 m of lateral wander while climbing 200 m: the
        // height spans a fifth of the track, under the quarter that refuses.
        let text: String = (0..=100)
            .map(|i| {
                let x = i as f64 * 10.0;
                format!("{i}.0 {x} {} {} 0 0 0 1\n", 5.0 * (x / 200.0).sin(), x / 5.0)
            })
            .collect();
        assert_eq!(parse_tum(Path::new("hill.txt"), &text, Plane::Xy).unwrap().len(), 101);
        // A handheld 0.8 m trajectory is below the 1 m floor of the check.
        let text: String = (0..10).map(|i| format!("{i}.0 0.5 0.01 {} 0 0 0 1\n", i as f64 * 0.08)).collect();
        assert_eq!(parse_tum(Path::new("hand.txt"), &text, Plane::Xy).unwrap().len(), 10);
    }
}
