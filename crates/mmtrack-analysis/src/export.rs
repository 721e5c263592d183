//! Trajectories as standard text files, for evo, the KITTI devkit and
//! pyboreas. Numbers are written with Rust's shortest round-trip formatting,
//! so a reader parses back exactly the `f64` we hold; times are exact decimals
//! of the integer nanoseconds. Each file appears atomically.
//!
//! | format | file | line | read by |
//! |---|---|---|---|
//! | TUM | `<seq>.estimate.tum.txt`, `<seq>.ground_truth.tum.txt` | `t_s x y z qx qy qz qw` | `evo_* tum` |
//! | KITTI | `<seq>.estimate.kitti.txt`, `<seq>.ground_truth.kitti.txt`, `<seq>.times.txt` | 12 numbers of the 3x4 `[R t]` of `world_from_vehicle`, row-major | KITTI devkit, `evo_* kitti` |
//! | Boreas | `boreas/estimate/<seq>.txt`, `boreas/ground_truth/<seq>.txt` | `t_us` + 12 numbers of `vehicle_from_world` | pyboreas odometry benchmark |
//!
//! TUM files are the tables as they are: every pose at its own time, each in
//! its own world frame (the estimate's is the first scan's pose); evo
//! associates by time itself (`--align` or `--align_origin` to compare
//! frames). KITTI files have no time stamps, so they hold the association
//! `mmtrack analyze` evaluates: one line per estimate pose inside the
//! ground-truth span, ground truth interpolated to the same instant, both
//! relative to their first pose; `times.txt` holds seconds since that pose.
//! Boreas files hold the same association with integer microseconds (floor
//! of `t_ns / 1000`), as the pyboreas benchmark asks (file name = sequence).

use std::path::{Path, PathBuf};

use mmtrack_core::{Se2, StampedPose};
use mmtrack_io::Overwrite;

use crate::pipeline::TrajectoryInput;
use crate::trajectory::{Association, associate, validate_trajectory};

/// Output format of [`export_sequence`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportFormat {
    /// TUM RGB-D trajectory format.
    Tum,
    /// KITTI odometry poses + `times.txt`.
    Kitti,
    /// pyboreas odometry benchmark (timestamp + KITTI-like matrix of `T_vehicle_world`).
    Boreas,
}

/// `t_ns` as exact decimal seconds (`123.000000456`).
#[must_use]
pub fn seconds_text(t_ns: i64) -> String {
    let sign = if t_ns < 0 { "-" } else { "" };
    let abs = t_ns.unsigned_abs();
    format!("{sign}{}.{:09}", abs / 1_000_000_000, abs % 1_000_000_000)
}

/// `+ 0.0` turns `-0.0` into `0.0` and leaves every other value unchanged.
fn num(v: f64) -> String {
    format!("{}", v + 0.0)
}

/// One TUM line: `t_s x y z qx qy qz qw` (yaw about z: `qz = sin(yaw/2)`,
/// `qw = cos(yaw/2)`).
#[must_use]
pub fn tum_line(t_ns: i64, pose: &Se2) -> String {
    let (s, c) = (0.5 * pose.yaw_rad).sin_cos();
    format!("{} {} {} 0 0 0 {} {}", seconds_text(t_ns), num(pose.x_m), num(pose.y_m), num(s), num(c))
}

/// The 12 numbers of the 3x4 matrix `[R t]` of `pose` in 3D, row-major.
#[must_use]
pub fn matrix_3x4(pose: &Se2) -> [f64; 12] {
    let (s, c) = pose.yaw_rad.sin_cos();
    [c, -s, 0.0, pose.x_m, s, c, 0.0, pose.y_m, 0.0, 0.0, 1.0, 0.0]
}

/// One KITTI line: the 3x4 matrix of `world_from_vehicle`.
#[must_use]
pub fn kitti_line(pose: &Se2) -> String {
    matrix_3x4(pose).iter().map(|v| num(*v)).collect::<Vec<_>>().join(" ")
}

/// One Boreas line: integer microseconds, then the 3x4 matrix of
/// `vehicle_from_world = world_from_vehicle.inverse()`.
#[must_use]
pub fn boreas_line(t_ns: i64, world_from_vehicle: &Se2) -> String {
    format!("{} {}", t_ns.div_euclid(1000), kitti_line(&world_from_vehicle.inverse()))
}

/// A file written by [`export_sequence`].
#[derive(Debug, Clone, PartialEq)]
pub struct ExportedFile {
    /// Where.
    pub path: PathBuf,
    /// What it holds, for the summary.
    pub what: &'static str,
    /// Lines written.
    pub lines: usize,
}

fn write_text(path: &Path, lines: &[String], overwrite: Overwrite) -> anyhow::Result<()> {
    let text: String = lines.iter().flat_map(|line| [line.as_str(), "\n"]).collect();
    mmtrack_io::atomic::write_file(path, text.as_bytes(), overwrite)?;
    Ok(())
}

