//! `mmtrack reproduce spebt`: the CI version on the real Oxford trajectory
//! (8 runs instead of 2000 with the pose-error model; radar odometry on the
//! first 480 slots), determinism across thread counts and the bad
//! trajectories of the issue, on small synthetic drives.

use std::path::Path;

use mmtrack_io::table::read_table;
use mmtrack_io::table::{SpebtSlotRow, SpebtSummaryRow};

use super::common::{mmtrack, realdata, text};

const README_BEFORE: &str = "# R\n\n<!-- reproduce-spebt:begin -->\nstale\n<!-- reproduce-spebt:end -->\n";
const EXPERIMENTS: [&str; 2] = ["pose-error-model", "radar-odometry"];

fn summary(experiment: &str) -> String {
    format!("tables/spebt_summary/sequence={experiment}/part-0.parquet")
}

fn per_slot(experiment: &str) -> String {
    format!("tables/spebt_per_slot/sequence={experiment}/part-0.parquet")
}

#[test]
fn quick_spebt_writes_tables_figure_verdicts_and_its_readme_block() {
    let Some(realdata) = realdata("reproduce_spebt_quick") else { return };
    let trajectory = realdata.join("oxford-gt-full-seq/radar_odometry.csv");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("README.md"), README_BEFORE).unwrap();
    let args = ["reproduce", "spebt", "--quick", "--trajectory", trajectory.to_str().unwrap()];
    let out = mmtrack(dir.path(), &[&args[..], &["-o", "out", "--readme", "README.md"]].concat());
    let (stdout, stderr) = text(&out);
    let report = std::fs::read_to_string(dir.path().join("out/reproduce.md"))
        .unwrap_or_else(|e| panic!("no report ({e}):\n{stdout}\n{stderr}"));
    println!("{report}");
    let missed = report.matches("| **missed** |").count();
    assert_eq!(out.status.success(), missed == 0, "exit status must follow the verdicts:\n{stderr}");
    // Five targets per experiment: AoD and AoA after and before re-initialisation, re-initialisation
    // share; |alpha| is reported only.
    assert_eq!(report.matches("| met |").count() + missed, 2 * 5, "{report}");
    assert_eq!(report.matches("| RMSE abs(alpha) (%) | 1.580 |").count(), 2, "{report}");
    // The pilot power is ours, not the paper's: (a) again at 20 and 40 dBm (4 runs at --quick)
    // beside the claims' 30 dBm run (8 runs), the others marked as variants.
    let row = |power: &str| report.lines().find(|l| l.starts_with(&format!("| {power} | "))).unwrap_or("");
    assert!(row("30").starts_with("| 30 | 8 |") && row("30").ends_with("| the claims' run |"), "{report}");
    for power in ["20", "40"] {
        let line = row(power);
        assert!(
            line.starts_with(&format!("| {power} | 4 |")) && line.ends_with("| variant, not a target |"),
            "{report}"
        );
    }

    // (a) on the 6388 Oxford slots, 8 runs; (b) on the simulator's scans along the first 480 poses, 4 runs.
    for (experiment, runs, slots) in [("pose-error-model", 8, 6388..=6388), ("radar-odometry", 4, 470..=480)] {
        let rows: Vec<SpebtSummaryRow> = read_table(&dir.path().join("out").join(summary(experiment))).unwrap();
        assert_eq!(rows.len(), 1);
        let row = &rows[0];
        assert_eq!((row.experiment.as_str(), row.runs), (experiment, runs), "{row:?}");
        assert!(slots.contains(&row.slots), "{row:?}");
        let share = 100.0 * row.reinitialisations_mean / (row.slots - 1) as f64;
        assert!((row.reinitialisation_share_pct - share).abs() < 1e-9, "{row:?}");
        assert!(row.reinitialisations_min <= row.reinitialisations_max);
        // Each re-initialisation has at least one test that fired.
        if row.reinitialisations_max > 0 {
            assert!(row.reinit_gain_pct + row.reinit_aod_pct + row.reinit_aoa_pct >= 100.0 - 1e-9, "{row:?}");
        }
        let per_slot: Vec<SpebtSlotRow> = read_table(&dir.path().join("out").join(per_slot(experiment))).unwrap();
        assert_eq!(per_slot.len() as u64, row.slots);
    }
    let slots: Vec<SpebtSlotRow> = read_table(&dir.path().join("out").join(per_slot(EXPERIMENTS[0]))).unwrap();
    // Slot 0 is the initial access: the estimate is the truth.
    assert_eq!((slots[0].run0_gain, slots[0].run0_aod_rad), (slots[0].true_gain, slots[0].true_aod_rad));
    assert_eq!(slots[0].rmse_aod_rad, 0.0);
    // The vehicle starts at (0, 0), 128.5 m from the base station at (-30, -125) m.
    assert!((slots[0].range_m - 30f64.hypot(125.0)).abs() < 1e-9 && slots[0].x_m == 0.0);
    // A slot re-initialised in run 0 ends on the true channel.
    let reset = slots.iter().find(|s| s.run0_reinitialised).expect("run 0 re-initialises somewhere");
    assert_eq!((reset.run0_gain, reset.run0_aoa_rad), (reset.true_gain, reset.true_aoa_rad));

    for figure in ["fig5_tracking.svg", "fig5_tracking_odometry.svg"] {
        let svg = std::fs::read_to_string(dir.path().join("out").join(figure)).unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap();
        assert_eq!(doc.root_element().tag_name().name(), "svg");
    }
    let readme = std::fs::read_to_string(dir.path().join("README.md")).unwrap();
    assert!(!readme.contains("stale") && readme.contains("| claim | paper (Table III, 10^5 runs) |"), "{readme}");
}

