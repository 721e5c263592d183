//! The pipeline on hand-built scans: exact motions, bad input, degenerate scenes.

use std::f64::consts::TAU;

use mmtrack_core::{AzimuthSample, PolarScan, PolarScanHeader, Se2};
use mmtrack_odometry::{OdometryConfig, OdometryError, RadarOdometry};

const AZIMUTHS: usize = 400;
const BINS: usize = 2000;
const RESOLUTION_M: f64 = 0.05;

/// Renders a static scene of line segments seen from `world_from_vehicle`
/// (an instantaneous sweep): each beam lights the bin of its nearest hit,
/// with a deterministic +-1 bin jitter so surfaces have thickness.
fn render(t_ns: i64, world_from_vehicle: Se2, walls: &[([f64; 2], [f64; 2])]) -> PolarScan {
    render_moving(t_ns, |_| world_from_vehicle, walls)
}

/// As [`render`], but each azimuth is seen from the pose at its own time
/// (`pose_at(seconds after t_ns)`): a sweep skewed by the vehicle's motion.
fn render_moving(t_ns: i64, pose_at: impl Fn(f64) -> Se2, walls: &[([f64; 2], [f64; 2])]) -> PolarScan {
    let mut power = vec![0u8; AZIMUTHS * BINS];
    let mut azimuths = Vec::with_capacity(AZIMUTHS);
    for a in 0..AZIMUTHS {
        let azimuth_rad = a as f64 * TAU / AZIMUTHS as f64;
        let offset_ns = a as i64 * 625_000;
        azimuths.push(AzimuthSample { t_ns: t_ns + offset_ns, azimuth_rad, valid: true });
        let world_from_vehicle = pose_at(offset_ns as f64 * 1e-9);
        let (s, c) = (world_from_vehicle.yaw_rad - azimuth_rad).sin_cos();
        let origin = [world_from_vehicle.x_m, world_from_vehicle.y_m];
        let nearest = walls.iter().filter_map(|&(p, q)| hit(origin, [c, s], p, q)).fold(f64::INFINITY, f64::min);
        if nearest.is_finite() {
            let bin = (nearest / RESOLUTION_M).round() as usize;
            for (offset, value) in [(0usize, 200u8), (1, 120), (2, 90)] {
                let jitter = (a * 7 + offset) % 3;
                if let Some(cell) = power.get_mut(a * BINS + bin + jitter + offset) {
                    *cell = value;
                }
            }
        }
    }
    let header = PolarScanHeader {
        t_ns,
        range_resolution_m: RESOLUTION_M,
        range_offset_m: 0.0,
        bins_per_azimuth: BINS,
        azimuths,
    };
    PolarScan::new(header, power).unwrap()
}

fn hit(o: [f64; 2], d: [f64; 2], a: [f64; 2], b: [f64; 2]) -> Option<f64> {
    let e = [b[0] - a[0], b[1] - a[1]];
    let den = d[0] * e[1] - d[1] * e[0];
    if den.abs() < 1e-12 {
        return None;
    }
    let w = [a[0] - o[0], a[1] - o[1]];
    let range = (w[0] * e[1] - w[1] * e[0]) / den;
    let along = (w[0] * d[1] - w[1] * d[0]) / den;
    (range > 0.0 && (0.0..=1.0).contains(&along)).then_some(range)
}

/// A street with building fronts at different set-backs and cross walls.
fn street() -> Vec<([f64; 2], [f64; 2])> {
    vec![
        ([-50.0, 12.0], [10.0, 12.0]),
        ([10.0, 16.0], [60.0, 16.0]),
        ([10.0, 12.0], [10.0, 16.0]),
        ([-50.0, -10.0], [25.0, -10.0]),
        ([25.0, -10.0], [25.0, -30.0]),
        ([30.0, -10.0], [90.0, -13.0]),
        ([70.0, 30.0], [75.0, -30.0]),
    ]
}

fn tunnel() -> Vec<([f64; 2], [f64; 2])> {
    vec![([-200.0, 6.0], [400.0, 6.0]), ([-200.0, -6.0], [400.0, -6.0])]
}

