//! `mmtrack process beam --tracker geometric` on a simulated sounder convoy.

use std::path::Path;

use mmtrack_core::wrap_angle_rad;
use mmtrack_io::Overwrite;
use mmtrack_io::table::{GeometricEpochRow, GeometricSummaryRow, RunComparisonRow};
use mmtrack_io::table::{RunInfo, read_table, write_table};

use super::common::{mmtrack, root, text};

#[test]
fn geometric_tracker_on_the_convoy_writes_its_table_and_refuses_mixing() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = root().join("data/sounder/convoy-tunnel.toml");
    let out = mmtrack(
        dir.path(),
        &["simulate", "sounder", "--scenario", scenario.to_str().unwrap(), "--output", "c.mcap", "--sets", "300", "-q"],
    );
    assert!(out.status.success(), "{}", text(&out).1);
    let out = mmtrack(dir.path(), &["process", "beam", "c.mcap", "--tracker", "geometric", "-o", "t"]);
    assert!(out.status.success(), "{}", text(&out).1);
    // Before: "h-infinity; last epoch range 6.66 m (true 86.42 m)" without saying it had not converged.
    assert!(text(&out).0.contains("h-infinity (not converged"), "{}", text(&out).0);
    // One partition, named after the recording's sequence.
    let partitions: Vec<_> = std::fs::read_dir(dir.path().join("t/geometric_per_epoch")).unwrap().collect();
    assert_eq!(partitions.len(), 1);
    let rows: Vec<GeometricEpochRow> =
        read_table(&partitions[0].as_ref().unwrap().path().join("part-0.parquet")).unwrap();
    // 300 sets of the convoy span about 3 s: about 150 epochs of 20 ms.
    assert!(rows.len() > 100, "{}", rows.len());
    // The transmitter drives ~80 m ahead: its azimuth stays in one beam, the
    // range is unobservable, and the tracker stays in H-infinity ("not
    // converged") with finite numbers (the paper's rank-deficient start).
    assert!(rows.iter().all(|r| r.filter == "h-infinity"), "{:?}", rows.last());
    assert!(rows.iter().all(|r| r.range_m.is_finite() && r.vx_mps.is_finite() && r.true_range_m > 50.0));
    // The paper's schedule: 10 full scans of 128 beams, then 3 per epoch.
    assert_eq!(rows.iter().map(|r| r.beams_measured).sum::<u64>(), 10 * 128 + (rows.len() as u64 - 10) * 3);
    // The radial relative speed is observed: the estimate's velocity along
    // the line of sight matches the truth within 1 m/s at the end.
    let last = rows.last().unwrap();
    let (c, s) = (last.true_azimuth_rad.cos(), last.true_azimuth_rad.sin());
    let radial = |vx: f64, vy: f64| vx * c + vy * s;
    assert!((radial(last.vx_mps, last.vy_mps) - radial(last.true_vx_mps, last.true_vy_mps)).abs() < 1.0, "{last:?}");

    analyze_geometric(dir.path(), &rows);

    let mixed = mmtrack(dir.path(), &["process", "beam", "c.mcap", "--tracker", "geometric,window", "-o", "u"]);
    assert!(!mixed.status.success() && text(&mixed).1.contains("runs alone"));
    let flag =
        mmtrack(dir.path(), &["process", "beam", "c.mcap", "--tracker", "window", "--epoch-ms", "10", "-o", "u"]);
    assert!(!flag.status.success() && text(&flag).1.contains("--epoch-ms is an option of --tracker geometric only"));
}

