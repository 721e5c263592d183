//! The Markdown report of `mmtrack analyze`: the numbers of the result tables
//! in a table per metric, and links to the plots. Deterministic: no clock, no
//! host names.

use std::fmt::Write;

use crate::compared::{Metric, TRAJECTORY_COMPARED};
use crate::pipeline::TrajectoryResult;
use crate::trajectory::DriftOptions;

/// The stored value of a compared `trajectory_metrics` column
/// ([`TRAJECTORY_COMPARED`]); the end point is given (none when pooled).
fn value_of(m: &mmtrack_io::table::TrajectoryMetrics, column: &str, end_point_m: Option<f64>) -> Option<f64> {
    match column {
        "kitti_translational_pct" => m.kitti_translational_pct,
        "kitti_rotational_deg_per_100m" => m.kitti_rotational_deg_per_100m,
        "ate_rmse_m" => Some(m.ate_rmse_m),
        "ate_max_m" => Some(m.ate_max_m),
        "x_rmse_m" => Some(m.x_rmse_m),
        "y_rmse_m" => Some(m.y_rmse_m),
        "position_rmse_m" => Some(m.position_rmse_m),
        "yaw_rmse_rad" => Some(m.yaw_rmse_rad),
        "rpe_translation_rmse_m" => Some(m.rpe_translation_rmse_m),
        "rpe_yaw_rmse_rad" => Some(m.rpe_yaw_rmse_rad),
        "final_position_error_m" => end_point_m,
        _ => None,
    }
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
        (Some(t), Some(rot)) => {
            format!("KITTI {t:.3} % {rot:.3} deg/100m ({})", mmtrack_core::words::counted(m.kitti_segments, "segment"))
        }
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
pub fn markdown(
    results: &[TrajectoryResult],
    skipped: &[(String, String)],
    options: &DriftOptions,
) -> anyhow::Result<String> {
    let mut out = String::from("# mmtrack analysis report\n\n");
    if !results.is_empty() {
        trajectory_section(&mut out, results, options)?;
    }
    out.push_str(&not_analyzed(skipped));
    Ok(out)
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

/// One row of the trajectory table; the compared columns formatted as the
/// compare report formats them ([`Metric::cell`]).
fn trajectory_row(
    name: &str,
    estimate_table: &str,
    m: &mmtrack_io::table::TrajectoryMetrics,
    end_point_m: Option<f64>,
) -> String {
    let [kitti_t, kitti_r, ate, ate_max, x, y, _position, yaw, rpe_t, rpe_yaw, end_point] =
        TRAJECTORY_COMPARED.map(|metric| (metric, value_of(m, metric.column, end_point_m)));
    let cell = |(metric, value): (Metric, Option<f64>)| metric.cell(value);
    format!(
        "| {name} | {estimate_table} | {} | {} | {:.1} | {} | {} | {} | {} | ({}, {}) | {} | {} | {} | {} |",
        m.associated_poses,
        m.dropped_poses,
        m.path_length_m,
        cell(kitti_t),
        cell(kitti_r),
        cell(ate),
        cell(ate_max),
        cell(x),
        cell(y),
        cell(yaw),
        cell(rpe_t),
        cell(rpe_yaw),
        if end_point_m.is_some() { cell(end_point) } else { "-".to_string() }
    )
}

fn trajectory_section(out: &mut String, results: &[TrajectoryResult], options: &DriftOptions) -> anyhow::Result<()> {
    let _ = write!(
        out,
        "## Trajectory (estimate against `ground_truth`)\n\n\
         The estimate (column `estimate`) is the sequence's `odometry` table (our radar odometry, `process \
         odometry`) or its `poses` table (the recording's own estimate, `process poses`). \
         Both trajectories are associated by time (ground truth interpolated); the metrics compare them from \
         their first associated pose on (both re-expressed relative to it). Per sequence, the first plot shows \
         them as the tables hold them, the second relative to each first pose. \
         KITTI drift follows the KITTI odometry devkit: segment lengths {} m, first frames {}; mean over all segments. \
         ATE is the position RMSE after the least-squares SE(2) alignment; x/y/yaw RMSE are without alignment; RPE \
         is the RMSE of the frame-to-frame relative translation and yaw errors. The pooled row (several sequences) \
         weights each sequence by what its metric averages over: KITTI drift by its segments (the mean over every \
         segment of every sequence, as the devkit pools a dataset), ATE and RMSEs by their poses, RPE by its frame \
         pairs; paths and poses are summed.\n\n",
        lengths(options),
        step(options)
    );
    out.push_str(
        "| sequence | estimate | poses | dropped | path (m) | KITTI t (%) | KITTI r (deg/100 m) | ATE (m) | \
         ATE max (m) | RMSE (x, y) (m) | yaw RMSE (deg) | RPE t (m) | RPE yaw (deg) | end-point error (m) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let pooled = if results.len() > 1 {
        crate::campaign::pooled_trajectory_metrics(&results.iter().map(|r| &r.metrics).collect::<Vec<_>>())?
    } else {
        None
    };
    // The pooled row has no end point, and its estimate is every sequence's.
    let rows = results
        .iter()
        .map(|r| {
            let table = r.estimate_table.map_or_else(|| "-".to_string(), |t| format!("`{t}`"));
            (r.sequence.as_str(), table, &r.metrics, Some(r.metrics.final_position_error_m))
        })
        .chain(pooled.as_ref().map(|p| ("all (pooled)", "-".to_string(), p, None)));
    for (name, table, m, end_point_m) in rows {
        let _ = writeln!(out, "{}", trajectory_row(name, &table, m, end_point_m));
    }
    out.push('\n');
    let without: Vec<&str> =
        results.iter().filter(|r| r.metrics.kitti_segments == 0).map(|r| r.sequence.as_str()).collect();
    if !without.is_empty() {
        let _ = writeln!(
            out,
            "KITTI drift is n/a for {}: the path is shorter than the shortest segment length ({} m); pass shorter \
             `--segment-lengths-m`.\n",
            without.iter().map(|s| format!("`{s}`")).collect::<Vec<_>>().join(", "),
            options.segment_lengths_m.iter().copied().fold(f64::INFINITY, f64::min)
        );
    }
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
            "![trajectory in the tables' frame (as the estimate and `ground_truth` hold it)](plots/{s}/trajectory.svg)\n\
             ![trajectory relative to each first pose (the frame of KITTI drift and RPE)](plots/{s}/trajectory_relative.svg)\n\
             ![errors vs distance](plots/{s}/errors_vs_distance.svg)"
        );
        if !r.drift.per_length.is_empty() {
            let _ = writeln!(out, "![drift per length](plots/{s}/drift_per_length.svg)");
        }
        out.push('\n');
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::campaign::pooled_trajectory_metrics;
    use crate::campaign::tests::trajectory as metrics;

    /// The run report shows every compared column, with the compare
    /// report's format (one formatting function for both).
    #[test]
    fn run_report_row_has_every_compared_column_in_the_compare_format() {
        let m = metrics(11, 3, Some(1.0), 1.0, 0.1);
        for metric in super::TRAJECTORY_COMPARED {
            assert!(super::value_of(&m, metric.column, Some(5.0)).is_some(), "{}", metric.column);
        }
        let text = super::trajectory_row("s", "`odometry`", &m, Some(5.0));
        // yaw 0.01 rad = 0.573 deg; RPE yaw 0.001 rad = 0.0573 deg; end point 5 m.
        assert!(text.ends_with("| 0.573 | 0.1000 | 0.0573 | 5.000 |"), "{text}");
        assert!(super::trajectory_row("all", "-", &m, None).ends_with("| 0.0573 | - |"));
    }

    #[test]
    fn pooled_row_weights_segments_poses_and_frame_pairs_by_hand() {
        // a: 11 poses (10 pairs), 3 segments at 1 %, ATE 1 m, RPE 0.1 m;
        // b: 31 poses (30 pairs), 1 segment at 5 %, ATE 2 m, RPE 0.2 m.
        let a = metrics(11, 3, Some(1.0), 1.0, 0.1);
        let b = metrics(31, 1, Some(5.0), 2.0, 0.2);
        let p = pooled_trajectory_metrics(&[&a, &b]).unwrap().unwrap();
        assert_eq!((p.associated_poses, p.kitti_segments, p.path_length_m), (42, 4, 200.0));
        // (3 x 1 + 1 x 5) / 4 = 2 %.
        assert_eq!(p.kitti_translational_pct, Some(2.0));
        // sqrt((11 x 1 + 31 x 4) / 42) and sqrt((10 x 0.01 + 30 x 0.04) / 40).
        assert!((p.ate_rmse_m - (135.0f64 / 42.0).sqrt()).abs() < 1e-12);
        assert!((p.rpe_translation_rmse_m - (1.3f64 / 40.0).sqrt()).abs() < 1e-12);
        assert_eq!(p.ate_max_m, 4.0);
        // A sequence without segments adds none and no drift.
        let short = metrics(5, 0, None, 1.0, 0.1);
        let p = pooled_trajectory_metrics(&[&a, &short]).unwrap().unwrap();
        assert_eq!((p.kitti_translational_pct, p.kitti_segments), (Some(1.0), 3));
    }
}
