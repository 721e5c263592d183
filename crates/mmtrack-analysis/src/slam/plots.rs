//! Figures of the 5G mmWave SLAM experiment: the map (true and estimated
//! sources, the true and estimated track, Kim et al. 2018 Fig. 3) and the
//! errors and confirmed-source counts over the epochs (Figs. 4-5).

use plotters::prelude::*;

use crate::plot_common::{err, padded_range};

/// Points, legend, colour, filled, small.
type Markers<'a> = (&'a [[f64; 2]], &'static str, RGBColor, bool, bool);

/// What the map figure shows, horizontal coordinates in metres.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MapFigure {
    /// Base station.
    pub bs_m: [f64; 2],
    /// True virtual anchors.
    pub true_va_m: Vec<[f64; 2]>,
    /// True scattering points.
    pub true_sp_m: Vec<[f64; 2]>,
    /// Confirmed virtual anchors at the end of the run.
    pub estimated_va_m: Vec<[f64; 2]>,
    /// Confirmed scattering points at the end of the run.
    pub estimated_sp_m: Vec<[f64; 2]>,
    /// True UE track.
    pub true_track_m: Vec<[f64; 2]>,
    /// Estimated UE track.
    pub estimated_track_m: Vec<[f64; 2]>,
}

/// An SVG of the map: true sources as hollow markers, estimates filled,
/// both tracks as lines.
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn map_svg(title: &str, figure: &MapFigure) -> anyhow::Result<String> {
    let all = || {
        std::iter::once(figure.bs_m)
            .chain(figure.true_va_m.iter().copied())
            .chain(figure.true_sp_m.iter().copied())
            .chain(figure.estimated_va_m.iter().copied())
            .chain(figure.estimated_sp_m.iter().copied())
            .chain(figure.true_track_m.iter().copied())
            .chain(figure.estimated_track_m.iter().copied())
    };
    let xr = padded_range(all().map(|p| p[0]));
    let yr = padded_range(all().map(|p| p[1]));
    let half = 0.5 * (xr.end - xr.start).max(yr.end - yr.start);
    let (cx, cy) = (0.5 * (xr.start + xr.end), 0.5 * (yr.start + yr.end));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (760, 760)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .build_cartesian_2d((cx - half)..(cx + half), (cy - half)..(cy + half))
            .map_err(err)?;
        crate::plot_common::draw_axes(&mut chart, "x (m)", "y (m)")?;
        let track = |points: &[[f64; 2]]| points.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>();
        let grey = RGBColor(120, 120, 120);
        crate::palette::draw_series_line(
            &mut chart,
            track(&figure.true_track_m),
            crate::palette::SeriesStyle::solid(grey, 3),
            "true track",
        )?;
        crate::palette::draw_series_line(
            &mut chart,
            track(&figure.estimated_track_m),
            crate::palette::SeriesStyle::solid(BLUE, 1),
            "estimated track",
        )?;
        let markers: [Markers<'_>; 5] = [
            (std::slice::from_ref(&figure.bs_m), "BS", BLACK, true, false),
            (&figure.true_va_m, "true VA", RED, false, false),
            (&figure.estimated_va_m, "estimated VA", RED, true, true),
            (&figure.true_sp_m, "true SP", GREEN, false, false),
            (&figure.estimated_sp_m, "estimated SP", GREEN, true, true),
        ];
        for (points, label, color, filled, small) in markers {
            let size = if small { 3 } else { 7 };
            let style = if filled { color.filled() } else { color.stroke_width(2) };
            chart
                .draw_series(points.iter().map(|p| Circle::new((p[0], p[1]), size, style)))
                .map_err(err)?
                .label(label)
                .legend(move |(x, y)| Circle::new((x + 10, y), size, style));
        }
        crate::plot_common::draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// One line of an over-the-epochs figure.
#[derive(Debug, Clone, PartialEq)]
pub struct EpochCurve {
    /// Legend text.
    pub label: String,
    /// Value per epoch (index 0 = epoch 1); NaN for a gap.
    pub values: Vec<f64>,
}

/// An SVG of `curves` against the epoch, linear axes, legend beside the
/// plot ([`epoch_panels_svg`] with one panel).
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn epoch_curves_svg(title: &str, y_desc: &str, curves: &[EpochCurve]) -> anyhow::Result<String> {
    epoch_panels_svg(title, &[EpochPanel { y_desc: y_desc.to_string(), curves: curves.to_vec() }])
}

/// One panel of [`epoch_panels_svg`]: its y axis name and curves.
#[derive(Debug, Clone, PartialEq)]
pub struct EpochPanel {
    /// y axis name with unit.
    pub y_desc: String,
    /// The curves; curve `k` of every panel gets the same style.
    pub curves: Vec<EpochCurve>,
}

/// Panels stacked over one epoch axis (as the paper's figures split VA and
/// SP, or position and clock bias), curve `k` in
/// [`crate::palette::series_style`]`(k)` in every panel; one legend beside the
/// panels, so it covers no data (the last epochs, where convergence is read).
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn epoch_panels_svg(title: &str, panels: &[EpochPanel]) -> anyhow::Result<String> {
    let epochs = panels.iter().flat_map(|p| p.curves.iter()).map(|c| c.values.len()).max().unwrap_or(1).max(2);
    let legend_px = 230;
    let panel_px = 360;
    let height_px = 40 + panel_px * panels.len().max(1) as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900 + legend_px, height_px)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 18)).map_err(err)?;
        let (plots, legend) = root.split_horizontally(900);
        for (panel, area) in panels.iter().zip(plots.split_evenly((panels.len().max(1), 1))) {
            let range = padded_range(panel.curves.iter().flat_map(|c| c.values.iter().copied()).chain([0.0]));
            let mut chart = ChartBuilder::on(&area)
                .margin(15)
                .x_label_area_size(45)
                .y_label_area_size(65)
                .build_cartesian_2d(1f64..epochs as f64, 0f64.min(range.start)..range.end)
                .map_err(err)?;
            // Epochs are whole numbers: no decimals on their ticks.
            crate::plot_common::axes(&mut chart, "epoch k (200 ms)", panel.y_desc.as_str())
                .x_label_formatter(&|v| format!("{v:.0}"))
                .draw()
                .map_err(err)?;
            for (k, curve) in panel.curves.iter().enumerate() {
                let points =
                    curve.values.iter().enumerate().filter(|(_, v)| v.is_finite()).map(|(k, v)| ((k + 1) as f64, *v));
                crate::palette::draw_series_line(
                    &mut chart,
                    points,
                    crate::palette::series_style(k),
                    curve.label.clone(),
                )?;
            }
        }
        // One entry per curve of the first panel, labelled as there.
        let entries: Vec<(String, crate::palette::SeriesStyle)> = panels
            .first()
            .map(|p| {
                p.curves.iter().enumerate().map(|(k, c)| (c.label.clone(), crate::palette::series_style(k))).collect()
            })
            .unwrap_or_default();
        crate::palette::draw_side_legend(&legend, &entries)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_are_svg_documents() {
        let figure = MapFigure {
            bs_m: [0.0, 0.0],
            true_va_m: vec![[200.0, 0.0]],
            estimated_va_m: vec![[200.5, 0.2]],
            true_track_m: vec![[70.0, 0.0], [0.0, 70.0]],
            estimated_track_m: vec![[70.2, 0.1], [0.1, 70.3]],
            ..MapFigure::default()
        };
        let svg = map_svg("map", &figure).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("estimated VA"));
        let svg =
            epoch_curves_svg("e", "m", &[EpochCurve { label: "ue".into(), values: vec![1.0, f64::NAN, 0.5] }]).unwrap();
        assert!(svg.contains("ue"));
    }
}
