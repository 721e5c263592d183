//! Ingest of the real Oxford Radar RobotCar sample (Barnes et al., ICRA 2020,
//! CC BY-NC-SA 4.0; sample as kept in Samleo8/RadarSLAMPy), from
//! `../shared/realdata`. Skips with a visible line where the data is absent.

use std::f64::consts::TAU;

use mmtrack_core::{PolarScan, StampedPose, path_length_m};
use mmtrack_ingest::oxford::odometry::read_radar_odometry;
use mmtrack_io::recording::PoseStream;
use mmtrack_io::{RecordingEvent, RecordingReader};

use super::common::{mmtrack, text};

#[test]
fn oxford_tiny_folder_gives_11_scans_and_a_19_4_m_ground_truth() {
    let Some(realdata) = super::common::realdata("oxford_tiny_folder") else { return };
    let input = realdata.join("oxford-radar-tiny");
    let dir = tempfile::tempdir().unwrap();
    let out = mmtrack(dir.path(), &["ingest", "oxford", input.to_str().unwrap(), "-o", "tiny.mcap", "--quiet"]);
    assert!(out.status.success(), "{}", text(&out).1);

    let mut scans: Vec<PolarScan> = Vec::new();
    let mut truth: Vec<StampedPose> = Vec::new();
    for event in RecordingReader::open(&dir.path().join("tiny.mcap")).unwrap() {
        match event.unwrap() {
            RecordingEvent::RadarScan(scan) => scans.push(scan),
            RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } => truth.push(pose),
            _ => {}
        }
    }
    assert_eq!(scans.len(), 11);
    for scan in &scans {
        assert_eq!(scan.header.azimuths.len(), 400);
        assert_eq!(scan.header.bins_per_azimuth, 3768);
        scan.header.check_azimuth_times().unwrap();
        assert!(scan.header.azimuths.iter().all(|a| (0.0..TAU).contains(&a.azimuth_rad)));
        // The scan stamp (file name) is the first azimuth's time on this sensor.
        assert_eq!(scan.header.azimuths[0].t_ns, scan.header.t_ns);
    }
    // Power equals the PNG's bins: carried bytes decode to the same image.
    let first_png = input.join("radar/1547131046353776.png");
    let (width, _, pixels) = mmtrack_io::decode_gray8(&std::fs::read(first_png).unwrap()).unwrap();
    assert_eq!(scans[0].row(7).unwrap(), &pixels[7 * width + 11..8 * width]);

    // One pose per scan, stamped with the scans' own times.
    assert_eq!(truth.len(), 11);
    assert!(truth.iter().zip(&scans).all(|(p, s)| p.t_ns == s.header.t_ns));
    // Sum of the 10 relative translations in the CSV (computed independently
    // with Python's csv module: 19.409088995767974 m); composition preserves
    // distances, so only float rounding separates the two.
    let length_m = path_length_m(&truth);
    assert!((length_m - 19.409_088_995_767_974).abs() < 1e-9, "{length_m}");
}

/// RMS distance, metres, between two planar paths after the best proper rigid
/// alignment of `a` onto `b` (2D Kabsch: rotation from the cross-covariance).
fn rms_after_alignment_m(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    let n = a.len() as f64;
    let mean = |p: &[[f64; 2]]| [p.iter().map(|q| q[0]).sum::<f64>() / n, p.iter().map(|q| q[1]).sum::<f64>() / n];
    let (ma, mb) = (mean(a), mean(b));
    let (mut dot, mut cross) = (0.0, 0.0);
    for (p, q) in a.iter().zip(b) {
        let (pa, qb) = ([p[0] - ma[0], p[1] - ma[1]], [q[0] - mb[0], q[1] - mb[1]]);
        dot += pa[0] * qb[0] + pa[1] * qb[1];
        cross += pa[0] * qb[1] - pa[1] * qb[0];
    }
    let (s, c) = cross.atan2(dot).sin_cos();
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| {
            let pa = [p[0] - ma[0], p[1] - ma[1]];
            let r = [c * pa[0] - s * pa[1] + mb[0], s * pa[0] + c * pa[1] + mb[1]];
            (r[0] - q[0]).powi(2) + (r[1] - q[1]).powi(2)
        })
        .sum();
    (sum / n).sqrt()
}

/// GPS (easting, northing) linearly interpolated at `t_ns`.
fn gps_at(rows: &[mmtrack_ingest::oxford::gps::OxfordGpsRow], t_ns: i64) -> Option<[f64; 2]> {
    let i = rows.partition_point(|r| r.fix.t_ns <= t_ns);
    let (a, b) = (rows.get(i.checked_sub(1)?)?, rows.get(i)?);
    let w = (t_ns - a.fix.t_ns) as f64 / (b.fix.t_ns - a.fix.t_ns) as f64;
    Some([a.easting_m + w * (b.easting_m - a.easting_m), a.northing_m + w * (b.northing_m - a.northing_m)])
}

