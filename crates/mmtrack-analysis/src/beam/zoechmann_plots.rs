//! The geometric Doppler-bearing tracking experiment of Zoechmann et al.
//! 2019 (`mmtrack reproduce zoechmann`): its figures (its tables are in
//! [`mmtrack_io::table`]), like the paper's Figs. 4 and 5: the `(x, y)` estimate of the proposed
//! tracker on the first Monte Carlo run against the true path (middle panel)
//! and the NMSE of the range over time for the four estimators (bottom
//! panel), one figure per manoeuvre; and the non-line-of-sight figure
//! ([`zoechmann_nlos_svg`]): each path's apparent source (the transmitter or
//! its wall image) on a map of the scene, and its RMS position error over
//! time.
//!
//! NMSE of the range at epoch `k` over the runs `n`:
//! `sum_n (r^_k,n - r_k,n)^2 / sum_n r_k,n^2`, in dB. The paper plots an
//! NMSE without defining its normalisation; this is the usual one.

use plotters::prelude::*;

use crate::plot_common::{err, padded_range};
use mmtrack_io::table::{ZoechmannNlosErrorRow, ZoechmannPathLabelRow};

/// One NMSE curve: label and NMSE (linear) per epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct NmseCurve {
    /// Legend text.
    pub label: String,
    /// NMSE of epoch `k` at index `k` (linear; plotted in dB).
    pub nmse: Vec<f64>,
}

/// The `(x, y)` panel: the true path and the estimates of one run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PositionTrace {
    /// True positions per epoch, metres.
    pub truth_m: Vec<[f64; 2]>,
    /// Estimated positions per epoch, metres.
    pub estimate_m: Vec<[f64; 2]>,
}

/// A figure like Figs. 4-5 of the paper: the first run's `(x, y)` estimate
/// over the true path (top) and the NMSE of the range in dB against time
/// (bottom), epochs `epoch_s` apart.
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn zoechmann_figure_svg(
    title: &str,
    trace: &PositionTrace,
    curves: &[NmseCurve],
    epoch_s: f64,
) -> anyhow::Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 900)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
        let panels = root.split_evenly((2, 1));
        draw_trace(&panels[0], trace)?;
        draw_nmse(&panels[1], curves, epoch_s)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

fn draw_trace(area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>, trace: &PositionTrace) -> anyhow::Result<()> {
    // The axes follow the true path (and the receiver), padded by 30 % or
    // 5 m: a diverged estimate must not squash the picture; estimates outside
    // are counted in the legend.
    let pad = |r: std::ops::Range<f64>| {
        let p = (0.3 * (r.end - r.start)).max(5.0);
        (r.start - p)..(r.end + p)
    };
    let x = pad(padded_range(trace.truth_m.iter().map(|p| p[0]).chain([0.0])));
    let y = pad(padded_range(trace.truth_m.iter().map(|p| p[1]).chain([0.0])));
    let inside: Vec<(f64, f64)> =
        trace.estimate_m.iter().map(|p| (p[0], p[1])).filter(|(a, b)| x.contains(a) && y.contains(b)).collect();
    let outside = trace.estimate_m.len() - inside.len();
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    crate::plot_common::draw_axes(&mut chart, "x along the receiver's heading (m)", "y (m)")?;
    let truth = crate::palette::SeriesStyle::solid(BLACK, 2);
    crate::palette::draw_series_line(&mut chart, trace.truth_m.iter().map(|p| (p[0], p[1])), truth, "true path")?;
    chart
        .draw_series(inside.iter().map(|&p| Cross::new(p, 3, RED.stroke_width(1))))
        .map_err(err)?
        .label(if outside == 0 {
            "proposed, first run".to_string()
        } else {
            format!("proposed, first run ({outside} estimates outside the frame)")
        })
        .legend(|(x, y)| Cross::new((x + 10, y), 3, RED.stroke_width(1)));
    chart
        .draw_series([Circle::new((0.0, 0.0), 5, BLUE.filled())])
        .map_err(err)?
        .label("receiver array")
        .legend(|(x, y)| Circle::new((x + 10, y), 4, BLUE.filled()));
    crate::plot_common::draw_legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    Ok(())
}

