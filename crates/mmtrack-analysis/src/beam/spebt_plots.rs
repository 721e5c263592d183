//! Figures of the SPEBT experiment: a tracking realisation against the
//! truth, `|alpha|`, AoD and AoA against the slot (Liu et al. 2024, Fig. 5).

use plotters::prelude::*;

use crate::plot_common::{err, padded_range, tick_decimals};

/// One realisation against the truth, per slot (index = slot).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SpebtTrackingSeries {
    /// True `|alpha|`.
    pub true_gain: Vec<f64>,
    /// True AoD, degrees.
    pub true_aod_deg: Vec<f64>,
    /// True AoA, degrees.
    pub true_aoa_deg: Vec<f64>,
    /// Estimated `|alpha|`.
    pub estimate_gain: Vec<f64>,
    /// Estimated AoD, degrees.
    pub estimate_aod_deg: Vec<f64>,
    /// Estimated AoA, degrees.
    pub estimate_aoa_deg: Vec<f64>,
    /// Slots that ended in a re-initialisation.
    pub reinitialised: Vec<bool>,
}

/// Three stacked panels (`|alpha|` in dB, AoD, AoA against the
/// slot), the truth in black and the estimate in red, re-initialisations as
/// blue ticks along the bottom of each panel. Angle lines break where the
/// angle wraps through +-180 deg.
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn spebt_tracking_svg(title: &str, series: &SpebtTrackingSeries) -> anyhow::Result<String> {
    let s = series;
    let slots = s.true_gain.len().max(2);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1000, 900)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
        let areas = root.split_evenly((3, 1));
        let x_range = 0f64..(slots - 1) as f64;
        // |alpha| spans decades along a drive: in dB (20 log10 |alpha|, a
        // linear axis with ticks) the distance between the lines is the
        // relative error. plotters' log axis drew no tick labels within a decade.
        let db = |values: &[f64]| -> Vec<f64> {
            values.iter().map(|v| if *v > 0.0 && v.is_finite() { 20.0 * v.log10() } else { f64::NAN }).collect()
        };
        let (true_db, estimate_db) = (db(&s.true_gain), db(&s.estimate_gain));
        let range = padded_range(true_db.iter().chain(&estimate_db).copied());
        let mut chart = ChartBuilder::on(&areas[0])
            .margin(10)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(x_range.clone(), range.clone())
            .map_err(err)?;
        crate::plot_common::axes(&mut chart, "slot", "|alpha| (dB, 20 log10)")
            .y_label_formatter(&|v| format!("{v:.decimals$}", decimals = tick_decimals(&range)))
            .draw()
            .map_err(err)?;
        let tick = range.start + 0.03 * (range.end - range.start);
        draw_panel(&mut chart, s, vec![finite_points(&true_db)], vec![finite_points(&estimate_db)], range.start, tick)?;
        for (area, label, truth, estimate) in [
            (&areas[1], "AoD (deg)", &s.true_aod_deg, &s.estimate_aod_deg),
            (&areas[2], "AoA (deg)", &s.true_aoa_deg, &s.estimate_aoa_deg),
        ] {
            let range = padded_range(truth.iter().chain(estimate.iter()).copied());
            let mut chart = ChartBuilder::on(area)
                .margin(10)
                .x_label_area_size(45)
                .y_label_area_size(80)
                .build_cartesian_2d(x_range.clone(), range.clone())
                .map_err(err)?;
            crate::plot_common::axes(&mut chart, "slot", label)
                .y_label_formatter(&|v| format!("{v:.decimals$}", decimals = tick_decimals(&range)))
                .draw()
                .map_err(err)?;
            let tick = range.start + 0.03 * (range.end - range.start);
            draw_panel(&mut chart, s, wrapped_segments(truth), wrapped_segments(estimate), range.start, tick)?;
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}

type Chart<'a, Y> = ChartContext<'a, SVGBackend<'a>, Cartesian2d<plotters::coord::types::RangedCoordf64, Y>>;

/// Re-initialisation ticks from `bottom` to `tick`, the estimate and the
/// truth (each a list of line segments), and the legend.
fn draw_panel<Y>(
    chart: &mut Chart<'_, Y>,
    s: &SpebtTrackingSeries,
    truth: Vec<Vec<(f64, f64)>>,
    estimate: Vec<Vec<(f64, f64)>>,
    bottom: f64,
    tick: f64,
) -> anyhow::Result<()>
where
    Y: Ranged<ValueType = f64>,
{
    chart
        .draw_series(
            s.reinitialised
                .iter()
                .enumerate()
                .filter(|(_, r)| **r)
                .map(|(k, _)| PathElement::new(vec![(k as f64, bottom), (k as f64, tick)], BLUE)),
        )
        .map_err(err)?
        .label("re-initialisation")
        .legend(|(x, y)| PathElement::new(vec![(x, y - 5), (x, y + 5)], BLUE));
    for (segments, color, width, label) in [(estimate, RED, 1, "estimate"), (truth, BLACK, 2, "truth")] {
        for (i, segment) in segments.into_iter().enumerate() {
            let drawn = chart.draw_series(LineSeries::new(segment, color.stroke_width(width))).map_err(err)?;
            if i == 0 {
                drawn
                    .label(label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
            }
        }
    }
    crate::plot_common::draw_legend(chart, SeriesLabelPosition::UpperRight)
}

/// `(slot, value)` of the finite values.
fn finite_points(values: &[f64]) -> Vec<(f64, f64)> {
    values.iter().enumerate().filter(|(_, v)| v.is_finite()).map(|(k, v)| (k as f64, *v)).collect()
}

/// `(slot, degrees)` runs of finite values, split where consecutive values
/// differ by more than 180 deg (a wrap through +-180).
fn wrapped_segments(values_deg: &[f64]) -> Vec<Vec<(f64, f64)>> {
    let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    let mut last: Option<f64> = None;
    for (k, &v) in values_deg.iter().enumerate() {
        if !v.is_finite() {
            continue;
        }
        if last.is_some_and(|l| (v - l).abs() > 180.0) {
            segments.push(Vec::new());
        }
        if let Some(segment) = segments.last_mut() {
            segment.push((k as f64, v));
        }
        last = Some(v);
    }
    segments
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_three_panels_with_truth_estimate_and_reinitialisations() {
        let n = 100;
        let ramp = |scale: f64| (0..n).map(|k| scale * k as f64).collect::<Vec<f64>>();
        let series = SpebtTrackingSeries {
            true_gain: ramp(1e-8),
            true_aod_deg: ramp(0.5),
            true_aoa_deg: ramp(-1.0),
            estimate_gain: ramp(1.1e-8),
            estimate_aod_deg: ramp(0.45),
            estimate_aoa_deg: ramp(-0.9),
            reinitialised: (0..n).map(|k| k % 30 == 0).collect(),
        };
        let svg = spebt_tracking_svg("test", &series).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("AoA (deg)") && svg.contains("re-initialisation"), "{svg}");
        // Per panel: truth, estimate and three legend samples; 4 ticks each.
        assert!(svg.matches("<polyline").count() >= 3 * (2 + 3 + 4), "{}", svg.matches("<polyline").count());
        // Angles break at wraps through +-180 deg.
        let segments = wrapped_segments(&[170.0, 179.0, -179.0, -170.0, f64::NAN, -160.0]);
        assert_eq!(segments, vec![vec![(0.0, 170.0), (1.0, 179.0)], vec![(2.0, -179.0), (3.0, -170.0), (5.0, -160.0)]]);
    }
}