fn drive(config: OdometryConfig, walls: &[([f64; 2], [f64; 2])], steps: usize) -> Vec<(Se2, Se2, bool)> {
    let mut odometry = RadarOdometry::new(config).unwrap();
    (0..steps)
        .map(|k| {
            let truth = Se2::new(1.9 * k as f64, 0.05 * k as f64, 0.004 * k as f64);
            let scan = render(1_000_000_000 + k as i64 * 250_000_000, truth, walls);
            let estimate = odometry.process(&scan).unwrap().estimate;
            (truth, estimate.world_from_vehicle, estimate.low_confidence)
        })
        .collect()
}

#[test]
fn both_presets_track_a_street_drive() {
    for config in
        [OdometryConfig::fast_cfear(), OdometryConfig { motion_compensation: false, ..OdometryConfig::cfear() }]
    {
        let results = drive(config, &street(), 10);
        let (truth, estimate, low) = results.last().copied().unwrap();
        // 17 m of travel; rendering quantises ranges to 5 cm bins, so allow a few cm of drift.
        let error = truth.inverse() * estimate;
        assert!(error.translation_norm_m() < 0.15, "{truth:?} vs {estimate:?}");
        assert!(error.yaw_rad.abs() < 0.3f64.to_radians(), "{truth:?} vs {estimate:?}");
        assert!(!low);
    }
}

#[test]
fn a_featureless_tunnel_is_flagged_not_nan() {
    let results = drive(OdometryConfig::fast_cfear(), &tunnel(), 4);
    for (_, estimate, low) in &results[1..] {
        assert!(estimate.is_finite());
        assert!(*low, "a tunnel must be flagged low-confidence");
    }
}

#[test]
fn an_all_zero_scan_is_flagged_and_follows_the_prediction() {
    let mut odometry = RadarOdometry::new(OdometryConfig::fast_cfear()).unwrap();
    let first = odometry.process(&render(0, Se2::IDENTITY, &street())).unwrap().estimate;
    assert!(!first.low_confidence);
    let mut empty = render(250_000_000, Se2::IDENTITY, &[]);
    empty.power.iter_mut().for_each(|p| *p = 0);
    let second = odometry.process(&empty).unwrap().estimate;
    assert!(second.low_confidence && second.world_from_vehicle.is_finite());
    assert_eq!(second.filtered_points, 0);
}

#[test]
fn duplicated_azimuths_are_an_error_naming_the_rows() {
    let mut scan = render(0, Se2::IDENTITY, &street());
    scan.header.azimuths[17].azimuth_rad = scan.header.azimuths[16].azimuth_rad;
    let error = RadarOdometry::new(OdometryConfig::cfear()).unwrap().process(&scan).unwrap_err();
    assert!(matches!(error, OdometryError::DuplicateAzimuth { first_row: 16, second_row: 17, .. }), "{error}");
}

#[test]
fn scans_out_of_time_order_are_an_error() {
    let mut odometry = RadarOdometry::new(OdometryConfig::fast_cfear()).unwrap();
    odometry.process(&render(500, Se2::IDENTITY, &street())).unwrap();
    let error = odometry.process(&render(400, Se2::IDENTITY, &street())).unwrap_err();
    assert_eq!(error, OdometryError::NonMonotonicTime { previous_t_ns: 500, t_ns: 400 });
}

#[test]
fn a_sweep_whose_middle_is_not_after_the_previous_one_is_an_error() {
    // Stamps increase, but the second sweep is 40 ms long and ends before
    // the middle of the first (125 ms): motion compensation places each
    // scan at the middle of its sweep, so it cannot take this order.
    let mut odometry = RadarOdometry::new(OdometryConfig::cfear()).unwrap();
    odometry.process(&render(0, Se2::IDENTITY, &street())).unwrap();
    let mut short = render(10_000_000, Se2::IDENTITY, &street());
    for (a, azimuth) in short.header.azimuths.iter_mut().enumerate() {
        azimuth.t_ns = 10_000_000 + a as i64 * 100_000;
    }
    let error = odometry.process(&short).unwrap_err().to_string();
    assert!(error.contains("scan at t_ns 10000000: the middle of its sweep (t_ns 29950000) is not after the previous scan's (t_ns 124687500)"), "{error}");
    // Without motion compensation the order of the stamps is all that counts.
    let mut odometry = RadarOdometry::new(OdometryConfig::fast_cfear()).unwrap();
    odometry.process(&render(0, Se2::IDENTITY, &street())).unwrap();
    odometry.process(&short).unwrap();
}

