//! `mmtrack reproduce kim --quick`: the CI version of the 5G mmWave SLAM
//! experiment (2 runs per row with 500 particles instead of 20 with 2000).

use mmtrack_io::table::read_table;
use mmtrack_io::table::{SlamPerEpochRow, SlamSummaryRow};

use super::common::{mmtrack, text};

const README_BEFORE: &str = "# R\n\n<!-- reproduce-kim:begin -->\nstale\n<!-- reproduce-kim:end -->\n";

#[test]
fn quick_kim_meets_its_tolerances_and_writes_tables_figures_and_its_readme_block() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("README.md"), README_BEFORE).unwrap();
    let out = mmtrack(dir.path(), &["reproduce", "kim", "--quick", "-o", "out", "--readme", "README.md"]);
    let (stdout, stderr) = text(&out);
    let report = std::fs::read_to_string(dir.path().join("out/reproduce.md"))
        .unwrap_or_else(|e| panic!("no report ({e}):\n{stdout}\n{stderr}"));
    println!("{report}");
    // The claims and their rules are in the report, and the exit status is
    // the targets' verdict (data/reproduce/kim.toml: --quick allows twice
    // the paper's errors, 500 particles, 2 runs).
    for claim in [
        "| mean UE position error (paper) |",
        "| mean VA localisation error, every confirmed VA (paper) |",
        "| all VAs confirmed by (paper), worst run |",
        "| no false source at any epoch (paper), worst epoch of any run |",
        "| mean UE position error, LOS blocked in epochs 41-60 (blocked), below LOS-only (blocked-los-only) |",
        "| UE position NEES (paper), mean over epochs and runs |",
    ] {
        assert!(report.contains(claim), "{claim}\n{report}");
    }
    let missed = report.matches("| **missed** |").count();
    assert_eq!(out.status.success(), missed == 0, "{missed} missed\n{stderr}");
    assert!(out.status.code().is_some_and(|c| c <= 1), "{stderr}");

    let summary: Vec<SlamSummaryRow> =
        read_table(&dir.path().join("out/tables/slam_summary/sequence=kim/part-0.parquet")).unwrap();
    let names: Vec<&str> = summary.iter().map(|r| r.row.as_str()).collect();
    assert_eq!(
        names,
        ["paper", "paper+floor", "los-only", "blocked", "blocked+floor", "blocked-los-only", "pd-0.9", "clutter-1"]
    );
    for row in &summary {
        assert_eq!((row.runs, row.epochs, row.particles), (2, 100, 500), "{row:?}");
        if row.row.contains("los-only") {
            // No map at all.
            assert_eq!((row.va_error_m, row.sp_error_m), (None, None), "{row:?}");
        } else {
            // Every row with a map finds every VA.
            assert!(row.all_va_epoch_max <= 100, "{row:?}");
        }
    }
    let per_epoch: Vec<SlamPerEpochRow> =
        read_table(&dir.path().join("out/tables/slam_per_epoch/sequence=kim/part-0.parquet")).unwrap();
    assert_eq!(per_epoch.len(), 8 * 100);
    for name in ["map.svg", "ue_errors.svg", "heading_error.svg", "confirmed_sources.svg", "source_errors.svg"] {
        let svg = std::fs::read_to_string(dir.path().join("out").join(name)).unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(doc.root_element().tag_name().name(), "svg");
    }
    let metrics = std::fs::read_to_string(dir.path().join("out/metrics.json")).unwrap();
    assert!(metrics.contains("\"paper UE position error\""), "{metrics}");
    let readme = std::fs::read_to_string(dir.path().join("README.md")).unwrap();
    assert!(!readme.contains("stale") && readme.contains("| claim (paper's numbers: at most"), "{readme}");
}

/// The same tables on 1 and 2 threads.
#[test]
fn kim_tables_do_not_depend_on_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    for threads in ["1", "2"] {
        let out = mmtrack(
            dir.path(),
            &["reproduce", "kim", "--runs", "1", "--particles", "300", "--threads", threads, "-o", threads],
        );
        assert!(out.status.code().is_some_and(|c| c <= 1), "{}", text(&out).1);
    }
    for table in ["slam_summary", "slam_per_epoch"] {
        let part = format!("tables/{table}/sequence=kim/part-0.parquet");
        let one = std::fs::read(dir.path().join("1").join(&part)).unwrap();
        let two = std::fs::read(dir.path().join("2").join(&part)).unwrap();
        assert!(one == two, "{table} differs between 1 and 2 threads");
    }
}
