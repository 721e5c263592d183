//! The binary's contract: help, exit codes, one-line errors, no partial output.

use super::common::{files, mmtrack, root, text};

#[test]
fn help_explains_every_subcommand() {
    let out = mmtrack(&root(), &["--help"]);
    assert!(out.status.success());
    let (stdout, _) = text(&out);
    for sub in
        ["ingest", "simulate", "process", "analyze", "reproduce", "check", "inspect", "demo", "bench", "Exit codes"]
    {
        assert!(stdout.contains(sub), "--help lacks {sub}:\n{stdout}");
    }
}

/// `export` offers four formats (issue 28: its summary named two).
#[test]
fn export_help_names_every_format() {
    let (stdout, _) = text(&mmtrack(&root(), &["--help"]));
    // The export entry, wrapped over lines, up to the next subcommand.
    let entry = stdout.split("\n  export ").nth(1).and_then(|rest| rest.split("\n  reproduce ").next()).unwrap();
    for format in ["TUM", "KITTI", "Boreas", "MCAP"] {
        assert!(entry.contains(format), "`mmtrack --help` export entry lacks {format}: {entry}");
    }
    let out = mmtrack(&root(), &["export", "--help"]);
    assert!(out.status.success());
    let (stdout, _) = text(&out);
    for format in ["tum", "kitti", "boreas", "mcap"] {
        assert!(stdout.contains(&format!("- {format}:")), "`mmtrack export --help` lacks {format}:\n{stdout}");
    }
}

