//! `mmtrack process mpc` and `mmtrack analyze` on a short simulated convoy:
//! the tables and their row counts, refusal without --force, the MPC
//! statistics of analyze, and a recording without CIRs named in the error;
//! on the real DW1000 log, the first path against the chip's leading edge.

use std::path::Path;

use mmtrack_core::{MpcDetection, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth, Se2, StampedPose};
use mmtrack_io::recording::{PoseStream, TimeBase};
use mmtrack_io::table::{GmPhdTrack, GroundTruthRxPose, GroundTruthTxPose, MpcSnapshotStats, TableRow, read_table_dir};
use mmtrack_io::{RecordingEvent, RecordingMetadata, RecordingOptions, RecordingReader, RecordingWriter};

use super::common::{mmtrack, realdata, root, text};

const SETS: usize = 8;

fn only<T: TableRow>(tables: &Path) -> (String, Vec<T>) {
    let mut all = read_table_dir::<T>(tables).unwrap();
    assert_eq!(all.len(), 1, "one partition of {}", T::SPEC.name);
    all.pop_first().unwrap()
}

fn simulate(dir: &Path) {
    let scenario = root().join("data/sounder/convoy-tunnel.toml");
    let sets = SETS.to_string();
    let args = ["simulate", "sounder", "--scenario", scenario.to_str().unwrap(), "-o", "rec.mcap", "--sets", &sets];
    let out = mmtrack(dir, &args);
    assert!(out.status.success(), "{}", text(&out).1);
}

