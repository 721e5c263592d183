//! The figure of `mmtrack analyze` for one `geometric_per_epoch` sequence
//! (Zoechmann et al. 2019): range (10) and azimuth (11) estimated against
//! the truth over time, and the beams measured per epoch, with the
//! H-infinity ("not converged") span shaded in every panel.

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use crate::plot_common::{err, padded_range};

/// One sequence against the truth, per epoch (index = epoch).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GeometricTrackingSeries {
    /// Time since the first epoch, seconds.
    pub t_s: Vec<f64>,
    /// Estimated range, metres.
    pub range_m: Vec<f64>,
    /// True range, metres.
    pub true_range_m: Vec<f64>,
    /// Estimated azimuth, degrees in (-180, 180].
    pub azimuth_deg: Vec<f64>,
    /// True azimuth, degrees in (-180, 180].
    pub true_azimuth_deg: Vec<f64>,
    /// Beams measured per epoch.
    pub beams_measured: Vec<u64>,
    /// Time of the hand-over to RLS since the first epoch; `None`: never
    /// (the whole run is shaded).
    pub handover_s: Option<f64>,
    /// Beams of a full scan.
    pub codebook_beams: u64,
}

type Area<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;
type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Three stacked panels against time: range (truth black, estimate red),
/// azimuth (the same; lines break where an angle wraps through +-180 deg)
/// and beams measured per epoch (a full scan is the codebook). The span
/// before the hand-over to RLS is shaded grey.
///
/// The range axis follows the truth (up to three times its largest value):
/// an unconverged estimate can be far off and must not flatten the truth;
/// estimates beyond the axis are drawn at its edge and counted in the legend.
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn geometric_tracking_svg(title: &str, series: &GeometricTrackingSeries) -> anyhow::Result<String> {
    let s = series;
    let t_end = s.t_s.last().copied().filter(|t| *t > 0.0).unwrap_or(1.0);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1000, 900)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
        let areas = root.split_evenly((3, 1));
        draw_range(&areas[0], s, t_end)?;
        draw_azimuth(&areas[1], s, t_end)?;
        draw_beams(&areas[2], s, t_end)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

fn chart<'a, 'b>(
    area: &'a Area<'b>,
    t_end: f64,
    y: std::ops::Range<f64>,
    y_desc: &str,
) -> anyhow::Result<Chart<'a, 'b>> {
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(0f64..t_end, y)
        .map_err(err)?;
    crate::plot_common::draw_axes(&mut chart, "time since the first epoch (s)", y_desc)?;
    Ok(chart)
}

/// The H-infinity span, `[0, hand-over)` or the whole run, shaded.
fn shade(chart: &mut Chart<'_, '_>, s: &GeometricTrackingSeries, t_end: f64) -> anyhow::Result<()> {
    let until = s.handover_s.unwrap_or(t_end);
    if until <= 0.0 {
        return Ok(());
    }
    let (x, y) = (chart.x_range(), chart.y_range());
    let fill = BLACK.mix(0.12).filled();
    chart
        .draw_series([Rectangle::new([(x.start, y.start), (until.min(x.end), y.end)], fill)])
        .map_err(err)?
        .label("H-infinity (not converged)")
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 20, y + 5)], fill));
    Ok(())
}

fn legend<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>) -> anyhow::Result<()> {
    crate::plot_common::draw_legend(chart, SeriesLabelPosition::UpperRight)
}

/// A line with its legend entry.
fn line(
    chart: &mut Chart<'_, '_>,
    segments: Vec<Vec<(f64, f64)>>,
    style: ShapeStyle,
    label: &str,
) -> anyhow::Result<()> {
    for (i, segment) in segments.into_iter().enumerate() {
        let drawn = chart.draw_series(LineSeries::new(segment, style)).map_err(err)?;
        if i == 0 {
            drawn.label(label).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        }
    }
    Ok(())
}

fn draw_range(area: &Area<'_>, s: &GeometricTrackingSeries, t_end: f64) -> anyhow::Result<()> {
    let true_max = s.true_range_m.iter().copied().filter(|v| v.is_finite()).fold(0.0f64, f64::max);
    let cap = if true_max > 0.0 { 3.0 * true_max } else { f64::INFINITY };
    let shown = s.true_range_m.iter().chain(&s.range_m).copied().filter(|v| v.is_finite()).map(|v| v.min(cap));
    let y = padded_range(shown.chain([0.0]));
    let mut chart = chart(area, t_end, y.clone(), "range (m)")?;
    shade(&mut chart, s, t_end)?;
    let outside = s.range_m.iter().filter(|v| !y.contains(*v)).count();
    let points = |values: &[f64]| -> Vec<Vec<(f64, f64)>> {
        vec![
            s.t_s
                .iter()
                .zip(values)
                .filter(|(_, v)| v.is_finite())
                .map(|(t, v)| (*t, v.clamp(y.start, y.end)))
                .collect(),
        ]
    };
    let label = if outside == 0 {
        "estimate (10)".to_string()
    } else {
        format!("estimate (10), {outside} epochs beyond the axis drawn at its edge")
    };
    line(&mut chart, points(&s.range_m), RED.stroke_width(1), &label)?;
    line(&mut chart, points(&s.true_range_m), BLACK.stroke_width(2), "truth")?;
    legend(&mut chart)
}

