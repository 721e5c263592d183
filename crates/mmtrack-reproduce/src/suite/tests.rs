use std::sync::Arc;

use arrow_array::{Float64Array, Int64Array, RecordBatch, StringArray};
use arrow_schema::{DataType, Field, Schema};

use super::*;

const SUITE: &str = r#"# my suite
description = "two metrics"

[[step]]
args = ["process", "odometry", "{suite}/rec.mcap", "-o", "{work}/tables"]

[[metric]]
name = "mean cost"
table = "tables/odometry"
sequence = "a"
column = "cost"
aggregate = "mean"
expected = 2.0 # from the first run
tolerance = 0.5

[[metric]]
name = "b preset x"
table = "tables/odometry"
where = { sequence = "b", preset = "x" }
column = "cost"
expected = 10.0
relative_tolerance = 0.1
"#;

fn write_part(path: &Path, preset: &[&str], cost: &[f64], scans: &[i64]) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let schema = Arc::new(Schema::new(vec![
        Field::new("preset", DataType::Utf8, false),
        Field::new("cost", DataType::Float64, false),
        Field::new("scans", DataType::Int64, false),
    ]));
    let batch = RecordBatch::try_new(
        schema.clone(),
        vec![
            Arc::new(StringArray::from(preset.to_vec())),
            Arc::new(Float64Array::from(cost.to_vec())),
            Arc::new(Int64Array::from(scans.to_vec())),
        ],
    )
    .unwrap();
    let mut writer = parquet::arrow::ArrowWriter::try_new(std::fs::File::create(path).unwrap(), schema, None).unwrap();
    writer.write(&batch).unwrap();
    writer.close().unwrap();
}

fn work() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let t = dir.path().join("tables/odometry");
    write_part(&t.join("sequence=a/part-0.parquet"), &["x", "y", "x"], &[1.0, 2.0, 4.0], &[10, 20, 30]);
    write_part(&t.join("sequence=b/part-0.parquet"), &["x", "y"], &[10.5, 7.0], &[5, 6]);
    dir
}

#[test]
fn metrics_select_rows_by_partition_and_column_and_reduce_them() {
    let dir = work();
    let suite = parse_suite(Path::new("s.toml"), SUITE).unwrap();
    assert_eq!(suite.steps[0][2], "{suite}/rec.mcap");
    assert_eq!(
        step_words(&suite.steps[0], Path::new("/d"), Path::new("/w"), &suite.env, &|_| None).unwrap(),
        ["process", "odometry", "/d/rec.mcap", "-o", "/w/tables"]
    );
    let checks = measure(&suite, dir.path());
    // (1 + 2 + 4) / 3 = 2.333 within 2.0 +- 0.5; 10.5 within 10 +- 10 %.
    assert_eq!(checks[0].measured, Ok(Selected { value: 7.0 / 3.0, rows: 3 }));
    assert_eq!(checks[1].measured, Ok(Selected { value: 10.5, rows: 1 }));
    assert!(checks.iter().all(SuiteCheck::ok), "{}", table(&checks));
    let t = dir.path().join("tables/odometry");
    let sel = |filters: Vec<(&str, Wanted)>, column: &str, aggregate| Selection {
        filters: filters.into_iter().map(|(k, v)| (k.to_string(), v)).collect(),
        column: column.to_string(),
        aggregate,
    };
    let one = |s: Selection| select::select(&t, &s).map(|s| s.value).map_err(|e| format!("{e:#}"));
    assert_eq!(one(sel(vec![("preset", Wanted::Text("y".into()))], "scans", Some(Aggregate::Sum))), Ok(26.0));
    assert_eq!(one(sel(vec![], "cost", Some(Aggregate::Max))), Ok(10.5));
    assert_eq!(one(sel(vec![], "cost", Some(Aggregate::Min))), Ok(1.0));
    assert_eq!(one(sel(vec![("scans", Wanted::Number(20.0))], "cost", None)), Ok(2.0));
    assert_eq!(one(sel(vec![("sequence", Wanted::Text("b".into()))], "x", Some(Aggregate::Count))), Ok(2.0));
    for (s, message) in [
        (sel(vec![], "cost", None), "5 rows have no filter; narrow them"),
        (sel(vec![("sequence", Wanted::Text("c".into()))], "cost", None), "partitions there: sequence=a, sequence=b"),
        (
            sel(vec![], "costs", Some(Aggregate::Mean)),
            "sequence=a/part-0.parquet: no column `costs` (columns: preset, cost, scans)",
        ),
        (sel(vec![("mode", Wanted::Text("a".into()))], "cost", None), "no column or partition `mode`"),
        (sel(vec![], "preset", Some(Aggregate::Mean)), "row 0: preset: a Utf8 column is not a number"),
        // The partition column: text from the path (it read "no column `sequence`").
        (
            sel(vec![], "sequence", Some(Aggregate::Mean)),
            "`sequence` is a partition (text from the path), not a numeric column",
        ),
    ] {
        let err = one(s).unwrap_err();
        assert!(err.contains(message), "{err}");
    }
    let err =
        format!("{:#}", select::select(&dir.path().join("tables/odometri"), &sel(vec![], "cost", None)).unwrap_err());
    assert!(err.contains("no such table directory (directories beside it: odometry)"), "{err}");
}