#[test]
fn oxford_ground_truth_yaw_sign_matches_the_gps_track() {
    use mmtrack_ingest::oxford::{gps::read_gps_csv, odometry};
    let Some(realdata) = super::common::realdata("oxford_yaw_sign") else { return };
    let folder = realdata.join("oxford-radar-tiny");
    let csv = folder.join("gt/radar_odometry.csv");
    let gps = read_gps_csv(&folder.join("gps/gps.csv")).unwrap();
    let rows = odometry::parse_radar_odometry(&csv, &std::fs::read_to_string(&csv).unwrap()).unwrap();
    let fit = |rows: &[odometry::RelativePose]| {
        let poses = odometry::chain(&csv, rows).unwrap();
        let (path, reference): (Vec<[f64; 2]>, Vec<[f64; 2]>) = poses
            .iter()
            .filter_map(|p| Some(([p.parent_from_child.x_m, p.parent_from_child.y_m], gps_at(&gps, p.t_ns)?)))
            .unzip();
        assert!(path.len() > 2000, "poses inside the GPS span: {}", path.len());
        rms_after_alignment_m(&path, &reference)
    };
    // As ingested: (x, -y, -yaw). 2.2 m measured (GPS sigma is about 0.7 m per
    // axis, and radar and GPS clocks differ by up to a scan); 5 m leaves room.
    let ours_m = fit(&rows);
    assert!(ours_m < 5.0, "{ours_m} m");
    // The CSV's own yaw sign in a z-up frame drifts away from the GPS (239 m).
    let flipped: Vec<_> = rows
        .iter()
        .map(|r| {
            let mut r = *r;
            r.destination_from_source.yaw_rad = -r.destination_from_source.yaw_rad;
            r
        })
        .collect();
    let theirs_m = fit(&flipped);
    assert!(theirs_m > 20.0 * ours_m, "ours {ours_m} m, flipped {theirs_m} m");
}

#[test]
fn oxford_full_sequence_ground_truth_chains_to_9_km() {
    let Some(realdata) = super::common::realdata("oxford_full_sequence_ground_truth") else { return };
    let poses = read_radar_odometry(&realdata.join("oxford-gt-full-seq/radar_odometry.csv")).unwrap();
    // radar.timestamps lists 8867 frames but the CSV holds 8865 relative poses
    // (counted with `wc -l`), giving 8866 absolute poses, the first at identity.
    assert_eq!(poses.len(), 8866);
    // The dataset documents a 9.02 km drive; the sum of the CSV's relative
    // translations, computed independently with Python, is 9.02464827213693 km.
    let length_km = path_length_m(&poses) / 1000.0;
    assert!((length_km - 9.024_648_272_136_93).abs() < 1e-9, "{length_km} km");
}

/// Issue 28: the report's trajectory plot is in the tables' frame (the
/// Oxford ground truth starts about 147 m east of its origin; re-anchored at
/// the origin the plot showed x 0-20 m beside a table of 147-166 m), and the
/// plot relative to the first poses says so.
#[test]
fn oxford_report_trajectory_plot_is_in_the_frame_of_the_tables() {
    use mmtrack_core::OdometryEstimate;
    use mmtrack_io::table::{GroundTruthPose, read_table};
    let Some(realdata) = super::common::realdata("oxford_report_frame") else { return };
    let input = realdata.join("oxford-radar-tiny");
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["ingest", "oxford", input.to_str().unwrap(), "-o", "tiny.mcap", "--quiet"][..],
        &["process", "odometry", "tiny.mcap", "-o", "tables", "--quiet"],
        &["analyze", "tables", "-o", "an", "--segment-lengths-m", "2,4,8", "--step-frames", "1", "--quiet"],
    ] {
        super::common::mmtrack_ok(dir.path(), args);
    }
    let part = |table: &str| dir.path().join(format!("tables/{table}/sequence=oxford-radar-tiny/part-0.parquet"));
    let truth: Vec<f64> = read_table::<GroundTruthPose>(&part("ground_truth"))
        .unwrap()
        .iter()
        .map(|p| p.0.parent_from_child.x_m)
        .collect();
    let estimate: Vec<f64> =
        read_table::<OdometryEstimate>(&part("odometry")).unwrap().iter().map(|e| e.world_from_vehicle.x_m).collect();
    let range = |v: &[f64]| {
        (v.iter().copied().fold(f64::INFINITY, f64::min), v.iter().copied().fold(f64::NEG_INFINITY, f64::max))
    };
    let ((t_lo, t_hi), (e_lo, e_hi)) = (range(&truth), range(&estimate));
    assert!(t_lo > 100.0, "the sample's ground truth starts away from the origin: {t_lo} m");
    // The x tick labels of a plot (numeric texts anchored in the middle).
    let x_ticks = |file: &str| -> (f64, f64) {
        let svg = std::fs::read_to_string(dir.path().join("an/plots/oxford-radar-tiny").join(file)).unwrap();
        let ticks: Vec<f64> = svg
            .split("text-anchor=\"middle\"")
            .skip(1)
            .filter_map(|rest| rest.split('>').nth(1)?.split('<').next()?.trim().parse().ok())
            .collect();
        range(&ticks)
    };
    let (lo, hi) = x_ticks("trajectory.svg");
    // The axis spans both tables' x (padded by 5 %, square axes) and no more than twice it.
    let (span_lo, span_hi) = (t_lo.min(e_lo), t_hi.max(e_hi));
    assert!(
        lo <= span_lo + 2.0 && hi >= span_hi - 2.0 && hi - lo <= 2.0 * (span_hi - span_lo),
        "x ticks {lo}..{hi}, tables {span_lo}..{span_hi}"
    );
    let (lo, hi) = x_ticks("trajectory_relative.svg");
    assert!(lo <= 0.0 && hi < 50.0, "relative plot from 0: {lo}..{hi}");
    let report = std::fs::read_to_string(dir.path().join("an/report.md")).unwrap();
    assert!(report.contains("![trajectory relative to each first pose"), "{report}");
    eprintln!(
        "oxford sample: tables x {span_lo:.1}..{span_hi:.1} m, trajectory.svg x ticks {:?}",
        x_ticks("trajectory.svg")
    );
}

