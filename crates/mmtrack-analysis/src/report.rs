//! The Markdown report of `mmtrack analyze`: the numbers of the result tables
//! in a table per metric, and links to the plots. Deterministic: no clock, no
//! host names.

use std::fmt::Write;

use crate::pipeline::TrajectoryResult;
use crate::trajectory::DriftOptions;

fn opt(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "n/a".to_string(), |v| format!("{v:.decimals$}"))
}

fn lengths(options: &DriftOptions) -> String {
    options.segment_lengths_m.iter().map(|l| format!("{l}")).collect::<Vec<_>>().join(", ")
}

fn step(options: &DriftOptions) -> String {
    match options.step {
        crate::trajectory::FirstFrameStep::Frames(n) => format!("every {n} frame{}", if n == 1 { "" } else { "s" }),
        crate::trajectory::FirstFrameStep::Metres(m) => format!("every {m} m"),
    }
}

/// The one-line summary of a sequence, as the CLI prints it.
#[must_use]
pub fn one_line(r: &TrajectoryResult) -> String {
    let m = &r.metrics;
    let kitti = match (m.kitti_translational_pct, m.kitti_rotational_deg_per_100m) {
        (Some(t), Some(rot)) => format!("KITTI {t:.3} % {rot:.3} deg/100m ({} segments)", m.kitti_segments),
        _ => format!(
            "KITTI n/a (path {:.1} m shorter than the shortest segment length {} m)",
            m.path_length_m,
            m.segment_lengths_m.iter().copied().fold(f64::INFINITY, f64::min)
        ),
    };
    format!(
        "{}: {} poses over {:.1} m, {kitti}, ATE {:.3} m, end-point error {:.3} m{}",
        r.sequence,
        m.associated_poses,
        m.path_length_m,
        m.ate_rmse_m,
        m.final_position_error_m,
        if m.dropped_poses > 0 {
            format!(
                ", {} estimate pose{} outside the ground-truth span dropped",
                m.dropped_poses,
                if m.dropped_poses == 1 { "" } else { "s" }
            )
        } else {
            String::new()
        }
    )
}

/// The report, with links relative to the output directory.
#[must_use]
pub fn markdown(results: &[TrajectoryResult], skipped: &[(String, String)], options: &DriftOptions) -> String {
    let mut out = String::from("# mmtrack analysis report\n\n");
    if !results.is_empty() {
        trajectory_section(&mut out, results, options);
    }
    out.push_str(&not_analyzed(skipped));
    out
}

/// The "Not analyzed" section (empty when nothing was skipped).
#[must_use]
pub fn not_analyzed(skipped: &[(String, String)]) -> String {
    let mut out = String::new();
    if !skipped.is_empty() {
        out.push_str("## Not analyzed\n\n");
        for (sequence, reason) in skipped {
            let _ = writeln!(out, "- `{sequence}`: {reason}");
        }
        out.push('\n');
    }
    out
}

fn trajectory_section(out: &mut String, results: &[TrajectoryResult], options: &DriftOptions) {
    let _ = write!(
        out,
        "## Trajectory (table `odometry` against `ground_truth`)\n\n\
         Both trajectories are associated by time (ground truth interpolated) and start at the identity. \
         KITTI drift follows the KITTI odometry devkit: segment lengths {} m, first frames {}; mean over all segments. \
         ATE is the position RMSE after the least-squares SE(2) alignment; x/y/yaw RMSE are without alignment.\n\n",
        lengths(options),
        step(options)
    );
    out.push_str(
        "| sequence | poses | dropped | path (m) | KITTI t (%) | KITTI r (deg/m) | KITTI r (deg/100 m) | ATE (m) | \
         RMSE (x, y) (m) | yaw RMSE (deg) | end-point error (m) |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in results {
        let m = &r.metrics;
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.1} | {} | {} | {} | {:.3} | ({:.3}, {:.3}) | {:.3} | {:.3} |",
            r.sequence,
            m.associated_poses,
            m.dropped_poses,
            m.path_length_m,
            opt(m.kitti_translational_pct, 3),
            opt(m.kitti_rotational_deg_per_m, 5),
            opt(m.kitti_rotational_deg_per_100m, 3),
            m.ate_rmse_m,
            m.x_rmse_m,
            m.y_rmse_m,
            m.yaw_rmse_rad.to_degrees(),
            m.final_position_error_m
        );
    }
    out.push('\n');
    for r in results {
        let _ = writeln!(out, "### `{}`\n", r.sequence);
        if r.drift.per_length.is_empty() {
            let _ = writeln!(
                out,
                "No KITTI segment: the ground-truth path ({:.1} m) is shorter than the shortest segment length.\n",
                r.drift.path_length_m
            );
        } else {
            out.push_str("| segment length (m) | segments | t (%) | r (deg/100 m) |\n|---|---|---|---|\n");
            for l in &r.drift.per_length {
                let _ = writeln!(
                    out,
                    "| {} | {} | {:.3} | {:.3} |",
                    l.length_m,
                    l.segments,
                    l.translational_pct,
                    l.rotational_deg_per_m * 100.0
                );
            }
            out.push('\n');
        }
        let s = &r.sequence;
        let _ = writeln!(
            out,
            "![trajectory](plots/{s}/trajectory.svg)\n![errors vs distance](plots/{s}/errors_vs_distance.svg)\n\
             ![drift per length](plots/{s}/drift_per_length.svg)\n"
        );
    }
}