fn draw_azimuth(area: &Area<'_>, s: &GeometricTrackingSeries, t_end: f64) -> anyhow::Result<()> {
    let y = padded_range(s.true_azimuth_deg.iter().chain(&s.azimuth_deg).copied());
    let mut chart = chart(area, t_end, y, "azimuth (deg)")?;
    shade(&mut chart, s, t_end)?;
    line(&mut chart, wrapped_segments(&s.t_s, &s.azimuth_deg), RED.stroke_width(1), "estimate (11)")?;
    line(&mut chart, wrapped_segments(&s.t_s, &s.true_azimuth_deg), BLACK.stroke_width(2), "truth")?;
    legend(&mut chart)
}

fn draw_beams(area: &Area<'_>, s: &GeometricTrackingSeries, t_end: f64) -> anyhow::Result<()> {
    let top = s.beams_measured.iter().copied().max().unwrap_or(0).max(s.codebook_beams).max(1) as f64;
    let mut chart = chart(area, t_end, 0.0..1.1 * top, "beams measured")?;
    shade(&mut chart, s, t_end)?;
    // A step line: each epoch's count holds until the next epoch.
    let mut steps = Vec::with_capacity(2 * s.beams_measured.len());
    for (k, (&t, &n)) in s.t_s.iter().zip(&s.beams_measured).enumerate() {
        if k > 0 {
            steps.push((t, steps.last().map_or(0.0, |p: &(f64, f64)| p.1)));
        }
        steps.push((t, n as f64));
    }
    let total: u64 = s.beams_measured.iter().sum();
    line(
        &mut chart,
        vec![steps],
        BLUE.stroke_width(2),
        &format!("per epoch ({total} in all; a full scan is {} beams)", s.codebook_beams),
    )?;
    legend(&mut chart)
}

/// `(t, degrees)` runs of finite values, split where consecutive values
/// differ by more than 180 deg (a wrap through +-180).
fn wrapped_segments(t_s: &[f64], values_deg: &[f64]) -> Vec<Vec<(f64, f64)>> {
    let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    let mut last: Option<f64> = None;
    for (&t, &v) in t_s.iter().zip(values_deg) {
        if !v.is_finite() {
            continue;
        }
        if last.is_some_and(|l| (v - l).abs() > 180.0) {
            segments.push(Vec::new());
        }
        if let Some(segment) = segments.last_mut() {
            segment.push((t, v));
        }
        last = Some(v);
    }
    segments
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(handover_s: Option<f64>) -> GeometricTrackingSeries {
        let n = 100;
        let t_s: Vec<f64> = (0..n).map(|k| 0.02 * f64::from(k)).collect();
        GeometricTrackingSeries {
            range_m: t_s.iter().map(|t| if *t < 0.5 { 1e4 } else { 20.0 - 5.0 * t }).collect(),
            true_range_m: t_s.iter().map(|t| 20.0 - 5.0 * t).collect(),
            azimuth_deg: t_s.iter().map(|t| 175.0 + 10.0 * t).map(|a| if a > 180.0 { a - 360.0 } else { a }).collect(),
            true_azimuth_deg: t_s
                .iter()
                .map(|t| 176.0 + 10.0 * t)
                .map(|a| if a > 180.0 { a - 360.0 } else { a })
                .collect(),
            beams_measured: (0..n).map(|k| if k < 10 { 128 } else { 3 }).collect(),
            t_s,
            handover_s,
            codebook_beams: 128,
        }
    }

    #[test]
    fn draws_three_panels_with_the_not_converged_span_shaded() {
        let svg = geometric_tracking_svg("test", &series(Some(0.5))).unwrap();
        for text in ["range (m)", "azimuth (deg)", "beams measured", "H-infinity (not converged)", "estimate (10)"] {
            assert!(svg.contains(text), "{text}");
        }
        // The 25 epochs before 0.5 s lie beyond 3x the largest true range.
        assert!(svg.contains("25 epochs beyond the axis"), "{svg}");
        // One shading rectangle per panel plus its legend sample: 6 filled
        // rects with the grey fill.
        assert_eq!(svg.matches("opacity=\"0.12\" fill=\"#000000\"").count(), 6, "{svg}");
        // Range: estimate and truth; azimuth: both wrap once (2 segments
        // each); beams: one step line; each legend sample is a polyline too.
        assert!(svg.matches("<polyline").count() >= 2 + 4 + 1 + 5, "{}", svg.matches("<polyline").count());
        // Never handed over: still shaded (whole run); without any epoch: drawn.
        assert!(geometric_tracking_svg("t", &series(None)).unwrap().contains("H-infinity (not converged)"));
        assert!(geometric_tracking_svg("t", &GeometricTrackingSeries::default()).is_ok());
    }
}
