//! SVG plots of the MPC statistics (Mahler et al. 2017, Figs. 6-9, 12-13),
//! drawn with plotters' SVG backend. Each returns the SVG document.

use plotters::prelude::*;

use crate::mpc::MpcResult;

/// Sets shown in the delay-vs-time plot (from the first set): 30 sets are
/// 0.3 s at the paper's 10 ms set period, enough to see tracks evolve.
pub const DELAY_PLOT_SETS: usize = 30;

/// Why the plot `file` (of [`crate::mpc_report::PLOTS`]) of `result` would
/// have nothing to draw, or `None` when it has data. `mmtrack analyze` writes
/// no such file and the report says why in its place (a single-snapshot
/// source, as the BUT 60 GHz sample, drew axes without curves).
#[must_use]
pub fn empty_because(result: &MpcResult, file: &str) -> Option<String> {
    let sets = mmtrack_core::words::counted(result.per_set.len() as u64, "set");
    match file {
        "mpc_delay_tracks.svg" if result.detections.is_empty() => Some("no detections".into()),
        // Without tracks the summary's counts are null ("n/a" in the report)
        // and so is their distribution: a plot of zeros would contradict it
        // (the UWB log, one snapshot per set, drew "252 sets with 0 MPCs").
        "mpc_count.svg" if result.counts.is_empty() => {
            Some("the MPCs of a set are its long-term tracks; this sequence has none".into())
        }
        "mpc_birth_death.svg"
            if result.per_set.iter().all(|s| s.birth_rate_per_s.is_none() && s.birth_rate_per_m.is_none()) =>
        {
            Some(format!("birth and death rates are taken between consecutive sets; this sequence has {sets}"))
        }
        "mpc_birth_death.svg" if result.summary.births.is_none() => {
            Some("births and deaths are of long-term tracks; this sequence has none".into())
        }
        "mpc_power_loss.svg" if result.per_set.len() < 2 => {
            Some(format!("gain and loss are drawn against time over sets; this sequence has {sets}"))
        }
        "mpc_power_std.svg" if result.power_std.is_empty() => Some(
            "no short-term tracks (a track follows one path over at least short_term.min_track_length snapshots \
             of one set)"
                .into(),
        ),
        _ => None,
    }
}

/// A labelled line: label, points, colour.
type Series<'a> = (&'a str, Vec<(f64, f64)>, RGBColor);

use crate::plot_common::{err, padded_range as padded};

/// Empirical CDF points (sorted value, share at or below).
fn ecdf(mut values: Vec<f64>) -> Vec<(f64, f64)> {
    values.retain(|v| v.is_finite());
    values.sort_by(f64::total_cmp);
    let n = values.len() as f64;
    values.iter().enumerate().map(|(i, &v)| (v, (i + 1) as f64 / n)).collect()
}

/// A five-stop viridis-like colour for `x` in 0..=1 (plotters' colormaps
/// feature is not enabled in the workspace).
pub(crate) fn viridis(x: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] =
        [(68.0, 1.0, 84.0), (59.0, 82.0, 139.0), (33.0, 145.0, 140.0), (94.0, 201.0, 98.0), (253.0, 231.0, 37.0)];
    let x = if x.is_finite() { x.clamp(0.0, 1.0) } else { 0.0 } * 4.0;
    let i = (x.floor() as usize).min(3);
    let w = x - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let lerp = |p: f64, q: f64| (p + w * (q - p)).round() as u8;
    RGBColor(lerp(a.0, b.0), lerp(a.1, b.1), lerp(a.2, b.2))
}

fn t0(result: &MpcResult) -> i64 {
    result.per_set.first().map_or(0, |s| s.t_ns)
}

