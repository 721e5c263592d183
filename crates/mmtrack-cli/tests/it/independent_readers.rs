//! An independent client reads our files: Python's `mcap` (with protobuf
//! decoding from the embedded descriptors), pyarrow and duckdb check counts,
//! schema names, values and units metadata. The script lives in
//! `tests/python/`; its packages are installed from PyPI into a venv under
//! the target directory. Skips with a visible line where Python or PyPI is
//! unavailable.

use std::path::{Path, PathBuf};
use std::process::Command;

use mmtrack_core::{CirSnapshot, Complex64, GnssFix, GnssFixQuality, MpcTrack, MpcTruth, Se2, StampedPose};
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase};
use mmtrack_io::table::{RunInfo, write_table};
use mmtrack_io::{Overwrite, RecordingOptions, RecordingWriter};

use super::common::{mmtrack, root};

const REQUIREMENTS: &str = "mcap==1.6.0 mcap-protobuf-support==0.6.0 protobuf==7.36.2 pyarrow==26.0.1 duckdb==2.0.0";

fn venv_python() -> Option<PathBuf> {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target"));
    let venv = std::env::var_os("MMTRACK_PY_VENV").map(PathBuf::from).unwrap_or_else(|| target.join("py-venv"));
    let python = venv.join("bin/python");
    let stamp = venv.join("requirements.txt");
    if std::fs::read_to_string(&stamp).ok().as_deref() == Some(REQUIREMENTS) && python.is_file() {
        return Some(python);
    }
    let system = ["python3", "python"]
        .into_iter()
        .find(|p| Command::new(p).arg("--version").output().is_ok_and(|o| o.status.success()))?;
    let ok = Command::new(system).args(["-m", "venv"]).arg(&venv).status().is_ok_and(|s| s.success())
        && Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
            .args(REQUIREMENTS.split(' '))
            .status()
            .is_ok_and(|s| s.success());
    if !ok {
        return None;
    }
    std::fs::write(&stamp, REQUIREMENTS).ok()?;
    Some(python)
}

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
        writer.write_pose(PoseStream::GroundTruth, &pose, "world", "vehicle").unwrap();
    }
    writer
        .write_gnss_fix(&GnssFix {
            t_ns: 1_000_000_000,
            latitude_deg: 51.762042,
            longitude_deg: -1.262751,
            altitude_m: 65.176138,
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

    let run = RunInfo { config_json: r#"{"who":"independent reader test"}"#.into() };
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
