//! The geometric Doppler-bearing tracker (Zoechmann et al. 2019) in `mmtrack
//! analyze`: the table `geometric_per_epoch` that `mmtrack process beam
//! --tracker geometric` wrote, checked and summarised per sequence
//! (`geometric_summary`), with a figure per sequence.
//!
//! The tracker starts in H-infinity mode and hands over to RLS at the epoch
//! of the third distinct measured azimuth (Sec. IV, the switch between (16)
//! and (19)); until then the regression matrix is rank deficient, the range
//! is unobservable and the estimate is "not converged". Errors are therefore
//! scored from the hand-over epoch on (inclusive): the range of the
//! projection (10) and the azimuth of the projection (11) against the truth,
//! `e_r,k = r^_k - r_k` and `e_phi,k = wrap(phi^_k - phi_k)`, RMS over those
//! epochs and the absolute value at the last epoch. A sequence that never
//! hands over has no error numbers (null), never a number of an
//! unconverged estimate.
//!
//! Beam accounting: a full scan measures the whole codebook; the codebook's
//! size is the most beams measured at one epoch (every schedule of `process
//! beam` starts with full scans); the saving is the beams a full scan at
//! every epoch would measure over the beams measured (the paper's Sec. VI:
//! 128 / 3 ~ 43 on the windowed epochs).

use mmtrack_io::table::{GEOMETRIC_FILTER_H_INFINITY as H_INFINITY, GEOMETRIC_FILTER_RLS as RLS};
use std::fmt::Write;

use mmtrack_core::stats::rms;
use mmtrack_core::wrap_angle_rad;

use super::geometric_plots::GeometricTrackingSeries;
use mmtrack_io::table::{GEOMETRIC_PER_EPOCH, GeometricEpochRow, GeometricSummaryRow};

/// The figure of one sequence, with its caption.
pub const SEQUENCE_PLOT: (&str, &str) =
    ("geometric_tracking.svg", "range, azimuth and beams measured against the truth");

/// One sequence: its summary and epochs.
#[derive(Debug, Clone, PartialEq)]
pub struct GeometricSequenceResult {
    /// Sequence id (the partition).
    pub sequence: String,
    /// The `geometric_summary` row.
    pub summary: GeometricSummaryRow,
    /// The `geometric_per_epoch` rows, epoch 0 first.
    pub per_epoch: Vec<GeometricEpochRow>,
}

impl GeometricSequenceResult {
    /// The estimate against the truth, for
    /// [`super::geometric_plots::geometric_tracking_svg`].
    #[must_use]
    pub fn tracking_series(&self) -> GeometricTrackingSeries {
        let t0 = self.per_epoch.first().map_or(0, |r| r.t_ns);
        let mut s = GeometricTrackingSeries {
            handover_s: self.summary.handover_s,
            codebook_beams: self.summary.codebook_beams,
            ..GeometricTrackingSeries::default()
        };
        for r in &self.per_epoch {
            s.t_s.push((r.t_ns - t0) as f64 * 1e-9);
            s.range_m.push(r.range_m);
            s.true_range_m.push(r.true_range_m);
            s.azimuth_deg.push(wrap_angle_rad(r.azimuth_rad).to_degrees());
            s.true_azimuth_deg.push(wrap_angle_rad(r.true_azimuth_rad).to_degrees());
            s.beams_measured.push(r.beams_measured);
        }
        s
    }
}

/// Everything computed from the `geometric_per_epoch` tables.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GeometricResults {
    /// Per sequence, in sequence order.
    pub sequences: Vec<GeometricSequenceResult>,
}

impl GeometricResults {
    /// Whether there is nothing.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.sequences.is_empty()
    }
}

