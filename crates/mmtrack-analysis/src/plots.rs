//! SVG plots of a trajectory evaluation, drawn with plotters (SVG backend
//! only: no font files, text is left to the SVG viewer). Each function returns
//! the SVG document; writing it is the caller's job. The helpers every figure
//! shares are in `plot_common`.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::pipeline::TrajectoryResult;
use crate::plot_common::{draw_legend, err, padded_range};

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// x-y view of the estimate and the ground truth (both from the identity),
/// equal axes: a square plot area over a square range.
pub fn trajectory_svg(result: &TrajectoryResult) -> anyhow::Result<String> {
    let est = &result.association.estimate;
    let gt = &result.association.ground_truth;
    let all = || est.iter().chain(gt.iter());
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
            .x_label_area_size(55)
            .y_label_area_size(55)
            .build_cartesian_2d((cx - half)..(cx + half), (cy - half)..(cy + half))
            .map_err(err)?;
        chart.configure_mesh().x_desc("x (m)").y_desc("y (m)").draw().map_err(err)?;
        chart
            .draw_series(LineSeries::new(gt.iter().map(|p| (p.x_m, p.y_m)), BLACK.stroke_width(2)))
            .map_err(err)?
            .label("ground truth")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
        chart
            .draw_series(LineSeries::new(est.iter().map(|p| (p.x_m, p.y_m)), RED.stroke_width(2)))
            .map_err(err)?
            .label(format!("estimate ({})", result.sequence))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
        chart.draw_series(std::iter::once(Circle::new((0.0, 0.0), 5, BLUE.filled()))).map_err(err)?;
        draw_legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
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
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            padded_range(points.iter().map(|p| p.0)),
            padded_range(points.iter().map(|p| p.1).chain(std::iter::once(0.0))),
        )
        .map_err(err)?;
    chart.configure_mesh().x_desc(x_desc).y_desc(y_desc).draw().map_err(err)?;
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