#[test]
fn a_value_past_its_tolerance_regresses_and_nan_never_passes() {
    let check = |measured: f64, tolerance| SuiteCheck {
        name: "m".into(),
        expected: 10.0,
        tolerance,
        measured: Ok(Selected { value: measured, rows: 1 }),
    };
    assert!(check(10.5, Tolerance::Absolute(0.5)).ok());
    assert!(!check(10.5001, Tolerance::Absolute(0.5)).ok());
    assert!(check(9.0, Tolerance::Relative(0.1)).ok());
    assert!(!check(8.99, Tolerance::Relative(0.1)).ok());
    assert!(!check(f64::NAN, Tolerance::Absolute(f64::MAX)).ok());
    let missing = SuiteCheck { measured: Err("gone".into()), ..check(0.0, Tolerance::Absolute(1.0)) };
    assert_eq!(missing.verdict(), "NOT MEASURED");
    let text = table(&[check(10.5001, Tolerance::Absolute(0.5)), missing]);
    assert!(text.contains("m       10        10.5001   +0.5001 (+5.001%)  +-0.5      REGRESSED"), "{text}");
    assert!(text.contains("\n    gone\n"), "{text}");
}

/// Before: a value that moved past a zero tolerance in its eighth digit
/// showed `0.0883317  0.0883317  +-0  REGRESSED`, and no row said how far a
/// metric moved. Now both values get every digit when six would look equal,
/// and a change column gives the difference, absolute and relative.
#[test]
fn a_regressed_row_shows_how_far_the_value_moved() {
    let check = |expected: f64, measured: f64, tolerance| SuiteCheck {
        name: "ATE".into(),
        expected,
        tolerance,
        measured: Ok(Selected { value: measured, rows: 1 }),
    };
    let text = table(&[check(0.088_331_717, 0.088_331_717_221_385_15, Tolerance::Absolute(0.0))]);
    let row = text.lines().nth(1).unwrap();
    let cells: Vec<&str> = row.split("  ").map(str::trim).filter(|c| !c.is_empty()).collect();
    assert_eq!(cells, ["ATE", "0.088331717", "0.08833171722138515", "+2.21385e-10 (+2.50629e-7%)", "+-0", "REGRESSED"]);
    // Values six digits tell apart keep six digits; a fall is negative.
    let text = table(&[check(2.0, 1.5, Tolerance::Relative(0.1))]);
    assert!(text.lines().nth(1).unwrap().contains("2         1.5       -0.5 (-25%)"), "{text}");
    // Against an expected zero, only the difference.
    let text = table(&[check(0.0, 0.25, Tolerance::Absolute(0.1))]);
    assert!(text.lines().nth(1).unwrap().contains("0         0.25      +0.25"), "{text}");
}

#[test]
fn bless_writes_the_measured_values_and_keeps_the_comments() {
    let dir = work();
    let nudged = SUITE.replace("expected = 10.0", "expected = 20.0");
    let suite = parse_suite(Path::new("s.toml"), &nudged).unwrap();
    let checks = measure(&suite, dir.path());
    assert!(!checks[1].ok());
    let blessed = bless(&nudged, &checks).unwrap();
    assert!(
        blessed.contains("# my suite") && blessed.contains("expected = 2.3333333333333335 # from the first run"),
        "{blessed}"
    );
    let again = parse_suite(Path::new("s.toml"), &blessed).unwrap();
    assert!(measure(&again, dir.path()).iter().all(SuiteCheck::ok));
    assert_eq!(again.metrics[1].expected, 10.5);
    let mut broken = checks.clone();
    broken[0].measured = Err("no table".into());
    let err = format!("{:#}", bless(&nudged, &broken).unwrap_err());
    assert!(err.contains("metric `mean cost` was not measured, nothing blessed: no table"), "{err}");
}