#[test]
fn process_mpc_writes_every_table_refuses_to_overwrite_and_analyze_reports_mpc_statistics() {
    let dir = tempfile::tempdir().unwrap();
    simulate(dir.path());
    let truth_in_recording = RecordingReader::open(&dir.path().join("rec.mcap"))
        .unwrap()
        .filter(|e| matches!(e.as_ref().unwrap(), RecordingEvent::MpcTruth(_)))
        .count();

    let out = mmtrack(dir.path(), &["process", "mpc", "rec.mcap", "-o", "tables", "--gmphd", "--threads", "2"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains(&format!("{SETS} sets")), "{stdout}");

    let tables = dir.path().join("tables");
    let (sequence, sets) = only::<MpcSetStats>(&tables);
    assert_eq!(sets.len(), SETS);
    assert!(sets.iter().all(|s| s.snapshots == 6), "the paper's set of six snapshots");
    let (_, detections) = only::<MpcDetection>(&tables);
    assert_eq!(detections.len() as u64, sets.iter().map(|s| u64::from(s.detections)).sum::<u64>());
    assert!(!detections.is_empty(), "the convoy has a LOS path and wall bounces");
    let (_, tracks) = only::<MpcTrack>(&tables);
    assert_eq!(tracks.len() as u64, sets.iter().map(|s| u64::from(s.short_term_tracks)).sum::<u64>());
    let (_, long_term) = only::<MpcLongTermEntry>(&tables);
    let (_, snapshots) = only::<MpcSnapshotStats>(&tables);
    assert_eq!(snapshots.len(), 6 * SETS, "one row per snapshot");
    assert_eq!(snapshots.iter().map(|s| u64::from(s.detections)).sum::<u64>(), detections.len() as u64);
    assert_eq!(long_term.len() as u64, sets.iter().map(|s| u64::from(s.full_lifetime_tracks)).sum::<u64>());
    let (_, truth) = only::<MpcTruth>(&tables);
    assert_eq!(truth.len(), truth_in_recording);
    let (_, tx) = only::<GroundTruthTxPose>(&tables);
    let (_, rx) = only::<GroundTruthRxPose>(&tables);
    assert_eq!((tx.len(), rx.len()), (SETS, SETS), "one pose per set and car");
    let _ = only::<GmPhdTrack>(&tables);

    // Refused without --force before any work, and the file is untouched.
    let part = tables.join("mpc_sets").join(format!("sequence={sequence}")).join("part-0.parquet");
    let before = std::fs::metadata(&part).unwrap().modified().unwrap();
    let again = mmtrack(dir.path(), &["process", "mpc", "rec.mcap", "-o", "tables", "--quiet"]);
    let (_, stderr) = text(&again);
    assert_eq!(again.status.code(), Some(1));
    assert!(stderr.contains("exists; use --force"), "{stderr}");
    assert_eq!(std::fs::metadata(&part).unwrap().modified().unwrap(), before);
    let forced = mmtrack(dir.path(), &["process", "mpc", "rec.mcap", "-o", "tables", "--quiet", "--force", "--gmphd"]);
    assert!(forced.status.success(), "{}", text(&forced).1);

    let analysis = mmtrack(dir.path(), &["analyze", "tables", "-o", "analysis"]);
    let (stdout, stderr) = text(&analysis);
    assert!(analysis.status.success(), "{stderr}");
    assert!(stdout.contains(&format!("{sequence}: {SETS} sets")), "{stdout}");
    let results = dir.path().join("analysis");
    let (_, summary) = only::<mmtrack_io::table::MpcSummary>(&results.join("tables"));
    let summary = &summary[0];
    assert_eq!(summary.sets, SETS as u64);
    assert_eq!(summary.distance_source, "ground_truth_tx+ground_truth_rx");
    // Both cars drive at tens of km/h for 70 ms: some metres, not zero.
    assert!(summary.distance_m.is_some_and(|d| d > 0.5 && d < 20.0), "{:?}", summary.distance_m);
    assert!(summary.precision.is_some() && summary.recall.is_some() && summary.track_purity.is_some());
    let (_, per_set) = only::<mmtrack_io::table::SetMetrics>(&results.join("tables"));
    assert_eq!(per_set.len(), SETS);
    assert_eq!(per_set.iter().map(|s| s.long_term_mpcs).sum::<u64>(), long_term.len() as u64);
    let report = std::fs::read_to_string(results.join("report.md")).unwrap();
    assert!(report.contains("## Multipath components"), "{report}");
    for (file, _) in mmtrack_analysis::mpc_report::PLOTS {
        let svg = std::fs::read_to_string(results.join("plots").join(&sequence).join(file)).unwrap();
        assert!(svg.starts_with("<svg"), "{file}");
    }
}

#[test]
fn a_recording_without_cir_snapshots_is_named_in_the_error() {
    let dir = tempfile::tempdir().unwrap();
    let metadata = RecordingMetadata {
        sequence_id: "no-cir".into(),
        source: "process mpc test".into(),
        time_base: TimeBase::UnixEpoch,
        extra: Default::default(),
    };
    let path = dir.path().join("poses.mcap");
    let mut writer = RecordingWriter::create(&path, &metadata, &RecordingOptions::default()).unwrap();
    for i in 0..3i64 {
        let pose = StampedPose { t_ns: i * 1_000_000, parent_from_child: Se2::new(i as f64, 0.0, 0.0) };
        writer.write_pose(PoseStream::GroundTruth, &pose, "world").unwrap();
    }
    writer.finish().unwrap();
    let out = mmtrack(dir.path(), &["process", "mpc", "poses.mcap", "-o", "tables"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("poses.mcap") && stderr.contains("no CIR snapshots"), "{stderr}");
    assert!(!dir.path().join("tables").join("mpc_sets").exists(), "nothing written");

    let bad_link = mmtrack(dir.path(), &["process", "mpc", "poses.mcap", "-o", "tables", "--link", "x"]);
    assert_eq!(bad_link.status.code(), Some(2), "a bad flag value is a usage error");
    assert!(text(&bad_link).1.contains("--link 'x'"));
}

#[test]
fn config_overrides_single_fields_of_any_table() {
    let dir = tempfile::tempdir().unwrap();
    let print = |config: &str| {
        std::fs::write(dir.path().join("c.toml"), config).unwrap();
        mmtrack(dir.path(), &["process", "mpc", "x.mcap", "-o", "t", "--config", "c.toml", "--print-config"])
    };
    // One field of two sub-tables; everything else keeps the paper's values.
    let out = print("[long_term]\ndelay_gate_s = 2.5e-9\n[detection]\nkaiser_beta = 0.0\n");
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let config: mmtrack_mpc::MpcConfig = toml::from_str(&stdout).unwrap();
    let mut expected = mmtrack_mpc::MpcConfig::default();
    expected.long_term.delay_gate_s = 2.5e-9;
    expected.detection.kaiser_beta = Some(0.0);
    assert_eq!(config, expected);
    // Another noise-floor method replaces the default's table.
    let out = print("[detection.noise_floor]\nmethod = \"fixed\"\npower_db = -140.0\n");
    assert!(out.status.success(), "{}", text(&out).1);
    let config: mmtrack_mpc::MpcConfig = toml::from_str(&text(&out).0).unwrap();
    assert_eq!(config.detection.noise_floor, mmtrack_mpc::NoiseFloor::Fixed { power_db: -140.0 });
    // Unknown fields are still refused by name.
    let out = print("[long_term]\ndelay_gate_ns = 2.5\n");
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out).1.contains("delay_gate_ns"), "{}", text(&out).1);
}

