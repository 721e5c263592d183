//! `mmtrack reproduce shaham --quick`: the CI version of the valid-tracking
//! experiment (200 runs per point instead of 3000).

use mmtrack_io::table::read_table;
use mmtrack_io::table::{BeamRmsRow, BeamValidTrackingRow};

use super::common::{mmtrack, text};

const README_BEFORE: &str = "# R\n\n<!-- reproduce-shaham:begin -->\nstale\n<!-- reproduce-shaham:end -->\n";

#[test]
fn quick_shaham_writes_tables_figures_verdicts_and_its_readme_block() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("README.md"), README_BEFORE).unwrap();
    let out = mmtrack(dir.path(), &["reproduce", "shaham", "--quick", "-o", "out", "--readme", "README.md"]);
    let (stdout, stderr) = text(&out);
    let report = std::fs::read_to_string(dir.path().join("out/reproduce.md"))
        .unwrap_or_else(|e| panic!("no report ({e}):\n{stdout}\n{stderr}"));
    println!("{report}");
    let missed = report.matches("| **missed** |").count();
    assert_eq!(out.status.success(), missed == 0, "exit status must follow the verdicts:\n{stderr}");
    // 7 published numbers, 2 orderings, 1 gain; and the open-loop row (ours, not counted).
    assert_eq!(report.matches("| met |").count() + missed, 10, "{report}");
    assert!(report.contains("| pv-ekf longer than its open-loop predictor at every point (baseline of ours) |"));

    let valid: Vec<BeamValidTrackingRow> =
        read_table(&dir.path().join("out/tables/beam_valid_tracking/sequence=shaham/part-0.parquet")).unwrap();
    assert_eq!(valid.len(), 6 * 4, "6 scenario points x 4 trackers");
    let blocks = |tracker: &str, snr: f64, speed: f64| {
        let row = valid.iter().find(|r| r.tracker == tracker && r.snr_db == snr && r.speed_kmh == speed).unwrap();
        row.valid_blocks.unwrap_or(u64::MAX)
    };
    // What the pilots add, at any run count (the full run's margins are
    // wide, see docs/results/shaham.md): the position-velocity EKF tracks
    // longer than its own predictor run open loop (168 / 135 blocks at 0 dB,
    // 60 km/h, 3000 runs) and than the angle-state EKF at every point, and
    // longer at each higher SNR (the paper's Fig. 2 ordering). An EKF whose
    // updates do nothing fails all three.
    for row in valid.iter().filter(|r| r.tracker == "pv-ekf") {
        let (snr, speed) = (row.snr_db, row.speed_kmh);
        let (pv, open, angle) =
            (blocks("pv-ekf", snr, speed), blocks("open-loop", snr, speed), blocks("angle-ekf", snr, speed));
        assert!(pv > open && pv > angle, "{row:?}: open-loop {open}, angle-ekf {angle}");
        assert!((row.threshold_rad.to_degrees() - 4.51).abs() < 0.01, "{row:?}");
    }
    assert!(blocks("pv-ekf", 0.0, 60.0) < blocks("pv-ekf", 5.0, 60.0));
    assert!(blocks("pv-ekf", 5.0, 60.0) < blocks("pv-ekf", 10.0, 60.0));
    // The gain claim is two-sided: more than 15 % above the paper's +49 % is a miss.
    let gain_row = report.lines().find(|l| l.starts_with("| longer valid tracking than the angle-state EKF")).unwrap();
    let gain = 100.0 * (blocks("pv-ekf", 0.0, 60.0) as f64 / blocks("angle-ekf", 0.0, 60.0) as f64 - 1.0);
    assert_eq!(gain_row.ends_with("| met |"), (gain - 49.0).abs() <= 7.35, "{gain_row} (gain {gain:.0} %)");
    let rms: Vec<BeamRmsRow> =
        read_table(&dir.path().join("out/tables/beam_rms_per_block/sequence=shaham/part-0.parquet")).unwrap();
    assert_eq!(rms.len(), 6 * 4 * 401, "401 blocks (block 0 and 400 tracked) per point and tracker");
    for name in ["fig2_rms_by_snr.svg", "fig3_rms_by_speed.svg", "fig4_rms_trackers.svg", "fig5_rms_by_distance.svg"] {
        assert!(report.contains(&format!("![{name}]({name})")), "reproduce.md shows {name}");
        let svg = std::fs::read_to_string(dir.path().join("out").join(name)).unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(doc.root_element().tag_name().name(), "svg");
    }
    let readme = std::fs::read_to_string(dir.path().join("README.md")).unwrap();
    assert!(!readme.contains("stale") && readme.contains("| claim (pv-ekf) | paper | measured | verdict |"));
}

/// The same numbers on 1 and 2 threads (runs are summed in fixed chunks).
#[test]
fn shaham_tables_do_not_depend_on_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    for threads in ["1", "2"] {
        let out = mmtrack(dir.path(), &["reproduce", "shaham", "--runs", "60", "--threads", threads, "-o", threads]);
        assert!(out.status.code().is_some_and(|c| c <= 1), "{}", text(&out).1);
    }
    for table in ["beam_valid_tracking", "beam_rms_per_block"] {
        let part = format!("tables/{table}/sequence=shaham/part-0.parquet");
        let one = std::fs::read(dir.path().join("1").join(&part)).unwrap();
        let two = std::fs::read(dir.path().join("2").join(&part)).unwrap();
        assert!(one == two, "{table} differs between 1 and 2 threads");
    }
}