/// The summary of `rows` computed here, independently of the analysis
/// crate: RMS and final errors over the RLS epochs, beams against 128 per
/// epoch (the paper's codebook; `process beam` starts with full scans).
fn expected_summary(rows: &[GeometricEpochRow]) -> GeometricSummaryRow {
    let rls: Vec<&GeometricEpochRow> = rows.iter().filter(|r| r.filter == "rls").collect();
    let first_rls = rows.iter().position(|r| r.filter == "rls");
    let rms = |e: &dyn Fn(&GeometricEpochRow) -> f64| {
        (!rls.is_empty()).then(|| (rls.iter().map(|r| e(r).powi(2)).sum::<f64>() / rls.len() as f64).sqrt())
    };
    let range_error = |r: &GeometricEpochRow| r.range_m - r.true_range_m;
    let azimuth_error = |r: &GeometricEpochRow| wrap_angle_rad(r.azimuth_rad - r.true_azimuth_rad);
    let last = rows.last().unwrap();
    let measured: u64 = rows.iter().map(|r| r.beams_measured).sum();
    GeometricSummaryRow {
        epochs: rows.len() as u64,
        duration_s: (last.t_ns - rows[0].t_ns) as f64 * 1e-9,
        handover_epoch: first_rls.map(|k| k as u64),
        handover_s: first_rls.map(|k| (rows[k].t_ns - rows[0].t_ns) as f64 * 1e-9),
        rls_share: rls.len() as f64 / rows.len() as f64,
        range_rmse_m: rms(&range_error),
        final_range_error_m: first_rls.map(|_| range_error(last).abs()),
        azimuth_rmse_rad: rms(&azimuth_error),
        final_azimuth_error_rad: first_rls.map(|_| azimuth_error(last).abs()),
        codebook_beams: 128,
        beams_measured: measured,
        beams_full_scan: 128 * rows.len() as u64,
        saving: (128 * rows.len() as u64) as f64 / measured as f64,
    }
}

/// Asserts two summaries agree: counts exactly, floats within 1e-9
/// relative (the same f64 sums, possibly in another order).
fn assert_close(ours: &GeometricSummaryRow, expected: &GeometricSummaryRow) {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-12);
    let close_opt = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) => close(a, b),
        (a, b) => a.is_none() && b.is_none(),
    };
    let counts =
        |s: &GeometricSummaryRow| (s.epochs, s.handover_epoch, s.codebook_beams, s.beams_measured, s.beams_full_scan);
    assert_eq!(counts(ours), counts(expected));
    assert!(close(ours.duration_s, expected.duration_s) && close(ours.rls_share, expected.rls_share), "{ours:?}");
    assert!(close(ours.saving, expected.saving), "{ours:?}");
    for (a, b) in [
        (ours.handover_s, expected.handover_s),
        (ours.range_rmse_m, expected.range_rmse_m),
        (ours.final_range_error_m, expected.final_range_error_m),
        (ours.azimuth_rmse_rad, expected.azimuth_rmse_rad),
        (ours.final_azimuth_error_rad, expected.final_azimuth_error_rad),
    ] {
        assert!(close_opt(a, b), "{a:?} vs {b:?}: {ours:?} vs {expected:?}");
    }
}

fn summary_of(out: &Path, sequence: &str) -> GeometricSummaryRow {
    let path = out.join(format!("tables/geometric_summary/sequence={sequence}/part-0.parquet"));
    let mut rows: Vec<GeometricSummaryRow> = read_table(&path).unwrap();
    assert_eq!(rows.len(), 1);
    rows.remove(0)
}

