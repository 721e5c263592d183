//! The artificial-channel experiment of Mahler et al. 2017, Sec. IV-A
//! (`mmtrack reproduce mpc-artificial`): its results as plain data and their
//! SVG plots (Figs. 4-5 and the delay error against the MPCs' separation).
//!
//! The CLI simulates, detects, tracks and tallies; this module only draws.
//! Each plot function returns the SVG document (plotters' SVG backend, as
//! [`crate::plots`]); writing it is the caller's job.

use std::ops::Range;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::mpc_plots::viridis;
use crate::plot_common::{err, padded_range};

/// The trackers compared on the artificial channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ArtificialTracker {
    /// The paper's short-term tracker (Sec. III-B).
    Proposed,
    /// The same tracker on the same detections re-estimated on the CIR
    /// without window or zeroing (`refit_unwindowed`, ours, not the paper's).
    ProposedRefit,
    /// The GM-PHD baseline with the paper's Table I parameters.
    GmPhd,
    /// The GM-PHD baseline with its measurement noise matched to the
    /// detector's delay noise at the same point (a sensitivity variant, not
    /// the paper's setting).
    GmPhdMatched,
}

impl ArtificialTracker {
    /// Every tracker, in table order.
    pub const ALL: [Self; 4] = [Self::Proposed, Self::ProposedRefit, Self::GmPhd, Self::GmPhdMatched];

    /// The name in CSV files and tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Proposed => "proposed",
            Self::ProposedRefit => "proposed-refit",
            Self::GmPhd => "gm-phd",
            Self::GmPhdMatched => "gm-phd-matched",
        }
    }

    /// The label in plot legends.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Proposed => "proposed",
            Self::ProposedRefit => "proposed, detections refitted (ours)",
            Self::GmPhd => "GM-PHD (Table I)",
            Self::GmPhdMatched => "GM-PHD (sigma matched)",
        }
    }

    fn color(self) -> RGBColor {
        match self {
            Self::Proposed => RGBColor(200, 30, 30),
            Self::ProposedRefit => RGBColor(150, 60, 170),
            Self::GmPhd => RGBColor(30, 70, 200),
            Self::GmPhdMatched => RGBColor(20, 140, 60),
        }
    }
}

/// One point of the sweep: one MPC power, window setting and tracker, over
/// all Monte Carlo runs.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepPoint {
    /// Power of each of the two MPCs, dB.
    pub power_db: f64,
    /// Whether detection applied the Kaiser window.
    pub kaiser_window: bool,
    /// The tracker that made the tracks.
    pub tracker: ArtificialTracker,
    /// Tracks (of at least 3 detections) per run.
    pub mean_tracks: f64,
    /// Tracks per run that follow a true MPC (most points within 1 ns of it).
    pub mean_true_tracks: f64,
    /// Runs with exactly two tracks.
    pub runs_with_two_tracks: u64,
    /// Runs with exactly two tracks on a true MPC (noise tracks aside).
    pub runs_with_two_true_tracks: u64,
    /// Monte Carlo runs (different noise and phases).
    pub runs: u64,
    /// Mean absolute delay error of the true tracks' points against the
    /// nearer true MPC, ns (NaN when no track followed a true MPC).
    pub mean_delay_error_ns: f64,
    /// Root mean square of the same errors, ns.
    pub rms_delay_error_ns: f64,
    /// The GM-PHD measurement noise used, m (`None` for the proposed tracker).
    pub sigma_measurement_m: Option<f64>,
}

/// The delay error of one sweep point's true tracks within one band of the
/// two MPCs' separation.
#[derive(Debug, Clone, PartialEq)]
pub struct SeparationBin {
    /// Power of each MPC, dB.
    pub power_db: f64,
    /// Whether detection applied the Kaiser window.
    pub kaiser_window: bool,
    /// The tracker that made the tracks.
    pub tracker: ArtificialTracker,
    /// The band `[min, max)` of the separation, ns (the last band also holds its upper edge).
    pub separation_ns: Range<f64>,
    /// True-track points whose snapshot falls in the band.
    pub points: u64,
    /// True MPC positions in the band over all runs (2 per snapshot): what
    /// `points` would be if both MPCs were followed in every snapshot.
    pub truth_points: u64,
    /// Mean absolute delay error of those points, ns (NaN when none).
    pub mean_delay_error_ns: f64,
}

type Chart<'a, X, Y> = ChartContext<'a, SVGBackend<'a>, Cartesian2d<X, Y>>;

