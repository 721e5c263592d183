//! Each experiment of this crate run through its library `run` at the smoke
//! tier, its metrics checked against the smoke expectations of
//! `data/reproduce/<experiment>.expected.toml`: the same check `mmtrack
//! reproduce --all --smoke` makes, without the binary.

use mmtrack_core::progress::NoProgress;
use mmtrack_reproduce::all::EXPERIMENTS;
use mmtrack_reproduce::expectation::compare;
use mmtrack_reproduce::model::{METRICS_FILE, Metric};
use mmtrack_reproduce::{Outcome, RunOptions, Tier, kim, mpc_artificial, shaham, zoechmann};

/// The smoke options of an experiment writing into a fresh directory.
fn smoke(dir: &tempfile::TempDir) -> RunOptions {
    RunOptions::new(Tier::Smoke, dir.path().join("out"))
}

/// Every metric within its smoke expectation (none missing, none
/// unexpected), and the outcome consistent with the files written.
fn check(outcome: &Outcome, options: &RunOptions) {
    let experiment = EXPERIMENTS.iter().find(|e| e.name == outcome.experiment).unwrap();
    let checks = compare(outcome.experiment, &outcome.metrics, &experiment.expectations().unwrap(), Tier::Smoke);
    let misses: Vec<String> = checks
        .iter()
        .filter(|c| !c.ok())
        .map(|c| format!("{} `{}`: measured {:?}, expected {:?}", c.experiment, c.key, c.measured, c.expected))
        .collect();
    assert!(misses.is_empty(), "{} metrics outside their smoke expectation:\n{}", misses.len(), misses.join("\n"));
    assert!(!outcome.verdicts.is_empty(), "{}: no verdicts", outcome.experiment);

    let out = &options.output_dir;
    let report = out.join("reproduce.md");
    assert!(outcome.files.contains(&report) && outcome.files.contains(&out.join(METRICS_FILE)), "{:?}", outcome.files);
    for file in &outcome.files {
        assert!(file.is_file(), "{} is listed but not written", file.display());
    }
    assert_eq!(std::fs::read_to_string(report).unwrap(), outcome.report);
    let written: Vec<Metric> = serde_json::from_str(&std::fs::read_to_string(out.join(METRICS_FILE)).unwrap()).unwrap();
    assert_eq!(written.len(), outcome.metrics.len());
    for (w, m) in written.iter().zip(&outcome.metrics) {
        // serde_json's default float parser may land one ulp off the
        // shortest representation it printed: 1e-12 relative.
        let close = (w.value - m.value).abs() <= 1e-12 * m.value.abs().max(1.0);
        assert!(w.key == m.key && w.unit == m.unit && w.paper == m.paper && close, "metrics.json: {w:?} vs {m:?}");
    }
    assert_eq!(outcome.readme.name, format!("reproduce-{}", outcome.experiment));
}

#[test]
fn mpc_artificial_smoke_meets_its_expectations() {
    let dir = tempfile::tempdir().unwrap();
    let options = smoke(&dir);
    let outcome = mpc_artificial::run(&mpc_artificial::Config::default(), &options, &NoProgress).unwrap();
    check(&outcome, &options);
    assert_eq!(outcome.verdicts.len(), 2, "the two targets of PAPERS.md section 2");
}

#[test]
fn shaham_smoke_meets_its_expectations() {
    let dir = tempfile::tempdir().unwrap();
    let options = smoke(&dir);
    let outcome = shaham::run(&shaham::Config::embedded().unwrap(), &options, &NoProgress).unwrap();
    check(&outcome, &options);
    assert_eq!(outcome.verdicts.len(), 11, "7 published numbers, 2 orderings, 1 gain, the open-loop row");
    assert_eq!(outcome.verdicts.iter().filter(|v| v.claim.informational).count(), 1, "the open-loop row is ours");
}

#[test]
fn zoechmann_smoke_meets_its_expectations() {
    let dir = tempfile::tempdir().unwrap();
    let options = smoke(&dir);
    let outcome = zoechmann::run(&zoechmann::Config::embedded().unwrap(), &options, &NoProgress).unwrap();
    check(&outcome, &options);
    assert!(outcome.verdicts.iter().any(|v| v.claim.informational), "the variants are reported beside the targets");
}

#[test]
fn kim_smoke_meets_its_expectations() {
    let dir = tempfile::tempdir().unwrap();
    let options = smoke(&dir);
    let outcome = kim::run(&kim::Config::embedded().unwrap(), None, &options, &NoProgress).unwrap();
    check(&outcome, &options);
    // The targets: the paper's five errors, two confirmation epochs and no
    // false source on the paper row, and SLAM below LOS-only with the LOS blocked.
    let targets: Vec<&str> =
        outcome.verdicts.iter().filter(|v| !v.claim.informational).map(|v| v.claim.what.as_str()).collect();
    assert_eq!(targets.iter().filter(|w| w.contains("(paper)")).count(), 8, "{targets:#?}");
    assert_eq!(targets.iter().filter(|w| w.contains("LOS blocked")).count(), 1, "{targets:#?}");
    assert_eq!(targets.len(), 9, "{targets:#?}");
}
