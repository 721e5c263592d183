//! Figures of the valid-tracking experiment: RMS AoD pointing error against
//! the block, one line per scenario point or tracker, with the half-beamwidth
//! threshold (the horizontal line of Shaham et al. 2020, Figs. 2-4).

use plotters::prelude::*;

use crate::plots::{err, padded_range};

/// One line of a figure: its label and RMS error per block, degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct RmsCurve {
    /// Legend text.
    pub label: String,
    /// RMS AoD error of block `k` at index `k`, degrees.
    pub rms_deg: Vec<f64>,
}

/// An SVG of `curves` with the threshold line at `threshold_deg`; the y axis
/// is logarithmic like the paper's MSE plots.
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn rms_curves_svg(title: &str, curves: &[RmsCurve], threshold_deg: f64) -> anyhow::Result<String> {
    let blocks = curves.iter().map(|c| c.rms_deg.len()).max().unwrap_or(1).max(2);
    let positive = || curves.iter().flat_map(|c| c.rms_deg.iter().copied()).filter(|v| *v > 0.0 && v.is_finite());
    let range = padded_range(positive().chain([threshold_deg]));
    let (y_lo, y_hi) = (positive().fold(threshold_deg, f64::min).max(1e-3) * 0.8, range.end.max(threshold_deg) * 1.2);
    let palette = [RED, BLUE, GREEN, MAGENTA, CYAN, BLACK, RGBColor(230, 140, 0)];
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(65)
            .build_cartesian_2d(0f64..(blocks - 1) as f64, (y_lo..y_hi).log_scale())
            .map_err(err)?;
        chart.configure_mesh().x_desc("block (1 ms)").y_desc("RMS AoD error (deg)").draw().map_err(err)?;
        for (curve, color) in curves.iter().zip(palette.iter().cycle()) {
            let points = curve
                .rms_deg
                .iter()
                .enumerate()
                .filter(|(_, v)| **v > 0.0 && v.is_finite())
                .map(|(k, v)| (k as f64, v.clamp(y_lo, y_hi)));
            let style = color.stroke_width(2);
            chart
                .draw_series(LineSeries::new(points, style))
                .map_err(err)?
                .label(curve.label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        }
        let threshold = BLACK.stroke_width(1);
        chart
            .draw_series(LineSeries::new([(0.0, threshold_deg), ((blocks - 1) as f64, threshold_deg)], threshold))
            .map_err(err)?
            .label(format!("half beamwidth ({threshold_deg:.2} deg)"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], threshold));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .border_style(BLACK)
            .background_style(WHITE.mix(0.85))
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_curves_and_threshold() {
        let curves = vec![
            RmsCurve { label: "a".into(), rms_deg: (0..50).map(|k| 0.1 * k as f64).collect() },
            RmsCurve { label: "b".into(), rms_deg: vec![0.0, f64::NAN, 1.0, 2.0] },
        ];
        let svg = rms_curves_svg("test", &curves, 4.5).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("half beamwidth (4.50 deg)"), "{svg}");
        // Two curves, the threshold and their three legend samples.
        assert!(svg.matches("<polyline").count() >= 6, "{svg}");
    }
}
