//! What every figure of this crate shares: plotters errors as `anyhow`
//! errors, the legend's look, padded axis ranges. A leaf: the figure modules
//! use it and it uses none of them.

use std::ops::Range;

use plotters::chart::MeshStyle;
use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;

/// Font of tick labels. plotters' SVG backend writes `font-size` as the
/// size / 1.24, so 16 gives 12.9 px text at the SVG's natural size (its
/// default, 12, gave 9.7 px); the report shows plots at natural size.
pub(crate) const TICK_FONT: (&str, u32) = ("sans-serif", 16);
/// Font of axis descriptions (name and unit): 14.5 px.
pub(crate) const AXIS_FONT: (&str, u32) = ("sans-serif", 18);
/// Font of legends: 12.9 px.
pub(crate) const LEGEND_FONT: (&str, u32) = ("sans-serif", 16);

/// A plotters error as an error of this crate, prefixed `plot:`.
pub(crate) fn err(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("plot: {e}")
}

/// Draws the legend of the series labelled so far at `position`: black
/// border on a translucent white box, the look of every figure here.
pub(crate) fn draw_legend<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> anyhow::Result<()>
where
    DB: DrawingBackend + 'a,
    CT: plotters::coord::CoordTranslate,
{
    chart
        .configure_series_labels()
        .position(position)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .label_font(LEGEND_FONT)
        .draw()
        .map_err(err)
}

/// The axes of every figure here: tick labels in [`TICK_FONT`], axis
/// descriptions (name and unit) in [`AXIS_FONT`]. Further settings (label
/// formatters, light lines) go on the returned style before its `draw()`;
/// [`draw_axes`] draws it as it is.
pub(crate) fn axes<'a, 'b, DB, XT, YT, X, Y>(
    chart: &'b mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    x_desc: impl Into<String>,
    y_desc: impl Into<String>,
) -> MeshStyle<'a, 'b, X, Y, DB>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = XT> + ValueFormatter<XT>,
    Y: Ranged<ValueType = YT> + ValueFormatter<YT>,
{
    let mut mesh = chart.configure_mesh();
    mesh.label_style(TICK_FONT).axis_desc_style(AXIS_FONT).x_desc(x_desc).y_desc(y_desc);
    mesh
}

/// Draws the axes of [`axes`] with nothing added.
pub(crate) fn draw_axes<DB, XT, YT, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    x_desc: impl Into<String>,
    y_desc: impl Into<String>,
) -> anyhow::Result<()>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = XT> + ValueFormatter<XT>,
    Y: Ranged<ValueType = YT> + ValueFormatter<YT>,
{
    axes(chart, x_desc, y_desc).draw().map_err(err)
}

/// Decimals that tell ticks over `range` apart: plotters places about ten
/// ticks at steps of 1, 2 or 5 x 10^k, so a tenth of the span, rounded down
/// to its power of ten, sets the last digit shown (0 to 6 decimals).
pub(crate) fn tick_decimals(range: &Range<f64>) -> usize {
    let step = (range.end - range.start).abs() / 10.0;
    if !(step.is_finite() && step > 0.0) {
        return 0;
    }
    (-step.log10().floor()).clamp(0.0, 6.0) as usize
}

/// `[min, max]` of `values` padded by 5 % (1 unit when flat).
pub(crate) fn padded_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) =
        values.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { 1.0 };
    (lo - pad)..(hi + pad)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_decimals_resolve_a_tenth_of_the_span() {
        // -113.6..-111.9 dB: steps of 0.2 dB need one decimal (with none,
        // five ticks all read -113).
        assert_eq!(tick_decimals(&(-113.6..-111.9)), 1);
        assert_eq!(tick_decimals(&(70.5..76.5)), 1);
        assert_eq!(tick_decimals(&(-180.0..180.0)), 0);
        assert_eq!(tick_decimals(&(0.0..0.003)), 4);
        assert_eq!(tick_decimals(&(1.0..1.0)), 0);
    }
}
