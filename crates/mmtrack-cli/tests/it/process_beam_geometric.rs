//! `mmtrack process beam --tracker geometric` on a simulated sounder convoy.

use mmtrack_analysis::beam::zoechmann_tables::GeometricEpochRow;
use mmtrack_io::table::read_table;

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

    let mixed = mmtrack(dir.path(), &["process", "beam", "c.mcap", "--tracker", "geometric,window", "-o", "u"]);
    assert!(!mixed.status.success() && text(&mixed).1.contains("runs alone"));
    let flag =
        mmtrack(dir.path(), &["process", "beam", "c.mcap", "--tracker", "window", "--epoch-ms", "10", "-o", "u"]);
    assert!(!flag.status.success() && text(&flag).1.contains("--epoch-ms is an option of --tracker geometric only"));
}
