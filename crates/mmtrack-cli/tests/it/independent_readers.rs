//! An independent client reads our files: Python's `mcap` (with protobuf
//! decoding from the embedded descriptors), pyarrow and duckdb check counts,
//! schema names, values and units metadata. The script lives in
//! `tests/python/`; its packages are installed from PyPI into a venv under
//! the target directory. NumPy, as an independent writer, makes `.npy` and
//! `.npz` files that `ingest cir` must read. Skips with a visible line where
//! Python or PyPI is unavailable.

use std::path::Path;
use std::process::Command;

use mmtrack_core::{CirSnapshot, Complex64, GnssFix, GnssFixQuality, MpcTrack, MpcTruth, Se2, StampedPose};
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase};
use mmtrack_io::table::{RunInfo, write_table};
use mmtrack_io::{Overwrite, RecordingOptions, RecordingWriter};

use super::common::{mmtrack, root, text, venv_python};

/// A recording and tables holding every canonical type.
fn write_samples(dir: &Path) {
    let metadata = RecordingMetadata {
        sequence_id: "seq-a".into(),
        source: "independent reader test".into(),
        time_base: TimeBase::UnixEpoch,
        extra: Default::default(),
    };
    let mut writer = RecordingWriter::create(&dir.join("all.mcap"), &metadata, &RecordingOptions::default()).unwrap();
    for i in 0..5i64 {
        let pose = StampedPose {
            t_ns: 1_000_000_000 + i * 100_000_000,
            parent_from_child: Se2::new(i as f64, -0.5, 0.1 * i as f64),
        };
        writer.write_pose(PoseStream::GroundTruth, &pose, "world").unwrap();
    }
    writer
        .write_gnss_fix(&GnssFix {
            t_ns: 1_000_000_000,
            latitude_deg: 51.762042,
            longitude_deg: -1.262751,
            altitude_m: Some(65.176138),
            horizontal_sigma_m: Some(0.77),
            num_satellites: None,
            quality: GnssFixQuality::Autonomous,
        })
        .unwrap();
    let cir = CirSnapshot {
        t_ns: 1_000_000_000,
        set_index: 3,
        snapshot_index: 2,
        tx_antenna: 1,
        rx_antenna: 0,
        carrier_hz: 5.7e9,
        tap_spacing_s: 1e-9,
        delay_offset_s: 0.0,
        taps: (0..16).map(|k| Complex64::new(k as f64, -(k as f64))).collect(),
        first_path_hint_s: Some(2.5e-9),
    };
    writer.write_cir(&cir).unwrap();
    writer
        .write_mpc_truth(&MpcTruth {
            t_ns: 1_000_000_000,
            set_index: 3,
            snapshot_index: 2,
            path_id: 7,
            delay_s: 4.25e-9,
            amplitude: Complex64::new(1e-5, -2e-5),
            doppler_hz: -321.5,
        })
        .unwrap();
    writer.finish().unwrap();

    let run = RunInfo::new(r#"{"who":"independent reader test"}"#, mmtrack_io::recording::TimeBase::UnixEpoch)
        .with_frame(mmtrack_io::table::Frame::new("test_world", "a test world frame"));
    let tables = dir.join("tables");
    let tracks = vec![MpcTrack {
        track_id: 4,
        doppler_hz: Some(12.5),
        detections: vec![mmtrack_core::MpcDetection {
            t_ns: 5,
            set_index: 0,
            snapshot_index: 1,
            delay_s: 2.5e-8,
            amplitude: Complex64::new(0.001, 0.0),
        }],
    }];
    write_table(&tables, "seq-a", &tracks, &run, Overwrite::Refuse).unwrap();
    write_table(&tables, "seq-b", &tracks, &run, Overwrite::Refuse).unwrap();
    write_table(&tables, "seq-a", &[cir], &run, Overwrite::Refuse).unwrap();
}

#[test]
fn python_mcap_pyarrow_and_duckdb_read_our_files() {
    let Some(python) = venv_python() else {
        eprintln!("skipped: independent readers: Python 3 with pip access to PyPI not available");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    write_samples(dir.path());
    assert!(mmtrack(dir.path(), &["demo", "--out", "demo", "--quiet"]).status.success());
    let script = root().join("tests/python/independent_readers.py");
    let out = Command::new(python).arg(script).arg(dir.path()).output().unwrap();
    assert!(
        out.status.success(),
        "independent readers failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("all checks passed"), "{stdout}");
}

/// NumPy itself (an independent writer): `np.save` in Fortran order,
/// `savez_compressed` (deflate, ZIP64 local headers), complex64 and float32
/// I/Q, read by `mmtrack ingest cir` into the same CIRs; a float64 member is
/// refused by name and dtype.
#[test]
fn numpy_written_files_are_ingested_value_for_value() {
    let Some(python) = venv_python() else {
        eprintln!("skipped: NumPy conformance: no Python venv (python3 or PyPI unavailable)");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let script = "import numpy as np, sys\n\
        d = sys.argv[1]\n\
        h = (np.arange(24).reshape(2, 3, 4) * (1 - 0.5j)).astype(np.complex64)\n\
        np.save(d + '/f.npy', np.asfortranarray(h.astype(np.complex128)))\n\
        iq = np.stack([h.real, h.imag], axis=-1).astype(np.float32)\n\
        np.savez_compressed(d + '/z.npz', cir=h, iq=iq, other=np.zeros(3))\n";
    let ran = Command::new(python).arg("-c").arg(script).arg(d).output().unwrap();
    assert!(ran.status.success(), "{}", String::from_utf8_lossy(&ran.stderr));
    let sidecar = |variable: &str| {
        let path = d.join(format!("{variable}.toml"));
        let variable = if variable == "f" { String::new() } else { format!("variable = \"{variable}\"\n") };
        std::fs::write(
            &path,
            format!("{variable}carrier_hz = 5.7e9\ntap_spacing_s = 1e-9\nsnapshot_period_s = 1e-3\naxes = [\"snapshot\", \"rx\", \"tap\"]\n"),
        )
        .unwrap();
        path
    };
    // Element (s, r, k) = (12 s + 4 r + k) (1 - 0.5 j), whatever the storage order.
    let expected = |s: u64, r: u32, k: usize| {
        let i = (12 * s + 4 * u64::from(r)) as f64 + k as f64;
        Complex64::new(i, -0.5 * i)
    };
    for (file, format, variable) in [("f.npy", "npy", "f"), ("z.npz", "npz", "cir"), ("z.npz", "npz", "iq")] {
        let side = sidecar(variable);
        let out = mmtrack(
            d,
            &[
                "ingest",
                "cir",
                file,
                "--format",
                format,
                "--sidecar",
                side.to_str().unwrap(),
                "-o",
                "r.mcap",
                "-q",
                "--force",
            ],
        );
        assert!(out.status.success(), "{file} {variable}: {}", text(&out).1);
        let cirs: Vec<CirSnapshot> = mmtrack_io::RecordingReader::open(&d.join("r.mcap"))
            .unwrap()
            .filter_map(|e| match e.unwrap() {
                mmtrack_io::RecordingEvent::Cir(c) => Some(c),
                _ => None,
            })
            .collect();
        assert_eq!(cirs.len(), 6, "{file} {variable}: two snapshots of three receive antennas");
        for c in &cirs {
            let want: Vec<Complex64> = (0..4).map(|k| expected(c.set_index, c.rx_antenna, k)).collect();
            assert_eq!(c.taps, want, "{file} {variable}: snapshot {} rx {}", c.set_index, c.rx_antenna);
        }
    }
    let side = sidecar("other");
    let out =
        mmtrack(d, &["ingest", "cir", "z.npz", "--format", "npz", "--sidecar", side.to_str().unwrap(), "-o", "o.mcap"]);
    let stderr = text(&out).1;
    assert!(!out.status.success() && stderr.contains("other.npy") && stderr.contains("<f8"), "{stderr}");
}

/// Issue 26: tables re-written by pyarrow (an independent writer) with each
/// codec common writers use (pyarrow's default snappy, gzip, lz4, brotli,
/// zstd, none) are read by `analyze`, `export` and `inspect`; the analysis
/// equals that of our own files (only the input path in the report differs).
#[test]
fn pyarrow_rewritten_tables_with_every_codec_are_read() {
    let Some(python) = venv_python() else {
        eprintln!("skipped: codecs: no Python venv (python3 or PyPI unavailable)");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(mmtrack(d, &["demo", "--out", "demo", "--quiet"]).status.success());
    let codecs = ["snappy", "gzip", "lz4", "brotli", "zstd", "none"];
    let script = "import pyarrow.parquet as pq, pathlib, sys\n\
        root = pathlib.Path(sys.argv[1])\n\
        for codec in sys.argv[2:]:\n\
        \x20   for f in (root / 'demo/tables').rglob('*.parquet'):\n\
        \x20       out = root / ('t_' + codec) / f.relative_to(root / 'demo/tables')\n\
        \x20       out.parent.mkdir(parents=True, exist_ok=True)\n\
        \x20       pq.write_table(pq.read_table(f), out, compression=codec)\n\
        \x20       assert pq.ParquetFile(out).metadata.row_group(0).column(0).compression == codec.upper().replace('NONE', 'UNCOMPRESSED'), out\n";
    let ran = Command::new(python).arg("-c").arg(script).arg(d).args(codecs).output().unwrap();
    assert!(ran.status.success(), "{}", String::from_utf8_lossy(&ran.stderr));

    let analyzed = mmtrack(d, &["analyze", "demo/tables", "-o", "a_ours", "-q"]);
    assert!(analyzed.status.success(), "{}", text(&analyzed).1);
    let ours = std::fs::read_to_string(d.join("a_ours/report.md")).unwrap();
    for codec in codecs {
        let tables = format!("t_{codec}");
        let out = mmtrack(d, &["analyze", &tables, "-o", &format!("a_{codec}"), "-q"]);
        assert!(out.status.success(), "analyze {codec}: {}", text(&out).1);
        let report = std::fs::read_to_string(d.join(format!("a_{codec}/report.md"))).unwrap();
        assert_eq!(report.replace(&tables, "demo/tables"), ours, "{codec}");
        let out = mmtrack(d, &["export", "--format", "tum", &tables, "-o", &format!("e_{codec}"), "-q"]);
        assert!(out.status.success(), "export {codec}: {}", text(&out).1);
        let file = format!("{tables}/odometry/sequence=oxford-demo/part-0.parquet");
        let out = mmtrack(d, &["inspect", &file]);
        let (stdout, stderr) = text(&out);
        assert!(out.status.success(), "inspect {codec}: {stderr}");
        assert!(stdout.contains("odometry / sequence=oxford-demo: 160 rows"), "{codec}: {stdout}");
    }
}