/// `analyze` of the convoy's table (never converged), of the same table with
/// a hand-over written in (scored from there), and of bad tables.
fn analyze_geometric(dir: &Path, rows: &[GeometricEpochRow]) {
    let out = mmtrack(dir, &["analyze", "t", "-o", "a"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let sequence = std::fs::read_dir(dir.join("t/geometric_per_epoch")).unwrap().next().unwrap().unwrap();
    let sequence = sequence.file_name().to_string_lossy().strip_prefix("sequence=").unwrap().to_string();
    let ours = summary_of(&dir.join("a"), &sequence);
    // Never handed over: no hand-over time and no error numbers.
    assert_eq!((ours.handover_s, ours.range_rmse_m, ours.azimuth_rmse_rad, ours.rls_share), (None, None, None, 0.0));
    assert_close(&ours, &expected_summary(rows));
    let report = std::fs::read_to_string(dir.join("a/report.md")).unwrap();
    assert!(report.contains("## Geometric Doppler-bearing tracking"), "{report}");
    assert!(report.contains(&format!("(plots/{sequence}/geometric_tracking.svg)")), "{report}");
    let svg = std::fs::read_to_string(dir.join(format!("a/plots/{sequence}/geometric_tracking.svg"))).unwrap();
    assert!(svg.contains("H-infinity (not converged)") && svg.contains("beams measured"));
    assert!(std::fs::read_to_string(dir.join("a/report.html")).unwrap().contains("Geometric Doppler-bearing tracking"));

    // The same epochs with RLS from epoch 40 on: errors are scored from there.
    let handed_over: Vec<GeometricEpochRow> = rows
        .iter()
        .map(|r| GeometricEpochRow { filter: if r.epoch >= 40 { "rls" } else { "h-infinity" }.into(), ..r.clone() })
        .collect();
    let run = RunInfo::new("{}", mmtrack_io::recording::TimeBase::UnixEpoch)
        .with_frame(mmtrack_io::table::Frame::new("test_world", "a test world frame"));
    write_table(&dir.join("h"), "handover", &handed_over, &run, Overwrite::Refuse).unwrap();
    let out = mmtrack(dir, &["analyze", "h", "-o", "b"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let ours = summary_of(&dir.join("b"), "handover");
    assert_eq!(ours.handover_epoch, Some(40));
    assert!(ours.range_rmse_m.is_some_and(|e| e > 0.0), "{ours:?}");
    assert_close(&ours, &expected_summary(&handed_over));
    // Both runs side by side: the campaign comparison carries the summary.
    let out = mmtrack(dir, &["analyze", "t", "h", "-o", "both"]);
    assert!(out.status.success(), "{}", text(&out).1);
    // Partitioned by sequence: run h's rows under sequence=handover, run t's under its own.
    let partitions = mmtrack_io::table::read_table_dir::<RunComparisonRow>(&dir.join("both/tables")).unwrap();
    let mut expected = vec![sequence.as_str(), "handover"];
    expected.sort_unstable();
    assert_eq!(partitions.keys().map(String::as_str).collect::<Vec<_>>(), expected);
    assert!(partitions["handover"].iter().all(|r| r.run == "h"), "{partitions:?}");
    let compared: Vec<RunComparisonRow> = partitions.into_values().flatten().collect();
    let value = |run: &str, metric: &str| {
        let found =
            compared.iter().find(|r| r.source_table == "geometric_summary" && r.run == run && r.metric == metric);
        found.unwrap_or_else(|| panic!("{run} {metric}: {compared:?}")).value
    };
    assert_eq!(value("h", "range_rmse_m"), ours.range_rmse_m);
    assert_eq!(value("t", "range_rmse_m"), None);
    assert_eq!(value("h", "saving"), Some(ours.saving));

    // Bad tables: the error names the file, sequence, row and column.
    let mut nan = rows.to_vec();
    nan[5].range_m = f64::NAN;
    let mut backwards = rows.to_vec();
    backwards[7].t_ns = backwards[6].t_ns - 1;
    for (name, bad, expected) in [
        ("nan", nan, "sequence nan: table geometric_per_epoch row 5: column range_m is NaN, expected finite"),
        ("backwards", backwards, "sequence backwards: table geometric_per_epoch row 7: column t_ns is"),
    ] {
        write_table(&dir.join(name), name, &bad, &run, Overwrite::Refuse).unwrap();
        let out = mmtrack(dir, &["analyze", name, "-o", &format!("{name}-out")]);
        let stderr = text(&out).1;
        assert!(!out.status.success() && stderr.contains(expected), "{stderr}");
        assert!(stderr.contains(&format!("geometric_per_epoch/sequence={name}/part-0.parquet")), "{stderr}");
        assert!(!dir.join(format!("{name}-out")).exists(), "no half-written output");
    }
}