/// Number of MPCs per set: histogram (top) and CDF (bottom) (Fig. 12).
pub fn count_svg(result: &MpcResult) -> anyhow::Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let panels = root.split_evenly((2, 1));
        let max_count = result.counts.iter().map(|c| c.mpcs).max().unwrap_or(0) as f64 + 1.0;
        let max_sets = result.counts.iter().map(|c| c.sets).max().unwrap_or(1) as f64;
        let mut hist = ChartBuilder::on(&panels[0])
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(-0.5..max_count, 0.0..max_sets * 1.1)
            .map_err(err)?;
        crate::plot_common::draw_axes(&mut hist, "MPCs per set", "sets")?;
        hist.draw_series(result.counts.iter().map(|c| {
            let x = c.mpcs as f64;
            Rectangle::new([(x - 0.4, 0.0), (x + 0.4, c.sets as f64)], BLUE.mix(0.6).filled())
        }))
        .map_err(err)?;
        let mut cdf = ChartBuilder::on(&panels[1])
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(-0.5..max_count, 0.0..1.05)
            .map_err(err)?;
        crate::plot_common::draw_axes(&mut cdf, "MPCs per set", "CDF")?;
        let steps: Vec<(f64, f64)> = result
            .counts
            .iter()
            .scan(0.0, |prev, c| {
                let out = [(c.mpcs as f64, *prev), (c.mpcs as f64, c.cdf)];
                *prev = c.cdf;
                Some(out)
            })
            .flatten()
            .collect();
        cdf.draw_series(LineSeries::new(steps, BLUE.stroke_width(2))).map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

