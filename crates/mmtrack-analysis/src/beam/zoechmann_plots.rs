//! The geometric Doppler-bearing tracking experiment of Zoechmann et al.
//! 2019 (`mmtrack reproduce zoechmann`): its result tables and its figures,
//! like the paper's Figs. 4 and 5: the `(x, y)` estimate of the proposed
//! tracker on the first Monte Carlo run against the true path (middle panel)
//! and the NMSE of the range over time for the four estimators (bottom
//! panel), one figure per manoeuvre.
//!
//! NMSE of the range at epoch `k` over the runs `n`:
//! `sum_n (r^_k,n - r_k,n)^2 / sum_n r_k,n^2`, in dB. The paper plots an
//! NMSE without defining its normalisation; this is the usual one.

use plotters::prelude::*;

use crate::plots::{err, padded_range};

mmtrack_io::define_table! {
    /// `zoechmann_nmse`: NMSE of the range per epoch, manoeuvre and estimator.
    pub const ZOECHMANN_NMSE = "zoechmann_nmse",
        "NMSE of the range over the Monte Carlo runs of one manoeuvre (Zoechmann et al. 2019, Figs. 4-5), per epoch and \
estimator: sum over runs of (r_est - r)^2 over the sum of r^2, r the true range at the epoch and r_est the estimator's \
range at the same time (the proposed tracker and the genies project their initial state (10); the batch baseline \
estimates it directly).";
    /// One row of [`ZOECHMANN_NMSE`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct ZoechmannNmseRow {
        manoeuvre: String, "", "half-overtaking or full-overtaking";
        estimator: String, "",
            "proposed, ho-chan, error-free-genie, nullspace-genie; variants: proposed-full-scan (the proposed tracker on \
a full scan's azimuth every epoch), proposed-gated (its 3-beam window only after the hand-over to RLS)";
        epoch: u64, "", "epoch index (20 ms each)";
        t_s: f64, "s", "time since the start of the manoeuvre";
        runs: u64, "", "Monte Carlo runs with an estimate at this epoch";
        nmse: f64, "", "sum (r_est - r)^2 / sum r^2";
        nmse_db: f64, "dB", "10 log10(nmse)";
        rmse_m: f64, "m", "root mean squared range error";
    }
}

mmtrack_io::define_table! {
    /// `zoechmann_summary`: per manoeuvre, convergence and beam accounting.
    pub const ZOECHMANN_SUMMARY = "zoechmann_summary",
        "Per manoeuvre of reproduce zoechmann: the proposed tracker's hand-over from H-infinity to RLS (the epoch of the \
third distinct azimuth) over the runs, and the beams it measured (full scans for the first 10 epochs, then the 3 beams \
nearest the projected azimuth) against a full scan at every epoch.";
    /// One row of [`ZOECHMANN_SUMMARY`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct ZoechmannSummaryRow {
        manoeuvre: String, "", "half-overtaking or full-overtaking";
        runs: u64, "", "Monte Carlo runs";
        epochs: u64, "", "epochs per run";
        not_converged_runs: u64, "", "runs that never saw three distinct azimuths (H-infinity to the end)";
        handover_median_s: Option<f64>, "s", "median hand-over time over converged runs; null if none";
        handover_mean_s: Option<f64>, "s", "mean hand-over time over converged runs; null if none";
        handover_p90_s: Option<f64>, "s", "90th percentile (nearest rank) of the hand-over time; null if none";
        handover_median_full_scan_s: Option<f64>, "s",
            "median hand-over time of the variant fed full-scan azimuths every epoch; null if none";
        beams_measured: u64, "", "beams measured by the proposed tracker, all runs";
        beams_full_scan: u64, "", "beams a full scan at every epoch would measure, all runs";
        saving: f64, "", "beams_full_scan / beams_measured over whole runs";
        windowed_saving: f64, "", "the same over the epochs after the full scans (the paper's 128 / 3)";
        window_hit_rate: f64, "", "share of windowed epochs whose 3 beams include the strongest beam of the codebook";
        gated_saving: f64, "",
            "saving over whole runs of the gated variant (window only after the hand-over to RLS, full scans before)";
        gated_window_hit_rate: f64, "", "window_hit_rate of the gated variant";
        estimator_failures: u64, "", "estimator updates that returned an error (all estimators, all runs)";
    }
}

/// One NMSE curve: label and NMSE (linear) per epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct NmseCurve {
    /// Legend text.
    pub label: String,
    /// NMSE of epoch `k` at index `k` (linear; plotted in dB).
    pub nmse: Vec<f64>,
}