/// A 1-D complex128 `.npy` file of `values`.
fn npy_complex(values: &[mmtrack_core::Complex64]) -> Vec<u8> {
    let dict = format!("{{'descr': '<c16', 'fortran_order': False, 'shape': ({},), }}", values.len());
    let pad = 64 - (10 + dict.len() + 1) % 64;
    let header = format!("{dict}{}\n", " ".repeat(pad % 64));
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&u16::try_from(header.len()).unwrap().to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in values {
        out.extend_from_slice(&v.re.to_le_bytes());
        out.extend_from_slice(&v.im.to_le_bytes());
    }
    out
}

/// `--pulse b2b.npy`: a back-to-back CIR as a bare `.npy` (no sidecar) takes
/// the recording's carrier and tap spacing; with the simulator's own pulse
/// it finds what the pulse from the recording's metadata finds.
#[test]
fn a_back_to_back_pulse_file_is_used_as_documented() {
    let dir = tempfile::tempdir().unwrap();
    simulate(dir.path());
    let mut reader = RecordingReader::open(&dir.path().join("rec.mcap")).unwrap();
    let _ = reader.next_item();
    let spectrum = mmtrack_io::recording::pulse::decode_pulse_spectrum(
        &reader.metadata().unwrap()[mmtrack_io::recording::pulse::PULSE_SPECTRUM_KEY],
    )
    .unwrap();
    let b2b = mmtrack_core::sounder::cir_from_spectrum(&spectrum);
    std::fs::write(dir.path().join("b2b.npy"), npy_complex(&b2b)).unwrap();

    let out = mmtrack(dir.path(), &["process", "mpc", "rec.mcap", "-o", "from-metadata", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let out = mmtrack(dir.path(), &["process", "mpc", "rec.mcap", "-o", "from-file", "-q", "--pulse", "b2b.npy"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let (_, expected) = only::<MpcDetection>(&dir.path().join("from-metadata"));
    let (_, found) = only::<MpcDetection>(&dir.path().join("from-file"));
    // The file's pulse is the metadata's up to its peak's delay and phase:
    // the same paths are found (the count within 5 %).
    let (e, f) = (expected.len() as f64, found.len() as f64);
    assert!((f - e).abs() <= 0.05 * e, "{f} detections with the file's pulse, {e} with the metadata's");
}

/// The real DecaWave DW1000 log (252 CIRs, channel 2, 1016 taps of 1.0016 ns;
/// Kolakowski, Zenodo 10.5281/zenodo.4742391, CC BY 4.0) through the CLI as a
/// user runs it, defaults throughout: ingest, process mpc, analyze. The first
/// path (earliest detection within 20 dB of the strongest) against the chip's
/// own leading edge HLP, which the recording carries per CIR.
#[test]
fn uwb_first_path_from_the_cli_lies_on_the_chips_leading_edge() {
    let Some(realdata) = realdata("uwb_first_path_from_the_cli_lies_on_the_chips_leading_edge") else { return };
    let dir = tempfile::tempdir().unwrap();
    let log = realdata.join("uwb-cirs-2018/1.log");
    let steps: [&[&str]; 3] = [
        &["ingest", "cir", log.to_str().unwrap(), "--format", "decawave", "-o", "uwb.mcap", "-q"],
        &["process", "mpc", "uwb.mcap", "-o", "tables"],
        &["analyze", "tables", "-o", "analysis"],
    ];
    let mut printed = String::new();
    for args in steps {
        printed += &super::common::mmtrack_ok(dir.path(), args);
    }
    let results = dir.path().join("analysis/tables");
    let (_, rows) = only::<mmtrack_io::table::FirstPathRow>(&results);
    assert_eq!(rows.len(), 252, "one row per CIR");
    assert!(rows.iter().all(|r| r.first_path_minus_hint_s.is_some()), "every CIR has a first path and an HLP");
    let (_, summary) = only::<mmtrack_io::table::MpcSummary>(&results);
    let s = &summary[0];
    let (median_ns, p90_ns) =
        (s.first_path_hint_abs_median_s.unwrap() * 1e9, s.first_path_hint_abs_p90_s.unwrap() * 1e9);
    println!(
        "DW1000, 252 CIRs, first path within {} dB of the strongest minus HLP: median {:+.3} ns, median |d| {median_ns:.3} ns, 90th percentile |d| {p90_ns:.3} ns",
        s.first_path_dynamic_range_db,
        s.first_path_minus_hint_median_s.unwrap() * 1e9
    );
    assert_eq!((s.first_path_snapshots, s.first_path_hint_snapshots), (252, 252));
    // Every CIR has noise peaks (at floor + 6 dB, more than 20 dB below the
    // strongest) ahead of its leading edge, and the report counts them.
    assert_eq!(s.first_path_earlier_snapshots, 252);
    // Tolerances: an outside check of the same rule on this log measured a
    // median of 0.055 ns and a 90th percentile of 0.184 ns; the bounds leave
    // about half that again for changes of detection that move the estimates
    // by a few hundredths of a tap (1 tap = 1.0016 ns; HLP itself is an
    // integer-plus-1/64-tap estimate). The rule it replaces (earliest
    // detection 12 dB above the floor) was 345-666 ns off.
    assert!(median_ns <= 0.1, "median |first path - HLP| {median_ns} ns");
    assert!(p90_ns <= 0.25, "90th percentile |first path - HLP| {p90_ns} ns");
    let report = std::fs::read_to_string(dir.path().join("analysis/report.md")).unwrap();
    assert!(report.contains("mpc_first_path"), "{report}");
    // One CIR per set: no short-term track can form, and both the command
    // and the report say why instead of leaving a row of "n/a".
    assert!(printed.contains("no short-term tracks: sets hold at most 1 snapshot(s)"), "{printed}");
    assert!(report.contains("`uwb`: no short-term tracks, so tracking and full-lifetime losses"), "{report}");
    assert!(report.contains("(first 30 of 252 sets)"), "the delay plot's subset is named: {report}");
    // Without tracks the tracked gains and losses are nulls, not -inf / +inf
    // (which pandas and DuckDB would average into infinities); the detection
    // loss is measured in every set.
    let (_, sets) = only::<mmtrack_core::MpcSetStats>(&dir.path().join("tables"));
    assert!(sets.iter().all(|s| s.tracked_gain_db.is_none() && s.full_lifetime_gain_db.is_none()), "{:?}", sets[0]);
    assert!(sets.iter().all(|s| s.detected_gain_db.is_some_and(f64::is_finite)), "{:?}", sets[0]);
    let (_, metrics) = only::<mmtrack_io::table::SetMetrics>(&results);
    assert!(metrics.iter().all(|m| m.tracking_loss_db.is_none()), "{:?}", metrics[0]);
    assert!(metrics.iter().all(|m| m.detection_loss_db.is_some_and(f64::is_finite)), "{:?}", metrics[0]);
}

/// Every entry under `dir` (relative), with a file's bytes (`None` for a
/// directory): what a run left there.
fn snapshot(dir: &Path) -> std::collections::BTreeMap<std::path::PathBuf, Option<Vec<u8>>> {
    let mut out = std::collections::BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            let relative = path.strip_prefix(dir).unwrap().to_path_buf();
            if path.is_dir() {
                out.insert(relative, None);
                stack.push(path);
            } else {
                out.insert(relative, Some(std::fs::read(&path).unwrap()));
            }
        }
    }
    out
}

/// Issue 26: a run's tables appear together. A table that cannot be
/// written half-way (here: a file where its directory goes, planted
/// before the run) leaves none of the run's tables, partial files or
/// directories, so the rerun needs no --force; with --force the previous
/// tables stay byte for byte, whether the failure comes while writing or
/// while renaming the set into place.
#[test]
fn a_failed_run_leaves_none_of_its_tables_and_the_previous_ones_untouched() {
    let dir = tempfile::tempdir().unwrap();
    simulate(dir.path());
    let tables = dir.path().join("tables");
    let run = |extra: &[&str]| {
        let mut args = vec!["process", "mpc", "rec.mcap", "-o", "tables", "--quiet"];
        args.extend_from_slice(extra);
        let out = mmtrack(dir.path(), &args);
        (out.status.success(), text(&out).1)
    };

    // ground_truth_rx is the last table written: the others are complete when it fails.
    std::fs::create_dir(&tables).unwrap();
    std::fs::write(tables.join("ground_truth_rx"), b"in the way").unwrap();
    let (ok, stderr) = run(&[]);
    assert!(!ok && stderr.contains("ground_truth_rx"), "{stderr}");
    let left: Vec<_> = snapshot(&tables).into_keys().collect();
    assert_eq!(left, [Path::new("ground_truth_rx")], "the failed run left some of its own");
    std::fs::remove_file(tables.join("ground_truth_rx")).unwrap();
    let (ok, stderr) = run(&[]);
    assert!(ok, "the rerun without --force: {stderr}");
    let first = snapshot(&tables);
    let (sequence, _) = only::<MpcSetStats>(&tables);

    // --force, failing while writing: the GM-PHD table (sixth of nine) cannot be staged.
    std::fs::write(tables.join("mpc_tracks_gmphd"), b"in the way").unwrap();
    let (ok, stderr) = run(&["--force", "--gmphd"]);
    assert!(!ok && stderr.contains("mpc_tracks_gmphd"), "{stderr}");
    std::fs::remove_file(tables.join("mpc_tracks_gmphd")).unwrap();
    assert_eq!(snapshot(&tables), first, "a failed --force run changed the previous tables");

    // --force, failing while publishing: a directory where the last table's file goes.
    let last = Path::new("ground_truth_rx").join(format!("sequence={sequence}")).join("part-0.parquet");
    std::fs::remove_file(tables.join(&last)).unwrap();
    std::fs::create_dir(tables.join(&last)).unwrap();
    let (ok, stderr) = run(&["--force"]);
    assert!(!ok && stderr.contains("ground_truth_rx"), "{stderr}");
    let mut expected = first.clone();
    expected.insert(last.clone(), None);
    assert_eq!(snapshot(&tables), expected, "a set that failed to publish changed the previous tables");
}

/// The sidecar example of docs/commands.md ("mmtrack ingest cir"), copied
/// from the page, ingests the real 60 GHz MIMO sample; without it the error
/// lists the file's variable.
#[test]
fn the_documented_sidecar_reads_the_real_60ghz_sample() {
    let Some(realdata) = realdata("the_documented_sidecar_reads_the_real_60ghz_sample") else { return };
    let page = std::fs::read_to_string(root().join("docs/commands.md")).unwrap();
    let example = page
        .split("```toml\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("a toml example in docs/commands.md");
    assert!(example.contains("variable = \"CIR_mat\""), "{example}");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("but-cir.toml"), example).unwrap();
    let mat = realdata.join("but-60ghz-mimo/CIR.mat");
    let mat = mat.to_str().unwrap();
    let out = mmtrack(dir.path(), &["ingest", "cir", "--format", "mat", mat, "-o", "but.mcap"]);
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("it holds `CIR_mat`") && err.contains("--sidecar"), "{err}");
    let out =
        mmtrack(dir.path(), &["ingest", "cir", "--format", "mat", "--sidecar", "but-cir.toml", mat, "-o", "but.mcap"]);
    let (stdout, err) = text(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        stdout.contains("16 CIR snapshots (1 time x 4 TX x 4 RX antennas) of 1001 taps, 0.0999 ns apart"),
        "{stdout}"
    );
}

/// Before: a run whose detection stopped at `[detection] max_mpcs` in every
/// snapshot (the real BUT 60 GHz sample at 200) said only "N detections".
/// With a cap of 2 every snapshot of the convoy (more than 2 paths above
/// the threshold) stops there; with the default none does.
#[test]
fn snapshots_that_stop_at_max_mpcs_are_counted_with_the_key_that_raises_it() {
    let dir = tempfile::tempdir().unwrap();
    simulate(dir.path());
    std::fs::write(dir.path().join("cap.toml"), "[detection]\nmax_mpcs = 2\n").unwrap();
    // A warning: on stderr, once, and also with -q (it was on stdout, once
    // per link, and -q dropped it).
    let out = mmtrack(dir.path(), &["process", "mpc", "rec.mcap", "-o", "capped", "--config", "cap.toml", "-q"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.is_empty(), "{stdout}");
    assert_eq!(stderr.matches("stopped at").count(), 1, "{stderr}");
    let line = stderr.lines().find(|l| l.starts_with("warning: ")).unwrap_or_else(|| panic!("{stderr}"));
    assert!(line.contains("[detection] max_mpcs = 2") && line.contains("raise max_mpcs"), "{line}");
    let counts: Vec<usize> = line.split_whitespace().take(4).filter_map(|w| w.parse().ok()).collect();
    assert_eq!(counts.len(), 2, "`<at cap> of <snapshots>`: {line}");
    assert!(counts[0] > 0 && counts[0] <= counts[1], "{line}");
    let out = mmtrack(dir.path(), &["process", "mpc", "rec.mcap", "-o", "default"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(!stdout.contains("stopped at") && !stderr.contains("stopped at"), "{stdout}{stderr}");
}