/// A TUM file of a drive at 10 m/s, 4 Hz: `poses` poses along `heading_rad`
/// from `(x0, y0)`; `edit` may change a line.
fn tum_drive(path: &Path, poses: usize, heading_rad: f64, edit: impl Fn(usize, String) -> String) {
    let (qz, qw) = ((0.5 * heading_rad).sin(), (0.5 * heading_rad).cos());
    let lines: Vec<String> = (0..poses)
        .map(|k| {
            let d = 2.5 * k as f64;
            let line = format!(
                "{:.6} {:.4} {:.4} 0 0 0 {qz:.9} {qw:.9}",
                0.25 * k as f64,
                d * heading_rad.cos(),
                d * heading_rad.sin()
            );
            edit(k, line)
        })
        .collect();
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
}

/// The same tables on 1 and 2 threads (runs are summed in fixed chunks;
/// the radar simulation and odometry are deterministic).
#[test]
fn spebt_tables_do_not_depend_on_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    tum_drive(&dir.path().join("drive.tum"), 120, 0.3, |_, line| line);
    for threads in ["1", "2"] {
        let out = mmtrack(
            dir.path(),
            &[
                "reproduce",
                "spebt",
                "--trajectory",
                "drive.tum",
                "--trajectory-format",
                "tum",
                "--runs",
                "22",
                "--threads",
                threads,
                "-o",
                threads,
            ],
        );
        assert!(out.status.code().is_some_and(|c| c <= 1), "{}", text(&out).1);
    }
    for part in EXPERIMENTS.iter().flat_map(|e| [summary(e), per_slot(e)]) {
        let one = std::fs::read(dir.path().join("1").join(&part)).unwrap();
        let two = std::fs::read(dir.path().join("2").join(&part)).unwrap();
        assert!(one == two, "{part} differs between 1 and 2 threads");
    }
    let rows: Vec<SpebtSummaryRow> = read_table(&dir.path().join("1").join(summary(EXPERIMENTS[0]))).unwrap();
    assert_eq!((rows[0].runs, rows[0].slots), (22, 120));
}

/// A trajectory through the base station, a NaN pose and a gap: a clear
/// error naming the file and the pose, and nothing written.
#[test]
fn bad_trajectories_are_refused_before_any_run() {
    let dir = tempfile::tempdir().unwrap();
    // Heading towards the base station at (-30, -125) m: the drive passes through it at 128.5 m.
    let towards_bs = (-125f64).atan2(-30.0);
    tum_drive(&dir.path().join("through.tum"), 100, towards_bs, |_, line| line);
    tum_drive(
        &dir.path().join("nan.tum"),
        100,
        0.3,
        |k, line| if k == 7 { line.replace("0 0 0", "NaN 0 0") } else { line },
    );
    tum_drive(
        &dir.path().join("gap.tum"),
        100,
        0.3,
        |k, line| if (40..43).contains(&k) { String::new() } else { line },
    );
    for (file, expected) in [
        ("through.tum", vec!["through.tum", "base station", "reference distance"]),
        ("nan.tum", vec!["nan.tum", "line 8"]),
        ("gap.tum", vec!["gap.tum", "pose 40", "gap of 1.000 s"]),
    ] {
        let out = mmtrack(
            dir.path(),
            &["reproduce", "spebt", "--trajectory", file, "--trajectory-format", "tum", "--runs", "2", "-o", "out"],
        );
        let (_, stderr) = text(&out);
        assert!(!out.status.success() && stderr.starts_with("error: "), "{file}: {stderr}");
        for needle in expected {
            assert!(stderr.contains(needle), "{file}: `{needle}` not in:\n{stderr}");
        }
        assert!(!dir.path().join("out").exists(), "{file}: nothing is written");
    }
}
