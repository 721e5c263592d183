//! The one palette of every multi-series figure (analyze, compare and the
//! `reproduce` figures): series `k` of a panel gets [`series_style`]`(k)`.
//!
//! Colours: the Okabe-Ito qualitative palette (Okabe and Ito, "Color
//! Universal Design", 2008), which stays distinguishable under the common
//! colour-vision deficiencies, without its yellow (#F0E442 is too faint on
//! white): seven colours. When the colours run out the dash pattern changes
//! (solid, dashed, dotted, dash-dot), so no two series of one panel with
//! fewer than [`DISTINCT_STYLES`] series look alike.
//!
//! Curves that can coincide exactly (trackers that agree, runs with the same
//! result) use [`layered_style`]: the first is drawn widest and solid, every
//! later one narrower and dashed on top of it, so an earlier curve shows
//! through the gaps of a later one that covers it.
//!
//! plotters' SVG backend has no dash attribute; dashed series are drawn as
//! plotters' [`DashedLineSeries`] (each dash its own segment).

use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::plot_common::err;

/// The Okabe-Ito palette without yellow, in its usual order, black last (it
/// is the colour of ground truth in many figures, so series use it last).
pub const COLORS: [RGBColor; 7] = [
    RGBColor(0xE6, 0x9F, 0x00), // orange
    RGBColor(0x00, 0x72, 0xB2), // blue
    RGBColor(0x00, 0x9E, 0x73), // bluish green
    RGBColor(0xD5, 0x5E, 0x00), // vermillion
    RGBColor(0xCC, 0x79, 0xA7), // reddish purple
    RGBColor(0x56, 0xB4, 0xE9), // sky blue
    RGBColor(0x00, 0x00, 0x00), // black
];

/// A line's dash pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dash {
    /// One unbroken line.
    Solid,
    /// Dashes of `on` px with gaps of `off` px.
    Pattern {
        /// Dash length, px.
        on_px: u32,
        /// Gap length, px.
        off_px: u32,
    },
}

/// The patterns in the order they are used when the colours run out.
pub const DASHES: [Dash; 4] = [
    Dash::Solid,
    Dash::Pattern { on_px: 10, off_px: 5 },
    Dash::Pattern { on_px: 2, off_px: 4 },
    Dash::Pattern { on_px: 16, off_px: 4 },
];

/// Series of one panel that get distinct styles.
pub const DISTINCT_STYLES: usize = COLORS.len() * DASHES.len();

/// How one series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SeriesStyle {
    /// Line colour.
    pub color: RGBColor,
    /// Dash pattern.
    pub dash: Dash,
    /// Line width, px.
    pub width_px: u32,
}

/// The style of series `index` of a panel: colour `index mod 7`, the dash
/// pattern changes each time the colours start over; 2 px.
#[must_use]
pub fn series_style(index: usize) -> SeriesStyle {
    SeriesStyle {
        color: COLORS[index % COLORS.len()],
        dash: DASHES[(index / COLORS.len()) % DASHES.len()],
        width_px: 2,
    }
}

/// The style of series `index` where later series may lie exactly on
/// earlier ones: the first solid and 4 px, later ones 2 px and dashed (the
/// dash lengths differ between neighbours), so a covered curve shows
/// through the gaps.
#[must_use]
pub fn layered_style(index: usize) -> SeriesStyle {
    let color = COLORS[index % COLORS.len()];
    if index == 0 {
        return SeriesStyle { color, dash: Dash::Solid, width_px: 4 };
    }
    let dash = match index % 3 {
        1 => Dash::Pattern { on_px: 10, off_px: 6 },
        2 => Dash::Pattern { on_px: 4, off_px: 6 },
        _ => Dash::Pattern { on_px: 16, off_px: 6 },
    };
    SeriesStyle { color, dash, width_px: 2 }
}

impl SeriesStyle {
    /// An unbroken line of `color`, `width_px` wide (truth, thresholds, and
    /// series whose colour carries their meaning).
    #[must_use]
    pub fn solid(color: RGBColor, width_px: u32) -> Self {
        Self { color, dash: Dash::Solid, width_px }
    }

    /// The plotters stroke.
    #[must_use]
    pub fn stroke(&self) -> ShapeStyle {
        self.color.stroke_width(self.width_px)
    }
}

