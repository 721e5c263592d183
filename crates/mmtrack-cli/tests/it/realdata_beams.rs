//! Real 60 GHz vehicle beam sweeps (DeepSense 6G scenarios 1 and 3, arrays
//! as packaged by Morais and Alkhateeb, ICC 2023) through `mmtrack ingest
//! beams`, `process beam` and `analyze`, checked against `mmtrack_beam`'s
//! evaluation run straight on the arrays; bad input through the same
//! commands.

use std::path::Path;

use mmtrack_beam::sweep::{SweepPass, SweepRecord, SweepSummary, WindowTracker, WindowTrackerConfig, evaluate};
use mmtrack_core::BeamSweep;
use mmtrack_io::table::{BeamSweepPooledRow, BeamSweepSummaryRow};
use mmtrack_io::table::{BeamSweepTracked, read_table_dir};
use mmtrack_io::{RecordingEvent, RecordingReader};

use super::common::{mmtrack, text};

/// The values of a little-endian, C-order `<f8` or `<i8` `.npy` file as
/// f64, read without the project's reader (an independent check of it).
fn npy_values(path: &Path) -> Vec<f64> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00", "{}: a version-1 .npy", path.display());
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(header.contains("'fortran_order': False"), "{header}");
    let words = bytes[10 + header_len..].chunks_exact(8).map(|c| <[u8; 8]>::try_from(c).unwrap());
    if header.contains("'<i8'") {
        words.map(|w| i64::from_le_bytes(w) as f64).collect()
    } else {
        words.map(f64::from_le_bytes).collect()
    }
}

/// Sweeps (power vectors), car fixes and unit fixes of one recording, with
/// its metadata.
struct Pass {
    power: Vec<Vec<f64>>,
    t_ns: Vec<i64>,
    car: Vec<[f64; 2]>,
    unit: Vec<[f64; 2]>,
    metadata: std::collections::BTreeMap<String, String>,
}

fn read_pass(path: &Path) -> Pass {
    let mut reader = RecordingReader::open(path).unwrap();
    let mut pass = Pass { power: vec![], t_ns: vec![], car: vec![], unit: vec![], metadata: Default::default() };
    for event in reader.by_ref() {
        match event.unwrap() {
            RecordingEvent::BeamSweep { sweep, codebook } => {
                assert_eq!(codebook.as_deref(), Some("deepsense-60ghz-64"));
                assert!(sweep.is_full());
                pass.t_ns.push(sweep.t_ns());
                pass.power.push((0..sweep.beam_count()).map(|b| sweep.power(b).unwrap()).collect());
            }
            RecordingEvent::Gnss(f) => pass.car.push([f.latitude_deg, f.longitude_deg]),
            RecordingEvent::ArrayGnss(f) => pass.unit.push([f.latitude_deg, f.longitude_deg]),
            _ => {}
        }
    }
    pass.metadata = reader.metadata().unwrap().clone();
    pass
}

/// Every row of the arrays lands, bit for bit, in the recording of its pass,
/// at row x 0.1 s.
fn check_scenario(arrays: &Path, recordings: &Path, scenario: u32, rows: usize, passes: usize, car_array: &str) {
    let file = |array: &str| arrays.join(format!("scenario{scenario}_{array}_1-{rows}.npy"));
    let power = npy_values(&file("unit1_pwr_60ghz"));
    let unit = npy_values(&file("unit1_loc"));
    let car = npy_values(&file(car_array));
    let pass_index = npy_values(&file("seq_index"));
    assert_eq!((power.len(), pass_index.len()), (rows * 64, rows));
    let mut row = 0;
    for pass in 1..=passes {
        let recording = recordings.join(format!("scenario{scenario}-pass{pass:02}.mcap"));
        let got = read_pass(&recording);
        let n = got.power.len();
        assert!(n > 0, "{}", recording.display());
        assert!(pass_index[row..row + n].iter().all(|&p| p == pass as f64), "pass {pass}: rows {row}..{}", row + n);
        assert_eq!(got.metadata["beam.first_row"], row.to_string());
        assert_eq!(got.metadata["beam.site"], format!("deepsense-scenario{scenario}"));
        for k in 0..n {
            let r = row + k;
            assert_eq!(got.t_ns[k], r as i64 * 100_000_000, "row {r}");
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got.power[k]), bits(&power[r * 64..(r + 1) * 64]), "row {r}");
            assert_eq!(bits(&got.car[k]), bits(&car[2 * r..2 * r + 2]), "row {r}");
            assert_eq!(bits(&got.unit[k]), bits(&unit[2 * r..2 * r + 2]), "row {r}");
        }
        row += n;
    }
    assert_eq!(row, rows, "every row in one of the {passes} passes");
    assert!(!recordings.join(format!("scenario{scenario}-pass{:02}.mcap", passes + 1)).exists());
}

