//! `mmtrack bench mpc`: prints the table and rewrites only its README block.
//! No time is asserted (STYLE.md: tests never assert wall-clock time).

use super::common::{mmtrack, text};

#[test]
fn bench_mpc_prints_the_table_and_rewrites_its_readme_block() {
    let dir = tempfile::tempdir().unwrap();
    let readme = dir.path().join("README.md");
    let before = "# R\n\nabove\n\n<!-- bench-mpc:begin -->\nstale\n<!-- bench-mpc:end -->\n\nbelow\n";
    std::fs::write(&readme, before).unwrap();
    let output = mmtrack(dir.path(), &["bench", "mpc", "--snapshots", "60", "--readme", "README.md"]);
    let (stdout, stderr) = text(&output);
    assert!(output.status.success(), "stdout:\n{stdout}\nstderr:\n{stderr}");
    assert!(stdout.contains("`mmtrack bench mpc`: 60 simulated snapshots of 2048 taps"), "{stdout}");
    assert!(stdout.contains("| threads | snapshots/s |"), "{stdout}");
    assert!(stdout.contains("GM-PHD baseline"), "{stdout}");
    assert!(stdout.contains("Target (one thread): "), "{stdout}");
    let rows: Vec<Vec<&str>> = stdout
        .lines()
        .filter(|l| l.starts_with("| 1 |") || l.starts_with("| 2 |"))
        .map(|l| l.split('|').map(str::trim).collect())
        .collect();
    assert_eq!(rows.len(), 2, "one row per thread count (1, 2):\n{stdout}");
    for row in &rows {
        // Cells: "", threads, snapshots/s, s, s per 10 000, detection s, tracking s, / FFT, detections,
        // per true path, verdict, "".
        assert_eq!(row.len(), 12, "{row:?}");
        let detections: f64 = row[8].parse().unwrap();
        // 40 paths, 15..50 dB over a -140 dB floor and several pulse widths
        // apart: each is found; noise peaks above floor + 6 dB add a few.
        assert!((38.0..=60.0).contains(&detections), "detections per snapshot {detections}");
        assert!(row[10] == "met" || row[10] == "**missed**", "{row:?}");
    }
    // Both thread counts see the same snapshots and must find the same detections.
    assert_eq!(rows[0][8], rows[1][8]);
    let after = std::fs::read_to_string(&readme).unwrap();
    assert!(after.starts_with("# R\n\nabove\n\n<!-- bench-mpc:begin -->\n`mmtrack bench mpc`: 60"), "{after}");
    assert!(after.ends_with("<!-- bench-mpc:end -->\n\nbelow\n") && !after.contains("stale"), "{after}");
}

#[test]
fn bench_mpc_refuses_zero_snapshots() {
    let dir = tempfile::tempdir().unwrap();
    let output = mmtrack(dir.path(), &["bench", "mpc", "--snapshots", "0"]);
    let (_, stderr) = text(&output);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("--snapshots"), "{stderr}");
}