/// Line style of a (tracker, window) series: solid with filled marks for the
/// Kaiser window, dashed with open marks without it.
fn series_style(tracker: ArtificialTracker, window: bool) -> (ShapeStyle, ShapeStyle) {
    let color = tracker.color();
    if window { (color.stroke_width(2), color.filled()) } else { (color.stroke_width(1), color.stroke_width(1)) }
}

fn series_label(tracker: ArtificialTracker, window: bool) -> String {
    format!("{}, {}", tracker.label(), if window { "Kaiser window" } else { "no window" })
}

/// One (tracker, window) line against the MPC power.
struct PowerSeries {
    tracker: ArtificialTracker,
    window: bool,
    xy: Vec<(f64, f64)>,
}

/// The (tracker, window) series of `points`, each sorted by power; `y`
/// picks the value and drops what cannot be drawn.
fn power_series(points: &[SweepPoint], y: impl Fn(&SweepPoint) -> Option<f64>) -> Vec<PowerSeries> {
    let mut out = Vec::new();
    for tracker in ArtificialTracker::ALL {
        for window in [true, false] {
            let mut xy: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.tracker == tracker && p.kaiser_window == window)
                .filter_map(|p| y(p).map(|v| (p.power_db, v)))
                .collect();
            xy.sort_by(|a, b| a.0.total_cmp(&b.0));
            if !xy.is_empty() {
                out.push(PowerSeries { tracker, window, xy });
            }
        }
    }
    out
}

/// Draws one series as a line (dashed without the window) with marks.
fn draw_series<'a, X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &mut Chart<'a, X, Y>,
    label: String,
    xy: &[(f64, f64)],
    (line, mark): (ShapeStyle, ShapeStyle),
    dashed: bool,
) -> anyhow::Result<()> {
    let legend = move |(x, y): (i32, i32)| PathElement::new(vec![(x, y), (x + 24, y)], line);
    if dashed {
        chart
            .draw_series(DashedLineSeries::new(xy.iter().copied(), 6, 4, line))
            .map_err(err)?
            .label(label)
            .legend(legend);
    } else {
        chart.draw_series(LineSeries::new(xy.iter().copied(), line)).map_err(err)?.label(label).legend(legend);
    }
    chart.draw_series(xy.iter().map(|&p| Circle::new(p, 4, mark))).map_err(err)?;
    Ok(())
}

fn legend<'a, X: Ranged<ValueType = f64>, Y: Ranged<ValueType = f64>>(
    chart: &mut Chart<'a, X, Y>,
    position: SeriesLabelPosition,
) -> anyhow::Result<()> {
    crate::plot_common::draw_legend(chart, position)
}

/// The minor grid lines (plotters' default is dark and dense on a log axis).
const LIGHT_LINES: RGBColor = RGBColor(242, 242, 242);

/// Share of a plot's height kept free above the data for the legend.
const LEGEND_HEADROOM: f64 = 0.3;

/// A log-scale range holding every positive finite value and `extra`, a
/// little beyond each end, with [`LEGEND_HEADROOM`] of the (logarithmic)
/// height free above them.
fn log_range(values: impl Iterator<Item = f64>, extra: f64) -> Range<f64> {
    let (lo, hi) = values
        .chain(std::iter::once(extra))
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return 1e-3..1.0;
    }
    let (lo, hi) = (lo / 1.5, hi * 1.2);
    let decades = (hi / lo).log10().max(0.5);
    lo..hi * 10f64.powf(decades * LEGEND_HEADROOM / (1.0 - LEGEND_HEADROOM))
}

fn positive(v: f64) -> Option<f64> {
    (v.is_finite() && v > 0.0).then_some(v)
}

fn canvas(svg: &mut String) -> anyhow::Result<DrawingArea<SVGBackend<'_>, Shift>> {
    let root = SVGBackend::with_string(svg, (1000, 650)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    Ok(root)
}

