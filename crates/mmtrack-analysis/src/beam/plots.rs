//! Figures of the valid-tracking experiment: RMS AoD pointing error against
//! the block, one line per scenario point or tracker, with the half-beamwidth
//! threshold (the horizontal line of Shaham et al. 2020, Figs. 2-4).

use plotters::prelude::*;

use crate::plot_common::{err, padded_range};

/// One line of a figure: its label and RMS error per block, degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct RmsCurve {
    /// Legend text.
    pub label: String,
    /// RMS AoD error of block `k` at index `k`, degrees.
    pub rms_deg: Vec<f64>,
}

/// Colours of the trackers' curves, in tracker order.
const PALETTE: [RGBColor; 7] = crate::palette::COLORS;

/// Bottom of a log-scale RMS axis: below the smallest positive value and the
/// threshold, never under 1e-3 deg.
fn log_floor_deg(positive: impl Iterator<Item = f64>, threshold_deg: f64) -> f64 {
    positive.fold(threshold_deg, f64::min).max(1e-3) * 0.8
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
    let (y_lo, y_hi) = (log_floor_deg(positive(), threshold_deg), range.end.max(threshold_deg) * 1.2);
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
        crate::plot_common::draw_axes(&mut chart, "block (1 ms)", "RMS AoD error (deg)")?;
        for (k, curve) in curves.iter().enumerate() {
            let points = curve
                .rms_deg
                .iter()
                .enumerate()
                .filter(|(_, v)| **v > 0.0 && v.is_finite())
                .map(|(k, v)| (k as f64, v.clamp(y_lo, y_hi)));
            crate::palette::draw_series_line(&mut chart, points, crate::palette::series_style(k), curve.label.clone())?;
        }
        let threshold = crate::palette::SeriesStyle::solid(BLACK, 1);
        crate::palette::draw_series_line(
            &mut chart,
            [(0.0, threshold_deg), ((blocks - 1) as f64, threshold_deg)],
            threshold,
            format!("half beamwidth ({threshold_deg:.2} deg)"),
        )?;
        crate::plot_common::draw_legend(&mut chart, SeriesLabelPosition::LowerRight)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// One line of the distance figure: RMS AoD error against the vehicle's
/// horizontal distance from the overpass.
#[derive(Debug, Clone, PartialEq)]
pub struct DistanceCurve {
    /// Legend text.
    pub label: String,
    /// Mean true distance `d` of block `k` at index `k`, metres (negative
    /// before the overpass).
    pub distance_m: Vec<f64>,
    /// RMS AoD error of block `k` at index `k`, degrees.
    pub rms_deg: Vec<f64>,
    /// Index into the palette (curves of one scenario point share it).
    pub color: usize,
    /// Drawn dashed (a baseline) rather than solid.
    pub dashed: bool,
}

/// An SVG of `curves` against the distance from the overpass, with the
/// threshold line at `threshold_deg` and a vertical line where the vehicle
/// passes under the overpass (`d = 0`); the y axis is logarithmic.
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn rms_against_distance_svg(title: &str, curves: &[DistanceCurve], threshold_deg: f64) -> anyhow::Result<String> {
    let x = padded_range(curves.iter().flat_map(|c| c.distance_m.iter().copied()).chain([0.0]));
    let positive = || curves.iter().flat_map(|c| c.rms_deg.iter().copied()).filter(|v| *v > 0.0 && v.is_finite());
    let y_lo = log_floor_deg(positive(), threshold_deg);
    let y_hi = positive().fold(threshold_deg, f64::max) * 1.2;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(65)
            .build_cartesian_2d(x.clone(), (y_lo..y_hi).log_scale())
            .map_err(err)?;
        crate::plot_common::draw_axes(
            &mut chart,
            "horizontal distance from the overpass d (m), negative before it",
            "RMS AoD error (deg)",
        )?;
        for curve in curves {
            let color = PALETTE[curve.color % PALETTE.len()];
            let points: Vec<(f64, f64)> = curve
                .distance_m
                .iter()
                .zip(&curve.rms_deg)
                .filter(|(d, v)| **v > 0.0 && v.is_finite() && d.is_finite())
                .map(|(d, v)| (*d, v.clamp(y_lo, y_hi)))
                .collect();
            let style = color.stroke_width(2);
            let series = if curve.dashed {
                chart.draw_series(DashedLineSeries::new(points, 6, 4, style))
            } else {
                chart.draw_series(LineSeries::new(points, style))
            };
            let dashed = curve.dashed;
            series.map_err(err)?.label(curve.label.clone()).legend(move |(x, y)| {
                let end = if dashed { x + 8 } else { x + 20 };
                PathElement::new(vec![(x, y), (end, y)], style)
            });
        }
        let thin = crate::palette::SeriesStyle::solid(BLACK, 1);
        crate::palette::draw_series_line(
            &mut chart,
            [(x.start, threshold_deg), (x.end, threshold_deg)],
            thin,
            format!("half beamwidth ({threshold_deg:.2} deg)"),
        )?;
        let grey = RGBColor(120, 120, 120).stroke_width(1);
        chart
            .draw_series(DashedLineSeries::new([(0.0, y_lo), (0.0, y_hi)], 8, 5, grey))
            .map_err(err)?
            .label("under the overpass (d = 0)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey));
        crate::plot_common::draw_legend(&mut chart, SeriesLabelPosition::LowerRight)?;
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

    #[test]
    fn draws_curves_against_distance_with_the_overpass_line() {
        let curve = |label: &str, dashed| DistanceCurve {
            label: label.into(),
            distance_m: (0..100).map(|k| -3.0 + 0.05 * f64::from(k)).collect(),
            rms_deg: (0..100).map(|k| 0.05 * f64::from(k)).collect(),
            color: 0,
            dashed,
        };
        let svg = rms_against_distance_svg("test", &[curve("pv", false), curve("open", true)], 4.5).unwrap();
        assert!(svg.contains("half beamwidth (4.50 deg)") && svg.contains("under the overpass (d = 0)"), "{svg}");
        assert!(svg.contains("horizontal distance from the overpass d (m)") && svg.contains("RMS AoD error (deg)"));
        assert!(svg.contains("\npv\n") && svg.contains("\nopen\n"), "both legend entries: {svg}");
    }
}

/// A beam index over time: one tracker's chosen beam, or each sweep's best.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamIndexSeries {
    /// Legend text.
    pub label: String,
    /// Sweep times, seconds from the sequence's first sweep.
    pub t_s: Vec<f64>,
    /// Beam index at each time.
    pub beam: Vec<f64>,
}

/// Beam index against time: each sweep's best beam as dots, each tracker's
/// chosen beam as a step line, over the codebook's `beam_count` beams.
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn beam_index_svg(
    title: &str,
    best: &BeamIndexSeries,
    chosen: &[BeamIndexSeries],
    beam_count: u32,
) -> anyhow::Result<String> {
    let all_t = || best.t_s.iter().chain(chosen.iter().flat_map(|c| c.t_s.iter())).copied();
    let t_end = all_t().filter(|t| t.is_finite()).fold(0.0, f64::max).max(0.1);
    let beams = f64::from(beam_count.max(1)) - 1.0;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(55)
            .build_cartesian_2d(0f64..t_end, -0.5..beams + 0.5)
            .map_err(err)?;
        crate::plot_common::draw_axes(&mut chart, "time (s)", "beam index")?;
        let dots = best.t_s.iter().zip(&best.beam).map(|(&t, &b)| Circle::new((t, b), 3, BLACK.filled()));
        chart
            .draw_series(dots)
            .map_err(err)?
            .label(best.label.clone())
            .legend(|(x, y)| Circle::new((x + 10, y), 3, BLACK.filled()));
        for (k, series) in chosen.iter().enumerate() {
            // A step line: the chosen beam holds from its sweep to the next.
            // Later trackers dashed over the first ([`crate::palette::layered_style`]),
            // so one that agrees with a later one still shows through its gaps.
            let mut points = Vec::with_capacity(2 * series.t_s.len());
            for (k, (&t, &b)) in series.t_s.iter().zip(&series.beam).enumerate() {
                if k > 0 {
                    points.push((t, series.beam[k - 1]));
                }
                points.push((t, b));
            }
            crate::palette::draw_series_line(
                &mut chart,
                points,
                crate::palette::layered_style(k),
                series.label.clone(),
            )?;
        }
        crate::plot_common::draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// One empirical loss distribution.
#[derive(Debug, Clone, PartialEq)]
pub struct LossCurve {
    /// Legend text.
    pub label: String,
    /// Received-power loss of each sweep, dB.
    pub loss_db: Vec<f64>,
}

/// Empirical CDF of the received-power loss, one line per curve, from 0 dB
/// to the largest finite loss.
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn loss_cdf_svg(title: &str, curves: &[LossCurve]) -> anyhow::Result<String> {
    let finite = || curves.iter().flat_map(|c| c.loss_db.iter().copied()).filter(|v| v.is_finite());
    let x_end = finite().fold(0.0, f64::max).max(0.5) * 1.02;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (760, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(55)
            .build_cartesian_2d(0f64..x_end, 0f64..1.0)
            .map_err(err)?;
        crate::plot_common::draw_axes(&mut chart, "received-power loss (dB)", "CDF")?;
        for (index, curve) in curves.iter().enumerate() {
            let mut sorted: Vec<f64> = curve.loss_db.iter().copied().filter(|v| v.is_finite()).collect();
            sorted.sort_by(f64::total_cmp);
            let n = sorted.len().max(1) as f64;
            // Steps: the CDF jumps at each loss value.
            let mut points = vec![(0.0, 0.0)];
            for (k, &loss) in sorted.iter().enumerate() {
                points.push((loss, k as f64 / n));
                points.push((loss, (k + 1) as f64 / n));
            }
            points.push((x_end, if sorted.is_empty() { 0.0 } else { 1.0 }));
            let style = crate::palette::layered_style(index);
            crate::palette::draw_series_line(&mut chart, points, style, curve.label.clone())?;
        }
        crate::plot_common::draw_legend(&mut chart, SeriesLabelPosition::LowerRight)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod sweep_plot_tests {
    use super::*;

    #[test]
    fn beam_index_and_loss_cdf_draw_every_series() {
        let series = |label: &str, offset: f64| BeamIndexSeries {
            label: label.into(),
            t_s: (0..20).map(|k| 0.1 * f64::from(k)).collect(),
            beam: (0..20).map(|k| 10.0 + f64::from(k) + offset).collect(),
        };
        let svg =
            beam_index_svg("pass", &series("best", 0.0), &[series("window", 1.0), series("gnss", -1.0)], 64).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("window") && svg.contains("best"), "{svg}");
        // Two step lines and their legend samples.
        assert!(svg.matches("<polyline").count() >= 4, "{svg}");
        let curves = [
            LossCurve { label: "window".into(), loss_db: vec![0.0, 0.0, 1.5, 3.0] },
            LossCurve { label: "empty".into(), loss_db: vec![] },
        ];
        let svg = loss_cdf_svg("loss", &curves).unwrap();
        assert!(svg.contains("received-power loss (dB)") && svg.contains("empty"), "{svg}");
        assert!(svg.matches("<polyline").count() >= 4, "{svg}");
    }
}
