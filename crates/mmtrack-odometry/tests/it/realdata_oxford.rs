//! Fast-CFEAR and CFEAR on the real Oxford Radar RobotCar sample: 11 scans,
//! 10 consecutive pairs of about 2 m, against the dataset's ground truth.
//!
//! Data: Oxford Radar RobotCar Dataset (Barnes et al., ICRA 2020), CC BY-NC-SA
//! 4.0, sample as kept in the public repo Samleo8/RadarSLAMPy; read from
//! `../shared/realdata/oxford-radar-tiny`, never copied into the repository.

use std::path::{Path, PathBuf};

use mmtrack_core::{PolarScan, Se2, StampedPose};
use mmtrack_ingest::oxford::{self, NavtechLayout, OxfordFolder};
use mmtrack_odometry::{OdometryConfig, RadarOdometry};

fn sample() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/realdata/oxford-radar-tiny");
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("skipped: real data not found at {}", dir.display());
        None
    }
}

fn scans(dir: &Path, layout: &NavtechLayout) -> Vec<PolarScan> {
    let folder = OxfordFolder::open(dir).unwrap();
    folder
        .scans
        .iter()
        .map(|file| {
            let png = std::fs::read(&file.path).unwrap();
            oxford::decode_scan_png(&file.path, &png, file.t_ns, layout).unwrap().into_scan()
        })
        .collect()
}

/// Per pair: (translation error m, yaw error deg, ground-truth step m, estimated step m).
fn pair_errors(scans: &[PolarScan], truth: &[StampedPose], config: OdometryConfig) -> Vec<(f64, f64, f64, f64)> {
    let mut odometry = RadarOdometry::new(config).unwrap();
    let estimates: Vec<Se2> = scans.iter().map(|s| odometry.process(s).unwrap().estimate.world_from_vehicle).collect();
    let truth_at = |t_ns: i64| truth.iter().find(|p| p.t_ns == t_ns).unwrap().parent_from_child;
    (1..scans.len())
        .map(|k| {
            let estimated = estimates[k - 1].inverse() * estimates[k];
            let reference = truth_at(scans[k - 1].header.t_ns).inverse() * truth_at(scans[k].header.t_ns);
            let error = reference.inverse() * estimated;

            (
                error.translation_norm_m(),
                error.yaw_rad.abs().to_degrees(),
                reference.translation_norm_m(),
                estimated.translation_norm_m(),
            )
        })
        .collect()
}

fn report(name: &str, errors: &[(f64, f64, f64, f64)]) -> (f64, f64) {
    eprintln!("{name}: pair  translation error m  yaw error deg  truth step m  estimated step m");
    for (i, e) in errors.iter().enumerate() {
        eprintln!("{name}: {:>4}  {:>19.4}  {:>13.4}  {:>12.4}  {:>16.4}", i + 1, e.0, e.1, e.2, e.3);
    }
    let n = errors.len() as f64;
    let mean_t = errors.iter().map(|e| e.0).sum::<f64>() / n;
    let mean_yaw = errors.iter().map(|e| e.1).sum::<f64>() / n;
    let ratio = errors.iter().map(|e| e.3).sum::<f64>() / errors.iter().map(|e| e.2).sum::<f64>();
    eprintln!("{name}: mean translation error {mean_t:.4} m, mean yaw error {mean_yaw:.4} deg, step ratio {ratio:.4}");
    (mean_t, mean_yaw)
}

/// The targets for the `cfear` preset, per pair, means over the 10 pairs.
const TARGET_CFEAR_TRANSLATION_M: f64 = 0.05;
const TARGET_CFEAR_YAW_DEG: f64 = 0.2;

/// Regression bounds: the measured means (docs/results/radar-odometry.md) plus about
/// 15 % margin for platform differences in floating point. They guard what we
/// have; the targets above are what we aim for and are reported beside them.
const BOUND_CFEAR_TRANSLATION_M: f64 = 0.095;
const BOUND_CFEAR_YAW_DEG: f64 = 0.12;
const BOUND_FAST_CFEAR_TRANSLATION_M: f64 = 0.12;
const BOUND_FAST_CFEAR_YAW_DEG: f64 = 0.13;

