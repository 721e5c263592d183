//! Each experiment of this crate run through its library `run` at the smoke
//! tier, its metrics checked against the smoke expectations of
//! `data/reproduce/<experiment>.expected.toml`: the same check `mmtrack
//! reproduce --all --smoke` makes, without the binary.

use mmtrack_core::progress::NoProgress;
use mmtrack_reproduce::all::EXPERIMENTS;
use mmtrack_reproduce::expectation::compare;
use mmtrack_reproduce::model::{METRICS_FILE, Metric};
use mmtrack_reproduce::{Outcome, RunOptions, Tier, kim, mpc_artificial, mpc_convoy, shaham, zoechmann};

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
    assert_eq!(outcome.verdicts.len(), 6, "the three claims of PAPERS.md section 2, and each for the refit");
    assert_eq!(outcome.verdicts.iter().filter(|v| v.claim.informational).count(), 3, "the refit rows are ours");
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

/// The convoy's smoke run (300 sets): its metrics as expected; with the
/// diffuse scatterers in the truth the Doppler-gated eq. (35) with a one-set
/// gap (ours) is within 2x of the true birth rate, and it splits true paths
/// less than the paper's eq. (35) (reported beside it, not judged). Without
/// the scatterers ours misses the 2x (a verdict, see docs/results/multipath.md)
/// but stays nearer the truth than the paper's.
#[test]
fn mpc_convoy_smoke_meets_its_expectations_and_ours_beats_the_paper_gate() {
    let dir = tempfile::tempdir().unwrap();
    let options = smoke(&dir);
    let outcome = mpc_convoy::run(&mpc_convoy::Config::embedded().unwrap(), &options, &NoProgress).unwrap();
    check(&outcome, &options);
    let verdict = |what: &[&str]| {
        let mut found = outcome.verdicts.iter().filter(|v| what.iter().all(|w| v.claim.what.contains(w)));
        let v = found.next().unwrap_or_else(|| panic!("no verdict with {what:?}"));
        assert!(found.next().is_none(), "several verdicts with {what:?}");
        v
    };
    let targets: Vec<_> = outcome.verdicts.iter().filter(|v| !v.claim.informational).collect();
    assert_eq!(targets.len(), 3, "two birth-rate targets (two truths) and the ordering");
    // Ours on the paper's search (its whose-text starts the claim); the
    // least-squares search's claims name it first.
    let ours_diffuse = verdict(&["/ true, Doppler-gated", "diffuse scatterers", "specular paths and"]);
    assert!(ours_diffuse.met, "{}: {}", ours_diffuse.claim.what, ours_diffuse.note);
    let ordering = verdict(&["fragments true paths less"]);
    assert!(ordering.met, "{}", ordering.note);
    let ratio = |v: &mmtrack_reproduce::Verdict| v.measured.unwrap_or(f64::INFINITY);
    let ours = ratio(verdict(&["/ true, Doppler-gated", "without diffuse"]));
    let paper = ratio(verdict(&["the paper's", "without diffuse"]));
    assert!(ours < paper, "without diffuse scatterers: ours {ours} x, the paper's {paper} x");
    let literal = outcome.verdicts.iter().filter(|v| v.claim.informational && v.claim.what.contains("the paper's"));
    assert_eq!(literal.count(), 3, "the paper's eq. (35) against the three truths");
    let least_squares =
        outcome.verdicts.iter().filter(|v| v.claim.informational && v.claim.what.contains("least-squares"));
    assert_eq!(least_squares.count(), 2, "the least-squares search against both fair truths, a variant");
}

