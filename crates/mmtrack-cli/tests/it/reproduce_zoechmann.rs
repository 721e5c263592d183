//! `mmtrack reproduce zoechmann --quick`: the CI version of the geometric
//! Doppler-bearing tracking experiment (2000 runs per manoeuvre instead of
//! 100 000).

use mmtrack_io::table::read_table;
use mmtrack_io::table::{ZoechmannNlosErrorRow, ZoechmannNmseRow, ZoechmannPathLabelRow, ZoechmannSummaryRow};

use super::common::{mmtrack, text};

const README_BEFORE: &str = "# R\n\n<!-- reproduce-zoechmann:begin -->\nstale\n<!-- reproduce-zoechmann:end -->\n";

fn final_nmse(rows: &[ZoechmannNmseRow], manoeuvre: &str, estimator: &str) -> f64 {
    rows.iter().filter(|r| r.manoeuvre == manoeuvre && r.estimator == estimator).max_by_key(|r| r.epoch).unwrap().nmse
}

#[test]
fn quick_zoechmann_writes_tables_figures_verdicts_and_its_readme_block() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("README.md"), README_BEFORE).unwrap();
    let out = mmtrack(dir.path(), &["reproduce", "zoechmann", "--quick", "-o", "out", "--readme", "README.md"]);
    let (stdout, stderr) = text(&out);
    let report = std::fs::read_to_string(dir.path().join("out/reproduce.md"))
        .unwrap_or_else(|e| panic!("no report ({e}):\n{stdout}\n{stderr}"));
    println!("{report}");
    let missed = report.matches("| **missed** |").count();
    assert_eq!(out.status.success(), missed == 0, "exit status must follow the verdicts:\n{stderr}");
    // 2 orderings, 1 hand-over, 2 savings (the time target only on the full
    // run); the variants and diagnostics report without a verdict of met or missed.
    assert_eq!(report.matches("| met |").count() + missed, 5, "{report}");

    let nmse: Vec<ZoechmannNmseRow> =
        read_table(&dir.path().join("out/tables/zoechmann_nmse/sequence=zoechmann/part-0.parquet")).unwrap();
    assert_eq!(nmse.len(), (101 + 201) * 11, "epochs 0..=100 and 0..=200, 11 estimators");
    assert!(nmse.iter().all(|r| r.runs == 2000), "every estimator counted in every run and epoch");
    // What holds at 2000 runs with wide margins (full-run numbers in the
    // docs/results/zoechmann.md): on half overtaking the proposed tracker ends within 2 dB of
    // the error-free genie (0.4 dB measured) and more than 10 dB below the
    // Ho-Chan baseline (14 dB), and the nullspace genie ends below the
    // error-free genie.
    let half = |e: &str| 10.0 * final_nmse(&nmse, "half-overtaking", e).log10();
    assert!((half("proposed") - half("error-free-genie")).abs() < 2.0, "{report}");
    assert!(half("proposed") < half("ho-chan") - 10.0, "{report}");
    assert!(half("nullspace-genie") < half("error-free-genie"), "{report}");
    // On full overtaking the tracker on full-scan azimuths converges (below
    // -30 dB at the end, -37 dB measured); the paper's literal beam schedule
    // does not (docs/results/zoechmann.md).
    let full = |e: &str| 10.0 * final_nmse(&nmse, "full-overtaking", e).log10();
    assert!(full("proposed-full-scan") < -30.0, "{report}");
    assert!(full("nullspace-genie") < full("error-free-genie"), "{report}");
    // The diagnostics of that miss (full-run numbers in docs/results/zoechmann.md): with the
    // Doppler equation in m/s the genie gains several dB (7.3 measured) and
    // the tracker on full-scan azimuths ends below the baseline (1.7 dB);
    // the baseline on true azimuths gains about 1 dB on full overtaking, 8 on
    // half overtaking.
    assert!(full("error-free-genie-doppler-mps") < full("error-free-genie") - 4.0, "{report}");
    assert!(full("proposed-full-scan-doppler-mps") < full("ho-chan-doppler-mps"), "{report}");
    assert!(half("ho-chan-true-azimuth") < half("ho-chan") - 5.0, "{report}");

    let summary: Vec<ZoechmannSummaryRow> =
        read_table(&dir.path().join("out/tables/zoechmann_summary/sequence=zoechmann/part-0.parquet")).unwrap();
    assert_eq!(summary.len(), 2);
    for row in &summary {
        // Counted beams: 10 full scans of 128 then 3 per epoch, exactly.
        let per_run = 10 * 128 + (row.epochs - 10) * 3;
        assert_eq!(row.beams_measured, per_run * row.runs, "{row:?}");
        assert!((row.windowed_saving - 128.0 / 3.0).abs() < 1e-9, "{row:?}");
        assert_eq!(row.estimator_failures, 0, "{row:?}");
    }
    let full_row = summary.iter().find(|r| r.manoeuvre == "full-overtaking").unwrap();
    // Full scans give the third distinct beam after about 0.5 s (0.56 s
    // median measured); the paper's "approximately 0.5 s".
    let median = full_row.handover_median_full_scan_s.unwrap();
    assert!((0.3..=0.8).contains(&median), "{full_row:?}");
    // The literal schedule's first window points away from the car in
    // almost every full-overtaking run (the range is unobserved while every
    // azimuth is the same beam), in none of the half-overtaking runs.
    assert!(full_row.first_window_off_share > 0.9, "{full_row:?}");
    let half_row = summary.iter().find(|r| r.manoeuvre == "half-overtaking").unwrap();
    assert!(half_row.first_window_off_share == 0.0, "{half_row:?}");
    for name in ["half-overtaking.svg", "full-overtaking.svg", "nlos.svg"] {
        let svg = std::fs::read_to_string(dir.path().join("out").join(name)).unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(doc.root_element().tag_name().name(), "svg");
    }
    // Non-line-of-sight paths: every path converges to well under a metre by
    // the end (0.4 m measured at 300 runs; 2 m leaves room for the few runs
    // of the quick version).
    let nlos: Vec<ZoechmannNlosErrorRow> =
        read_table(&dir.path().join("out/tables/zoechmann_nlos_error/sequence=zoechmann/part-0.parquet")).unwrap();
    assert_eq!(nlos.len(), 3 * 201);
    for path in ["los", "left-wall", "right-wall"] {
        let last = nlos.iter().filter(|r| r.path == path).max_by_key(|r| r.epoch).unwrap();
        assert!(last.runs == 300 && last.position_rmse_m < 2.0 && last.velocity_rmse_mps < 0.5, "{last:?}");
    }
    let labels: Vec<ZoechmannPathLabelRow> =
        read_table(&dir.path().join("out/tables/zoechmann_path_labels/sequence=zoechmann/part-0.parquet")).unwrap();
    assert_eq!(labels.len(), 3 * 201, "one run, three paths, every epoch");
    assert!(labels.iter().all(|r| (r.path == "los") == r.reflection_x_m.is_none()));
    let readme = std::fs::read_to_string(dir.path().join("README.md")).unwrap();
    assert!(!readme.contains("stale") && readme.contains("| claim | paper | measured | verdict |"));
    assert!(readme.contains("| left-wall |"));
}

/// The same numbers on 1 and 2 threads (runs are summed in fixed chunks).
#[test]
fn zoechmann_tables_do_not_depend_on_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    for threads in ["1", "2"] {
        let out =
            mmtrack(dir.path(), &["reproduce", "zoechmann", "--runs", "600", "--threads", threads, "-o", threads]);
        assert!(out.status.code().is_some_and(|c| c <= 1), "{}", text(&out).1);
    }
    for table in ["zoechmann_nmse", "zoechmann_summary", "zoechmann_nlos_error", "zoechmann_path_labels"] {
        let part = format!("tables/{table}/sequence=zoechmann/part-0.parquet");
        let one = std::fs::read(dir.path().join("1").join(&part)).unwrap();
        let two = std::fs::read(dir.path().join("2").join(&part)).unwrap();
        assert!(one == two, "{table} differs between 1 and 2 threads");
    }
}