#[test]
fn oxford_sample_pairs_against_ground_truth() {
    let Some(dir) = sample() else { return };
    let truth = oxford::odometry::read_radar_odometry(&dir.join("gt/radar_odometry.csv")).unwrap();
    let scans = scans(&dir, &oxford::OXFORD);
    assert_eq!(scans.len(), 11);

    let (fast_t, fast_yaw) = report("fast-cfear", &pair_errors(&scans, &truth, OdometryConfig::fast_cfear()));
    let (cfear_t, cfear_yaw) = report("cfear", &pair_errors(&scans, &truth, OdometryConfig::cfear()));
    let verdict = |ok: bool| if ok { "met" } else { "MISSED" };
    eprintln!(
        "cfear vs target: translation {cfear_t:.4} m (target <= {TARGET_CFEAR_TRANSLATION_M}: {}), \
         yaw {cfear_yaw:.4} deg (target <= {TARGET_CFEAR_YAW_DEG}: {})",
        verdict(cfear_t <= TARGET_CFEAR_TRANSLATION_M),
        verdict(cfear_yaw <= TARGET_CFEAR_YAW_DEG)
    );
    eprintln!(
        "fast-cfear vs the authors' C++ on the same scans: {fast_t:.4} m / {fast_yaw:.4} deg vs 0.093 m / 0.097 deg"
    );
    assert!(cfear_t <= BOUND_CFEAR_TRANSLATION_M && cfear_yaw <= BOUND_CFEAR_YAW_DEG, "cfear regressed");
    assert!(fast_t <= BOUND_FAST_CFEAR_TRANSLATION_M && fast_yaw <= BOUND_FAST_CFEAR_YAW_DEG, "fast-cfear regressed");
}

/// Which range resolution fits the ground truth better: the SDK's 0.0432 m or
/// CFEAR's 0.0438 m. Estimated over true path length of the 10 pairs, per
/// preset; printed for docs/results/radar-odometry.md (the scale differs by 1.4 %, about what
/// the estimates' own bias is, so the sample cannot settle it).
#[test]
fn oxford_range_resolution_scale() {
    let Some(dir) = sample() else { return };
    let truth = oxford::odometry::read_radar_odometry(&dir.join("gt/radar_odometry.csv")).unwrap();
    for resolution_m in [0.0432, 0.0438] {
        let scans = scans(&dir, &NavtechLayout { range_resolution_m: resolution_m, ..oxford::OXFORD });
        for preset in OdometryConfig::PRESETS {
            let errors = pair_errors(&scans, &truth, OdometryConfig::preset(preset).unwrap());
            let ratio = errors.iter().map(|e| e.3).sum::<f64>() / errors.iter().map(|e| e.2).sum::<f64>();
            eprintln!("range resolution {resolution_m} m, {preset}: estimated / true path length = {ratio:.4}");
            assert!((ratio - 1.0).abs() < 0.05, "scale far off: {ratio}");
        }
    }
}

/// Every other scan of the real sample: 0.5 s and about 4.5 m apart, beyond
/// the 3 m association radius from rest. The second scan's registration
/// starts again ahead of rest when few of its surface points found a
/// correspondence; before, both presets stayed near rest (end point 20.7 m /
/// 14.4 m off on 19.4 m) and flagged nothing.
#[test]
fn every_other_oxford_scan_is_followed_from_rest() {
    let Some(dir) = sample() else { return };
    let truth = oxford::odometry::read_radar_odometry(&dir.join("gt/radar_odometry.csv")).unwrap();
    let scans: Vec<PolarScan> = scans(&dir, &oxford::OXFORD).into_iter().step_by(2).collect();
    assert_eq!(scans.len(), 6);
    for config in [OdometryConfig::cfear(), OdometryConfig::fast_cfear()] {
        let name = if config.motion_compensation { "cfear, every other scan" } else { "fast-cfear, every other scan" };
        let radius_m = config.grid_m;
        let errors = pair_errors(&scans, &truth, config);
        assert!(errors[0].2 > radius_m, "the first step is beyond the association radius: {errors:?}");
        let (mean_t, mean_yaw) = report(name, &errors);
        // Twice the consecutive scans' regression bounds: about twice the motion per pair.
        assert!(mean_t <= 2.0 * BOUND_FAST_CFEAR_TRANSLATION_M && mean_yaw <= 2.0 * BOUND_FAST_CFEAR_YAW_DEG, "{name}");
    }
}