fn draw_nmse(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    curves: &[NmseCurve],
    epoch_s: f64,
) -> anyhow::Result<()> {
    let db = |v: f64| 10.0 * v.log10();
    let values = || curves.iter().flat_map(|c| c.nmse.iter().copied()).filter(|v| *v > 0.0 && v.is_finite()).map(db);
    let y = padded_range(values());
    let epochs = curves.iter().map(|c| c.nmse.len()).max().unwrap_or(2).max(2);
    let t_end = (epochs - 1) as f64 * epoch_s;
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(0f64..t_end, y.clone())
        .map_err(err)?;
    crate::plot_common::draw_axes(&mut chart, "time (s)", "NMSE of the range (dB)")?;
    // Variants (after the paper's four) thin and first, so the four stay on top.
    let order: Vec<usize> = (4..curves.len()).chain(0..curves.len().min(4)).collect();
    for index in order {
        let curve = &curves[index];
        // The paper's four 3 px, the variants 2 px: each keeps its own colour and dash.
        let style = crate::palette::SeriesStyle {
            width_px: if index < 4 { 3 } else { 2 },
            ..crate::palette::series_style(index)
        };
        let points = curve
            .nmse
            .iter()
            .enumerate()
            .filter(|(_, v)| **v > 0.0 && v.is_finite())
            .map(|(k, v)| (k as f64 * epoch_s, db(*v).clamp(y.start, y.end)));
        crate::palette::draw_series_line(&mut chart, points, style, curve.label.clone())?;
    }
    crate::plot_common::draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    Ok(())
}

/// Colours of the paths, in order of first appearance.
const PATH_COLORS: [RGBColor; 7] = crate::palette::COLORS;