/// Mean number of tracks against the MPC power for each tracker with and
/// without the Kaiser window, the "2 tracks" reference line and the power
/// down to which the target asks for two tracks (the paper's Fig. 4).
pub fn tracks_vs_power_svg(points: &[SweepPoint], two_tracks_down_to_db: f64) -> anyhow::Result<String> {
    let series = power_series(points, |p| p.mean_tracks.is_finite().then_some(p.mean_tracks));
    let xs = padded_range(points.iter().map(|p| p.power_db).chain(std::iter::once(two_tracks_down_to_db)));
    let y_max = series.iter().flat_map(|s| s.xy.iter().map(|p| p.1)).fold(3.0, f64::max) / (1.0 - LEGEND_HEADROOM);
    let mut svg = String::new();
    {
        let root = canvas(&mut svg)?;
        let mut chart = ChartBuilder::on(&root)
            .margin(15)
            .caption("Number of tracks, two equal MPCs approaching 20 -> 2.5 ns", ("sans-serif", 18))
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(xs.clone(), 0.0..y_max)
            .map_err(err)?;
        crate::plot_common::axes(&mut chart, "MPC power (dB)", "mean number of tracks")
            .light_line_style(LIGHT_LINES)
            .draw()
            .map_err(err)?;
        chart
            .draw_series(DashedLineSeries::new([(xs.start, 2.0), (xs.end, 2.0)], 8, 5, BLACK.stroke_width(1)))
            .map_err(err)?
            .label("2 tracks (the two MPCs)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], BLACK.stroke_width(1)));
        let grey = RGBColor(120, 120, 120).stroke_width(1);
        chart
            .draw_series(DashedLineSeries::new(
                [(two_tracks_down_to_db, 0.0), (two_tracks_down_to_db, y_max)],
                3,
                4,
                grey,
            ))
            .map_err(err)?
            .label(format!("target: 2 tracks down to {two_tracks_down_to_db} dB (proposed)"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], grey));
        for PowerSeries { tracker, window, xy } in &series {
            draw_series(&mut chart, series_label(*tracker, *window), xy, series_style(*tracker, *window), !window)?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// Mean delay error of the true tracks against the MPC power (log scale),
/// each tracker with and without the Kaiser window, the target marked at
/// its power (the paper's Fig. 5).
pub fn delay_error_vs_power_svg(
    points: &[SweepPoint],
    target_error_ns: f64,
    target_power_db: f64,
) -> anyhow::Result<String> {
    let series = power_series(points, |p| positive(p.mean_delay_error_ns));
    let xs = padded_range(points.iter().map(|p| p.power_db).chain(std::iter::once(target_power_db)));
    let ys = log_range(series.iter().flat_map(|s| s.xy.iter().map(|p| p.1)), target_error_ns);
    let mut svg = String::new();
    {
        let root = canvas(&mut svg)?;
        let mut chart = ChartBuilder::on(&root)
            .margin(15)
            .caption("Mean delay error of the tracks on a true MPC, separations 20 -> 2.5 ns", ("sans-serif", 18))
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(xs.clone(), ys.log_scale())
            .map_err(err)?;
        crate::plot_common::axes(&mut chart, "MPC power (dB)", "mean delay error (ns)")
            .light_line_style(LIGHT_LINES)
            .draw()
            .map_err(err)?;
        let target = BLACK.stroke_width(1);
        chart
            .draw_series(DashedLineSeries::new([(xs.start, target_error_ns), (xs.end, target_error_ns)], 8, 5, target))
            .map_err(err)?
            .label(format!("target: below {target_error_ns} ns at {target_power_db} dB (proposed, Kaiser)"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], target));
        chart
            .draw_series(std::iter::once(Cross::new((target_power_db, target_error_ns), 9, BLACK.stroke_width(3))))
            .map_err(err)?;
        for PowerSeries { tracker, window, xy } in &series {
            draw_series(&mut chart, series_label(*tracker, *window), xy, series_style(*tracker, *window), !window)?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// Mean delay error against the two MPCs' separation (band centres, log
/// scale) for one tracker and window setting, one line per power in
/// `powers_db` (those present in `bins`), with the target level.
pub fn delay_error_vs_separation_svg(
    bins: &[SeparationBin],
    tracker: ArtificialTracker,
    kaiser_window: bool,
    powers_db: &[f64],
    target_error_ns: f64,
) -> anyhow::Result<String> {
    let mut lines: Vec<(f64, Vec<(f64, f64)>)> = powers_db
        .iter()
        .map(|&power_db| {
            let mut xy: Vec<(f64, f64)> = bins
                .iter()
                .filter(|b| b.tracker == tracker && b.kaiser_window == kaiser_window && b.power_db == power_db)
                .filter_map(|b| {
                    positive(b.mean_delay_error_ns).map(|e| (0.5 * (b.separation_ns.start + b.separation_ns.end), e))
                })
                .collect();
            xy.sort_by(|a, b| a.0.total_cmp(&b.0));
            (power_db, xy)
        })
        .filter(|(_, xy)| !xy.is_empty())
        .collect();
    lines.sort_by(|a, b| b.0.total_cmp(&a.0));
    let xs = padded_range(bins.iter().flat_map(|b| [b.separation_ns.start, b.separation_ns.end]));
    let ys = log_range(lines.iter().flat_map(|l| l.1.iter().map(|p| p.1)), target_error_ns);
    let mut svg = String::new();
    {
        let root = canvas(&mut svg)?;
        let mut chart = ChartBuilder::on(&root)
            .margin(15)
            .caption(
                format!(
                    "Mean delay error against separation: {}, {}",
                    tracker.label(),
                    if kaiser_window { "Kaiser window" } else { "no window" }
                ),
                ("sans-serif", 18),
            )
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(xs.clone(), ys.log_scale())
            .map_err(err)?;
        crate::plot_common::axes(&mut chart, "separation of the two MPCs (ns, band centre)", "mean delay error (ns)")
            .light_line_style(LIGHT_LINES)
            .draw()
            .map_err(err)?;
        let target = BLACK.stroke_width(1);
        chart
            .draw_series(DashedLineSeries::new([(xs.start, target_error_ns), (xs.end, target_error_ns)], 8, 5, target))
            .map_err(err)?
            .label(format!("target level {target_error_ns} ns"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], target));
        // Colours by rank, highest power darkest; viridis' last stop (yellow)
        // is left out, it does not show on white.
        let last = lines.len().saturating_sub(1).max(1) as f64;
        for (rank, (power_db, xy)) in lines.iter().enumerate() {
            let color = viridis(0.8 * rank as f64 / last);
            let style = (color.stroke_width(2), color.filled());
            draw_series(&mut chart, format!("{power_db} dB"), xy, style, false)?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(power_db: f64, window: bool, tracker: ArtificialTracker, tracks: f64, error_ns: f64) -> SweepPoint {
        SweepPoint {
            power_db,
            kaiser_window: window,
            tracker,
            mean_tracks: tracks,
            mean_true_tracks: tracks,
            runs_with_two_tracks: 0,
            runs_with_two_true_tracks: 0,
            runs: 3,
            mean_delay_error_ns: error_ns,
            rms_delay_error_ns: error_ns,
            sigma_measurement_m: None,
        }
    }

    fn sweep() -> Vec<SweepPoint> {
        let mut points = Vec::new();
        for power_db in [-100.0, -116.0, -126.0] {
            for tracker in ArtificialTracker::ALL {
                for window in [true, false] {
                    // A NaN error (no true track) must be left out, not drawn.
                    let error = if power_db == -126.0 && !window { f64::NAN } else { 0.01 * (-100.0 - power_db + 1.0) };
                    points.push(point(power_db, window, tracker, 2.0 - power_db / 100.0, error));
                }
            }
        }
        points
    }

    #[test]
    fn power_plots_label_every_series_and_the_targets() {
        let points = sweep();
        for svg in
            [tracks_vs_power_svg(&points, -126.0).unwrap(), delay_error_vs_power_svg(&points, 0.03, -116.0).unwrap()]
        {
            assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{svg}");
            for tracker in ArtificialTracker::ALL {
                for window in [true, false] {
                    assert!(svg.contains(&series_label(tracker, window)), "{}", series_label(tracker, window));
                }
            }
            assert!(!svg.contains("NaN") && !svg.contains("inf"), "a non-finite value reached the SVG");
        }
        assert!(tracks_vs_power_svg(&points, -126.0).unwrap().contains("2 tracks (the two MPCs)"));
        assert!(delay_error_vs_power_svg(&points, 0.03, -116.0).unwrap().contains("target: below 0.03 ns at -116 dB"));
    }

    #[test]
    fn separation_plot_draws_one_line_per_power_present() {
        let bins: Vec<SeparationBin> = [-100.0, -116.0]
            .into_iter()
            .flat_map(|power_db| {
                (0..7).map(move |i| SeparationBin {
                    power_db,
                    kaiser_window: true,
                    tracker: ArtificialTracker::Proposed,
                    separation_ns: (2.5 + 2.5 * f64::from(i))..(5.0 + 2.5 * f64::from(i)),
                    points: 10,
                    truth_points: 20,
                    mean_delay_error_ns: 0.01 + 0.001 * f64::from(i),
                })
            })
            .collect();
        // -130 dB has no bins: no legend entry for it.
        let svg =
            delay_error_vs_separation_svg(&bins, ArtificialTracker::Proposed, true, &[-100.0, -116.0, -130.0], 0.03)
                .unwrap();
        assert!(svg.contains("-100 dB") && svg.contains("-116 dB") && !svg.contains("-130 dB"), "{svg}");
        assert!(svg.contains("target level 0.03 ns"));
    }

    #[test]
    fn empty_input_gives_a_plot_not_a_panic() {
        assert!(tracks_vs_power_svg(&[], -126.0).unwrap().contains("<svg"));
        assert!(delay_error_vs_power_svg(&[], 0.03, -116.0).unwrap().contains("<svg"));
        assert!(
            delay_error_vs_separation_svg(&[], ArtificialTracker::Proposed, true, &[-116.0], 0.03)
                .unwrap()
                .contains("<svg")
        );
    }
}