#[test]
fn deepsense_scenarios_become_one_recording_per_pass_bit_for_bit() {
    let Some(realdata) = super::common::realdata("deepsense_ingest") else { return };
    let arrays = realdata.join("deepsense-60ghz-beams");
    let dir = tempfile::tempdir().unwrap();
    let out = mmtrack(dir.path(), &["ingest", "beams", arrays.to_str().unwrap(), "--format", "deepsense", "-o", "rec"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    // Pass and sweep counts from the README row of the data set and the
    // arrays' shapes.
    assert!(stdout.contains("scenario 1: 29 passes, 2422 sweeps of 64 beams, raw car positions"), "{stdout}");
    assert!(stdout.contains("scenario 3: 52 passes, 1487 sweeps of 64 beams, calibrated car positions"), "{stdout}");
    let recordings = dir.path().join("rec");
    check_scenario(&arrays, &recordings, 1, 2422, 29, "unit2_loc");
    check_scenario(&arrays, &recordings, 3, 1487, 52, "unit2_loc_cal");

    // Again without --force: refused, nothing changed.
    let before = std::fs::read(recordings.join("scenario3-pass52.mcap")).unwrap();
    let again =
        mmtrack(dir.path(), &["ingest", "beams", arrays.to_str().unwrap(), "--format", "deepsense", "-o", "rec"]);
    let (_, stderr) = text(&again);
    assert!(!again.status.success() && stderr.contains("already exists") && stderr.contains("--force"), "{stderr}");
    assert_eq!(std::fs::read(recordings.join("scenario3-pass52.mcap")).unwrap(), before);
}

/// `.npy` bytes of a C-order array of `descr` holding `data`.
fn npy(descr: &str, shape: &str, data: impl IntoIterator<Item = [u8; 8]>) -> Vec<u8> {
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    while (11 + header.len()) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend(data.into_iter().flatten());
    out
}

fn npy_f8(shape: &str, values: &[f64]) -> Vec<u8> {
    npy("<f8", shape, values.iter().map(|v| v.to_le_bytes()))
}

#[test]
fn a_bad_beam_array_is_one_error_line_naming_file_row_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let arrays = dir.path().join("arrays");
    std::fs::create_dir(&arrays).unwrap();
    let write = |name: &str, bytes: Vec<u8>| std::fs::write(arrays.join(name), bytes).unwrap();
    let mut power = vec![0.5; 3 * 4];
    power[6] = -0.25;
    write("scenario2_unit1_pwr_60ghz_1-3.npy", npy_f8("(3, 4)", &power));
    write("scenario2_unit1_loc_1-3.npy", npy_f8("(3, 2)", &[33.4, -111.9, 33.4, -111.9, 33.4, -111.9]));
    write("scenario2_unit2_loc_1-3.npy", npy_f8("(3, 2)", &[33.4, -111.9, 33.4, -111.9, 33.4, -111.9]));
    let index = npy("<i8", "(3,)", [1i64, 1, 2].iter().map(|v| v.to_le_bytes()));
    write("scenario2_seq_index_1-3.npy", index);
    let out = mmtrack(dir.path(), &["ingest", "beams", "arrays", "--format", "deepsense", "-o", "rec"]);
    let (_, stderr) = text(&out);
    assert!(!out.status.success());
    assert!(
        stderr
            .contains("scenario2_unit1_pwr_60ghz_1-3.npy: row 1: beam 2 power: -0.25, expected a finite, non-negative"),
        "{stderr}"
    );
    assert!(!dir.path().join("rec").exists(), "nothing written");
}

/// Two passes of 20 sweeps of `beams` beams with power `power(row, beam)`,
/// the car driving east past the unit, ingested into `dir/rec`.
fn ingest_written_passes(dir: &Path, beams: usize, power: impl Fn(usize, usize) -> f64) {
    let arrays = dir.join("arrays");
    std::fs::create_dir(&arrays).unwrap();
    let n = 40;
    let write =
        |name: &str, bytes: Vec<u8>| std::fs::write(arrays.join(format!("scenario1_{name}_1-{n}.npy")), bytes).unwrap();
    let power: Vec<f64> = (0..n).flat_map(|r| (0..beams).map(move |b| (r, b))).map(|(r, b)| power(r, b)).collect();
    write("unit1_pwr_60ghz", npy_f8(&format!("({n}, {beams})"), &power));
    write("unit1_loc", npy_f8(&format!("({n}, 2)"), &[33.42, -111.93].repeat(n)));
    let car: Vec<f64> = (0..n).flat_map(|r| [33.4201, -111.9302 + (r % 20) as f64 * 1e-5]).collect();
    write("unit2_loc", npy_f8(&format!("({n}, 2)"), &car));
    let index: Vec<i64> = (0..n).map(|r| 1 + (r / 20) as i64).collect();
    write("seq_index", npy("<i8", &format!("({n},)"), index.iter().map(|v| v.to_le_bytes())));
    let out = mmtrack(dir, &["ingest", "beams", "arrays", "--format", "deepsense", "-o", "rec", "--quiet"]);
    assert!(out.status.success(), "{}", text(&out).1);
}

/// All-zero power or a one-beam codebook: the GNSS policies say so, not
/// that `gnss_sigma_beams` (a parameter nobody set) is 0.
#[test]
fn flat_power_or_one_beam_names_the_cause_not_a_parameter() {
    for (beams, expected) in [
        (
            64,
            "has an RMS residual of 0 beams: their best beam is 0 in every sweep: the power does not vary across the beams",
        ),
        (1, "scenario1-pass01.mcap: sweeps of 1 beam: the GNSS policies fit a beam map"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        ingest_written_passes(dir.path(), beams, |_, _| 0.0);
        for tracker in ["gnss-window", "gnss-map"] {
            let out = mmtrack(dir.path(), &["process", "beam", "rec", "-o", "tables", "--tracker", tracker]);
            let (_, stderr) = text(&out);
            assert!(!out.status.success(), "{beams} beams, {tracker}");
            assert!(stderr.contains(expected) && !stderr.contains("gnss_sigma_beams"), "{stderr}");
        }
    }
}

/// The window tracker run straight on the arrays of scenario 1 (no
/// recording, no table): the records of each pass, as `mmtrack_beam`
/// computes them (the DeepSense test of that crate drives it the same way).
fn window_on_arrays(arrays: &Path) -> Vec<Vec<SweepRecord>> {
    let file = |array: &str| arrays.join(format!("scenario1_{array}_1-2422.npy"));
    let power = npy_values(&file("unit1_pwr_60ghz"));
    let pass_index = npy_values(&file("seq_index"));
    let mut passes: Vec<Vec<BeamSweep>> = Vec::new();
    for (row, &pass) in pass_index.iter().enumerate() {
        if row == 0 || pass != pass_index[row - 1] {
            passes.push(Vec::new());
        }
        let sweep = BeamSweep::full(row as i64 * 100_000_000, power[row * 64..(row + 1) * 64].to_vec()).unwrap();
        passes.last_mut().unwrap().push(sweep);
    }
    passes
        .iter()
        .map(|sweeps| {
            let mut tracker = WindowTracker::new(WindowTrackerConfig::default()).unwrap();
            evaluate(&mut tracker, &[SweepPass { sweeps, gnss_beam: None }]).unwrap()
        })
        .collect()
}

/// `mmtrack ingest beams --scenario 1` then `process beam --tracker window`
/// into `dir/tables`; returns the arrays' folder.
fn ingest_and_process(dir: &Path, realdata: &Path) -> std::path::PathBuf {
    let arrays = realdata.join("deepsense-60ghz-beams");
    let a = arrays.to_str().unwrap();
    let out = mmtrack(dir, &["ingest", "beams", a, "--format", "deepsense", "--scenario", "1", "-o", "rec", "--quiet"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let out = mmtrack(dir, &["process", "beam", "rec", "-o", "tables", "--tracker", "window"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("deepsense-scenario1: 29 passes, 2422 sweeps"), "{stdout}");
    arrays
}

/// Ingest, process and analyze scenario 1 with the window tracker: the
/// table equals `mmtrack_beam::evaluate` on the raw arrays row for row, and
/// analyze's per-sequence and pooled numbers equal its `SweepSummary`.
#[test]
fn ingest_process_analyze_scenario_1_equals_evaluate_on_the_raw_arrays() {
    let Some(realdata) = super::common::realdata("deepsense_process") else { return };
    let dir = tempfile::tempdir().unwrap();
    let arrays = ingest_and_process(dir.path(), &realdata);
    let expected = window_on_arrays(&arrays);
    check_table(dir.path(), &expected);
    check_analysis(dir.path(), &expected);
}

fn check_table(dir: &Path, expected: &[Vec<SweepRecord>]) {
    let tables = read_table_dir::<BeamSweepTracked>(&dir.join("tables")).unwrap();
    assert_eq!(tables.len(), 29);
    for (pass, records) in expected.iter().enumerate() {
        let rows = &tables[&format!("scenario1-pass{:02}", pass + 1)];
        assert_eq!(rows.len(), records.len(), "pass {}", pass + 1);
        for (row, r) in rows.iter().zip(records) {
            let got = (row.t_ns, row.sweep, row.chosen_beam, row.best_beam, row.beams_measured, row.reinitialised);
            let want = (
                r.t_ns,
                r.sweep as u64,
                r.chosen_beam as u32,
                r.best_beam as u32,
                r.beams_measured as u32,
                r.reinitialised,
            );
            assert_eq!(got, want, "pass {} sweep {}", pass + 1, r.sweep);
            assert_eq!(row.loss_db.to_bits(), r.loss_db.to_bits(), "pass {} sweep {}", pass + 1, r.sweep);
            assert_eq!(
                (row.tracker.as_str(), row.site.as_str(), row.beam_count),
                ("window", "deepsense-scenario1", 64)
            );
            assert_eq!(row.gnss_beam, None);
        }
    }
}

/// The summary columns of a result row against `mmtrack_beam`'s summary.
/// Equal to the bit: the same formulas, losses summed in ascending order.
fn assert_same(row: &BeamSweepSummaryRow, want: &SweepSummary, what: &str) {
    let got = (row.sweeps, row.mean_loss_db, row.median_loss_db, row.top1, row.within_one, row.mean_beams_per_sweep);
    let expected = (
        want.sweeps as u64,
        want.mean_loss_db,
        want.median_loss_db,
        want.top1,
        want.within_one,
        want.mean_beams_per_sweep,
    );
    assert_eq!(got, expected, "{what}");
    assert_eq!(row.reinitialisations, want.reinitialisations as u64, "{what}");
}

fn check_analysis(dir: &Path, expected: &[Vec<SweepRecord>]) {
    let out = mmtrack(dir, &["analyze", "tables", "-o", "analysis"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let pooled = SweepSummary::from_records(expected.iter().flatten()).unwrap();
    // What the beam crate's DeepSense test prints for scenario 1 (rounded).
    assert_eq!(
        (format!("{:.3}", pooled.mean_loss_db), format!("{:.2}", pooled.mean_beams_per_sweep)),
        ("0.289".into(), "4.14".into())
    );
    assert!(stdout.contains("deepsense-scenario1 (29 passes, 2422 sweeps) window: mean loss 0.289 dB"), "{stdout}");
    let analysis = dir.join("analysis");
    let rows = read_table_dir::<BeamSweepPooledRow>(&analysis.join("tables")).unwrap();
    let all = &rows["all"];
    assert_eq!(all.len(), 1);
    let BeamSweepPooledRow(row) = &all[0];
    assert_eq!(
        (row.tracker.as_str(), row.site.as_str(), row.passes, row.beam_count),
        ("window", "deepsense-scenario1", 29, 64)
    );
    assert_same(row, &pooled, "pooled");
    let per_sequence = read_table_dir::<BeamSweepSummaryRow>(&analysis.join("tables")).unwrap();
    assert_eq!(per_sequence.len(), 29);
    for (pass, records) in expected.iter().enumerate() {
        let sequence = format!("scenario1-pass{:02}", pass + 1);
        let want = SweepSummary::from_records(records).unwrap();
        assert_same(&per_sequence[&sequence][0], &want, &sequence);
        for file in ["beam_index.svg", "loss_cdf.svg"] {
            let svg = std::fs::read_to_string(analysis.join("plots").join(&sequence).join(file)).unwrap();
            roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{sequence}/{file}: {e}"));
        }
    }
    let site_plot = std::fs::read_to_string(analysis.join("plots/site=deepsense-scenario1/loss_cdf.svg")).unwrap();
    roxmltree::Document::parse(&site_plot).unwrap();
    let report = std::fs::read_to_string(analysis.join("report.md")).unwrap();
    let line = format!(
        "| deepsense-scenario1 | window | 29 | 2422 | {:.3} | {:.3} |",
        pooled.mean_loss_db, pooled.median_loss_db
    );
    assert!(report.contains("## Beam sweeps") && report.contains(&line), "{report}");
}

#[test]
fn process_beam_refuses_gnss_policies_without_two_passes_and_recordings_without_sweeps() {
    let dir = tempfile::tempdir().unwrap();
    let arrays = dir.path().join("arrays");
    std::fs::create_dir(&arrays).unwrap();
    let write = |name: &str, bytes: Vec<u8>| std::fs::write(arrays.join(name), bytes).unwrap();
    write("scenario2_unit1_pwr_60ghz_1-3.npy", npy_f8("(3, 4)", &[0.1, 0.2, 0.9, 0.3].repeat(3)));
    let place = [33.4, -111.9].repeat(3);
    write("scenario2_unit1_loc_1-3.npy", npy_f8("(3, 2)", &place));
    write("scenario2_unit2_loc_1-3.npy", npy_f8("(3, 2)", &[33.4001, -111.9002, 33.4001, -111.9001, 33.4001, -111.9]));
    write("scenario2_seq_index_1-3.npy", npy("<i8", "(3,)", [1i64, 1, 1].iter().map(|v| v.to_le_bytes())));
    let out = mmtrack(dir.path(), &["ingest", "beams", "arrays", "--format", "deepsense", "-o", "rec", "--quiet"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let out = mmtrack(dir.path(), &["process", "beam", "rec", "-o", "tables", "--tracker", "window,gnss-window"]);
    let (_, stderr) = text(&out);
    assert!(!out.status.success());
    assert!(stderr.contains("site deepsense-scenario2") && stderr.contains("at least two passes"), "{stderr}");
    assert!(!dir.path().join("tables").exists(), "nothing written");
    // The window tracker alone needs no map: the best beam (2) every sweep.
    let out = mmtrack(dir.path(), &["process", "beam", "rec", "-o", "tables", "--tracker", "window"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let rows = &read_table_dir::<BeamSweepTracked>(&dir.path().join("tables")).unwrap()["scenario2-pass01"];
    assert!(rows.iter().all(|r| r.chosen_beam == 2 && r.loss_db == 0.0), "{rows:?}");
    // Again: refused without --force.
    let out = mmtrack(dir.path(), &["process", "beam", "rec", "-o", "tables", "--tracker", "window"]);
    assert!(!out.status.success() && text(&out).1.contains("--force"));
    // A recording without sweeps.
    assert!(mmtrack(dir.path(), &["demo", "--out", "d", "--quiet"]).status.success());
    let out = mmtrack(dir.path(), &["process", "beam", "d/recording.mcap", "-o", "t2", "--tracker", "window"]);
    let (_, stderr) = text(&out);
    assert!(!out.status.success() && stderr.contains("recording.mcap: no beam sweeps"), "{stderr}");
}
