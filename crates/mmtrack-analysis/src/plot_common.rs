//! What every figure of this crate shares: plotters errors as `anyhow`
//! errors, the legend's look, padded axis ranges. A leaf: the figure modules
//! use it and it uses none of them.

use std::ops::Range;

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