/// The `(x, y)` panel: the true path and the estimates of one run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PositionTrace {
    /// True positions per epoch, metres.
    pub truth_m: Vec<[f64; 2]>,
    /// Estimated positions per epoch, metres.
    pub estimate_m: Vec<[f64; 2]>,
}

/// A figure like Figs. 4-5 of the paper: the first run's `(x, y)` estimate
/// over the true path (top) and the NMSE of the range in dB against time
/// (bottom), epochs `epoch_s` apart.
///
/// # Errors
/// When plotters fails to draw (not expected for finite input).
pub fn zoechmann_figure_svg(
    title: &str,
    trace: &PositionTrace,
    curves: &[NmseCurve],
    epoch_s: f64,
) -> anyhow::Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 900)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
        let panels = root.split_evenly((2, 1));
        draw_trace(&panels[0], trace)?;
        draw_nmse(&panels[1], curves, epoch_s)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

fn draw_trace(area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>, trace: &PositionTrace) -> anyhow::Result<()> {
    // The axes follow the true path (and the receiver), padded by 30 % or
    // 5 m: a diverged estimate must not squash the picture; estimates outside
    // are counted in the legend.
    let pad = |r: std::ops::Range<f64>| {
        let p = (0.3 * (r.end - r.start)).max(5.0);
        (r.start - p)..(r.end + p)
    };
    let x = pad(padded_range(trace.truth_m.iter().map(|p| p[0]).chain([0.0])));
    let y = pad(padded_range(trace.truth_m.iter().map(|p| p[1]).chain([0.0])));
    let inside: Vec<(f64, f64)> =
        trace.estimate_m.iter().map(|p| (p[0], p[1])).filter(|(a, b)| x.contains(a) && y.contains(b)).collect();
    let outside = trace.estimate_m.len() - inside.len();
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    chart.configure_mesh().x_desc("x along the receiver's heading (m)").y_desc("y (m)").draw().map_err(err)?;
    let truth = BLACK.stroke_width(2);
    chart
        .draw_series(LineSeries::new(trace.truth_m.iter().map(|p| (p[0], p[1])), truth))
        .map_err(err)?
        .label("true path")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], truth));
    chart
        .draw_series(inside.iter().map(|&p| Cross::new(p, 3, RED.stroke_width(1))))
        .map_err(err)?
        .label(if outside == 0 {
            "proposed, first run".to_string()
        } else {
            format!("proposed, first run ({outside} estimates outside the frame)")
        })
        .legend(|(x, y)| Cross::new((x + 10, y), 3, RED.stroke_width(1)));
    chart
        .draw_series([Circle::new((0.0, 0.0), 5, BLUE.filled())])
        .map_err(err)?
        .label("receiver array")
        .legend(|(x, y)| Circle::new((x + 10, y), 4, BLUE.filled()));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .draw()
        .map_err(err)?;
    Ok(())
}

