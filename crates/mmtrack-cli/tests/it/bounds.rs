//! Issue 26: counts, sizes and times that scale memory or run time are
//! refused before anything is allocated, with one line naming the flag or
//! key and the limit (`mmtrack_core::limits`); nothing panics. Each case is
//! one of the repros, which aborted, panicked or ran out of memory.

use std::path::Path;
use std::time::{Duration, Instant};

use super::common::{mmtrack, text};

/// Runs `args` in `dir`: must fail within seconds, with one error line
/// holding every piece of `expected`, no panic, and without creating `-o`.
fn refused(dir: &Path, args: &[&str], expected: &[&str]) {
    let started = Instant::now();
    let out = mmtrack(dir, args);
    let elapsed = started.elapsed();
    let (_, stderr) = text(&out);
    // A flag's value is a usage error (2), a file's key a failure on data (1).
    let code = if expected.first().is_some_and(|p| p.starts_with("--")) { 2 } else { 1 };
    assert_eq!(out.status.code(), Some(code), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    let line = stderr.lines().find(|l| l.starts_with("error:")).unwrap_or_else(|| panic!("{args:?}: {stderr}"));
    for piece in expected {
        assert!(line.contains(piece), "{args:?}: `{piece}` not in `{line}`");
    }
    // Generous: a refusal is milliseconds; the repros took minutes or aborted.
    assert!(elapsed < Duration::from_secs(20), "{args:?}: {elapsed:?}");
    if let Some(i) = args.iter().position(|a| *a == "-o") {
        assert!(!dir.join(args[i + 1]).exists(), "{args:?}: output created");
    }
}

const RADAR: &str = "seed = 1\nmax_scans = 2\n[sensor]\nbins = 300\n[motion]\nspeed_mps = 8.0\nyaw_rate_radps = 0.0\nduration_s = 2.0\n";

fn radar_with(dir: &Path, name: &str, replace: (&str, &str), extra: &str) {
    let text = format!("{}{extra}", RADAR.replace(replace.0, replace.1));
    std::fs::write(dir.join(name), text).unwrap();
}

#[test]
fn simulator_settings_beyond_the_limits_are_refused_by_key() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sim = |name: &'static str| ["simulate", "radar", "--scenario", name, "-o", "x.mcap", "-q"];
    // start_t_ns near i64::MAX: "attempt to add with overflow" before.
    radar_with(d, "late.toml", ("seed = 1", "seed = 1\nstart_t_ns = 9223372036854775000"), "");
    refused(d, &sim("late.toml"), &["start_t_ns", "9223372036854775000", "2262"]);
    radar_with(d, "bins.toml", ("bins = 300", "bins = 100000000"), "");
    refused(d, &sim("bins.toml"), &["sensor.bins", "100000000", "64 Mi pixels"]);
    radar_with(d, "fast.toml", ("speed_mps = 8.0", "speed_mps = 1e9"), "");
    refused(d, &sim("fast.toml"), &["motion.speed_mps", "150 m/s"]);
    radar_with(d, "long.toml", ("duration_s = 2.0", "duration_s = 1e9"), "");
    refused(d, &sim("long.toml"), &["motion.duration_s", "86400"]);
    let far = RADAR.replace("duration_s = 2.0", "duration_s = 80000").replace("speed_mps = 8.0", "speed_mps = 20.0");
    std::fs::write(d.join("far.toml"), far).unwrap();
    refused(d, &sim("far.toml"), &["motion.duration_s", "1000 km"]);
    radar_with(d, "poles.toml", ("seed = 1", "seed = 1"), "[generator]\npole_spacing_m = 1e-6\n");
    refused(d, &sim("poles.toml"), &["generator.pole_spacing_m", "reflectors"]);

    // simulate slam: epochs, clutter, scattering points.
    let slam = |name: &'static str| ["simulate", "slam", "--scenario", name, "-o", "s.mcap", "-q"];
    std::fs::write(d.join("clutter.toml"), "clutter_per_epoch = 1000000000\n").unwrap();
    refused(d, &slam("clutter.toml"), &["clutter_per_epoch", "10000"]);
    std::fs::write(d.join("sps.toml"), "random_scattering_points = 100000000\n").unwrap();
    refused(d, &slam("sps.toml"), &["random_scattering_points", "100000"]);
    refused(
        d,
        &["simulate", "slam", "--epochs", "1000000000", "-o", "e.mcap", "-q"],
        &["--epochs 1000000000", "1000000"],
    );

    // simulate sounder: snapshots held in memory.
    let artificial = std::fs::read_to_string(super::common::root().join("data/sounder/artificial.toml")).unwrap();
    std::fs::write(d.join("snap.toml"), artificial.replace("snapshots = 200", "snapshots = 1000000000")).unwrap();
    refused(
        d,
        &["simulate", "sounder", "--scenario", "snap.toml", "-o", "c.mcap", "-q"],
        &["artificial.snapshots", "100000"],
    );
}

