//! CI fuzzing: every target for a fixed number of executions (deterministic:
//! the same seed and count give the same inputs on every machine), and
//! checks that the harness itself catches what it claims to.
//!
//! A failure leaves the input under `target/fuzz-findings/<target>/`;
//! replay it with `cargo run -p mmtrack-fuzz -- <target> --replay FILE`.
#![allow(clippy::unwrap_used)]

use std::path::Path;
use std::time::Duration;

use mmtrack_fuzz::alloc::{ALLOCATION_CAP_BYTES, TOTAL_CAP_BYTES};
use mmtrack_fuzz::runner::{Budget, FindingKind, RunConfig, run};
use mmtrack_fuzz::seeds::realdata_dir;
use mmtrack_fuzz::targets::{Scratch, TARGETS, Target, find, png_chunk_crcs};

/// The CI configuration: a fixed seed and count, wall-clock time not judged.
fn config(executions: u64, findings_dir: &Path) -> RunConfig {
    RunConfig {
        seed: 0x006d_6d74_7261_636b,
        budget: Budget::Executions(executions),
        max_input_bytes: 1 << 20,
        slow_is_finding: false,
        slow_limit: Duration::from_secs(2),
        findings_dir: findings_dir.to_path_buf(),
    }
}

/// Runs `name` for `executions` inputs and fails on any finding. The counts
/// below take about 1-3 s each in the test profile on one core.
fn fuzz(name: &str, executions: u64) {
    let target = find(name).unwrap();
    let realdata = realdata_dir();
    if realdata.is_none() {
        eprintln!("{name}: real data not found (set MMTRACK_REALDATA): written seeds only");
    }
    let seeds = (target.seeds)(realdata.as_deref());
    let report = run(target, &seeds, &config(executions, &mmtrack_fuzz::findings_dir())).unwrap();
    println!(
        "fuzz {name}: {} executions in {:.1} s, {} accepted, {} seeds, corpus {}, {} outcomes, slowest {:.3} s",
        report.executions,
        report.elapsed.as_secs_f64(),
        report.accepted,
        report.seeds,
        report.corpus,
        report.outcomes,
        report.slowest.as_secs_f64()
    );
    assert_eq!(report.executions, executions);
    // Mutations must still reach the end of the reader now and then, or the
    // run tests only its first checks.
    assert!(report.accepted > 0, "{name}: no input accepted");
    let found: Vec<String> = report
        .findings
        .iter()
        .map(|f| format!("{:?} x{}: {} ({})", f.kind, f.hits, f.message, f.input.display()))
        .collect();
    assert!(found.is_empty(), "{name}: findings:\n{}", found.join("\n"));
}

#[test]
fn fuzz_png() {
    fuzz("png", 50_000);
}

#[test]
fn fuzz_nmea() {
    fuzz("nmea", 100_000);
}

#[test]
fn fuzz_cdr() {
    fuzz("cdr", 600_000);
}

#[test]
fn fuzz_decawave() {
    fuzz("decawave", 60_000);
}

#[test]
fn fuzz_npy() {
    fuzz("npy", 150_000);
}

#[test]
fn fuzz_mat() {
    fuzz("mat", 1_000);
}

#[test]
fn fuzz_csv() {
    fuzz("csv", 250_000);
}

#[test]
fn fuzz_sigmf() {
    fuzz("sigmf", 150_000);
}

/// The written seeds are valid inputs: every reader accepts them (else the
/// fuzzing would start from the error paths only).
#[test]
fn written_seeds_are_accepted() {
    let scratch = Scratch::new().unwrap();
    for target in &TARGETS {
        for (i, seed) in (target.seeds)(None).iter().enumerate() {
            let outcome = (target.run)(&scratch, seed);
            assert!(outcome.split(" | ").any(|o| o.starts_with("ok")), "{} written seed {i}: {outcome}", target.name);
        }
        if let Some(realdata) = realdata_dir() {
            for (i, seed) in (target.seeds)(Some(&realdata)).iter().enumerate() {
                println!("{} seed {i} ({} bytes): {}", target.name, seed.len(), (target.run)(&scratch, seed));
            }
        }
    }
}

