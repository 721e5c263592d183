//! `mmtrack-fuzz`: runs the fuzz targets offline.
//!
//! ```text
//! cargo run --profile fuzz -p mmtrack-fuzz -- <target>|all [--seconds N] [--executions N] [--seed S] [--slow-s X]
//! cargo run -p mmtrack-fuzz -- <target> --replay FILE...
//! ```
//!
//! Prints executions, executions per second and findings per target; exits
//! with status 1 when anything was found. `--replay` runs the target once on
//! each saved input, outside the harness, so a panic shows as usual (with
//! `RUST_BACKTRACE=1`, its backtrace).

use std::process::ExitCode;
use std::time::Duration;

use mmtrack_fuzz::runner::{Budget, RunConfig, run};
use mmtrack_fuzz::seeds::realdata_dir;
use mmtrack_fuzz::targets::{Scratch, TARGETS, Target, find};

const USAGE: &str = "usage: mmtrack-fuzz <target>|all [--seconds N] [--executions N] [--seed S] [--slow-s X]
       mmtrack-fuzz <target> --replay FILE...
  Runs each target for N seconds (default 10) or N executions; findings go to target/fuzz-findings/<target>/.
  --slow-s X: an input taking longer than X seconds (default 2) is a finding.
  --replay: runs the target once on each file, outside the harness, and prints the outcome.";

struct Args {
    targets: Vec<&'static Target>,
    budget: Budget,
    seed: u64,
    slow_s: f64,
    replay: Vec<String>,
}

fn parse_args() -> Result<Args, String> {
    let mut args = std::env::args().skip(1);
    let mut names = Vec::new();
    let (mut budget, mut seed, mut slow_s) = (Budget::Time(Duration::from_secs(10)), 1, 2.0f64);
    let (mut replay, mut replaying) = (Vec::new(), false);
    while let Some(arg) = args.next() {
        let mut value = |flag: &str| args.next().ok_or_else(|| format!("{flag} needs a value"));
        match arg.as_str() {
            "--seconds" => {
                let s: f64 = value("--seconds")?.parse().map_err(|e| format!("--seconds: {e}"))?;
                budget = Budget::Time(Duration::try_from_secs_f64(s).map_err(|e| format!("--seconds: {e}"))?);
            }
            "--executions" => {
                budget = Budget::Executions(value("--executions")?.parse().map_err(|e| format!("--executions: {e}"))?);
            }
            "--seed" => seed = value("--seed")?.parse().map_err(|e| format!("--seed: {e}"))?,
            "--slow-s" => slow_s = value("--slow-s")?.parse().map_err(|e| format!("--slow-s: {e}"))?,
            "--replay" => replaying = true,
            "-h" | "--help" => return Err(String::new()),
            file if replaying && !file.starts_with('-') => replay.push(arg),
            name if !name.starts_with('-') => names.push(arg),
            other => return Err(format!("unknown option {other}")),
        }
    }
    let mut targets = Vec::new();
    for name in &names {
        if name == "all" {
            targets.extend(TARGETS.iter());
        } else {
            let known = TARGETS.iter().map(|t| t.name).collect::<Vec<_>>().join(", ");
            targets.push(find(name).ok_or_else(|| format!("unknown target {name}; targets: {known}, all"))?);
        }
    }
    if targets.is_empty() {
        return Err("name a target or all".into());
    }
    if !(slow_s.is_finite() && slow_s > 0.0) {
        return Err(format!("--slow-s {slow_s}: expected a positive number of seconds"));
    }
    if replaying && (replay.is_empty() || targets.len() != 1) {
        return Err("--replay needs one target and at least one file".into());
    }
    Ok(Args { targets, budget, seed, slow_s, replay })
}

fn main() -> ExitCode {
    let args = match parse_args() {
        Ok(args) => args,
        Err(e) => {
            if !e.is_empty() {
                eprintln!("mmtrack-fuzz: {e}");
            }
            eprintln!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    if !args.replay.is_empty() {
        return replay(args.targets[0], &args.replay);
    }
    let realdata = realdata_dir();
    match &realdata {
        Some(dir) => println!("seeds: real samples from {}", dir.display()),
        None => println!("seeds: real samples not found (set MMTRACK_REALDATA); written seeds only"),
    }
    let config = RunConfig {
        seed: args.seed,
        budget: args.budget,
        max_input_bytes: 1 << 20,
        slow_is_finding: true,
        slow_limit: Duration::from_secs_f64(args.slow_s),
        findings_dir: mmtrack_fuzz::findings_dir(),
    };
    println!(
        "{:<9} {:>11} {:>9} {:>10} {:>10} {:>7} {:>8} {:>10} {:>8}",
        "target", "executions", "seconds", "execs/s", "accepted", "seeds", "corpus", "slowest_s", "findings"
    );
    let mut found = 0;
    for target in &args.targets {
        let seeds = (target.seeds)(realdata.as_deref());
        let report = match run(target, &seeds, &config) {
            Ok(report) => report,
            Err(e) => {
                eprintln!("mmtrack-fuzz: {}: no scratch directory: {e}", target.name);
                return ExitCode::from(2);
            }
        };
        println!(
            "{:<9} {:>11} {:>9.1} {:>10.0} {:>10} {:>7} {:>8} {:>10.3} {:>8}",
            report.target,
            report.executions,
            report.elapsed.as_secs_f64(),
            report.rate(),
            report.accepted,
            report.seeds,
            report.corpus,
            report.slowest.as_secs_f64(),
            report.findings.len()
        );
        for f in &report.findings {
            println!("  {:?} x{}: {}\n    input: {}", f.kind, f.hits, f.message.replace('\n', " "), f.input.display());
        }
        found += report.findings.len();
    }
    if found > 0 { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}

/// Runs `target` once on each file, outside the harness.
fn replay(target: &Target, files: &[String]) -> ExitCode {
    let scratch = match Scratch::new() {
        Ok(scratch) => scratch,
        Err(e) => {
            eprintln!("mmtrack-fuzz: no scratch directory: {e}");
            return ExitCode::from(2);
        }
    };
    for file in files {
        match std::fs::read(file) {
            Ok(input) => println!("{file}: {}", (target.run)(&scratch, &input)),
            Err(e) => {
                eprintln!("mmtrack-fuzz: {file}: {e}");
                return ExitCode::from(2);
            }
        }
    }
    ExitCode::SUCCESS
}