#[test]
fn suites_are_refused_naming_the_file_the_entry_and_the_key() {
    let step = "[[step]]\nargs = [\"analyze\", \"{work}/t\", \"-o\", \"{work}/a\"]\n";
    let metric = "[[metric]]\nname = \"m\"\ntable = \"a/t\"\ncolumn = \"c\"\nexpected = 1.0\ntolerance = 0.1\n";
    for (text, message) in [
        (metric.to_string(), "s.toml: no [[step]] entries"),
        (step.to_string(), "s.toml: no [[metric]] entries"),
        (format!("[[step]]\nargs = []\n{metric}"), "s.toml: step 1: empty args"),
        (format!("[[step]]\nargs = [\"demo\"]\n{metric}"), "s.toml: step 1: `demo` is not a step command"),
        (
            format!("[[step]]\nargs = [\"analyze\", \"{{wrok}}/t\"]\n{metric}"),
            "step 1: `{wrok}/t`: unknown placeholder `{wrok}`",
        ),
        (format!("{step}{metric}{metric}"), "metric 2 (`m`): the name is used twice"),
        (format!("{step}{}", metric.replace("a/t", "../t")), "metric 1 (`m`): table: `../t` must be a path inside"),
        (format!("{step}{}", metric.replace("a/t", "/t")), "table: `/t` must be a path inside"),
        (format!("{step}{}", metric.replace("tolerance = 0.1", "")), "metric 1 (`m`): no tolerance"),
        (
            format!("{step}{}", metric.replace("tolerance = 0.1", "tolerance = -1.0")),
            "tolerance: -1; expected a finite number >= 0",
        ),
        (format!("{step}{}relative_tolerance = 0.1\n", metric), "not both"),
        (
            format!("{step}{}", metric.replace("expected = 1.0", "expected = nan")),
            "expected: NaN is not a finite number",
        ),
        (format!("{step}{}colum = \"x\"\n", metric), "unknown field `colum`"),
        (format!("{step}{}sequence = \"a\"\nwhere = {{ sequence = \"b\" }}\n", metric), "`sequence` is given twice"),
        (format!("{step}{}aggregate = \"median\"\n", metric), "unknown variant `median`"),
    ] {
        let err = parse_suite(Path::new("s.toml"), &text).map(|_| ()).map_err(|e| format!("{e:#}")).unwrap_err();
        assert!(err.contains(message), "{text}\n-> {err}");
        assert!(err.starts_with("s.toml"), "{err}");
    }
}

/// Before: a suite could point at data only through `{suite}`, so the
/// example suite failed from a clone not beside `shared/` even with
/// MMTRACK_REALDATA set (the notebook honours it). Now `{env:NAME}` takes
/// the variable, else the suite's `[env]` default.
#[test]
fn env_placeholders_take_the_variable_else_the_suite_default() {
    let text = SUITE.replace(
        "[[step]]",
        "[env]\nDATA = \"{suite}/data\"\n\n[[step]]\nargs = [\"ingest\", \"oxford\", \"{env:DATA}/x\", \"{env:OTHER}\"]\n\n[[step]]",
    );
    let suite = parse_suite(Path::new("s.toml"), &text).unwrap();
    let words = |lookup: &dyn Fn(&str) -> Option<String>| {
        step_words(&suite.steps[0], Path::new("/d"), Path::new("/w"), &suite.env, lookup)
    };
    let set = |name: &str| Some(format!("/set/{name}"));
    assert_eq!(words(&set).unwrap()[2..], ["/set/DATA/x", "/set/OTHER"]);
    let only_other = |name: &str| (name == "OTHER").then(|| "o".to_string());
    assert_eq!(words(&only_other).unwrap()[2..], ["/d/data/x", "o"]);
    let error = format!("{:#}", words(&|_| None).unwrap_err());
    assert!(error.contains("{env:OTHER}: the environment variable OTHER is not set"), "{error}");
    for (bad, message) in [
        ("{env:1X}", "unknown placeholder `{env:1X}`"),
        ("{env:}", "unknown placeholder `{env:}`"),
        ("{home}", "unknown placeholder `{home}`"),
    ] {
        let text = SUITE.replace("{suite}/rec.mcap", bad);
        let error = format!("{:#}", parse_suite(Path::new("s.toml"), &text).unwrap_err());
        assert!(error.contains(message), "{error}");
    }
    let text = SUITE.replace("[[step]]", "[env]\nD = \"{work}/x\"\n\n[[step]]");
    let error = format!("{:#}", parse_suite(Path::new("s.toml"), &text).unwrap_err());
    assert!(error.contains("[env] D") && error.contains("unknown placeholder `{work}`"), "{error}");
}