fn cdf_chart(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    x_desc: &str,
    series: &[Series<'_>],
) -> anyhow::Result<()> {
    let xs = padded(series.iter().flat_map(|s| s.1.iter().map(|p| p.0)));
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(xs, 0.0..1.05)
        .map_err(err)?;
    crate::plot_common::draw_axes(&mut chart, x_desc, "CDF")?;
    for (label, points, color) in series {
        let color = *color;
        crate::palette::draw_series_line(
            &mut chart,
            points.iter().copied(),
            crate::palette::SeriesStyle::solid(color, 2),
            *label,
        )?;
    }
    crate::plot_common::draw_legend(&mut chart, SeriesLabelPosition::LowerRight)?;
    Ok(())
}

/// CDF of the per-transition birth and death rates (Fig. 13): per metre when
/// a distance is known, else per second.
pub fn birth_death_svg(result: &MpcResult) -> anyhow::Result<String> {
    let per_m = result.per_set.iter().any(|s| s.birth_rate_per_m.is_some());
    let (births, deaths): (Vec<f64>, Vec<f64>) = if per_m {
        (
            result.per_set.iter().filter_map(|s| s.birth_rate_per_m).collect(),
            result.per_set.iter().filter_map(|s| s.death_rate_per_m).collect(),
        )
    } else {
        (
            result.per_set.iter().filter_map(|s| s.birth_rate_per_s).collect(),
            result.per_set.iter().filter_map(|s| s.death_rate_per_s).collect(),
        )
    };
    let unit = if per_m { "1/m travelled, both vehicles" } else { "1/s; no trajectory in the tables" };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 500)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        cdf_chart(
            &root,
            &format!("rate per set transition ({unit})"),
            &[("birth rate", ecdf(births), BLUE), ("death rate", ecdf(deaths), RED)],
        )?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// Channel, detected and tracked gain per set (top, Fig. 8) and the losses
/// (bottom, Fig. 9) against time.
pub fn power_loss_svg(result: &MpcResult) -> anyhow::Result<String> {
    let t0 = t0(result);
    let t = |t_ns: i64| (t_ns - t0) as f64 * 1e-9;
    type Getter = fn(&mmtrack_io::table::SetMetrics) -> Option<f64>;
    let gains: [(&str, Getter, RGBColor); 4] = [
        ("channel", |s| s.channel_gain_db, BLACK),
        ("detected", |s| s.detected_gain_db, BLUE),
        ("tracked (short-term)", |s| s.tracked_gain_db, RED),
        ("tracked (GM-PHD)", |s| s.gmphd_tracked_gain_db, GREEN),
    ];
    let losses: [(&str, Getter, RGBColor); 3] = [
        ("detection loss", |s| s.detection_loss_db, BLUE),
        ("tracking loss (short-term)", |s| s.tracking_loss_db, RED),
        ("tracking loss (GM-PHD)", |s| s.gmphd_tracking_loss_db, GREEN),
    ];
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 760)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let panels = root.split_evenly((2, 1));
        for (panel, (series, y_desc)) in
            panels.iter().zip([(&gains[..], "gain (dB)"), (&losses[..], "power loss (dB)")])
        {
            let points: Vec<Series<'_>> = series
                .iter()
                .map(|(label, get, color)| {
                    let p: Vec<(f64, f64)> = result
                        .per_set
                        .iter()
                        .filter_map(|s| get(s).filter(|v| v.is_finite()).map(|v| (t(s.t_ns), v)))
                        .collect();
                    (*label, p, *color)
                })
                .filter(|(_, p, _)| !p.is_empty())
                .collect();
            let xs = padded(result.per_set.iter().map(|s| t(s.t_ns)));
            let ys = padded(points.iter().flat_map(|s| s.1.iter().map(|p| p.1)));
            let mut chart = ChartBuilder::on(panel)
                .margin(12)
                .x_label_area_size(45)
                .y_label_area_size(60)
                .build_cartesian_2d(xs, ys)
                .map_err(err)?;
            crate::plot_common::draw_axes(&mut chart, "time (s)", y_desc)?;
            for (label, p, color) in points {
                chart
                    .draw_series(LineSeries::new(p, color.stroke_width(1)))
                    .map_err(err)?
                    .label(label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
            }
            crate::plot_common::draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// CDF of the per-track power standard deviation (Fig. 7).
pub fn power_std_svg(result: &MpcResult) -> anyhow::Result<String> {
    let full = ecdf(result.power_std.iter().filter(|p| p.full_lifetime).map(|p| p.power_std_db).collect());
    let all = ecdf(result.power_std.iter().map(|p| p.power_std_db).collect());
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 500)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        cdf_chart(
            &root,
            "power standard deviation over the set (dB)",
            &[("full-lifetime tracks", full, RED), ("all short-term tracks", all, BLUE)],
        )?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// What the delay plot leaves out: `Some("first 30 of 412 sets")` when the
/// sequence has more than [`DELAY_PLOT_SETS`] sets, else `None`.
#[must_use]
pub fn delay_plot_subset(result: &MpcResult) -> Option<String> {
    let sets = result.per_set.len();
    (sets > DELAY_PLOT_SETS).then(|| format!("first {DELAY_PLOT_SETS} of {sets} sets"))
}

/// Delay against time over the first [`DELAY_PLOT_SETS`] sets (the caption
/// says so when there are more): detections
/// coloured by power (dark weak, yellow strong), short-term tracks as lines.
pub fn delay_tracks_svg(result: &MpcResult) -> anyhow::Result<String> {
    let t0 = t0(result);
    let window_end = result.per_set.get(DELAY_PLOT_SETS).map_or(i64::MAX, |s| s.t_ns);
    let in_window = |t_ns: i64| t_ns < window_end;
    let t = |t_ns: i64| (t_ns - t0) as f64 * 1e-9;
    let detections: Vec<_> = result.detections.iter().filter(|d| in_window(d.t_ns)).collect();
    let powers: Vec<f64> = detections.iter().map(|d| d.power_db()).filter(|p| p.is_finite()).collect();
    let p_hi = powers.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let p_lo = powers.iter().copied().fold(f64::INFINITY, f64::min).max(p_hi - 40.0);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1000, 650)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let xs = padded(detections.iter().map(|d| t(d.t_ns)));
        let ys = padded(detections.iter().map(|d| d.delay_s * 1e9));
        let mut chart = ChartBuilder::on(&root)
            .margin(12)
            .caption(
                format!(
                    "{}: detections by power ({p_lo:.0}..{p_hi:.0} dB, dark to yellow), short-term tracks{}",
                    result.sequence,
                    delay_plot_subset(result).map_or_else(String::new, |note| format!("; {note}"))
                ),
                ("sans-serif", 16),
            )
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(xs, ys)
            .map_err(err)?;
        crate::plot_common::draw_axes(&mut chart, "time (s)", "delay (ns)")?;
        let span = (p_hi - p_lo).max(1e-9);
        chart
            .draw_series(detections.iter().map(|d| {
                let c = viridis((d.power_db() - p_lo) / span);
                Circle::new((t(d.t_ns), d.delay_s * 1e9), 3, c.filled())
            }))
            .map_err(err)?;
        for track in result.tracks.iter().filter(|tr| tr.detections.first().is_some_and(|d| in_window(d.t_ns))) {
            chart
                .draw_series(LineSeries::new(
                    track.detections.iter().map(|d| (t(d.t_ns), d.delay_s * 1e9)),
                    RED.stroke_width(1),
                ))
                .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}