#[test]
fn demo_writes_a_recording_and_a_table_and_says_where() {
    let dir = tempfile::tempdir().unwrap();
    let out = mmtrack(dir.path(), &["demo", "--out", "demo-out"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("demo-out/recording.mcap") && stdout.contains("demo-out/tables"), "{stdout}");
    assert!(stdout.contains("/radar/image") && stdout.contains("foxglove.CompressedImage"));
    assert!(stdout.contains("demo-out/analysis/report.md"), "{stdout}");
    // Running it again replaces its own outputs.
    let again = mmtrack(dir.path(), &["demo", "--out", "demo-out", "--quiet"]);
    assert!(again.status.success(), "{}", text(&again).1);
    assert!(text(&again).0.is_empty(), "--quiet prints nothing");

    // Issue 28: inspect names each table's time base and frame, and a
    // recording's start as the date a viewer shows.
    let tables = text(&mmtrack(dir.path(), &["inspect", "demo-out/tables"])).0;
    assert!(tables.contains("ground_truth / sequence=oxford-demo: 160 rows"), "{tables}");
    // The demo's radar drive is simulated: its Oxford folder says so and the
    // ingest records the simulator's clock (it said unix_epoch before).
    assert!(tables.contains("time base: scenario_start, frame: ground_truth"), "{tables}");
    assert!(!tables.contains("unix_epoch"), "{tables}");
    assert!(tables.contains("time base: scenario_start, frame: recording_world"), "{tables}");
    let recording = text(&mmtrack(dir.path(), &["inspect", "demo-out/recording.mcap"])).0;
    assert!(recording.contains("; from 2023-11-14 22:13:20 UTC)"), "{recording}");
    let inspect = mmtrack(dir.path(), &["inspect", "--json", "demo-out/recording.mcap"]);
    let summary: serde_json::Value = serde_json::from_slice(&inspect.stdout).unwrap();
    let scans = summary["channels"].as_array().unwrap().iter().find(|c| c["topic"] == "/radar/image").unwrap();
    // The demo drive (issue 28): 160 scans over 320 m, long enough for KITTI
    // segments of 100 to 300 m, so the plots and drift numbers say something.
    assert_eq!(scans["messages"], 160);
    let metrics: Vec<mmtrack_io::table::TrajectoryMetrics> = mmtrack_io::table::read_table(
        &dir.path().join("demo-out/analysis/tables/trajectory_metrics/sequence=oxford-demo/part-0.parquet"),
    )
    .unwrap();
    let m = &metrics[0];
    assert!(m.path_length_m > 300.0 && m.associated_poses >= 150, "{m:?}");
    assert!(m.kitti_segments > 0 && m.kitti_rotational_deg_per_100m.is_some(), "{m:?}");
}

/// The demo from a clean directory: every pipeline's tables, the analysis
/// report and every plot it links exist and are non-empty, and each table
/// reads back in pyarrow and DuckDB with its documented schema
/// (`tests/python/demo_tables.py` against `schemas/tables/`).
#[test]
fn demo_runs_every_pipeline_and_its_tables_read_back_as_documented() {
    let dir = tempfile::tempdir().unwrap();
    let out = mmtrack(dir.path(), &["demo", "--out", "d"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    for command in [
        "$ mmtrack process odometry",
        "$ mmtrack process mpc",
        "$ mmtrack process beam",
        "$ mmtrack simulate slam",
        "$ mmtrack process slam",
        "$ mmtrack analyze",
    ] {
        assert!(stdout.contains(command), "{command}: {stdout}");
    }
    let d = dir.path().join("d");
    for table in [
        "odometry",
        "ground_truth",
        "mpc_detections",
        "mpc_tracks",
        "mpc_tracks_gmphd",
        "spebt_summary",
        "slam_ue",
        "slam_map",
        "slam_associations",
        "slam_true_sources",
    ] {
        let tables = d.join("tables").join(table);
        let part = std::fs::read_dir(&tables).unwrap().next().unwrap().unwrap().path().join("part-0.parquet");
        assert!(std::fs::metadata(&part).unwrap().len() > 0, "{}", part.display());
    }
    let report = std::fs::read_to_string(d.join("analysis/report.md")).unwrap();
    for section in ["KITTI", "## Multipath components", "## SPEBT beam tracking", "## 5G mmWave SLAM"] {
        assert!(report.contains(section), "{section}: {report}");
    }
    let plots: Vec<&str> = report.split("](plots/").skip(1).map(|rest| rest.split(')').next().unwrap()).collect();
    assert!(plots.len() >= 8, "{plots:?}");
    for plot in plots {
        let svg = std::fs::read_to_string(d.join("analysis/plots").join(plot)).unwrap();
        assert!(svg.starts_with("<svg") && svg.len() > 1000, "{plot}");
    }
    let Some(python) = super::common::venv_python() else { panic!("the Python venv (pyarrow, duckdb) is required") };
    let script = root().join("tests/python/demo_tables.py");
    let checked = std::process::Command::new(python).arg(script).arg(&d).arg(root().join("schemas/tables")).output();
    let checked = checked.unwrap();
    let (stdout, stderr) = text(&checked);
    assert!(checked.status.success(), "{stdout}{stderr}");
    assert!(stdout.contains("tables/spebt_pooled: 1 rows") && stdout.contains("checked 32 tables"), "{stdout}");
    // The two odometry runs side by side.
    let compare = std::fs::read_to_string(d.join("compare/report.md")).unwrap();
    assert!(compare.contains("| cfear | fast-cfear | fast-cfear - cfear | fast-cfear vs cfear |"), "{compare}");
    // One sequence: no pooled rows repeating it.
    assert!(compare.contains("| oxford-demo | ATE (m) |") && !compare.contains("| all |"), "{compare}");
    // Angles in degrees, as each run's report shows them.
    assert!(compare.contains("| oxford-demo | yaw RMSE (deg) |"), "{compare}");
    assert!(d.join("compare/run=fast-cfear/report.html").is_file());
}

#[test]
fn corrupt_recording_is_one_line_naming_the_file_exit_1() {
    let dir = tempfile::tempdir().unwrap();
    assert!(mmtrack(dir.path(), &["demo", "--out", "d", "--quiet"]).status.success());
    let bytes = std::fs::read(dir.path().join("d/recording.mcap")).unwrap();
    std::fs::write(dir.path().join("cut.mcap"), &bytes[..bytes.len() / 2]).unwrap();
    let out = mmtrack(dir.path(), &["inspect", "cut.mcap"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(stdout.is_empty());
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("error: ") && stderr.contains("cut.mcap") && stderr.contains("truncated"), "{stderr}");
}

#[test]
fn table_with_a_missing_column_is_one_line_exit_1() {
    // A Parquet file written by an independent writer path (our own writer,
    // then a column dropped via a raw Arrow write) is covered in mmtrack-io's
    // tests; here the CLI surfaces a non-Parquet file in a table directory.
    let dir = tempfile::tempdir().unwrap();
    let part = dir.path().join("poses/sequence=a");
    std::fs::create_dir_all(&part).unwrap();
    std::fs::write(part.join("part-0.parquet"), b"PAR1 not really").unwrap();
    let out = mmtrack(dir.path(), &["inspect", "."]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("part-0.parquet") && stderr.contains("not a readable Parquet table"), "{stderr}");
}

#[test]
fn known_table_with_a_missing_column_is_one_line_exit_1() {
    let dir = tempfile::tempdir().unwrap();
    assert!(mmtrack(dir.path(), &["demo", "--out", "d", "--quiet"]).status.success());
    // Rewrite the demo's ground-truth table without its y_m column, with
    // pyarrow-free tooling: read it with parquet's Arrow reader and write a
    // projection.
    let file = dir.path().join("d/tables/ground_truth/sequence=oxford-demo/part-0.parquet");
    let batch = {
        let reader =
            parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(std::fs::File::open(&file).unwrap())
                .unwrap()
                .build()
                .unwrap();
        reader.into_iter().next().unwrap().unwrap()
    };
    let projected = batch.project(&[0, 1, 3]).unwrap();
    let mut writer =
        parquet::arrow::ArrowWriter::try_new(std::fs::File::create(&file).unwrap(), projected.schema(), None).unwrap();
    writer.write(&projected).unwrap();
    writer.close().unwrap();

    let out = mmtrack(dir.path(), &["inspect", "d/tables"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("part-0.parquet") && stderr.contains("no column 'y_m'"), "{stderr}");
}

#[test]
fn existing_output_without_force_is_refused_and_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let fixture = root().join("data/demo/oxford-demo");
    let fixture = fixture.to_str().unwrap();
    let args = ["ingest", "oxford", fixture, "-o", "rec.mcap", "--bins", "auto", "--quiet"];
    assert!(mmtrack(dir.path(), &args).status.success());
    let before = std::fs::read(dir.path().join("rec.mcap")).unwrap();
    let out = mmtrack(dir.path(), &args);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("rec.mcap") && stderr.contains("--force"), "{stderr}");
    assert_eq!(std::fs::read(dir.path().join("rec.mcap")).unwrap(), before);
    assert_eq!(files(dir.path()), vec![std::path::PathBuf::from("rec.mcap")], "no temporary files left");

    let mut forced = args.to_vec();
    forced.push("--force");
    assert!(mmtrack(dir.path(), &forced).status.success());
}

#[test]
fn failed_ingest_leaves_no_partial_output() {
    let dir = tempfile::tempdir().unwrap();
    // A copy of the fixture with one scan truncated halfway.
    let input = dir.path().join("seq");
    let fixture = root().join("data/demo/oxford-demo");
    for relative in files(&fixture) {
        let target = input.join(&relative);
        std::fs::create_dir_all(target.parent().unwrap()).unwrap();
        std::fs::copy(fixture.join(&relative), &target).unwrap();
    }
    let last = files(&input.join("radar")).pop().unwrap();
    let png = input.join("radar").join(last);
    let bytes = std::fs::read(&png).unwrap();
    std::fs::write(&png, &bytes[..bytes.len() / 2]).unwrap();

    let out = mmtrack(dir.path(), &["ingest", "oxford", "seq", "-o", "out/rec.mcap", "--bins", "auto"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains(png.file_name().unwrap().to_str().unwrap()) && stderr.contains("PNG"), "{stderr}");
    let leftovers = if dir.path().join("out").exists() { files(&dir.path().join("out")) } else { vec![] };
    assert!(leftovers.is_empty(), "partial output left: {leftovers:?}");
}

/// Default builds (CI's) know HDF5 and MATLAB v7.3 inputs and say how to
/// rebuild for them, in one line naming the file; no output is written.
#[cfg(not(feature = "hdf5"))]
#[test]
fn hdf5_inputs_without_the_feature_say_how_to_rebuild() {
    let dir = tempfile::tempdir().unwrap();
    let mut v73 = format!("{:<116}", "MATLAB 7.3 MAT-file, Platform: GLNXA64").into_bytes();
    v73.extend_from_slice(&[0, 0, 0, 0, 0, 0, 0, 0, 0, 2, b'I', b'M']);
    v73.resize(512, 0);
    v73.extend_from_slice(b"\x89HDF\r\n\x1a\n");
    std::fs::write(dir.path().join("h.mat"), &v73).unwrap();
    std::fs::write(dir.path().join("h.h5"), &v73[512..]).unwrap();
    std::fs::write(dir.path().join("s.toml"), "variable = \"h\"\ncarrier_hz = 1e9\n").unwrap();
    for (input, format, what) in [("h.mat", "mat", "a MATLAB v7.3 (HDF5) .mat file"), ("h.h5", "hdf5", "an HDF5 file")]
    {
        let sidecar: &[&str] = if format == "mat" { &["--sidecar", "s.toml"] } else { &[] };
        let args = [&["ingest", "cir", input, "--format", format, "-o", "out.mcap"], sidecar].concat();
        let out = mmtrack(dir.path(), &args);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(stderr.starts_with(&format!("error: {input}: {what}")), "{stderr}");
        assert!(stderr.contains("--features hdf5") && stderr.contains("libhdf5"), "{stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(!dir.path().join("out.mcap").exists());
    }
}

#[test]
fn schema_documents_are_current() {
    let out = mmtrack(&root(), &["schemas", "--check", "schemas"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let out = mmtrack(&root(), &["schemas"]);
    assert!(out.status.success(), "{}", text(&out).1);
}

/// Before: without `schemas/` here, `mmtrack schemas` listed every
/// document as "stale".
#[test]
fn schemas_without_a_folder_says_what_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    let out = mmtrack(dir.path(), &["schemas"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("no such folder") && stderr.contains("--write DIR") && stderr.contains("--check DIR"));
    assert!(!stderr.contains("stale"), "{stderr}");
    let out = mmtrack(dir.path(), &["schemas", "--check", "docs"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("docs: no such folder to check"), "{stderr}");
}

#[test]
fn poses_are_added_to_an_existing_recording_in_place() {
    let dir = tempfile::tempdir().unwrap();
    assert!(mmtrack(dir.path(), &["demo", "--out", "d", "--quiet"]).status.success());
    let tum = "# t x y z qx qy qz qw\n1700000000.0 0 0 0 0 0 0 1\n1700000000.5 1.0 0.1 0 0 0 0.0499792 0.9987503\n";
    std::fs::write(dir.path().join("est.txt"), tum).unwrap();
    let rec = "d/recording.mcap";
    let out = mmtrack(
        dir.path(),
        &["ingest", "poses", "est.txt", "--format", "tum", "--estimate", "--add-to", rec, "-o", rec],
    );
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("2 poses on /estimate/pose"), "{stdout}");

    let inspect = mmtrack(dir.path(), &["inspect", "--json", rec]);
    let summary: serde_json::Value = serde_json::from_slice(&inspect.stdout).unwrap();
    let count = |topic: &str| {
        summary["channels"].as_array().unwrap().iter().find(|c| c["topic"] == topic).map(|c| c["messages"].clone())
    };
    assert_eq!(count("/estimate/pose"), Some(serde_json::json!(2)));
    assert_eq!(count("/radar/image"), Some(serde_json::json!(160)), "the scans were copied");
    assert_eq!(count("/ground_truth/pose"), Some(serde_json::json!(160)));
    assert_eq!(summary["metadata"]["mmtrack.recording"]["sequence_id"], "oxford-demo");

    // A second ground truth is refused and the recording is left as it was.
    let before = std::fs::read(dir.path().join(rec)).unwrap();
    let out = mmtrack(dir.path(), &["ingest", "poses", "est.txt", "--format", "tum", "--add-to", rec, "-o", rec]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("already has /ground_truth/pose"), "{stderr}");
    assert_eq!(std::fs::read(dir.path().join(rec)).unwrap(), before);
    assert_eq!(files(&dir.path().join("d")).iter().filter(|p| p.to_string_lossy().contains("partial")).count(), 0);
}

/// `mmtrack inspect ... | head -1`: the reader closes the pipe early; the
/// command ends quietly instead of panicking on the broken pipe.
#[test]
fn a_closed_stdout_pipe_ends_the_command_quietly() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = super::common::root().join("data/sounder/artificial.toml");
    let out = super::common::mmtrack(
        dir.path(),
        &["simulate", "sounder", "--scenario", scenario.to_str().unwrap(), "-o", "a.mcap", "-q"],
    );
    assert!(out.status.success());
    for _ in 0..3 {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_mmtrack"))
            .args(["inspect", "a.mcap"])
            .current_dir(dir.path())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success() && !stderr.contains("panicked"), "{:?}: {stderr}", out.status);
    }
}

/// `--print-config` needs neither a recording nor `-o`.
#[test]
fn print_config_needs_no_recording_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    for (pipeline, key) in [("odometry", "k_strongest"), ("mpc", "[detection]")] {
        let out = mmtrack(dir.path(), &["process", pipeline, "--print-config"]);
        let (stdout, stderr) = text(&out);
        assert!(out.status.success(), "process {pipeline} --print-config: {stderr}");
        assert!(stdout.parse::<toml::Table>().is_ok(), "not TOML:\n{stdout}");
        assert!(stdout.contains(key), "process {pipeline} --print-config lacks {key}:\n{stdout}");
        // Without it, both stay required.
        let out = mmtrack(dir.path(), &["process", pipeline]);
        assert_eq!(out.status.code(), Some(2), "{}", text(&out).1);
    }
    assert!(files(dir.path()).is_empty(), "--print-config wrote files");
}

/// Defaults that point beside the repository say so in `--help` and name
/// the missing default and the option to pass when run elsewhere.
#[test]
fn defaults_beside_the_repository_say_so_and_fail_clearly_elsewhere() {
    // A directory whose parent certainly holds no `shared/` (a temporary
    // directory's parent may: a CI clone in /tmp has ../shared beside it).
    let top = tempfile::tempdir().unwrap();
    let dir = tempfile::tempdir_in(top.path()).unwrap();
    let cases = [
        (
            ["reproduce", "odometry", "--quick"],
            "../shared/realdata/oxford-gt-full-seq/radar_odometry.csv",
            "--trajectory",
        ),
        (["bench", "odometry", "--check"], "../shared/realdata/oxford-radar-tiny", "--from"),
    ];
    for (command, default, option) in cases {
        let help = mmtrack(dir.path(), &[command[0], command[1], "--help"]);
        let (stdout, _) = text(&help);
        let flat = stdout.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(flat.contains(default) && flat.contains("beside the repository"), "{command:?} --help:\n{stdout}");
        let out = mmtrack(dir.path(), &command);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(1), "{command:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains(&format!("default {default} not found")) && stderr.contains(&format!("pass {option} PATH")),
            "{command:?}: {stderr}"
        );
    }
}

/// `process mpc` counts tracks as tracks: one record of `mpc_tracks` is a
/// whole track (a row per point), so "65 rows" misread the table.
#[test]
fn process_mpc_summary_names_what_it_counts() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = root().join("data/sounder/artificial.toml");
    let sim = mmtrack(dir.path(), &["simulate", "sounder", "--scenario", scenario.to_str().unwrap(), "-o", "a.mcap"]);
    assert!(sim.status.success(), "{}", text(&sim).1);
    let out = mmtrack(dir.path(), &["process", "mpc", "a.mcap", "-o", "tables", "--gmphd"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let summary = stdout.lines().next().unwrap();
    let tracks = summary.split(", ").find_map(|p| p.strip_suffix(" short-term tracks")).unwrap();
    let line = |table: &str| stdout.lines().find(|l| l.contains(&format!("/{table}/"))).unwrap().to_string();
    assert!(line("mpc_tracks").ends_with(&format!("({tracks} tracks)")), "{stdout}");
    assert!(line("mpc_tracks_gmphd").ends_with(" tracks)"), "{stdout}");
    assert!(line("mpc_detections").ends_with(" detections)") && line("mpc_sets").ends_with(" sets)"), "{stdout}");
}

/// `inspect` shortens long metadata values (a sounder recording's pulse
/// spectrum runs to kilobytes) and says how to get them whole.
#[test]
fn inspect_shortens_long_metadata_values() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = root().join("data/sounder/artificial.toml");
    let sim = mmtrack(dir.path(), &["simulate", "sounder", "--scenario", scenario.to_str().unwrap(), "-o", "a.mcap"]);
    assert!(sim.status.success(), "{}", text(&sim).1);
    let out = mmtrack(dir.path(), &["inspect", "a.mcap"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let line = stdout.lines().find(|l| l.trim_start().starts_with("sounder.pulse_spectrum = ")).unwrap();
    let json = mmtrack(dir.path(), &["inspect", "--json", "a.mcap"]);
    let summary: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let whole = summary["metadata"]["mmtrack.recording"]["sounder.pulse_spectrum"].as_str().unwrap();
    assert!(whole.len() > 1000, "the JSON keeps the value whole ({} bytes)", whole.len());
    assert!(line.chars().count() < 200, "{line}");
    assert!(line.contains(&whole[..40]) && line.contains(&format!("({} bytes; `--json`", whole.len())), "{line}");
    assert!(stdout.lines().all(|l| l.chars().count() < 200), "{stdout}");
}

/// Before: `ingest cir`, `ingest nmea` and `ingest poses` listed the radar
/// Cartesian view's options, which only the radar kinds use.
#[test]
fn radar_view_options_are_listed_only_where_they_apply() {
    for kind in ["cir", "nmea", "poses"] {
        let out = mmtrack(&root(), &["ingest", kind, "--help"]);
        let (stdout, _) = text(&out);
        assert!(out.status.success() && stdout.contains("--force"), "{stdout}");
        assert!(!stdout.contains("radar-cartesian"), "ingest {kind}: {stdout}");
    }
    let (stdout, _) = text(&mmtrack(&root(), &["ingest", "oxford", "--help"]));
    assert!(stdout.contains("--radar-cartesian-m-per-px"), "{stdout}");
}