/// A panic, an over-cap allocation and too many allocations in all are
/// findings, saved with their message.
#[test]
fn harness_catches_panics_and_over_cap_allocations() {
    fn misbehave(_: &Scratch, input: &[u8]) -> String {
        match input {
            b"panic" => panic!("deliberate panic of the harness test"),
            b"allocate" => {
                // Asked for, never written: costs address space, not memory.
                let block: Vec<u8> = Vec::with_capacity(ALLOCATION_CAP_BYTES + 1);
                std::hint::black_box(&block);
                "ok".into()
            }
            b"churn" => {
                // 1 MiB at a time, each freed: only the sum passes a cap.
                for _ in 0..(TOTAL_CAP_BYTES >> 20) + 1 {
                    let block: Vec<u8> = Vec::with_capacity(1 << 20);
                    std::hint::black_box(&block);
                }
                "ok".into()
            }
            _ => "ok".into(),
        }
    }
    fn seeds(_: Option<&Path>) -> Vec<Vec<u8>> {
        vec![b"fine".to_vec(), b"panic".to_vec(), b"allocate".to_vec(), b"churn".to_vec()]
    }
    let target = Target { name: "misbehave", reader: "test", run: misbehave, seeds, fixup: |_| {} };
    let dir = tempfile::tempdir().unwrap();
    let report = run(&target, &seeds(None), &config(200, dir.path())).unwrap();
    let kinds: Vec<FindingKind> = report.findings.iter().map(|f| f.kind).collect();
    let expected = [FindingKind::Panic, FindingKind::OverCapAllocation, FindingKind::OverCapTotal];
    assert_eq!(kinds, expected, "{:?}", report.findings);
    assert!(report.findings[0].message.contains("deliberate panic"), "{}", report.findings[0].message);
    assert!(report.findings[0].message.contains("main.rs"), "location: {}", report.findings[0].message);
    assert!(report.findings[1].message.contains(&(ALLOCATION_CAP_BYTES + 1).to_string()));
    assert!(report.findings[2].message.contains("in all for one input"), "{}", report.findings[2].message);
    for (f, input) in report.findings.iter().zip([&b"panic"[..], b"allocate", b"churn"]) {
        assert_eq!(std::fs::read(&f.input).unwrap(), input);
        assert!(f.input.with_extension("txt").is_file());
        assert!(f.input.starts_with(dir.path().join("misbehave")));
    }
}

/// The PNG fixup makes a mutated chunk's CRC right again.
#[test]
fn png_chunk_crcs_are_repaired() {
    let png = (find("png").unwrap().seeds)(None).remove(0);
    let mut mutated = png.clone();
    // Byte 16 is in the IHDR chunk (the width's high byte).
    mutated[16] ^= 0x40;
    let scratch = Scratch::new().unwrap();
    let run = find("png").unwrap().run;
    assert!(run(&scratch, &mutated).contains("CRC"), "{}", run(&scratch, &mutated));
    png_chunk_crcs(&mut mutated);
    assert!(!run(&scratch, &mutated).contains("CRC"), "{}", run(&scratch, &mutated));
    let mut same = png.clone();
    png_chunk_crcs(&mut same);
    assert_eq!(same, png);
}

/// The same seed gives the same run (inputs, outcomes and corpus), so a CI
/// failure reproduces.
#[test]
fn same_seed_same_run() {
    let target = find("npy").unwrap();
    let seeds = (target.seeds)(realdata_dir().as_deref());
    let dir = tempfile::tempdir().unwrap();
    let summary = || {
        let r = run(target, &seeds, &config(20_000, dir.path())).unwrap();
        (r.executions, r.accepted, r.corpus, r.outcomes)
    };
    assert_eq!(summary(), summary());
}