/// The non-line-of-sight figure of `reproduce zoechmann`: a map of the scene
/// (top: the walls at `y = walls_y_m[0]` and `walls_y_m[1]`, the receiver
/// at the origin, per path the true track of the apparent source, the first
/// run's estimates and the reflection points) and the RMS position error of
/// each path over time (bottom, log axis), paths in order of first
/// appearance in `errors`.
///
/// The map's axes follow the true tracks, reflection points, receiver and
/// walls (padded, with room for the legend above); estimates outside (an
/// unconverged start) are counted in the legend, not drawn.
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn zoechmann_nlos_svg(
    title: &str,
    walls_y_m: [f64; 2],
    labels: &[ZoechmannPathLabelRow],
    errors: &[ZoechmannNlosErrorRow],
) -> anyhow::Result<String> {
    let mut paths: Vec<&str> = Vec::new();
    for name in errors.iter().map(|e| e.path.as_str()).chain(labels.iter().map(|l| l.path.as_str())) {
        if !paths.contains(&name) {
            paths.push(name);
        }
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 1000)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
        let panels = root.split_evenly((2, 1));
        draw_nlos_map(&panels[0], walls_y_m, &paths, labels)?;
        draw_nlos_errors(&panels[1], &paths, errors)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

fn draw_nlos_map(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    walls_y_m: [f64; 2],
    paths: &[&str],
    labels: &[ZoechmannPathLabelRow],
) -> anyhow::Result<()> {
    let reflections = || labels.iter().filter_map(|l| l.reflection_x_m.zip(l.reflection_y_m));
    let xs = labels.iter().map(|l| l.true_x_m).chain(reflections().map(|p| p.0)).chain([0.0]);
    let ys = labels.iter().map(|l| l.true_y_m).chain(reflections().map(|p| p.1)).chain(walls_y_m).chain([0.0]);
    let pad = |r: std::ops::Range<f64>| {
        let p = (0.1 * (r.end - r.start)).max(2.0);
        (r.start - p)..(r.end + p)
    };
    let (x, y) = (pad(padded_range(xs)), pad(padded_range(ys)));
    // Room above the scene for the legend (up to ten entries).
    let y = y.start..(y.end + 0.8 * (y.end - y.start));
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(x.clone(), y.clone())
        .map_err(err)?;
    crate::plot_common::draw_axes(&mut chart, "x along the receiver's heading (m)", "y (m)")?;
    let wall = BLACK.stroke_width(3);
    for (i, wall_y) in walls_y_m.into_iter().enumerate() {
        let drawn = chart.draw_series(LineSeries::new([(x.start, wall_y), (x.end, wall_y)], wall)).map_err(err)?;
        if i == 0 {
            drawn.label("walls").legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], wall));
        }
    }
    chart
        .draw_series([Circle::new((0.0, 0.0), 5, BLACK.filled())])
        .map_err(err)?
        .label("receiver")
        .legend(|(x, y)| Circle::new((x + 10, y), 4, BLACK.filled()));
    for (i, path) in paths.iter().enumerate() {
        let color = PATH_COLORS[i % PATH_COLORS.len()];
        let rows: Vec<&ZoechmannPathLabelRow> = labels.iter().filter(|l| l.path == *path).collect();
        let truth = crate::palette::SeriesStyle::solid(color, 2);
        crate::palette::draw_series_line(
            &mut chart,
            rows.iter().map(|l| (l.true_x_m, l.true_y_m)),
            truth,
            format!("{path}: true apparent source"),
        )?;
        let estimates: Vec<(f64, f64)> = rows.iter().map(|l| (l.x_m, l.y_m)).collect();
        let inside: Vec<(f64, f64)> =
            estimates.iter().copied().filter(|(a, b)| x.contains(a) && y.contains(b)).collect();
        let outside = estimates.len() - inside.len();
        let mark = color.mix(0.6).stroke_width(1);
        chart
            .draw_series(inside.iter().map(|&p| Cross::new(p, 2, mark)))
            .map_err(err)?
            .label(if outside == 0 {
                format!("{path}: estimates of the first run")
            } else {
                format!("{path}: estimates of the first run ({outside} outside the frame)")
            })
            .legend(move |(x, y)| Cross::new((x + 10, y), 3, mark));
        let points: Vec<(f64, f64)> = rows.iter().filter_map(|l| l.reflection_x_m.zip(l.reflection_y_m)).collect();
        if !points.is_empty() {
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 2, color.filled())))
                .map_err(err)?
                .label(format!("{path}: reflection points"))
                .legend(move |(x, y)| Circle::new((x + 10, y), 3, color.filled()));
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .label_font(crate::plot_common::LEGEND_FONT)
        .draw()
        .map_err(err)?;
    Ok(())
}