/// The pair as the KITTI and Boreas files hold it: associated when ground
/// truth exists, else the estimate alone relative to its first pose.
fn frame_aligned(input: &TrajectoryInput) -> anyhow::Result<Association> {
    if let Some(truth) = &input.ground_truth {
        return Ok(associate(&input.estimate, truth)?);
    }
    validate_trajectory("estimate", &input.estimate)?;
    let estimate_first = input.estimate[0].parent_from_child;
    let first = estimate_first.inverse();
    let estimate: Vec<Se2> = input.estimate.iter().map(|p| first * p.parent_from_child).collect();
    Ok(Association {
        t_ns: input.estimate.iter().map(|p| p.t_ns).collect(),
        estimate,
        ground_truth: Vec::new(),
        estimate_first,
        ground_truth_first: Se2::IDENTITY,
        exact_matches: 0,
        interpolated: 0,
        dropped_before: 0,
        dropped_after: 0,
    })
}

/// Writes one sequence in `format` under `out_dir`.
pub fn export_sequence(
    out_dir: &Path,
    sequence: &str,
    input: &TrajectoryInput,
    format: ExportFormat,
    overwrite: Overwrite,
) -> anyhow::Result<Vec<ExportedFile>> {
    let mut files: Vec<(PathBuf, &'static str, Vec<String>)> = Vec::new();
    match format {
        ExportFormat::Tum => {
            validate_trajectory("estimate", &input.estimate)?;
            let lines = |poses: &[StampedPose]| poses.iter().map(|p| tum_line(p.t_ns, &p.parent_from_child)).collect();
            files.push((out_dir.join(format!("{sequence}.estimate.tum.txt")), "estimate", lines(&input.estimate)));
            if let Some(truth) = &input.ground_truth {
                validate_trajectory("ground truth", truth)?;
                files.push((out_dir.join(format!("{sequence}.ground_truth.tum.txt")), "ground truth", lines(truth)));
            }
        }
        ExportFormat::Kitti => {
            let a = frame_aligned(input)?;
            let t0 = a.t_ns[0];
            files.push((
                out_dir.join(format!("{sequence}.estimate.kitti.txt")),
                "estimate",
                a.estimate.iter().map(kitti_line).collect(),
            ));
            if !a.ground_truth.is_empty() {
                files.push((
                    out_dir.join(format!("{sequence}.ground_truth.kitti.txt")),
                    "ground truth at the estimate's times",
                    a.ground_truth.iter().map(kitti_line).collect(),
                ));
            }
            let times = a.t_ns.iter().map(|t| seconds_text(t - t0)).collect();
            files.push((out_dir.join(format!("{sequence}.times.txt")), "seconds since the first pose", times));
        }
        ExportFormat::Boreas => {
            let a = frame_aligned(input)?;
            let lines = |poses: &[Se2]| a.t_ns.iter().zip(poses).map(|(t, p)| boreas_line(*t, p)).collect();
            let dir = out_dir.join("boreas");
            files.push((dir.join("estimate").join(format!("{sequence}.txt")), "estimate", lines(&a.estimate)));
            if !a.ground_truth.is_empty() {
                let path = dir.join("ground_truth").join(format!("{sequence}.txt"));
                files.push((path, "ground truth at the estimate's times", lines(&a.ground_truth)));
            }
        }
    }
    // Refuse before writing anything, so a refusal leaves no partial export.
    if overwrite == Overwrite::Refuse
        && let Some((path, _, _)) = files.iter().find(|(p, _, _)| p.exists())
    {
        anyhow::bail!("{}: exists; use --force to replace it (nothing was written)", path.display());
    }
    files
        .into_iter()
        .map(|(path, what, lines)| {
            write_text(&path, &lines, overwrite)?;
            Ok(ExportedFile { path, what, lines: lines.len() })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_round_trip_exactly() {
        assert_eq!(seconds_text(1_500_000_000_000_000_123), "1500000000.000000123");
        assert_eq!(seconds_text(-5), "-0.000000005");
        let pose = Se2::new(1.0 / 3.0, -2.5e-7, 0.7);
        let kitti: Vec<f64> = kitti_line(&pose).split(' ').map(|v| v.parse().unwrap()).collect();
        assert_eq!(kitti, matrix_3x4(&pose).to_vec());
        assert_eq!(kitti_line(&Se2::IDENTITY), "1 0 0 0 0 1 0 0 0 0 1 0");
        let tum: Vec<f64> = tum_line(10, &pose).split(' ').map(|v| v.parse().unwrap()).collect();
        assert_eq!(tum[1], 1.0 / 3.0);
        // 1e-15: the quaternion's yaw 2 atan2(qz, qw) loses an ulp or two.
        assert!((2.0 * tum[6].atan2(tum[7]) - 0.7).abs() < 1e-15);
        let boreas: Vec<f64> = boreas_line(1_999, &pose).split(' ').map(|v| v.parse().unwrap()).collect();
        assert_eq!(boreas[0], 1.0);
        assert_eq!(boreas[1..].to_vec(), matrix_3x4(&pose.inverse()).to_vec());
    }
}
