//! `mmtrack check`: the example regression suite on the real samples
//! passes; nudged past a tolerance it fails naming the metric; `--bless`
//! writes back the values the unnudged suite holds; bad suites and work
//! directories are refused without touching anything.

use std::path::Path;

use super::common::{mmtrack, root, text};

/// The example suite with its real-data paths made absolute, so a copy
/// runs from anywhere.
fn suite_copy(realdata: &Path) -> String {
    let text = std::fs::read_to_string(root().join("examples/regression-suite.toml")).unwrap();
    assert!(text.contains("{suite}/../../shared/realdata"), "the example names the real samples beside the clone");
    text.replace("{suite}/../../shared/realdata", realdata.to_str().unwrap())
}

fn expected_values(text: &str) -> Vec<(String, f64)> {
    let value: toml::Value = toml::from_str(text).unwrap();
    value["metric"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| (m["name"].as_str().unwrap().to_string(), m["expected"].as_float().unwrap()))
        .collect()
}

#[test]
fn the_example_suite_passes_fails_when_nudged_and_bless_round_trips() {
    let Some(realdata) = super::common::realdata("check_example_suite") else { return };
    let dir = tempfile::tempdir().unwrap();
    let out = mmtrack(&root(), &["check", "examples/regression-suite.toml"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stdout}{stderr}");
    assert!(stdout.contains("all 7 metrics within their tolerances"), "{stdout}");
    let words = |l: &str| l.split_whitespace().map(str::to_string).collect::<Vec<_>>();
    assert!(stdout.lines().any(|l| words(l) == ["oxford", "scans", "11", "11", "0", "+-0", "ok"]), "{stdout}");
    // docs/check.md shows this run's table as printed.
    let table = &stdout[stdout.find("metric ").unwrap()..];
    let docs = std::fs::read_to_string(root().join("docs/check.md")).unwrap();
    let shown = docs.split("```text\n").nth(1).and_then(|b| b.split("```").next()).unwrap();
    assert_eq!(shown, table, "docs/check.md's example output is not what the example suite prints");

    let original = suite_copy(&realdata);
    let originals = expected_values(&original);
    // ATE RMSE expected 0.0825... +- 0.001: 0.0015 past it.
    let (name, ate) = &originals[1];
    assert_eq!(name, "oxford ATE RMSE (m)");
    let nudged_value = ate + 0.0025;
    let nudged = original.replace(&format!("expected = {ate}"), &format!("expected = {nudged_value}"));
    assert_ne!(nudged, original);
    let suite = dir.path().join("suite.toml");
    std::fs::write(&suite, &nudged).unwrap();
    let out = mmtrack(dir.path(), &["check", "suite.toml", "--quiet"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stdout}{stderr}");
    assert!(stderr.contains("1 of 7 metrics regressed: `oxford ATE RMSE (m)` measured"), "{stderr}");
    assert!(stdout.contains("REGRESSED") && stdout.matches(" ok").count() == 6, "{stdout}");

    let out = mmtrack(dir.path(), &["check", "suite.toml", "--bless"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let blessed = std::fs::read_to_string(&suite).unwrap();
    assert_eq!(expected_values(&blessed), originals, "bless writes back what the example holds");
    assert_eq!(blessed, original, "only the nudged value changed back; comments and layout kept");
    let out = mmtrack(dir.path(), &["check", "suite.toml", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
}

#[test]
fn failing_steps_bad_suites_and_used_work_dirs_are_named_and_nothing_is_touched() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let metric =
        "[[metric]]\nname = \"m\"\ntable = \"t/odometry\"\ncolumn = \"x_m\"\nexpected = 1.0\ntolerance = 0.1\n";
    let write = |name: &str, text: &str| std::fs::write(d.join(name), text).unwrap();
    write(
        "missing.toml",
        &format!(
            "[[step]]\nargs = [\"process\", \"odometry\", \"{{suite}}/none.mcap\", \"-o\", \"{{work}}/t\"]\n{metric}"
        ),
    );
    let out = mmtrack(d, &["check", "missing.toml"]);
    let stderr = text(&out).1;
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("missing.toml: step 1 (mmtrack process odometry ") && stderr.contains("none.mcap"),
        "{stderr}"
    );

    write("usage.toml", &format!("[[step]]\nargs = [\"process\", \"odometry\", \"--presett\", \"x\"]\n{metric}"));
    let out = mmtrack(d, &["check", "usage.toml"]);
    let stderr = text(&out).1;
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("usage.toml: step 1") && stderr.contains("--presett"), "{stderr}");

    write("bad.toml", &format!("[[step]]\nargs = [\"reproduce\", \"spebt\"]\n{metric}"));
    let out = mmtrack(d, &["check", "bad.toml"]);
    assert!(text(&out).1.contains("bad.toml: step 1: `reproduce` is not a step command"), "{}", text(&out).1);

    // A work directory with files we did not write is refused and kept.
    std::fs::create_dir(d.join("used")).unwrap();
    write("used/notes.txt", "precious");
    let out = mmtrack(d, &["check", "missing.toml", "--work-dir", "used"]);
    assert!(text(&out).1.contains("used: --work-dir is not empty"), "{}", text(&out).1);
    assert_eq!(std::fs::read_to_string(d.join("used/notes.txt")).unwrap(), "precious");

    // --bless with a metric not measured writes nothing.
    let scenario = root().join("data/demo/radar-scenario.toml");
    let sim = format!(
        "[[step]]\nargs = [\"simulate\", \"radar\", \"--scenario\", \"{}\", \"-o\", \"{{work}}/r.mcap\"]\n\
         [[step]]\nargs = [\"process\", \"odometry\", \"{{work}}/r.mcap\", \"-o\", \"{{work}}/t\"]\n",
        scenario.to_str().unwrap()
    );
    let mean = format!("{metric}aggregate = \"mean\"\n");
    let gone = format!("{sim}{mean}{}", mean.replace("name = \"m\"", "name = \"n\"").replace("x_m", "no_such_m"));
    write("gone.toml", &gone);
    let out = mmtrack(d, &["check", "gone.toml", "--bless"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("metric `n` was not measured, nothing blessed"), "{stderr}");
    assert!(stdout.contains("NOT MEASURED") && stdout.contains("no column `no_such_m`"), "{stdout}");
    assert_eq!(std::fs::read_to_string(d.join("gone.toml")).unwrap(), gone);
}
