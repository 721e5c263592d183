//! SVG plots of a trajectory evaluation, drawn with plotters (SVG backend
//! only: no font files, text is left to the SVG viewer). Each function returns
//! the SVG document; writing it is the caller's job. The helpers every figure
//! shares are in `plot_common`.

use plotters::coord::Shift;
use plotters::prelude::*;

use mmtrack_core::Se2;

use crate::pipeline::TrajectoryResult;
use crate::plot_common::{draw_legend, err, padded_range};

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// x-y view of one ground truth and any number of labelled estimates, equal
/// axes (a square plot area over a square range), a dot at the ground
/// truth's first pose; `frame` names the axes' frame.
fn xy_svg(frame: &str, truth: &[Se2], estimates: &[(String, Vec<Se2>)]) -> anyhow::Result<String> {
    let all = || truth.iter().chain(estimates.iter().flat_map(|e| e.1.iter()));
    let xs = padded_range(all().map(|p| p.x_m));
    let ys = padded_range(all().map(|p| p.y_m));
    let half = 0.5 * (xs.end - xs.start).max(ys.end - ys.start);
    let (cx, cy) = (0.5 * (xs.start + xs.end), 0.5 * (ys.start + ys.end));
    let mut svg = String::new();
    {
        // Equal label areas left and bottom and no caption keep the plot
        // area square, so 1 m is as long along x as along y.
        let root = SVGBackend::with_string(&mut svg, (760, 760)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .margin(15)
            .x_label_area_size(80)
            .y_label_area_size(80)
            .build_cartesian_2d((cx - half)..(cx + half), (cy - half)..(cy + half))
            .map_err(err)?;
        crate::plot_common::draw_axes(&mut chart, format!("x (m), {frame}"), format!("y (m), {frame}"))?;
        crate::palette::draw_series_line(
            &mut chart,
            truth.iter().map(|p| (p.x_m, p.y_m)),
            crate::palette::SeriesStyle::solid(BLACK, 2),
            "ground truth",
        )?;
        for (k, (label, poses)) in estimates.iter().enumerate() {
            crate::palette::draw_series_line(
                &mut chart,
                poses.iter().map(|p| (p.x_m, p.y_m)),
                crate::palette::layered_style(k),
                label.as_str(),
            )?;
        }
        if let Some(first) = truth.first() {
            chart.draw_series(std::iter::once(Circle::new((first.x_m, first.y_m), 5, BLUE.filled()))).map_err(err)?;
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// x-y view of the estimate and the ground truth as their tables hold them
/// (the frame of the estimate and `ground_truth` tables; no re-anchoring),
/// equal axes, a dot at the first associated ground-truth pose.
pub fn trajectory_svg(result: &TrajectoryResult) -> anyhow::Result<String> {
    let a = &result.association;
    xy_svg(
        "table frame",
        &a.ground_truth_in_table_frame(),
        &[(format!("estimate ({})", result.sequence), a.estimate_in_table_frame())],
    )
}

/// x-y view of both trajectories relative to their own first associated
/// pose (both start at the origin facing +x): the frame KITTI drift and the
/// RPE compare them in.
pub fn trajectory_relative_svg(result: &TrajectoryResult) -> anyhow::Result<String> {
    let a = &result.association;
    xy_svg(
        "relative to each first pose",
        &a.ground_truth,
        &[(format!("estimate ({})", result.sequence), a.estimate.clone())],
    )
}

/// Several runs' estimates of one sequence over the ground truth, in the
/// tables' frame (the compare report). The ground truth is the first run's
/// (runs of one sequence share it).
pub fn trajectory_overlay_svg(runs: &[(&str, &TrajectoryResult)]) -> anyhow::Result<String> {
    let truth = runs.first().map(|(_, r)| r.association.ground_truth_in_table_frame()).unwrap_or_default();
    let estimates: Vec<(String, Vec<Se2>)> =
        runs.iter().map(|(run, r)| (format!("run {run}"), r.association.estimate_in_table_frame())).collect();
    xy_svg("table frame", &truth, &estimates)
}

/// Several runs' frame-to-frame translation and yaw errors against the
/// distance travelled, one line per run (the compare report).
pub fn errors_overlay_svg(runs: &[(&str, &TrajectoryResult)]) -> anyhow::Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let panels = root.split_evenly((2, 1));
        type Get = fn(&crate::trajectory::RelativePoseError) -> f64;
        let panels_spec: [(&str, Get); 2] =
            [("RPE translation (m)", |e| e.translation_error_m), ("RPE yaw (deg)", |e| e.yaw_error_rad.to_degrees())];
        for (panel, (y_desc, get)) in panels.iter().zip(panels_spec) {
            let series: Vec<(String, Vec<(f64, f64)>)> = runs
                .iter()
                .map(|(run, r)| (format!("run {run}"), r.rpe.iter().map(|e| (e.distance_m, get(e))).collect()))
                .collect();
            let mut chart = ChartBuilder::on(panel)
                .margin(12)
                .x_label_area_size(50)
                .y_label_area_size(80)
                .build_cartesian_2d(
                    padded_range(series.iter().flat_map(|s| s.1.iter().map(|p| p.0))),
                    padded_range(series.iter().flat_map(|s| s.1.iter().map(|p| p.1)).chain(std::iter::once(0.0))),
                )
                .map_err(err)?;
            crate::plot_common::draw_axes(&mut chart, "distance travelled (m)", y_desc)?;
            for (k, (label, points)) in series.into_iter().enumerate() {
                crate::palette::draw_series_line(&mut chart, points, crate::palette::layered_style(k), label)?;
            }
            draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// One line chart with points on `area`.
fn line_chart(
    area: &Area<'_>,
    x_desc: &str,
    y_desc: &str,
    points: &[(f64, f64)],
    color: RGBColor,
) -> anyhow::Result<()> {
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(
            padded_range(points.iter().map(|p| p.0)),
            padded_range(points.iter().map(|p| p.1).chain(std::iter::once(0.0))),
        )
        .map_err(err)?;
    crate::plot_common::draw_axes(&mut chart, x_desc, y_desc)?;
    chart.draw_series(LineSeries::new(points.iter().copied(), color.stroke_width(1))).map_err(err)?;
    if points.len() <= 50 {
        chart.draw_series(points.iter().map(|&p| Circle::new(p, 4, color.filled()))).map_err(err)?;
    }
    Ok(())
}

fn empty_note(area: &Area<'_>, text: &str) -> anyhow::Result<()> {
    area.draw(&Text::new(text.to_string(), (40, 60), ("sans-serif", 18).into_font())).map_err(err)
}

/// Frame-to-frame translation and yaw errors against the distance travelled.
pub fn errors_vs_distance_svg(result: &TrajectoryResult) -> anyhow::Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let panels = root.split_evenly((2, 1));
        let translation: Vec<(f64, f64)> = result.rpe.iter().map(|e| (e.distance_m, e.translation_error_m)).collect();
        let yaw: Vec<(f64, f64)> = result.rpe.iter().map(|e| (e.distance_m, e.yaw_error_rad.to_degrees())).collect();
        line_chart(&panels[0], "distance travelled (m)", "RPE translation (m)", &translation, BLUE)?;
        line_chart(&panels[1], "distance travelled (m)", "RPE yaw (deg)", &yaw, RED)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// KITTI drift per segment length: translational (%) and rotational (deg/100 m).
pub fn drift_per_length_svg(result: &TrajectoryResult) -> anyhow::Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let panels = root.split_evenly((2, 1));
        let per_length = &result.drift.per_length;
        if per_length.is_empty() {
            let shortest = result.metrics.segment_lengths_m.iter().copied().fold(f64::INFINITY, f64::min);
            empty_note(
                &panels[0],
                &format!(
                    "no KITTI segment: path {:.1} m is shorter than the shortest segment length {shortest} m",
                    result.drift.path_length_m
                ),
            )?;
        } else {
            let t: Vec<(f64, f64)> = per_length.iter().map(|l| (l.length_m, l.translational_pct)).collect();
            let r: Vec<(f64, f64)> = per_length.iter().map(|l| (l.length_m, l.rotational_deg_per_m * 100.0)).collect();
            line_chart(&panels[0], "segment length (m)", "translational drift (%)", &t, BLUE)?;
            line_chart(&panels[1], "segment length (m)", "rotational drift (deg/100 m)", &r, RED)?;
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use mmtrack_core::{Se2, StampedPose};

    use super::*;
    use crate::pipeline::analyze_trajectory;
    use crate::trajectory::{DriftOptions, FirstFrameStep};

    /// The x tick labels (numeric texts anchored in the middle) of an SVG.
    fn x_ticks(svg: &str) -> Vec<f64> {
        svg.split("text-anchor=\"middle\"")
            .skip(1)
            .filter_map(|rest| rest.split('>').nth(1)?.split('<').next()?.trim().parse().ok())
            .collect()
    }

    #[test]
    fn trajectory_plot_is_in_the_tables_frame_and_the_relative_one_says_so() {
        // Ground truth 150..170 m along x at y = 40 m; the estimate in the
        // same frame, 1 % short. Re-anchored, both would start at 0.
        let pose = |k: i64, scale: f64| StampedPose {
            t_ns: k * 100_000_000,
            parent_from_child: Se2 { x_m: 150.0 + scale * k as f64, y_m: 40.0, yaw_rad: 0.0 },
        };
        let truth: Vec<StampedPose> = (0..21).map(|k| pose(k, 1.0)).collect();
        let estimate: Vec<StampedPose> = (0..21).map(|k| pose(k, 0.99)).collect();
        let options = DriftOptions { segment_lengths_m: vec![5.0], step: FirstFrameStep::Frames(1) };
        let result = analyze_trajectory("s", &estimate, &truth, &options).unwrap();
        let table = trajectory_svg(&result).unwrap();
        let ticks = x_ticks(&table);
        let (lo, hi) = (ticks.iter().copied().fold(f64::INFINITY, f64::min), ticks.iter().copied().fold(0.0, f64::max));
        assert!((140.0..=152.0).contains(&lo) && (168.0..=180.0).contains(&hi), "{ticks:?}");
        assert!(table.contains("x (m), table frame"), "the frame is named");
        let relative = trajectory_relative_svg(&result).unwrap();
        let ticks = x_ticks(&relative);
        assert!(ticks.contains(&0.0) && ticks.iter().all(|t| *t < 30.0), "{ticks:?}");
        assert!(relative.contains("x (m), relative to each first pose"), "labelled as relative");
        // Two runs overlaid: both estimates and the truth, in the tables' frame.
        let overlay = trajectory_overlay_svg(&[("a", &result), ("b", &result)]).unwrap();
        assert!(overlay.contains("run a") && overlay.contains("run b") && overlay.contains("ground truth"));
        assert!(x_ticks(&overlay).iter().all(|t| *t > 100.0), "{:?}", x_ticks(&overlay));
        let errors = errors_overlay_svg(&[("a", &result), ("b", &result)]).unwrap();
        assert_eq!(errors.matches(">\nrun b\n<").count(), 2, "one legend entry per panel");
    }
}
