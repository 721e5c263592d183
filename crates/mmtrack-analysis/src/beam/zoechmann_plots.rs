//! The geometric Doppler-bearing tracking experiment of Zoechmann et al.
//! 2019 (`mmtrack reproduce zoechmann`): its figures (its tables are in
//! [`super::zoechmann_tables`]), like the paper's Figs. 4 and 5: the `(x, y)` estimate of the proposed
//! tracker on the first Monte Carlo run against the true path (middle panel)
//! and the NMSE of the range over time for the four estimators (bottom
//! panel), one figure per manoeuvre.
//!
//! NMSE of the range at epoch `k` over the runs `n`:
//! `sum_n (r^_k,n - r_k,n)^2 / sum_n r_k,n^2`, in dB. The paper plots an
//! NMSE without defining its normalisation; this is the usual one.

use plotters::prelude::*;

use crate::plots::{err, padded_range};

// The rows `reproduce zoechmann` and its test still import from here; new
// code names `zoechmann_tables`.
pub use super::zoechmann_tables::{
    ZoechmannNlosErrorRow, ZoechmannNmseRow, ZoechmannPathLabelRow, ZoechmannSummaryRow,
};

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
    chart.configure_mesh().x_desc("x along the receiver's heading (m)").y_desc("y (m)").draw().map_err(err)?;
    let truth = BLACK.stroke_width(2);
    chart
        .draw_series(LineSeries::new(trace.truth_m.iter().map(|p| (p[0], p[1])), truth))
        .map_err(err)?
        .label("true path")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], truth));
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
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .draw()
        .map_err(err)?;
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
    let palette = [RED, BLUE, GREEN, MAGENTA, CYAN, BLACK];
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(0f64..t_end, y.clone())
        .map_err(err)?;
    chart.configure_mesh().x_desc("time (s)").y_desc("NMSE of the range (dB)").draw().map_err(err)?;
    // Variants (after the paper's four) thin and first, so the four stay on top.
    let order: Vec<usize> = (4..curves.len()).chain(0..curves.len().min(4)).collect();
    for index in order {
        let (curve, color) = (&curves[index], palette[index % palette.len()]);
        let style = color.stroke_width(if index < 4 { 2 } else { 1 });
        let points = curve
            .nmse
            .iter()
            .enumerate()
            .filter(|(_, v)| **v > 0.0 && v.is_finite())
            .map(|(k, v)| (k as f64 * epoch_s, db(*v).clamp(y.start, y.end)));
        chart
            .draw_series(LineSeries::new(points, style))
            .map_err(err)?
            .label(curve.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .draw()
        .map_err(err)?;
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
}