/// Draws `points` joined in `style` and enters the series in the legend as
/// `label`, with a legend sample of the same colour, width and dash.
pub(crate) fn draw_series_line<'a, DB, X, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    points: impl IntoIterator<Item = (f64, f64)>,
    style: SeriesStyle,
    label: impl Into<String>,
) -> anyhow::Result<()>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let points: Vec<(f64, f64)> = points.into_iter().collect();
    let stroke = style.stroke();
    let drawn = match style.dash {
        Dash::Solid => chart.draw_series(LineSeries::new(points, stroke)).map_err(err)?,
        Dash::Pattern { on_px, off_px } => {
            chart.draw_series(DashedLineSeries::new(points, on_px, off_px, stroke)).map_err(err)?
        }
    };
    drawn.label(label).legend(move |(x, y)| legend_sample(x, y, style));
    Ok(())
}

/// A legend in its own drawing area (beside a plot, so it covers no data):
/// one line per entry, its sample and label, from the top.
pub(crate) fn draw_side_legend(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    entries: &[(String, SeriesStyle)],
) -> anyhow::Result<()> {
    let line_px = 22;
    for (k, (label, style)) in entries.iter().enumerate() {
        let y = 30 + line_px * k as i32;
        area.draw(&legend_sample(4, y, *style)).map_err(err)?;
        area.draw(&Text::new(label.clone(), (36, y - 8), crate::plot_common::LEGEND_FONT)).map_err(err)?;
    }
    Ok(())
}

/// A 24 px legend sample of `style`: the line, or its first dashes.
fn legend_sample(x: i32, y: i32, style: SeriesStyle) -> DashedPathElement<std::vec::IntoIter<(i32, i32)>, u32> {
    // A solid sample is one dash longer than the sample.
    let (on_px, off_px) = match style.dash {
        Dash::Solid => (32, 1),
        Dash::Pattern { on_px, off_px } => (on_px, off_px),
    };
    DashedPathElement::new(vec![(x, y), (x + 24, y)], on_px, off_px, style.stroke())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_series_of_a_panel_below_the_distinct_count_has_its_own_style() {
        for n in 1..=DISTINCT_STYLES {
            let styles: std::collections::HashSet<(RGBColor, Dash)> =
                (0..n).map(series_style).map(|s| (s.color, s.dash)).collect();
            assert_eq!(styles.len(), n);
        }
        let layered: std::collections::HashSet<(RGBColor, Dash)> =
            (0..COLORS.len()).map(layered_style).map(|s| (s.color, s.dash)).collect();
        assert_eq!(layered.len(), COLORS.len());
        // No pure primaries, no cyan or yellow on white.
        for c in COLORS {
            assert!(![RED, GREEN, BLUE, CYAN, YELLOW, MAGENTA].contains(&c), "{c:?}");
        }
    }

    /// 16 horizontal series in one panel: the SVG holds 16 distinct
    /// (colour, dash length) pairs, read back from the drawn segments.
    #[test]
    fn sixteen_series_render_with_sixteen_distinct_styles() {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (800, 600)).into_drawing_area();
            let mut chart = ChartBuilder::on(&root).build_cartesian_2d(0f64..10.0, 0f64..17.0).unwrap();
            for k in 0..16 {
                let y = (k + 1) as f64;
                draw_series_line(&mut chart, [(0.0, y), (10.0, y)], series_style(k), format!("s{k}")).unwrap();
            }
            root.present().unwrap();
        }
        // Per series row (its y in px): the stroke colour and the length of
        // its first drawn segment (the whole width when solid).
        let mut rows: std::collections::BTreeMap<i64, (String, i64)> = std::collections::BTreeMap::new();
        for element in svg.split('<').filter(|e| e.starts_with("polyline")) {
            let attr = |name: &str| {
                element.split(&format!(" {name}=\"")).nth(1).and_then(|rest| rest.split('"').next()).unwrap_or("")
            };
            let points: Vec<(i64, i64)> = attr("points")
                .split_whitespace()
                .filter_map(|p| p.split_once(',').and_then(|(x, y)| Some((x.parse().ok()?, y.parse().ok()?))))
                .collect();
            let (Some(first), Some(last)) = (points.first(), points.last()) else { continue };
            rows.entry(first.1).or_insert((attr("stroke").to_string(), last.0 - first.0));
        }
        let distinct: std::collections::BTreeSet<&(String, i64)> = rows.values().collect();
        assert_eq!(rows.len(), 16, "{rows:?}");
        assert_eq!(distinct.len(), 16, "{rows:?}");
    }
}
