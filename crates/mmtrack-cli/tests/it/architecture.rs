//! The dependency rule of ARCHITECTURE.md, checked on `cargo metadata`.

use std::collections::BTreeMap;
use std::process::Command;

/// Which of our crates each crate may depend on (normal and build deps).
fn allowed_internal(name: &str) -> Option<&'static [&'static str]> {
    Some(match name {
        "mmtrack-core" => &[],
        "mmtrack-filter" => &["mmtrack-core"],
        "mmtrack-odometry" | "mmtrack-mpc" | "mmtrack-beam" | "mmtrack-slam" => &["mmtrack-core", "mmtrack-filter"],
        "mmtrack-io" => &["mmtrack-core"],
        "mmtrack-ingest" => &["mmtrack-core", "mmtrack-io"],
        "mmtrack-sim" => &["mmtrack-core"],
        "mmtrack-analysis" => &["mmtrack-core", "mmtrack-io"],
        // The pipelines: algorithms wired to io (and ingest's readers, for a
        // pulse file or GNSS geodesy); never analysis (polars) or a front end.
        "mmtrack-process" => &[
            "mmtrack-core",
            "mmtrack-filter",
            "mmtrack-io",
            "mmtrack-ingest",
            "mmtrack-sim",
            "mmtrack-odometry",
            "mmtrack-mpc",
            "mmtrack-beam",
            "mmtrack-slam",
        ],
        // The paper experiments: everything below the CLI.
        "mmtrack-reproduce" => &[
            "mmtrack-core",
            "mmtrack-filter",
            "mmtrack-odometry",
            "mmtrack-mpc",
            "mmtrack-beam",
            "mmtrack-slam",
            "mmtrack-io",
            "mmtrack-ingest",
            "mmtrack-sim",
            "mmtrack-analysis",
            "mmtrack-process",
        ],
        "mmtrack-cli" => ANY,
        // The Python package: a front end over the libraries, as the CLI
        // (never the CLI itself: nothing re-enters it through argv).
        "mmtrack-py" => &[
            "mmtrack-core",
            "mmtrack-io",
            "mmtrack-ingest",
            "mmtrack-process",
            "mmtrack-analysis",
            "mmtrack-reproduce",
            "mmtrack-mpc",
            "mmtrack-beam",
        ],
        // Dev-only fuzzing of the readers (publish = false).
        "mmtrack-fuzz" => &["mmtrack-core", "mmtrack-io", "mmtrack-ingest"],
        _ => return None,
    })
}

const ANY: &[&str] = &["*"];

/// External crates of the terminal and the command line: only the CLI talks
/// to them.
const TERMINAL_CRATES: &[&str] = &["clap", "indicatif"];

/// External crates that mean I/O, terminal or heavy data frames.
const IO_CRATES: &[&str] = &["clap", "indicatif", "mcap", "foxglove", "parquet", "arrow", "polars", "png", "memmap2"];

fn is_io_crate(name: &str) -> bool {
    IO_CRATES.iter().any(|c| name == *c || name.starts_with(&format!("{c}-")) || name.starts_with(&format!("{c}_")))
}

#[test]
fn crates_follow_the_dependency_rule() {
    let output = Command::new(env!("CARGO"))
        .args(["metadata", "--format-version", "1", "--no-deps", "--offline"])
        .current_dir(super::common::root())
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let metadata: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let mut violations = Vec::new();
    let mut seen = BTreeMap::new();
    for package in metadata["packages"].as_array().unwrap() {
        let name = package["name"].as_str().unwrap();
        let Some(allowed) = allowed_internal(name) else {
            violations.push(format!("{name}: not a crate of ARCHITECTURE.md; add it to the rule"));
            continue;
        };
        seen.insert(name.to_string(), ());
        for dep in package["dependencies"].as_array().unwrap() {
            let dep_name = dep["name"].as_str().unwrap();
            let dev = dep["kind"].as_str() == Some("dev");
            if dep_name.starts_with("polars") && name != "mmtrack-analysis" {
                violations.push(format!("{name} depends on {dep_name}: polars lives in mmtrack-analysis only"));
            }
            if dep_name.starts_with("pyo3") && name != "mmtrack-py" {
                violations.push(format!("{name} depends on {dep_name}: the Python bindings live in mmtrack-py only"));
            }
            if dev || allowed == ANY {
                continue;
            }
            if dep_name.starts_with("mmtrack-") && !allowed.contains(&dep_name) {
                violations.push(format!("{name} depends on {dep_name}; allowed: {allowed:?}"));
            }
            let pure = matches!(
                name,
                "mmtrack-core"
                    | "mmtrack-filter"
                    | "mmtrack-odometry"
                    | "mmtrack-mpc"
                    | "mmtrack-beam"
                    | "mmtrack-slam"
                    | "mmtrack-sim"
            );
            if pure && is_io_crate(dep_name) {
                violations.push(format!("{name} depends on {dep_name}: algorithms and simulators do no I/O"));
            }
            // The libraries, and the Python front end: only the CLI parses
            // arguments or draws progress.
            let library = matches!(name, "mmtrack-reproduce" | "mmtrack-process" | "mmtrack-py");
            if library && TERMINAL_CRATES.iter().any(|c| dep_name == *c || dep_name.starts_with(&format!("{c}_"))) {
                violations
                    .push(format!("{name} depends on {dep_name}: only the CLI parses arguments or draws progress"));
            }
        }
    }
    assert!(
        seen.contains_key("mmtrack-core") && seen.contains_key("mmtrack-cli") && seen.contains_key("mmtrack-py"),
        "metadata lists our crates"
    );
    assert!(violations.is_empty(), "dependency rule broken:\n{}", violations.join("\n"));
}