/// Checks the rows of one sequence: epochs in order, time increasing, every
/// number finite, ranges positive, a known filter that never returns from
/// RLS to H-infinity (the tracker's hand-over is one-way), at least one beam
/// per epoch.
fn check(sequence: &str, rows: &[GeometricEpochRow]) -> Result<(), String> {
    let table = GEOMETRIC_PER_EPOCH.name;
    let at = |k: usize| format!("sequence {sequence}: table {table} row {k}");
    if rows.is_empty() {
        return Err(format!("sequence {sequence}: table {table} has no rows"));
    }
    let mut in_rls = false;
    for (k, r) in rows.iter().enumerate() {
        if r.epoch != k as u64 {
            return Err(format!("{}: column epoch is {}, expected {k} (rows in epoch order)", at(k), r.epoch));
        }
        if k > 0 && r.t_ns <= rows[k - 1].t_ns {
            return Err(format!(
                "{}: column t_ns is {}, not after the previous row's {} (time must increase)",
                at(k),
                r.t_ns,
                rows[k - 1].t_ns
            ));
        }
        let columns = [
            ("measured_azimuth_rad", r.measured_azimuth_rad),
            ("measured_doppler_hz", r.measured_doppler_hz),
            ("range_m", r.range_m),
            ("true_range_m", r.true_range_m),
            ("azimuth_rad", r.azimuth_rad),
            ("true_azimuth_rad", r.true_azimuth_rad),
            ("vx_mps", r.vx_mps),
            ("vy_mps", r.vy_mps),
            ("true_vx_mps", r.true_vx_mps),
            ("true_vy_mps", r.true_vy_mps),
        ];
        if let Some((name, value)) = columns.iter().find(|(_, v)| !v.is_finite()) {
            return Err(format!("{}: column {name} is {value}, expected finite", at(k)));
        }
        if r.true_range_m <= 0.0 {
            return Err(format!("{}: column true_range_m is {}, expected positive", at(k), r.true_range_m));
        }
        if r.beams_measured == 0 {
            return Err(format!("{}: column beams_measured is 0, expected at least one beam", at(k)));
        }
        match r.filter.as_str() {
            RLS => in_rls = true,
            H_INFINITY if in_rls => {
                return Err(format!(
                    "{}: column filter is {H_INFINITY} after {RLS}; the hand-over to RLS is one-way",
                    at(k)
                ));
            }
            H_INFINITY => {}
            other => return Err(format!("{}: column filter is `{other}`, expected {H_INFINITY} or {RLS}", at(k))),
        }
    }
    Ok(())
}

/// Checks one sequence's `geometric_per_epoch` rows and summarises them
/// (module docs).
///
/// # Errors
/// A message naming the sequence, the table, the row and the column when the
/// table is empty, out of epoch order, not increasing in `t_ns`, holds a
/// non-finite number, a non-positive true range, an epoch without beams, or
/// a filter other than `h-infinity` then `rls`.
pub fn sequence_result(sequence: &str, rows: Vec<GeometricEpochRow>) -> Result<GeometricSequenceResult, String> {
    check(sequence, &rows)?;
    // `check` refuses an empty table.
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    let handover = rows.iter().position(|r| r.filter == RLS);
    let converged = &rows[handover.unwrap_or(rows.len())..];
    let range_error = |r: &GeometricEpochRow| r.range_m - r.true_range_m;
    let azimuth_error = |r: &GeometricEpochRow| wrap_angle_rad(r.azimuth_rad - r.true_azimuth_rad);
    let codebook_beams = rows.iter().map(|r| r.beams_measured).max().unwrap_or(0);
    let beams_measured: u64 = rows.iter().map(|r| r.beams_measured).sum();
    let beams_full_scan = rows.len() as u64 * codebook_beams;
    let summary = GeometricSummaryRow {
        epochs: rows.len() as u64,
        duration_s: (last.t_ns - first.t_ns) as f64 * 1e-9,
        handover_epoch: handover.map(|k| k as u64),
        handover_s: handover.map(|k| (rows[k].t_ns - first.t_ns) as f64 * 1e-9),
        rls_share: converged.len() as f64 / rows.len() as f64,
        range_rmse_m: rms(converged.iter().map(range_error)),
        final_range_error_m: handover.map(|_| range_error(last).abs()),
        azimuth_rmse_rad: rms(converged.iter().map(azimuth_error)),
        final_azimuth_error_rad: handover.map(|_| azimuth_error(last).abs()),
        codebook_beams,
        beams_measured,
        beams_full_scan,
        saving: beams_full_scan as f64 / beams_measured as f64,
    };
    Ok(GeometricSequenceResult { sequence: sequence.to_string(), summary, per_epoch: rows })
}

fn opt(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "n/a".to_string(), |v| format!("{v:.decimals$}"))
}