#[test]
fn pipeline_flags_and_keys_beyond_the_limits_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // --threads on any command (8000 threads took 66 s).
    refused(
        d,
        &["simulate", "slam", "--epochs", "3", "-o", "t.mcap", "--threads", "100000", "-q"],
        &["--threads", "1024"],
    );

    let out = mmtrack(d, &["simulate", "slam", "--epochs", "3", "-o", "w.mcap", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
    // --particles: "capacity overflow" (u64::MAX) and 15 GB then abort (1e8) before.
    for particles in ["18446744073709551615", "100000000"] {
        refused(
            d,
            &["process", "slam", "w.mcap", "-o", "p", "--particles", particles, "-q"],
            &["--particles", "1000000"],
        );
    }
    // A flag's value is a usage error (exit 2), as clap's own checks; exit 1 before.
    refused(d, &["process", "slam", "w.mcap", "-o", "p", "--particles", "1", "-q"], &["--particles 1", "between 2"]);
    // The same flag of reproduce kim (exit 1 before, blaming the embedded experiment file).
    refused(d, &["reproduce", "kim", "--quick", "--particles", "0", "-o", "k", "-q"], &["--particles 0", "between 2"]);

    let out = mmtrack(d, &["simulate", "radar", "--scenario", "r.toml", "-o", "r.mcap", "-q"]);
    assert!(!out.status.success());
    std::fs::write(d.join("r.toml"), RADAR).unwrap();
    let out = mmtrack(d, &["simulate", "radar", "--scenario", "r.toml", "-o", "r.mcap", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
    std::fs::write(d.join("rounds.toml"), "association_rounds = 100000000\n").unwrap();
    refused(
        d,
        &["process", "odometry", "r.mcap", "--config", "rounds.toml", "-o", "o", "-q"],
        &["association_rounds", "10000"],
    );
    // k_strongest = 1e8 asked for a 1.6 TB allocation: now it keeps every bin in range.
    std::fs::write(d.join("k.toml"), "k_strongest = 100000000\n").unwrap();
    let out = mmtrack(d, &["process", "odometry", "r.mcap", "--config", "k.toml", "-o", "k", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);

    refused(
        d,
        &["process", "beam", "r.mcap", "--tracker", "spebt", "--runs", "100000000", "-o", "b", "-q"],
        &["--runs", "1000000"],
    );
    // Not finite, or finite but overflowing the filter once squared (1e300 failed at block 0 before).
    for (flag, value, range) in [
        ("--sigma-r-m", "NaN", "[0, 1000] m"),
        ("--sigma-theta-deg", "inf", "[0, 180] deg"),
        ("--sigma-theta-deg", "1e300", "[0, 180] deg"),
    ] {
        refused(d, &["process", "beam", "r.mcap", "--tracker", "spebt", flag, value, "-o", "b", "-q"], &[flag, range]);
    }
}

/// Configuration files are read within a cap: `/dev/zero` or a 17 MiB file
/// as a scenario, a pipeline configuration, a manifest or a suite is refused
/// by name before it is read (these read without a bound before).
#[test]
fn configuration_files_beyond_their_cap_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::File::create(d.join("big.toml")).unwrap().set_len(17 * 1024 * 1024).unwrap();
    for config in ["/dev/zero", "big.toml"] {
        let what: &[&str] = if config == "big.toml" {
            &["big.toml", "too large", "at most 16777216 bytes"]
        } else {
            &["/dev/zero", "is a device"]
        };
        refused(d, &["simulate", "radar", "--scenario", config, "-o", "r.mcap"], what);
        refused(d, &["simulate", "sounder", "--scenario", config, "-o", "s.mcap"], what);
        refused(d, &["process", "manifest", config, "-o", "t"], what);
        refused(d, &["process", "odometry", "r.mcap", "--config", config, "-o", "t"], what);
        refused(d, &["check", config], what);
    }
}