fn draw_nlos_errors(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    paths: &[&str],
    errors: &[ZoechmannNlosErrorRow],
) -> anyhow::Result<()> {
    let shown = |e: &&ZoechmannNlosErrorRow| e.position_rmse_m > 0.0 && e.position_rmse_m.is_finite();
    let (lo, hi) = errors
        .iter()
        .filter(shown)
        .fold((f64::INFINITY, 0.0f64), |(a, b), e| (a.min(e.position_rmse_m), b.max(e.position_rmse_m)));
    let (lo, hi) = if lo.is_finite() { (lo / 1.5, hi * 1.5) } else { (1e-2, 1e2) };
    let t_end = errors.iter().map(|e| e.t_ns as f64 * 1e-9).fold(0.0f64, f64::max).max(1e-3);
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(0f64..t_end, (lo..hi).log_scale())
        .map_err(err)?;
    crate::plot_common::axes(&mut chart, "time (s)", "RMS position error (m)")
        .y_label_formatter(&|v| format!("{v:.2}"))
        .draw()
        .map_err(err)?;
    for (i, path) in paths.iter().enumerate() {
        let style = crate::palette::SeriesStyle::solid(PATH_COLORS[i % PATH_COLORS.len()], 2);
        let points =
            errors.iter().filter(|e| e.path == *path).filter(shown).map(|e| (e.t_ns as f64 * 1e-9, e.position_rmse_m));
        crate::palette::draw_series_line(&mut chart, points, style, format!("{path}: RMS position error"))?;
    }
    crate::plot_common::draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_both_panels() {
        let trace = PositionTrace {
            truth_m: (0..50).map(|k| [0.4 * k as f64, 8.0]).collect(),
            estimate_m: (0..50).map(|k| [0.4 * k as f64, 8.1]).chain([[f64::NAN, 1.0]]).collect(),
        };
        let curves = vec![
            NmseCurve { label: "proposed".into(), nmse: (1..50).map(|k| 1.0 / k as f64).collect() },
            NmseCurve { label: "ho-chan".into(), nmse: vec![0.0, f64::NAN, 0.5, 0.4] },
        ];
        let svg = zoechmann_figure_svg("test", &trace, &curves, 0.02).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("NMSE of the range (dB)") && svg.contains("true path"));
        assert!(svg.matches("<polyline").count() >= 4, "{svg}");
    }

    #[test]
    fn nlos_figure_has_the_map_and_one_error_curve_per_path() {
        let label = |path: &str, k: usize, image_y: f64, reflection: Option<[f64; 2]>| ZoechmannPathLabelRow {
            path: path.into(),
            t_ns: 20_000_000 * k as i64,
            x_m: if k == 0 { 1e5 } else { -10.0 + 0.4 * k as f64 },
            y_m: image_y + 0.1,
            vx_mps: 20.0,
            vy_mps: 0.0,
            true_x_m: -10.0 + 0.4 * k as f64,
            true_y_m: image_y,
            true_vx_mps: 20.0,
            true_vy_mps: 0.0,
            reflection_x_m: reflection.map(|r| r[0]),
            reflection_y_m: reflection.map(|r| r[1]),
        };
        let paths = [("los", 2.0, None), ("left-wall", 13.0, Some(7.5)), ("right-wall", -9.0, Some(-3.5))];
        let mut labels = Vec::new();
        let mut errors = Vec::new();
        for (path, image_y, wall) in paths {
            for k in 0..50 {
                labels.push(label(path, k, image_y, wall.map(|w| [-5.0 + 0.2 * k as f64, w])));
                errors.push(ZoechmannNlosErrorRow {
                    path: path.into(),
                    epoch: k as u64,
                    t_ns: 20_000_000 * k as i64,
                    runs: 10,
                    position_rmse_m: if k == 0 { f64::NAN } else { 10.0 / k as f64 },
                    velocity_rmse_mps: 1.0,
                });
            }
        }
        let svg = zoechmann_nlos_svg("nlos", [7.5, -3.5], &labels, &errors).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("x along the receiver"), "map panel");
        assert!(svg.contains("RMS position error (m)"), "error panel");
        // Text sits on its own line in plotters' SVG.
        for ((path, _, _), color) in paths.iter().zip(["#E69F00", "#0072B2", "#009E73"]) {
            assert_eq!(svg.matches(&format!("\n{path}: RMS position error\n")).count(), 1, "{path}");
            assert!(svg.contains(&format!("\n{path}: estimates of the first run (1 outside the frame)\n")), "{path}");
            // In the path's colour at width 2: its true track and its error
            // curve, each with a legend sample; nothing else.
            let line = format!("<polyline fill=\"none\" opacity=\"1\" stroke=\"{color}\" stroke-width=\"2\"");
            assert_eq!(svg.matches(&line).count(), 4, "{path}");
        }
        assert!(svg.contains("\nleft-wall: reflection points\n") && !svg.contains("los: reflection points"));
        // Both walls span the map (plus the legend sample).
        assert_eq!(svg.matches("stroke=\"#000000\" stroke-width=\"3\"").count(), 3);
    }
}