/// The report section.
pub fn section(out: &mut String, results: &GeometricResults) {
    out.push_str(
        "## Geometric Doppler-bearing tracking (table `geometric_per_epoch`)\n\n\
         Zoechmann et al. 2019: H-infinity until the third distinct azimuth, then RLS (Sec. IV). Errors of the \
         projected range (10) and azimuth (11) against the truth from the hand-over on; `n/a`: the tracker never \
         handed over (the range is unobservable while the azimuth stays in one beam: not converged, not scored). \
         Beams: measured against a full scan at every epoch.\n\n\
         | sequence | epochs | duration (s) | hand-over (s) | RLS epochs (%) | range RMSE (m) | final range error \
         (m) | azimuth RMSE (deg) | final azimuth error (deg) | beams measured / full scan | saving |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &results.sequences {
        let s = &r.summary;
        let _ = writeln!(
            out,
            "| {} | {} | {:.2} | {} | {:.1} | {} | {} | {} | {} | {} / {} | {:.1} |",
            r.sequence,
            s.epochs,
            s.duration_s,
            opt(s.handover_s, 2),
            100.0 * s.rls_share,
            opt(s.range_rmse_m, 2),
            opt(s.final_range_error_m, 2),
            opt(s.azimuth_rmse_rad.map(f64::to_degrees), 2),
            opt(s.final_azimuth_error_rad.map(f64::to_degrees), 2),
            s.beams_measured,
            s.beams_full_scan,
            s.saving,
        );
    }
    out.push('\n');
    for r in &results.sequences {
        let _ = writeln!(
            out,
            "### `{}` (geometric)\n\n![{}](plots/{}/{})\n",
            r.sequence, SEQUENCE_PLOT.1, r.sequence, SEQUENCE_PLOT.0
        );
    }
}