/// The traced cause of the convoy's missed row (ours, no diffuse
/// scatterers; docs/results/multipath.md): most births on the traffic cars
/// follow a set where the car was above floor + 6 dB and clear of stronger
/// paths but its own detections did not make a full-lifetime track (a
/// detection missing or 0.5-1.24 ns off, or all six detected and the
/// short-term search lost them), and the search of eqs. (17)-(23) loses the
/// weak cars' sets (4-8 dB above floor + 6 dB) far more often than the
/// strong ones' (12 dB and more), as their delay noise predicts.
#[test]
fn mpc_convoy_smoke_traces_the_traffic_births_to_the_cars_own_delay_noise() {
    use mmtrack_reproduce::mpc_convoy::causes::{Cause, MARGIN_BIN_DB};
    use mmtrack_sim::sounder::PathKind;

    let config = mpc_convoy::Config::embedded().unwrap();
    let measured = mpc_convoy::measure(&config.convoy, config.seed, mpc_convoy::SMOKE_SETS, &NoProgress).unwrap();
    let (_, d) = measured
        .rows
        .iter()
        .zip(&measured.diagnoses)
        .find(|(r, _)| r.truth == mpc_convoy::Truth::NoDiffuse && r.variant == mpc_convoy::OURS)
        .unwrap();
    let is_car = |p: u64| PathKind::of(p) == Some(PathKind::Traffic);
    let histogram = d.histogram(is_car);
    let births: u64 = histogram.values().sum();
    let own_noise: u64 = [Cause::MissedClear, Cause::MissedOffset, Cause::ShortTermSplit]
        .iter()
        .map(|c| histogram.get(c).copied().unwrap_or(0))
        .sum();
    assert!(births >= 20, "too few traffic births to judge: {histogram:?}");
    assert!(3 * own_noise > 2 * births, "own delay noise {own_noise} of {births} traffic births: {histogram:?}");

    // (sets, passing every search, with a full-lifetime track) per margin bin.
    let bin = |from_db: f64, to_db: f64| {
        d.noise
            .iter()
            .filter(|r| is_car(r.path_id) && r.margin_from_db >= from_db && r.margin_from_db + MARGIN_BIN_DB <= to_db)
            .fold((0u64, 0u64, 0u64), |a, r| (a.0 + r.sets, a.1 + r.chain_passes, a.2 + r.full_lifetime))
    };
    let share = |(sets, n): (u64, u64)| n as f64 / sets as f64;
    let (weak, strong) = (bin(4.0, 8.0), bin(12.0, f64::INFINITY));
    assert!(weak.0 >= 50 && strong.0 >= 20, "too few sets: weak {weak:?}, strong {strong:?}");
    assert!(share((weak.0, weak.1)) < 0.75, "weak cars' sets passing every search: {weak:?}");
    assert!(share((strong.0, strong.1)) > 0.95, "strong cars' sets passing every search: {strong:?}");
    // The search explains the short-term tracker: full-lifetime tracks
    // where the detections pass, within a tenth of the sets.
    assert!((share((weak.0, weak.2)) - share((weak.0, weak.1))).abs() < 0.1, "weak: {weak:?}");
}

/// What the least-squares short-term search (ours, not the paper's eq.
/// (17)) is for: on the traffic cars of the scatter-free tunnel it follows
/// more sets with a full-lifetime track than the paper's search, and fewer
/// births follow a set where all six snapshots were detected but the
/// search lost the car. Its birth-rate rows are judged like ours (a missed
/// 2x is a verdict, docs/results/multipath.md), not asserted here.
#[test]
fn mpc_convoy_smoke_least_squares_search_follows_the_cars_in_more_sets() {
    use mmtrack_reproduce::mpc_convoy::causes::Cause;
    use mmtrack_sim::sounder::PathKind;

    let config = mpc_convoy::Config::embedded().unwrap();
    let measured = mpc_convoy::measure(&config.convoy, config.seed, mpc_convoy::SMOKE_SETS, &NoProgress).unwrap();
    let diagnosis = |variant: &str| {
        measured
            .rows
            .iter()
            .zip(&measured.diagnoses)
            .find(|(r, _)| r.truth == mpc_convoy::Truth::NoDiffuse && r.variant == variant)
            .map(|(_, d)| d)
            .unwrap()
    };
    let (paper, ls) = (diagnosis(mpc_convoy::OURS), diagnosis(mpc_convoy::LS_OURS));
    let is_car = |p: u64| PathKind::of(p) == Some(PathKind::Traffic);
    let followed = |d: &mmtrack_reproduce::mpc_convoy::causes::Diagnosis| -> u64 {
        d.paths.iter().filter(|p| is_car(p.path_id)).map(|p| p.followed_sets).sum()
    };
    // Smoke run (measured): 206 sets followed on the paper's search, 236 on
    // the least-squares one; a gain of at least 5 % is asked, well below the
    // measured 15 % and well above zero (the same search gives equal counts).
    let (f_paper, f_ls) = (followed(paper), followed(ls));
    assert!(f_paper >= 100, "too few followed sets to judge: {f_paper}");
    assert!(20 * f_ls >= 21 * f_paper, "cars' sets followed: least-squares {f_ls}, paper's search {f_paper}");
    let lost = |d: &mmtrack_reproduce::mpc_convoy::causes::Diagnosis| {
        d.histogram(is_car).get(&Cause::ShortTermSplit).copied().unwrap_or(0)
    };
    assert!(lost(ls) < lost(paper), "births after the search lost a detected car: {} vs {}", lost(ls), lost(paper));
}
