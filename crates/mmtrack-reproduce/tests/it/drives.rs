//! The odometry and SPEBT experiments through their library `run` at the
//! smoke tier, on a short synthetic drive (the real Oxford trajectory they
//! default to is not in the repository; `mmtrack reproduce --all --smoke`
//! checks their metrics on it): the claims come back with the paper's
//! numbers and a measured value each, and the outcome matches the files.

use std::path::{Path, PathBuf};

use mmtrack_core::progress::NoProgress;
use mmtrack_process::simulate::radar::TrajectoryFormat;
use mmtrack_reproduce::model::{METRICS_FILE, Rule};
use mmtrack_reproduce::{Outcome, RunOptions, Tier, odometry, spebt};

/// A TUM file of `poses` poses at 10 m/s, 4 Hz, heading 0.3 rad (away
/// from the SPEBT base station at (-30, -125) m) and turning slowly.
fn tum_drive(dir: &Path, poses: usize) -> PathBuf {
    let (mut x_m, mut y_m, mut yaw_rad) = (0.0f64, 0.0f64, 0.3f64);
    let mut lines = Vec::new();
    for k in 0..poses {
        let (qz, qw) = ((0.5 * yaw_rad).sin(), (0.5 * yaw_rad).cos());
        lines.push(format!("{:.6} {x_m:.4} {y_m:.4} 0 0 0 {qz:.9} {qw:.9}", 0.25 * k as f64));
        x_m += 2.5 * yaw_rad.cos();
        y_m += 2.5 * yaw_rad.sin();
        yaw_rad += 0.05 * (k as f64 / 25.0).sin();
    }
    let path = dir.join("drive.tum");
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    path
}

/// The outcome agrees with what was written.
fn check_files(outcome: &Outcome, options: &RunOptions) {
    let out = &options.output_dir;
    for file in [out.join("reproduce.md"), out.join(METRICS_FILE)] {
        assert!(outcome.files.contains(&file), "{} not listed: {:?}", file.display(), outcome.files);
    }
    for file in &outcome.files {
        assert!(file.is_file(), "{} is listed but not written", file.display());
    }
    assert_eq!(std::fs::read_to_string(out.join("reproduce.md")).unwrap(), outcome.report);
    assert_eq!(outcome.readme.name, format!("reproduce-{}", outcome.experiment));
    assert!(!outcome.metrics.is_empty());
}

#[test]
fn odometry_smoke_judges_the_drift_targets() {
    let dir = tempfile::tempdir().unwrap();
    let trajectory = tum_drive(dir.path(), 170);
    let config = odometry::Config::load(None, trajectory, TrajectoryFormat::Tum).unwrap();
    let options = RunOptions::new(Tier::Smoke, dir.path().join("out"));
    let outcome = odometry::run(&config, &options, &NoProgress).unwrap();
    check_files(&outcome, &options);
    let claims: Vec<(&str, Option<f64>, &Rule)> =
        outcome.verdicts.iter().map(|v| (v.claim.what.as_str(), v.claim.paper_value, &v.claim.rule)).collect();
    assert_eq!(
        claims,
        [
            ("fast-cfear translational drift %", Some(6.56), &Rule::Below { bound: 6.56 }),
            ("cfear translational drift %", None, &Rule::AtMost { bound: 1.5 }),
            ("cfear rotational drift deg/100 m", None, &Rule::AtMost { bound: 0.5 }),
        ]
    );
    for v in &outcome.verdicts {
        let measured = v.measured.unwrap_or_else(|| panic!("{}: nothing measured", v.claim.what));
        assert_eq!(v.met, v.claim.rule.holds(measured) == Some(true), "{v:?}");
    }
    assert!(outcome.report.starts_with("# reproduce odometry (quick)\n"), "{}", outcome.report);
    let refused = odometry::run(&config, &RunOptions { runs: Some(2), ..options }, &NoProgress).unwrap_err();
    assert!(refused.to_string().contains("no run count"), "{refused}");
}

#[test]
fn spebt_smoke_judges_table_iii_for_both_experiments() {
    let dir = tempfile::tempdir().unwrap();
    let trajectory = tum_drive(dir.path(), 120);
    let config = spebt::Config::load(None, trajectory, TrajectoryFormat::Tum).unwrap();
    let options = RunOptions { runs: Some(4), ..RunOptions::new(Tier::Smoke, dir.path().join("out")) };
    let outcome = spebt::run(&config, &options, &NoProgress).unwrap();
    check_files(&outcome, &options);
    // Five targets per experiment, (a) then (b), with Table III's numbers: AoD and AoA RMSE after
    // and before re-initialisation, the re-initialisation share.
    let paper = &config.experiment.paper;
    let share_pct = 100.0 * paper.reinitialisations as f64 / paper.slots as f64;
    let expected_paper = [paper.rmse_aod_deg, paper.rmse_aoa_deg, paper.rmse_aod_deg, paper.rmse_aoa_deg, share_pct];
    // Then (a) at the two [sensitivity] pilot powers, 20 and 40 dBm: AoD and AoA before
    // re-initialisation and the share, variants rather than targets.
    assert_eq!(outcome.verdicts.len(), 10 + 2 * 3);
    let (targets, variants) = outcome.verdicts.split_at(10);
    assert!(targets.iter().all(|v| !v.claim.informational), "{targets:?}");
    for (v, power) in variants.iter().zip(["20", "20", "20", "40", "40", "40"]) {
        assert!(v.claim.informational && v.claim.what.contains(&format!("pilot {power} dBm, variant")), "{v:?}");
    }
    for (i, v) in targets.iter().enumerate() {
        let paper_value = v.claim.paper_value.unwrap();
        assert_eq!(paper_value, expected_paper[i % 5], "{v:?}");
        let measured = v.measured.unwrap_or_else(|| panic!("{}: nothing measured", v.claim.what));
        assert_eq!(v.met, v.claim.rule.holds(measured) == Some(true), "{v:?}");
    }
    assert_eq!(outcome.metrics.len(), 4 * 4, "|alpha|, AoD, AoA, share per experiment and pilot-power variant");
    assert!(outcome.metrics.iter().all(|m| m.paper.is_some()), "{:?}", outcome.metrics);
}