#[test]
fn bad_configs_name_the_field() {
    let error = RadarOdometry::new(OdometryConfig { grid_m: -1.0, ..OdometryConfig::cfear() }).unwrap_err();
    assert!(error.to_string().contains("grid_m"), "{error}");
    let error = RadarOdometry::new(OdometryConfig { k_strongest: 0, ..OdometryConfig::cfear() }).unwrap_err();
    assert!(error.to_string().contains("k_strongest"), "{error}");
}

#[test]
fn results_are_deterministic() {
    let a = drive(OdometryConfig::cfear(), &street(), 6);
    let b = drive(OdometryConfig::cfear(), &street(), 6);
    assert_eq!(a, b);
}

/// Motion compensation on sweeps skewed by a turning drive at 9 m/s (2.25 m
/// and 1.4 deg per 250 ms sweep, as long as a step): with the points placed
/// at the middle of each sweep with the previous step's velocity, the steps
/// settle on the true one instead of oscillating (placed at the stamp, the
/// step errors would obey d_k = -(d_{k-1} - d_{k-2}) / 2, a root at -1), the
/// first scan's pose at its stamp is the world origin (no half-sweep
/// offset), and compensation beats the instantaneous sweep.
#[test]
fn motion_compensation_follows_a_skewed_turning_drive_without_oscillating() {
    use mmtrack_odometry::filter::BodyVelocity;
    let velocity = BodyVelocity { vx_mps: 9.0, vy_mps: 0.0, yaw_rate_radps: 0.1 };
    let start = Se2::new(-20.0, 1.0, 0.0);
    let truth = |k: usize| start * velocity.motion_over(0.25 * k as f64);
    let run = |config: OdometryConfig| {
        let mut odometry = RadarOdometry::new(config).unwrap();
        (0..16)
            .map(|k| {
                let scan = render_moving(
                    1_000_000_000 + k as i64 * 250_000_000,
                    |dt_s| start * velocity.motion_over(0.25 * k as f64 + dt_s),
                    &street(),
                );
                odometry.process(&scan).unwrap().estimate.world_from_vehicle
            })
            .collect::<Vec<Se2>>()
    };
    let step_errors = |poses: &[Se2]| -> Vec<(f64, f64)> {
        (1..poses.len())
            .map(|k| {
                let true_step = truth(k - 1).inverse() * truth(k);
                let error = true_step.inverse() * (poses[k - 1].inverse() * poses[k]);
                (error.translation_norm_m(), error.yaw_rad.abs().to_degrees())
            })
            .collect()
    };
    let compensated = run(OdometryConfig::cfear());
    let instantaneous = run(OdometryConfig { motion_compensation: false, ..OdometryConfig::cfear() });
    let errors = step_errors(&compensated);
    let worst = errors.iter().fold((0.0f64, 0.0f64), |w, e| (w.0.max(e.0), w.1.max(e.1)));
    eprintln!("compensated step errors (m, deg): {errors:.3?}");
    eprintln!("instantaneous step errors (m, deg): {:.3?}", step_errors(&instantaneous));
    assert!(worst.0 < 0.02 && worst.1 < 0.01, "worst step error {worst:?}");
    let end_error = |poses: &[Se2]| (truth(0).inverse() * truth(poses.len() - 1)).inverse() * poses[poses.len() - 1];
    let (with, without) = (end_error(&compensated), end_error(&instantaneous));
    eprintln!("end-point error over 34 m: compensated {with:?}, instantaneous {without:?}");
    assert_eq!(compensated[0], Se2::IDENTITY);
    assert!(with.translation_norm_m() < 0.05, "{with:?}");
    assert!(with.translation_norm_m() < 0.5 * without.translation_norm_m(), "{with:?} vs {without:?}");
}
