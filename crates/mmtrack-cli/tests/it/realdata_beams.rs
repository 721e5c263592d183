//! Real 60 GHz vehicle beam sweeps (DeepSense 6G scenarios 1 and 3, arrays
//! as packaged by Morais and Alkhateeb, ICC 2023) through `mmtrack ingest
//! beams`, and a bad array through the same command.

use std::path::Path;

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