fn draw_nmse(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    curves: &[NmseCurve],
    epoch_s: f64,
) -> anyhow::Result<()> {
    let db = |v: f64| 10.0 * v.log10();
    let values = || curves.iter().flat_map(|c| c.nmse.iter().copied()).filter(|v| *v > 0.0 && v.is_finite()).map(db);
    let y = padded_range(values());
    let epochs = curves.iter().map(|c| c.nmse.len()).max().unwrap_or(2).max(2);
    let t_end = (epochs - 1) as f64 * epoch_s;
    let palette = [RED, BLUE, GREEN, MAGENTA, CYAN, BLACK];
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(0f64..t_end, y.clone())
        .map_err(err)?;
    chart.configure_mesh().x_desc("time (s)").y_desc("NMSE of the range (dB)").draw().map_err(err)?;
    // Variants (after the paper's four) thin and first, so the four stay on top.
    let order: Vec<usize> = (4..curves.len()).chain(0..curves.len().min(4)).collect();
    for index in order {
        let (curve, color) = (&curves[index], palette[index % palette.len()]);
        let style = color.stroke_width(if index < 4 { 2 } else { 1 });
        let points = curve
            .nmse
            .iter()
            .enumerate()
            .filter(|(_, v)| **v > 0.0 && v.is_finite())
            .map(|(k, v)| (k as f64 * epoch_s, db(*v).clamp(y.start, y.end)));
        chart
            .draw_series(LineSeries::new(points, style))
            .map_err(err)?
            .label(curve.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .draw()
        .map_err(err)?;
    Ok(())
}

mmtrack_io::define_table! {
    /// `zoechmann_nlos_error`: per path, position error over time.
    pub const ZOECHMANN_NLOS_ERROR = "zoechmann_nlos_error",
        "The proposed geometric tracker on each path of an overtaking between two walls (line of sight and the two \
single wall bounces, image method), per epoch: RMS error over the Monte Carlo runs of the apparent source's position \
(the transmitter or its mirror image) and velocity, against the simulator's truth.";
    /// One row of [`ZOECHMANN_NLOS_ERROR`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct ZoechmannNlosErrorRow {
        path: String, "", "los, left-wall or right-wall";
        epoch: u64, "", "epoch index (20 ms each)";
        t_s: f64, "s", "time since the start of the manoeuvre";
        runs: u64, "", "runs with an estimate at this epoch";
        position_rmse_m: f64, "m", "RMS distance between estimated and true apparent source";
        velocity_rmse_mps: f64, "m/s", "RMS norm of the relative-velocity error";
    }
}

mmtrack_io::define_table! {
    /// `zoechmann_path_labels`: per path and epoch, the tracker's state of one run.
    pub const ZOECHMANN_PATH_LABELS = "zoechmann_path_labels",
        "Labels for other sensors (Zoechmann et al. 2019, Sec. II and VII): for each path of the first Monte Carlo run, \
the tracker's estimate of the apparent source (transmitter or wall image) in the receiver's frame (x along its heading, \
y to the left) and its relative velocity, per epoch, beside the simulator's truth and the reflection point.";
    /// One row of [`ZOECHMANN_PATH_LABELS`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct ZoechmannPathLabelRow {
        path: String, "", "los, left-wall or right-wall";
        t_s: f64, "s", "time since the start of the manoeuvre";
        x_m: f64, "m", "estimated x of the apparent source";
        y_m: f64, "m", "estimated y of the apparent source";
        vx_mps: f64, "m/s", "estimated relative velocity, x";
        vy_mps: f64, "m/s", "estimated relative velocity, y";
        true_x_m: f64, "m", "true x of the apparent source";
        true_y_m: f64, "m", "true y of the apparent source";
        true_vx_mps: f64, "m/s", "true relative velocity, x";
        true_vy_mps: f64, "m/s", "true relative velocity, y";
        reflection_x_m: Option<f64>, "m", "x of the reflection point on the wall; null for line of sight";
        reflection_y_m: Option<f64>, "m", "y of the reflection point; null for line of sight";
    }
}

mmtrack_io::define_table! {
    /// `geometric_per_epoch`: `process beam --tracker geometric`, one row per epoch.
    pub const GEOMETRIC_PER_EPOCH = "geometric_per_epoch",
        "The geometric Doppler-bearing tracker (Zoechmann et al. 2019) on a recording's two vehicles (channel-sounder \
ground truth of transmitter and receiver): the receiver's 60 GHz UCA codebook and Doppler are simulated along the true \
poses every epoch; per epoch the tracker's estimate and the truth in the receiver's frame (x forward, y left), the \
filter in use and the beams measured.";
    /// One row of [`GEOMETRIC_PER_EPOCH`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct GeometricEpochRow {
        epoch: u64, "", "epoch index";
        t_ns: i64, "ns", "time of the epoch (recording clock)";
        filter: String, "", "h-infinity (not converged) or rls";
        beams_measured: u64, "", "beams measured at this epoch (full scan or window)";
        measured_azimuth_rad: f64, "rad", "azimuth of the strongest measured beam";
        measured_doppler_hz: f64, "Hz", "simulated Doppler shift (range rate / wavelength plus noise)";
        range_m: f64, "m", "estimated range";
        true_range_m: f64, "m", "true range";
        azimuth_rad: f64, "rad", "estimated azimuth (projection (11))";
        true_azimuth_rad: f64, "rad", "true azimuth";
        vx_mps: f64, "m/s", "estimated relative velocity, x";
        vy_mps: f64, "m/s", "estimated relative velocity, y";
        true_vx_mps: f64, "m/s", "true relative velocity in the receiver's frame, x (central difference)";
        true_vy_mps: f64, "m/s", "true relative velocity, y";
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_both_panels() {
        let trace = PositionTrace {
            truth_m: (0..50).map(|k| [0.4 * k as f64, 8.0]).collect(),
            estimate_m: (0..50).map(|k| [0.4 * k as f64, 8.1]).chain([[f64::NAN, 1.0]]).collect(),
        };
        let curves = vec![
            NmseCurve { label: "proposed".into(), nmse: (1..50).map(|k| 1.0 / k as f64).collect() },
            NmseCurve { label: "ho-chan".into(), nmse: vec![0.0, f64::NAN, 0.5, 0.4] },
        ];
        let svg = zoechmann_figure_svg("test", &trace, &curves, 0.02).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("NMSE of the range (dB)") && svg.contains("true path"));
        assert!(svg.matches("<polyline").count() >= 4, "{svg}");
    }
}
