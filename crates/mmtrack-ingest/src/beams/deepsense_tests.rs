//! DeepSense ingest on synthesised arrays: a good folder becomes one
//! recording per pass; each kind of bad array is an error naming the file,
//! row and field, and writes nothing.

use std::path::Path;

use mmtrack_core::BeamSweep;
use mmtrack_io::{IoError, Overwrite, RecordingEvent, RecordingOptions, RecordingReader};

use super::*;
use crate::cir::parse_npy_matrix;

/// A version-1 `.npy` file of `descr` (e.g. `<f8`) with `shape`, C order,
/// holding `data` (already in the dtype's byte order).
fn npy(descr: &str, shape: &str, fortran: bool, data: &[u8]) -> Vec<u8> {
    let order = if fortran { "True" } else { "False" };
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {shape}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

fn f8(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn i8(values: &[i64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// A scenario of `passes.len()` sweeps of 3 beams, the best beam moving
/// with the row; the unit fixed, the car moving east.
struct Arrays {
    power: Vec<f64>,
    unit: Vec<f64>,
    car: Vec<f64>,
    passes: Vec<i64>,
}

fn arrays(passes: &[i64]) -> Arrays {
    let n = passes.len();
    Arrays {
        power: (0..n * 3).map(|i| if i % 3 == (i / 3) % 3 { 0.9 } else { 0.1 + i as f64 * 1e-3 }).collect(),
        unit: (0..n).flat_map(|_| [33.42, -111.93]).collect(),
        car: (0..n).flat_map(|r| [33.4201, -111.9302 + r as f64 * 1e-5]).collect(),
        passes: passes.to_vec(),
    }
}

fn write_folder(dir: &Path, scenario: u32, a: &Arrays, calibrated: bool) {
    let n = a.passes.len();
    let name = |array: &str| dir.join(format!("scenario{scenario}_{array}_1-{n}.npy"));
    std::fs::write(name("unit1_pwr_60ghz"), npy("<f8", &format!("({}, 3)", a.power.len() / 3), false, &f8(&a.power)))
        .unwrap();
    std::fs::write(name("unit1_loc"), npy("<f8", &format!("({}, 2)", a.unit.len() / 2), false, &f8(&a.unit))).unwrap();
    std::fs::write(name("unit2_loc"), npy("<f8", &format!("({}, 2)", a.car.len() / 2), false, &f8(&a.car))).unwrap();
    if calibrated {
        let cal: Vec<f64> = a.car.iter().map(|v| v + 1e-6).collect();
        std::fs::write(name("unit2_loc_cal"), npy("<f8", &format!("({}, 2)", cal.len() / 2), false, &f8(&cal)))
            .unwrap();
    }
    std::fs::write(name("seq_index"), npy("<i8", &format!("({},)", a.passes.len()), false, &i8(&a.passes))).unwrap();
}

fn ingest(folder: &Path, out: &Path, options: &DeepsenseOptions) -> Result<Vec<PassRecording>, IngestError> {
    ingest_deepsense(folder, out, options, &RecordingOptions::default(), &mut |_, _| {})
}

fn error_text(passes: &[i64], edit: impl FnOnce(&mut Arrays)) -> String {
    let dir = tempfile::tempdir().unwrap();
    let mut a = arrays(passes);
    edit(&mut a);
    write_folder(dir.path(), 1, &a, false);
    let out = dir.path().join("out");
    let err = ingest(dir.path(), &out, &DeepsenseOptions::default()).unwrap_err();
    assert!(!out.exists(), "nothing written on a bad array");
    err.to_string()
}

#[test]
fn each_pass_becomes_a_recording_with_sweeps_and_both_units_fixes() {
    let dir = tempfile::tempdir().unwrap();
    let a = arrays(&[1, 1, 1, 2, 2]);
    write_folder(dir.path(), 3, &a, true);
    let out = dir.path().join("out");
    let options = DeepsenseOptions { sweep_period_ns: 50_000_000, ..Default::default() };
    let written = ingest(dir.path(), &out, &options).unwrap();
    let ids: Vec<&str> = written.iter().map(|w| w.sequence_id.as_str()).collect();
    assert_eq!(ids, ["scenario3-pass01", "scenario3-pass02"]);
    assert_eq!(written.iter().map(|w| w.sweeps).collect::<Vec<_>>(), [3, 2]);
    assert!(written.iter().all(|w| w.calibrated && w.beams == 3), "auto picks the calibrated positions");

    let second = out.join("scenario3-pass02.mcap");
    let mut reader = RecordingReader::open(&second).unwrap();
    let events: Vec<RecordingEvent> = reader.by_ref().collect::<Result<_, _>>().unwrap();
    let metadata = reader.metadata().unwrap();
    assert_eq!(metadata["sequence_id"], "scenario3-pass02");
    assert_eq!(metadata["beam.site"], "deepsense-scenario3");
    assert_eq!(metadata["beam.pass"], "2");
    assert_eq!(metadata["beam.first_row"], "3");
    assert_eq!(metadata["time_base"], "relative");
    assert!(metadata["gnss.vehicle_positions"].starts_with("calibrated (scenario3_unit2_loc_cal_1-5.npy)"));
    let sweeps: Vec<(BeamSweep, Option<String>)> = events
        .iter()
        .filter_map(|e| match e {
            RecordingEvent::BeamSweep { sweep, codebook } => Some((sweep.clone(), codebook.clone())),
            _ => None,
        })
        .collect();
    // Rows 3 and 4 of the scenario, 50 ms apart from its first row.
    let want: Vec<(BeamSweep, Option<String>)> = (3..5)
        .map(|row| {
            let sweep = BeamSweep::full(row as i64 * 50_000_000, a.power[row * 3..row * 3 + 3].to_vec()).unwrap();
            (sweep, Some("deepsense-60ghz-3".to_string()))
        })
        .collect();
    assert_eq!(sweeps, want);
    let car: Vec<(i64, f64, f64)> = events
        .iter()
        .filter_map(|e| {
            if let RecordingEvent::Gnss(f) = e { Some((f.t_ns, f.latitude_deg, f.longitude_deg)) } else { None }
        })
        .collect();
    assert_eq!(car, [(150_000_000, a.car[6] + 1e-6, a.car[7] + 1e-6), (200_000_000, a.car[8] + 1e-6, a.car[9] + 1e-6)]);
    let unit = events.iter().filter(|e| matches!(e, RecordingEvent::ArrayGnss(f) if f.latitude_deg == 33.42)).count();
    assert_eq!(unit, 2);

    // Raw positions on request; an existing output is refused and kept.
    let before = std::fs::read(&second).unwrap();
    let raw = DeepsenseOptions { positions: VehiclePositions::Raw, ..options.clone() };
    let err = ingest(dir.path(), &out, &raw).unwrap_err();
    assert!(matches!(err, IngestError::Io(IoError::OutputExists { .. })), "{err}");
    assert_eq!(std::fs::read(&second).unwrap(), before);
    let recording = RecordingOptions { overwrite: Overwrite::Replace, ..Default::default() };
    let replaced = ingest_deepsense(dir.path(), &out, &raw, &recording, &mut |_, _| {}).unwrap();
    assert!(replaced.iter().all(|w| !w.calibrated));
}

#[test]
fn scenario_choice_and_missing_arrays_are_named() {
    let dir = tempfile::tempdir().unwrap();
    write_folder(dir.path(), 1, &arrays(&[4, 4]), false);
    write_folder(dir.path(), 3, &arrays(&[1]), false);
    let out = dir.path().join("out");
    let only = DeepsenseOptions { scenario: Some(1), ..Default::default() };
    let written = ingest(dir.path(), &out, &only).unwrap();
    assert_eq!(written.iter().map(|w| w.sequence_id.as_str()).collect::<Vec<_>>(), ["scenario1-pass04"]);
    let missing = DeepsenseOptions { scenario: Some(2), ..Default::default() };
    let text = ingest(dir.path(), &out, &missing).unwrap_err().to_string();
    assert!(text.contains("no scenario 2") && text.contains("[1, 3]"), "{text}");
    let calibrated = DeepsenseOptions { positions: VehiclePositions::Calibrated, ..Default::default() };
    let text = ingest(dir.path(), &dir.path().join("cal"), &calibrated).unwrap_err().to_string();
    assert!(text.contains("scenario 1 has no calibrated car positions"), "{text}");
    std::fs::remove_file(dir.path().join("scenario3_seq_index_1-1.npy")).unwrap();
    let text = find_scenarios(dir.path()).unwrap_err().to_string();
    assert!(text.contains("scenario 3 has no `seq_index` array"), "{text}");
    let empty = tempfile::tempdir().unwrap();
    let text = find_scenarios(empty.path()).unwrap_err().to_string();
    assert!(text.contains("no DeepSense beam arrays"), "{text}");
}

#[test]
fn mismatched_lengths_name_the_file_and_the_row_counts() {
    let text = error_text(&[1, 1, 2], |a| {
        a.car.truncate(4);
    });
    assert!(text.contains("scenario1_unit2_loc_1-3.npy") && text.contains("rows"), "{text}");
    assert!(text.contains("2 rows, but scenario1_unit1_pwr_60ghz_1-3.npy has 3"), "{text}");
    let text = error_text(&[1, 1, 2], |a| a.passes.push(2));
    assert!(text.contains("scenario1_seq_index_1-4.npy: row 3: rows: 4 rows, but"), "{text}");
}

#[test]
fn nan_or_negative_power_names_file_row_and_beam() {
    let text = error_text(&[1, 1, 2], |a| a.power[7] = f64::NAN);
    assert!(text.contains("scenario1_unit1_pwr_60ghz_1-3.npy: row 2: beam 1 power: NaN"), "{text}");
    let text = error_text(&[1, 1, 2], |a| a.power[3] = -1e-9);
    assert!(text.contains("row 1: beam 0 power: -0.000000001"), "{text}");
}

#[test]
fn non_consecutive_passes_and_bad_positions_name_the_row() {
    let text = error_text(&[1, 1, 3], |_| {});
    assert!(text.contains("scenario1_seq_index_1-3.npy: row 2: pass index: pass 3 follows pass 1"), "{text}");
    let text = error_text(&[1, 2, 1], |_| {});
    assert!(text.contains("row 2: pass index: pass 1 follows pass 2"), "{text}");
    let text = error_text(&[1, 1, 2], |a| a.car[3] = f64::INFINITY);
    assert!(text.contains("scenario1_unit2_loc_1-3.npy: row 1: longitude (column 1): inf"), "{text}");
    let text = error_text(&[1, 1, 2], |a| a.unit[0] = 91.0);
    assert!(text.contains("scenario1_unit1_loc_1-3.npy: row 0: latitude (column 0): 91"), "{text}");
    // A car or a roadside unit at (0, 0), a GPS log's "no fix": valid degrees, named in its own file.
    let text = error_text(&[1, 1, 2], |a| a.car[2..4].copy_from_slice(&[0.0, 0.0]));
    assert!(text.contains("scenario1_unit2_loc_1-3.npy: row 1: latitude, longitude: (0, 0), a GPS log's"), "{text}");
    let text = error_text(&[1, 1, 2], |a| a.unit[0..2].copy_from_slice(&[0.0, 0.0]));
    assert!(text.contains("scenario1_unit1_loc_1-3.npy: row 0: latitude, longitude: (0, 0)"), "{text}");
    // A car far from the unit (here about 1100 km).
    let text = error_text(&[1, 1, 2], |a| a.car[2] += 10.0);
    assert!(
        text.contains("scenario1_unit2_loc_1-3.npy: row 1: latitude, longitude: (43.4201, ")
            && text.contains("km from the roadside unit at (33.42, -111.93); a link spans at most 10 km"),
        "{text}"
    );
}

#[test]
fn float32_power_is_read_and_integer_power_names_the_accepted_dtypes() {
    let dir = tempfile::tempdir().unwrap();
    let a = arrays(&[1, 1, 2, 2]);
    write_folder(dir.path(), 1, &a, false);
    let power = dir.path().join("scenario1_unit1_pwr_60ghz_1-4.npy");
    // The same power as float32: the same recordings, power rounded to f32.
    let f4: Vec<u8> = a.power.iter().flat_map(|&v| (v as f32).to_le_bytes()).collect();
    std::fs::write(&power, npy("<f4", "(4, 3)", false, &f4)).unwrap();
    let passes = ingest(dir.path(), &dir.path().join("out"), &DeepsenseOptions::default()).unwrap();
    assert_eq!(passes.len(), 2);
    // As int64: refused, naming the dtypes that are accepted.
    let i8_power: Vec<i64> = a.power.iter().map(|&v| (v * 100.0) as i64).collect();
    std::fs::write(&power, npy("<i8", "(4, 3)", false, &i8(&i8_power))).unwrap();
    let err = ingest(dir.path(), &dir.path().join("out2"), &DeepsenseOptions::default()).unwrap_err().to_string();
    assert!(
        err.contains(
            "scenario1_unit1_pwr_60ghz_1-4.npy: header: descr: dtype `<i8`, expected float64 (`<f8`) or float32 (`<f4`)"
        ),
        "{err}"
    );
}

#[test]
fn npy_matrix_reads_fortran_order_big_endian_and_refuses_other_dtypes() {
    let path = Path::new("m.npy");
    // [[1, 2, 3], [4, 5, 6]] stored column by column.
    let fortran = npy("<f8", "(2, 3)", true, &f8(&[1.0, 4.0, 2.0, 5.0, 3.0, 6.0]));
    let m = parse_npy_matrix(path, &fortran).unwrap();
    assert_eq!((m.rows, m.columns), (2, 3));
    assert_eq!(m.values, NpyValues::F64(vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]));
    let big: Vec<u8> = [7i64, -2].iter().flat_map(|v| v.to_be_bytes()).collect();
    let m = parse_npy_matrix(path, &npy(">i8", "(2,)", false, &big)).unwrap();
    assert_eq!((m.rows, m.columns, m.values), (2, 1, NpyValues::I64(vec![7, -2])));
    // float32 and int32 (numpy's default integer on Windows before 2.0) are
    // widened exactly.
    let f4: Vec<u8> = [0.25f32, -1.5e-7].iter().flat_map(|v| v.to_le_bytes()).collect();
    let m = parse_npy_matrix(path, &npy("<f4", "(2,)", false, &f4)).unwrap();
    assert_eq!((m.values, m.dtype.as_str()), (NpyValues::F64(vec![0.25, f64::from(-1.5e-7f32)]), "<f4"));
    let i4: Vec<u8> = [3i32, -4, 5, -6].iter().flat_map(|v| v.to_be_bytes()).collect();
    let m = parse_npy_matrix(path, &npy(">i4", "(2, 2)", true, &i4)).unwrap();
    assert_eq!(m.values, NpyValues::I64(vec![3, 5, -4, -6]));
    let text = parse_npy_matrix(path, &npy("<f2", "(2,)", false, &[0; 4])).unwrap_err().to_string();
    assert!(
        text.contains(
            "m.npy: header: descr: dtype `<f2`, expected float64 (`<f8`), float32 (`<f4`), int64 (`<i8`) or int32 (`<i4`)"
        ),
        "{text}"
    );
    let text = parse_npy_matrix(path, &npy("<f8", "(2, 2, 2)", false, &[0; 64])).unwrap_err().to_string();
    assert!(text.contains("shape: [2, 2, 2], expected one or two dimensions"), "{text}");
    let text = parse_npy_matrix(path, &npy("<f8", "(3, 2)", false, &[0; 40])).unwrap_err().to_string();
    assert!(text.contains("truncated: shape [3, 2]") && text.contains("needs 48 bytes"), "{text}");
}