/// Someone else's odometry scores as ours: our CFEAR run on the real Oxford
/// scans, put into a copy of the recording as `/estimate/pose` (`export
/// --format mcap`, as a ROS 2 bag's /odom would be by `ingest ros2`), read
/// back by `process poses` and analyzed beside the original run, gives the
/// same poses and the same trajectory metrics, value for value.
#[test]
fn an_estimate_in_the_recording_scores_exactly_as_the_odometry_it_came_from() {
    use mmtrack_io::table::{TrajectoryMetrics, read_table};
    let Some(realdata) = super::common::realdata("oxford_external_estimate") else { return };
    let input = realdata.join("oxford-radar-tiny");
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = |args: &[&str]| super::common::mmtrack_ok(d, args);
    run(&["ingest", "oxford", input.to_str().unwrap(), "-o", "tiny.mcap", "-q"]);
    // Without an estimate the recording is refused, naming the topic.
    let out = mmtrack(d, &["process", "poses", "tiny.mcap", "-o", "runs", "--run-id", "none"]);
    assert!(!out.status.success());
    assert!(
        text(&out).1.contains("tiny.mcap: the recording has no estimated poses (topic /estimate/pose"),
        "{}",
        text(&out).1
    );
    assert!(!d.join("runs/run=none").exists());

    run(&["process", "odometry", "tiny.mcap", "-o", "runs", "--run-id", "ours", "-q"]);
    run(&["export", "--format", "mcap", "runs/run=ours", "--recording", "tiny.mcap", "-o", "est.mcap", "-q"]);
    let stdout = run(&["process", "poses", "est.mcap", "-o", "runs", "--run-id", "external"]);
    assert!(stdout.contains("poses: estimate 11 (2.5 s, 19.3 m), ground truth 11 (2.5 s, 19.4 m)"), "{stdout}");
    let part =
        |run: &str, table: &str| d.join(format!("runs/run={run}/{table}/sequence=oxford-radar-tiny/part-0.parquet"));
    let ours: Vec<mmtrack_core::OdometryEstimate> = read_table(&part("ours", "odometry")).unwrap();
    let external: Vec<StampedPose> = read_table(&part("external", "poses")).unwrap();
    assert_eq!(external.len(), 11);
    for (e, o) in external.iter().zip(&ours) {
        assert_eq!((e.t_ns, e.parent_from_child), (o.t_ns, o.world_from_vehicle));
    }

    run(&["analyze", "runs", "-o", "an", "--segment-lengths-m", "5,10", "--step-frames", "1", "-q"]);
    let metrics = |run: &str| -> Vec<TrajectoryMetrics> {
        read_table(&d.join(format!("an/run={run}/tables/trajectory_metrics/sequence=oxford-radar-tiny/part-0.parquet")))
            .unwrap()
    };
    let (a, b) = (metrics("ours"), metrics("external"));
    assert_eq!(a.len(), 1);
    assert!(a[0].kitti_translational_pct.is_some_and(f64::is_finite), "{a:?}");
    assert_eq!(a, b);

    // Both estimates in one sequence of one run: which to score is ambiguous, so analyze says so.
    run(&["process", "poses", "est.mcap", "-o", "runs/run=ours", "--force", "-q"]);
    let out = mmtrack(d, &["analyze", "runs/run=ours", "-o", "an2"]);
    assert!(!out.status.success());
    assert!(text(&out).1.contains("has two estimates (odometry and poses tables)"), "{}", text(&out).1);
}