/// One line per sequence, as the CLI prints it.
#[must_use]
pub fn one_lines(results: &GeometricResults) -> Vec<String> {
    results
        .sequences
        .iter()
        .map(|r| {
            let s = &r.summary;
            let errors = match (s.handover_s, s.range_rmse_m, s.azimuth_rmse_rad) {
                (Some(t), Some(range), Some(azimuth)) => format!(
                    "hand-over to RLS at {t:.2} s, then range RMSE {range:.2} m, azimuth RMSE {:.2} deg",
                    azimuth.to_degrees()
                ),
                _ => "never handed over to RLS (not converged)".to_string(),
            };
            // A full scan every epoch measures as many beams as the reference.
            let saving = if s.saving < 1.05 {
                "as many as a full scan every epoch".to_string()
            } else {
                format!("{:.1}x fewer than a full scan every epoch", s.saving)
            };
            format!(
                "{}: geometric tracker, {} epochs over {:.2} s, {errors}; {} beams measured ({saving})",
                r.sequence, s.epochs, s.duration_s, s.beams_measured
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Epoch `k` at 20 ms, range error `dr` and azimuth error `da`.
    fn row(k: u64, filter: &str, beams: u64, dr: f64, da: f64) -> GeometricEpochRow {
        GeometricEpochRow {
            epoch: k,
            t_ns: 1_000_000_000 + 20_000_000 * k as i64,
            filter: filter.into(),
            beams_measured: beams,
            measured_azimuth_rad: 0.1,
            measured_doppler_hz: -50.0,
            range_m: 10.0 + dr,
            true_range_m: 10.0,
            azimuth_rad: wrap_angle_rad(3.1 + da),
            true_azimuth_rad: 3.1,
            vx_mps: 1.0,
            vy_mps: 0.0,
            true_vx_mps: 1.0,
            true_vy_mps: 0.0,
        }
    }

    #[test]
    fn summary_scores_only_from_the_hand_over_by_hand() {
        // 2 H-infinity epochs (errors huge, not scored), then 3 RLS epochs
        // with range errors 1, -2, 2 m (RMS sqrt(3)) and azimuth errors 0.1,
        // -0.1, 0.2 rad across the +-pi wrap (RMS sqrt(0.02)).
        let rows = vec![
            row(0, H_INFINITY, 128, -10.0, 1.0),
            row(1, H_INFINITY, 128, 50.0, 1.0),
            row(2, RLS, 3, 1.0, 0.1),
            row(3, RLS, 3, -2.0, -0.1),
            row(4, RLS, 3, 2.0, 0.2),
        ];
        let s = sequence_result("s", rows).unwrap().summary;
        assert_eq!((s.epochs, s.handover_epoch, s.codebook_beams), (5, Some(2), 128));
        // Times are integers of ns: 1e-12 s covers the f64 conversion.
        assert!((s.duration_s - 0.08).abs() < 1e-12 && (s.handover_s.unwrap() - 0.04).abs() < 1e-12, "{s:?}");
        assert!((s.rls_share - 0.6).abs() < 1e-15);
        // 1e-12: a handful of f64 operations on numbers of order 10.
        assert!((s.range_rmse_m.unwrap() - 3f64.sqrt()).abs() < 1e-12, "{s:?}");
        assert!((s.final_range_error_m.unwrap() - 2.0).abs() < 1e-12);
        assert!((s.azimuth_rmse_rad.unwrap() - 0.02f64.sqrt()).abs() < 1e-12, "{s:?}");
        assert!((s.final_azimuth_error_rad.unwrap() - 0.2).abs() < 1e-12);
        assert_eq!((s.beams_measured, s.beams_full_scan), (265, 640));
        assert!((s.saving - 640.0 / 265.0).abs() < 1e-15);
        let mut text = String::new();
        section(
            &mut text,
            &GeometricResults { sequences: vec![sequence_result("s", vec![row(0, RLS, 5, 0.5, 0.0)]).unwrap()] },
        );
        assert!(text.contains("| s | 1 | 0.00 | 0.00 | 100.0 | 0.50 | 0.50 | 0.00 | 0.00 | 5 / 5 | 1.0 |"), "{text}");
    }

    #[test]
    fn a_run_that_never_hands_over_has_no_error_numbers() {
        let rows: Vec<_> = (0..4).map(|k| row(k, H_INFINITY, if k < 2 { 128 } else { 3 }, 80.0, 0.5)).collect();
        let s = sequence_result("s", rows).unwrap().summary;
        assert_eq!((s.handover_epoch, s.handover_s, s.range_rmse_m, s.final_range_error_m), (None, None, None, None));
        assert_eq!((s.azimuth_rmse_rad, s.final_azimuth_error_rad, s.rls_share), (None, None, 0.0));
        assert_eq!((s.beams_measured, s.beams_full_scan), (262, 512));
        let line = one_lines(&GeometricResults {
            sequences: vec![GeometricSequenceResult { sequence: "s".into(), summary: s, per_epoch: Vec::new() }],
        });
        assert!(line[0].contains("never handed over to RLS (not converged)"), "{line:?}");
    }

    #[test]
    fn bad_tables_are_named_with_sequence_row_and_column() {
        let good = || (0..3).map(|k| row(k, if k < 1 { H_INFINITY } else { RLS }, 3, 0.0, 0.0)).collect::<Vec<_>>();
        let mut rows = good();
        rows[1].range_m = f64::NAN;
        let err = sequence_result("p", rows).unwrap_err();
        assert_eq!(err, "sequence p: table geometric_per_epoch row 1: column range_m is NaN, expected finite");
        let mut rows = good();
        rows[2].t_ns = rows[1].t_ns;
        let err = sequence_result("p", rows).unwrap_err();
        assert!(err.starts_with("sequence p: table geometric_per_epoch row 2: column t_ns is"), "{err}");
        let mut rows = good();
        rows[2].filter = H_INFINITY.into();
        let err = sequence_result("p", rows).unwrap_err();
        assert!(err.contains("row 2: column filter is h-infinity after rls"), "{err}");
        let mut rows = good();
        rows[0].filter = "kalman".into();
        assert!(sequence_result("p", rows).unwrap_err().contains("column filter is `kalman`"));
        let mut rows = good();
        rows[1].epoch = 7;
        assert!(sequence_result("p", rows).unwrap_err().contains("row 1: column epoch is 7, expected 1"));
        let mut rows = good();
        rows[0].beams_measured = 0;
        assert!(sequence_result("p", rows).unwrap_err().contains("row 0: column beams_measured is 0"));
        let mut rows = good();
        rows[0].true_range_m = 0.0;
        assert!(sequence_result("p", rows).unwrap_err().contains("row 0: column true_range_m is 0, expected positive"));
        assert!(sequence_result("p", Vec::new()).unwrap_err().contains("has no rows"));
    }
}
