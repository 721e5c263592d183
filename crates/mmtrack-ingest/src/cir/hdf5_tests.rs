//! Tests of the HDF5 and MATLAB v7.3 reader (`cargo test -p mmtrack-ingest
//! --features hdf5`). Fixtures are written at test time into temporary
//! folders, by `hdf5-metno` itself and, where Python with h5py can be had, by
//! h5py (an independent writer bundling its own libhdf5).

use std::path::{Path, PathBuf};
use std::process::Command;

use h5::types::FixedAscii;
use hdf5_metno as h5;
use mmtrack_core::{CirSnapshot, Complex64};

use super::hdf5::tests::mat73_head;
use super::hdf5_read::element::{RealImag, Ri};
use super::matlab::tests::{indexed_array, mat_file, matrix};
use super::{CirFormat, CirSidecar, MatCirLayout, ingest_cir, read_cir_file, read_mat_cir_file};
use crate::IngestError;

mod narrow {
    //! Narrower complex members than the reader's, to check libhdf5 converts them.
    use hdf5_metno::H5Type;

    #[derive(H5Type, Clone, Copy)]
    #[repr(C)]
    pub struct Ri32 {
        pub r: f32,
        pub i: f32,
    }

    /// Members in the other order, as some writers store them.
    #[derive(H5Type, Clone, Copy)]
    #[repr(C)]
    pub struct ImagReal16 {
        pub imag: i16,
        pub real: i16,
    }
}
use narrow::{ImagReal16, Ri32};

fn sidecar(text: &str) -> CirSidecar {
    CirSidecar::parse(Path::new("s.toml"), text).unwrap()
}

/// Snapshot `s`, tap `k` of the small test channel (exact in f32 and i16).
fn value(s: usize, k: usize) -> Complex64 {
    let v = (10 * s + k) as f64;
    Complex64::new(v, 0.5 - v)
}

/// 2 snapshots of 3 taps, times 1 ms apart.
const SIDECAR: &str = "carrier_hz = 28e9\ntap_spacing_s = 1e-9\nsnapshot_period_s = 1e-3\n";

fn check_channel(cirs: &[CirSnapshot]) {
    assert_eq!(cirs.len(), 2);
    for (s, c) in cirs.iter().enumerate() {
        assert_eq!(c.taps, (0..3).map(|k| value(s, k)).collect::<Vec<_>>(), "snapshot {s}");
        assert_eq!((c.t_ns, c.carrier_hz, c.tap_spacing_s), (s as i64 * 1_000_000, 28e9, 1e-9));
    }
}

/// Writes every layout of the test channel into one file.
fn write_channel(path: &Path) {
    let file = h5::File::create(path).unwrap();
    let group = file.create_group("sounder").unwrap();
    let at = |s: usize, k: usize| value(s, k);
    let ri32: Vec<Ri32> = (0..6).map(|n| at(n / 3, n % 3)).map(|v| Ri32 { r: v.re as f32, i: v.im as f32 }).collect();
    group.new_dataset::<Ri32>().shape([2, 3]).create("ri32").unwrap().write_raw(&ri32).unwrap();
    let realimag: Vec<RealImag> =
        (0..6).map(|n| at(n / 3, n % 3)).map(|v| RealImag { real: v.re, imag: v.im }).collect();
    group.new_dataset::<RealImag>().shape([2, 3]).create("realimag").unwrap().write_raw(&realimag).unwrap();
    // Taps first: (3, 2), to be named by `axes`.
    let transposed: Vec<Ri> = (0..6).map(|n| at(n % 2, n / 2)).map(|v| Ri { r: v.re, i: v.im }).collect();
    group.new_dataset::<Ri>().shape([3, 2]).create("taps_first").unwrap().write_raw(&transposed).unwrap();
    // (2, 3, 2) float32 and (2, 3, 2) int16 with a trailing I/Q axis (0.5 is not an
    // integer: the int16 channel holds 2 * value).
    let iq: Vec<f32> = (0..6).flat_map(|n| [at(n / 3, n % 3).re as f32, at(n / 3, n % 3).im as f32]).collect();
    file.new_dataset::<f32>().shape([2, 3, 2]).create("iq").unwrap().write_raw(&iq).unwrap();
    let iq16: Vec<i16> = iq.iter().map(|&v| (2.0 * v) as i16).collect();
    file.new_dataset::<i16>().shape([2, 3, 2]).create("iq16").unwrap().write_raw(&iq16).unwrap();
    let swapped: Vec<ImagReal16> = (0..6)
        .map(|n| at(n / 3, n % 3))
        .map(|v| ImagReal16 { imag: (2.0 * v.im) as i16, real: (2.0 * v.re) as i16 })
        .collect();
    file.new_dataset::<ImagReal16>().shape([2, 3]).create("swapped16").unwrap().write_raw(&swapped).unwrap();
}

#[test]
fn complex_compounds_and_iq_axes_give_the_same_cirs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("channel.h5");
    write_channel(&path);
    for (dataset, extra) in [
        ("/sounder/ri32", ""),
        ("sounder/realimag", ""),
        ("/sounder/taps_first", "axes = [\"tap\", \"snapshot\"]\n"),
        ("/iq", ""),
    ] {
        let s = sidecar(&format!("{SIDECAR}dataset = \"{dataset}\"\n{extra}"));
        let file = read_cir_file(CirFormat::Hdf5, &path, Some(&s)).unwrap();
        check_channel(&file.snapshots);
        assert_eq!(file.metadata["cir.format"], "hdf5");
        assert!(file.metadata["cir.array"].starts_with("dataset `/"), "{:?}", file.metadata);
    }
    // Integer storage, members in either order: the channel times 2.
    for dataset in ["/iq16", "/swapped16"] {
        let s = sidecar(&format!("{SIDECAR}dataset = \"{dataset}\"\n"));
        let cirs = read_cir_file(CirFormat::Hdf5, &path, Some(&s)).unwrap().snapshots;
        assert_eq!(cirs[1].taps[2], value(1, 2) * 2.0, "{dataset}");
    }
    // Several datasets and no `dataset` key: listed, with the key to set.
    let err = read_cir_file(CirFormat::Hdf5, &path, Some(&sidecar(SIDECAR))).unwrap_err().to_string();
    assert!(err.starts_with(&format!("{}: holds `/iq` (float32 2x3x2)", path.display())), "{err}");
    assert!(err.contains("`/sounder/ri32` (compound {r: float32, i: float32} 2x3)"), "{err}");
    assert!(err.contains("choose one with `dataset = \"...\"`"), "{err}");
    // One dataset needs no key.
    let single = dir.path().join("single.h5");
    let file = h5::File::create(&single).unwrap();
    let ri: Vec<Ri> = (0..6).map(|n| value(n / 3, n % 3)).map(|v| Ri { r: v.re, i: v.im }).collect();
    file.new_dataset::<Ri>().shape([2, 3]).create("cir").unwrap().write_raw(&ri).unwrap();
    drop(file);
    let cir = read_cir_file(CirFormat::Hdf5, &single, Some(&sidecar(SIDECAR))).unwrap();
    check_channel(&cir.snapshots);
    // `variable` is the .mat key, not HDF5's.
    let err = read_cir_file(CirFormat::Hdf5, &single, Some(&sidecar("variable = \"cir\""))).unwrap_err();
    assert!(err.to_string().contains("key `variable`: does not apply to --format hdf5"), "{err}");
}

/// Writes MATLAB array `(dims)` (column-major `real`/`imag`) as a v7.3 file
/// would hold it: 512-byte user block with the MAT header, variable `name`
/// with reversed dimensions, `MATLAB_class`, complex as `{real, imag}`.
fn write_mat73(path: &Path, name: &str, dims: &[usize], real: &[f64], imag: Option<&[f64]>, class: &str) {
    let file = h5::File::with_options().with_fcpl(|p| p.userblock(512)).create(path).unwrap();
    let reversed: Vec<usize> = dims.iter().rev().copied().collect();
    let ds = match imag {
        Some(imag) => {
            let values: Vec<RealImag> = real.iter().zip(imag).map(|(&real, &imag)| RealImag { real, imag }).collect();
            let ds = file.new_dataset::<RealImag>().shape(reversed).create(name).unwrap();
            ds.write_raw(&values).unwrap();
            ds
        }
        None => {
            let ds = file.new_dataset::<f64>().shape(reversed).create(name).unwrap();
            ds.write_raw(real).unwrap();
            ds
        }
    };
    let class = FixedAscii::<16>::from_ascii(class).unwrap();
    ds.new_attr::<FixedAscii<16>>().create("MATLAB_class").unwrap().write_scalar(&class).unwrap();
    drop(ds);
    file.close().unwrap();
    let mut bytes = std::fs::read(path).unwrap();
    bytes[..128].copy_from_slice(&mat73_head()[..128]);
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn a_v73_file_gives_the_same_cirs_as_the_v5_file_of_the_same_array() {
    let dir = tempfile::tempdir().unwrap();
    let (real, imag) = indexed_array();
    let v5 = dir.path().join("v5.mat");
    std::fs::write(&v5, mat_file(&[matrix("h", &[2, 3, 4], &real, Some(&imag))])).unwrap();
    let v73 = dir.path().join("v73.mat");
    write_mat73(&v73, "h", &[2, 3, 4], &real, Some(&imag), "double");
    assert_eq!(&std::fs::read(&v73).unwrap()[512..520], b"\x89HDF\r\n\x1a\n");
    for axes in ["", "axes = [\"rx\", \"tx\", \"tap\"]", "axes = [\"tx\", \"rx\", \"tap\"]"] {
        let s = sidecar(&format!("variable = \"h\"\ncarrier_hz = 60e9\ntap_spacing_s = 1e-10\n{axes}"));
        let a = read_cir_file(CirFormat::Mat, &v5, Some(&s)).unwrap();
        let b = read_cir_file(CirFormat::Mat, &v73, Some(&s)).unwrap();
        assert_eq!(a.snapshots, b.snapshots, "{axes}");
        assert_eq!(a.snapshots.len(), 6);
        assert_eq!(a.metadata["cir.axes"], b.metadata["cir.axes"]);
        assert_eq!(a.metadata["cir.mat_version"], "5 (v5/v7)");
        assert!(b.metadata["cir.mat_version"].starts_with("7.3 (HDF5"), "{:?}", b.metadata);
    }
    // MATLAB's h(i, j, k) = (i-1) + 10 (j-1) + 100 (k-1): TX 2 (j = 3), RX 1 (i = 2), tap 3 (k = 4).
    let s = sidecar("variable = \"h\"\ncarrier_hz = 60e9\ntap_spacing_s = 1e-10\n");
    let b = read_cir_file(CirFormat::Mat, &v73, Some(&s)).unwrap();
    let c = b.snapshots.iter().find(|c| (c.tx_antenna, c.rx_antenna) == (2, 1)).unwrap();
    assert_eq!(c.taps[3], Complex64::new(321.0, -321.0));
    // The MatCirLayout reader too.
    let layout = MatCirLayout {
        variable: "h".into(),
        carrier_hz: 60e9,
        tap_spacing_s: 1e-10,
        delay_offset_s: 0.0,
        t_ns: 5,
        tap_axis: 2,
        tx_axis: Some(1),
        rx_axis: Some(0),
        allow_real: false,
    };
    assert_eq!(read_mat_cir_file(&v5, &layout).unwrap(), read_mat_cir_file(&v73, &layout).unwrap());
    // As plain HDF5 the dimensions are the stored (reversed) ones.
    let s = sidecar("dataset = \"h\"\ncarrier_hz = 60e9\ntap_spacing_s = 1e-10\naxes = [\"tap\", \"tx\", \"rx\"]");
    let plain = read_cir_file(CirFormat::Hdf5, &v73, Some(&s)).unwrap();
    assert_eq!(plain.snapshots, b.snapshots);
    // Real arrays as in v5: refused unless allow_real; single and integer classes read.
    let real_v73 = dir.path().join("real.mat");
    write_mat73(&real_v73, "r", &[2, 3, 4], &real, None, "single");
    let s = sidecar("variable = \"r\"\ncarrier_hz = 60e9\ntap_spacing_s = 1e-10\n");
    let err = read_cir_file(CirFormat::Mat, &real_v73, Some(&s)).unwrap_err().to_string();
    assert!(err.contains("variable `r` (single 2x3x4): complex flag: a real array"), "{err}");
    let s = sidecar("variable = \"r\"\ncarrier_hz = 60e9\ntap_spacing_s = 1e-10\nallow_real = true\n");
    let cirs = read_cir_file(CirFormat::Mat, &real_v73, Some(&s)).unwrap().snapshots;
    assert_eq!(cirs[5].taps[3], Complex64::new(321.0, 0.0));
}

#[test]
fn matlab_classes_and_groups_that_are_not_numbers_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (real, imag) = indexed_array();
    let s =
        |v: &str| sidecar(&format!("variable = \"{v}\"\ncarrier_hz = 1e9\ntap_spacing_s = 1e-9\nallow_real = true"));
    for class in ["logical", "char", "cell"] {
        let path = dir.path().join(format!("{class}.mat"));
        write_mat73(&path, "x", &[2, 3, 4], &real, None, class);
        let err = read_cir_file(CirFormat::Mat, &path, Some(&s("x"))).unwrap_err().to_string();
        assert!(err.contains(&format!("variable `x`: MATLAB_class: {class}, expected a numeric")), "{err}");
    }
    let path = dir.path().join("struct.mat");
    write_mat73(&path, "h", &[2, 3, 4], &real, Some(&imag), "double");
    let file = h5::File::open_rw(&path).unwrap();
    let group = file.create_group("st").unwrap();
    let class = FixedAscii::<16>::from_ascii("struct").unwrap();
    group.new_attr::<FixedAscii<16>>().create("MATLAB_class").unwrap().write_scalar(&class).unwrap();
    let empty = file.new_dataset::<u64>().shape([2]).create("e").unwrap();
    empty.write_raw(&[0u64, 0]).unwrap();
    empty
        .new_attr::<FixedAscii<16>>()
        .create("MATLAB_class")
        .unwrap()
        .write_scalar(&FixedAscii::<16>::from_ascii("double").unwrap())
        .unwrap();
    empty.new_attr::<u8>().create("MATLAB_empty").unwrap().write_scalar(&1u8).unwrap();
    drop((group, empty));
    file.close().unwrap();
    let err = read_cir_file(CirFormat::Mat, &path, Some(&s("st"))).unwrap_err().to_string();
    assert!(err.contains("variable `st`: MATLAB_class: struct, stored as an HDF5 group"), "{err}");
    let err = read_cir_file(CirFormat::Mat, &path, Some(&s("e"))).unwrap_err().to_string();
    assert!(err.contains("variable `e`: MATLAB_empty: an empty array"), "{err}");
    // A missing variable lists the others in MATLAB's dimension order.
    let err = read_cir_file(CirFormat::Mat, &path, Some(&s("CIR"))).unwrap_err().to_string();
    assert!(err.starts_with(&format!("{}: no variable `CIR` in the v7.3 file", path.display())), "{err}");
    assert!(err.contains("`h` (double complex 2x3x4)") && err.contains("`st` (group)"), "{err}");
}

/// Reads `path` as `--format hdf5` with dataset `/cir` into a recording, and
/// checks that it fails without leaving the recording behind.
fn ingest_fails(path: &Path) -> String {
    let out = path.with_extension("mcap");
    let dir = path.parent().unwrap();
    let sidecar_path = dir.join("s.toml");
    std::fs::write(&sidecar_path, format!("{SIDECAR}dataset = \"/cir\"\n")).unwrap();
    let result = ingest_cir(CirFormat::Hdf5, path, Some(&sidecar_path), &out, &Default::default(), &mut |_, _| {});
    assert!(!out.exists(), "{} left behind", out.display());
    result.unwrap_err().to_string()
}

#[test]
fn bad_inputs_are_named_and_leave_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.h5");
    let file = h5::File::create(&path).unwrap();
    let mut ri: Vec<Ri> = (0..6).map(|n| value(n / 3, n % 3)).map(|v| Ri { r: v.re, i: v.im }).collect();
    ri[5].i = f64::NAN;
    file.new_dataset::<Ri>().shape([2, 3]).create("cir").unwrap().write_raw(&ri).unwrap();
    let text = FixedAscii::<8>::from_ascii("not taps").unwrap();
    file.new_dataset::<FixedAscii<8>>().shape([2]).create("text").unwrap().write_raw(&[text, text]).unwrap();
    file.new_dataset::<f64>().shape([2, 3]).create("real").unwrap().write_raw(&[0.0; 6]).unwrap();
    file.new_dataset::<f64>().shape(()).create("scalar").unwrap().write_scalar(&1.0).unwrap();
    file.create_group("grp").unwrap();
    file.close().unwrap();
    let read = |dataset: &str| {
        let s = sidecar(&format!("{SIDECAR}dataset = \"{dataset}\"\n"));
        read_cir_file(CirFormat::Hdf5, &path, Some(&s)).unwrap_err().to_string()
    };
    let name = path.display().to_string();
    // NaN: file, dataset, snapshot and field.
    let err = ingest_fails(&path);
    assert!(err.starts_with(&format!("{name}: dataset `/cir`, snapshot 1, TX 0, RX 0: taps:")), "{err}");
    // Missing dataset and a group: file and dataset named, contents listed.
    let err = read("/nope");
    assert!(err.starts_with(&format!("{name}: `/nope`: no such dataset; the file holds `/cir`")), "{err}");
    assert!(read("/grp").contains("`/grp`: is a group, not a dataset"));
    // Wrong element types and shapes.
    let err = read("/text");
    assert!(
        err.contains("dataset `/text`: element type: string (len 8), expected numbers with a trailing I/Q"),
        "{err}"
    );
    let err = read("/real");
    assert!(err.contains("dataset `/real`: shape: shape [2, 3]: a real array needs a trailing I/Q axis"), "{err}");
    assert!(read("/scalar").contains("dataset `/scalar`: shape: a scalar (float64)"));
    // Not HDF5 at all, and a missing file.
    let junk = dir.path().join("junk.h5");
    std::fs::write(&junk, vec![7u8; 4096]).unwrap();
    let err = ingest_fails(&junk);
    assert!(err.starts_with(&format!("{}: not a readable HDF5 file (libhdf5: ", junk.display())), "{err}");
    let err = read_cir_file(CirFormat::Hdf5, &dir.path().join("none.h5"), None).unwrap_err();
    assert!(matches!(err, IngestError::Os { .. }), "{err}");
}

#[test]
fn truncated_files_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.h5");
    let file = h5::File::create(&good).unwrap();
    let ri: Vec<Ri> = (0..600).map(|n| value(n / 3, n % 3)).map(|v| Ri { r: v.re, i: v.im }).collect();
    file.new_dataset::<Ri>().shape([200, 3]).create("cir").unwrap().write_raw(&ri).unwrap();
    file.close().unwrap();
    let (real, imag) = indexed_array();
    let mat = dir.path().join("good.mat");
    write_mat73(&mat, "h", &[2, 3, 4], &real, Some(&imag), "double");
    let s = sidecar("variable = \"h\"\ncarrier_hz = 1e9\ntap_spacing_s = 1e-9\n");
    read_cir_file(CirFormat::Mat, &mat, Some(&s)).unwrap();
    for (source, format) in [(&good, CirFormat::Hdf5), (&mat, CirFormat::Mat)] {
        let bytes = std::fs::read(source).unwrap();
        let cut_path = dir.path().join("cut.bin");
        // Every 97th length, and the last few bytes.
        let cuts: Vec<usize> = (0..bytes.len()).step_by(97).chain(bytes.len() - 8..bytes.len()).collect();
        for cut in cuts {
            std::fs::write(&cut_path, &bytes[..cut]).unwrap();
            let s = sidecar(if format == CirFormat::Mat {
                "variable = \"h\"\ncarrier_hz = 1e9\ntap_spacing_s = 1e-9\n"
            } else {
                "dataset = \"/cir\"\ncarrier_hz = 1e9\ntap_spacing_s = 1e-9\nsnapshot_period_s = 1e-3\n"
            });
            let err = read_cir_file(format, &cut_path, Some(&s)).unwrap_err().to_string();
            assert!(err.starts_with(&cut_path.display().to_string()), "cut at {cut}: {err}");
        }
    }
    std::fs::write(dir.path().join("cir.h5"), &std::fs::read(&good).unwrap()[..1000]).unwrap();
    let err = ingest_fails(&dir.path().join("cir.h5"));
    assert!(err.contains("not a readable HDF5 file") && err.contains("truncated"), "{err}");
}

/// Python with h5py: the system's, or a venv under the target directory.
fn h5py_python() -> Option<PathBuf> {
    const REQUIREMENTS: &str = "h5py==3.16.0 numpy==2.4.6";
    let works = |python: &Path| {
        Command::new(python).args(["-c", "import h5py, numpy"]).output().is_ok_and(|o| o.status.success())
    };
    if works(Path::new("python3")) {
        return Some("python3".into());
    }
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target"));
    let venv = target.join("h5py-venv");
    let python = venv.join("bin/python");
    let stamp = venv.join("requirements.txt");
    if std::fs::read_to_string(&stamp).ok().as_deref() == Some(REQUIREMENTS) && works(&python) {
        return Some(python);
    }
    let ok = Command::new("python3").args(["-m", "venv"]).arg(&venv).status().is_ok_and(|s| s.success())
        && Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
            .args(REQUIREMENTS.split(' '))
            .status()
            .is_ok_and(|s| s.success());
    (ok && std::fs::write(&stamp, REQUIREMENTS).is_ok()).then_some(python)
}

/// h5py (with its own, newer libhdf5) writes complex64 as `{r, i}` float32,
/// big-endian complex128, chunked gzip datasets, I/Q int16, and a v7.3-style
/// file through its `userblock_size`; all read back as the channel.
#[test]
fn h5py_written_files() {
    let Some(python) = h5py_python() else {
        eprintln!("skipped: python3 with h5py (PyPI) not available for the h5py conformance test");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let script = r#"
import sys, h5py, numpy as np
d = sys.argv[1]
s, k = np.meshgrid(np.arange(2), np.arange(3), indexing="ij")
v = 10 * s + k
h = (v + 1j * (0.5 - v))
with h5py.File(d + "/py.h5", "w") as f:
    f["c64"] = h.astype(np.complex64)
    f.create_dataset("be128", data=h.astype(">c16"))
    f.create_dataset("zipped/cir", data=h, chunks=(1, 3), compression="gzip")
    f["iq16"] = (2 * np.stack([h.real, h.imag], axis=-1)).astype(np.int16)
with h5py.File(d + "/py.mat", "w", userblock_size=512) as f:
    f["h"] = np.ascontiguousarray(h.T).view(np.dtype([("real", "<f8"), ("imag", "<f8")]))
    f["h"].attrs["MATLAB_class"] = np.bytes_("double")
head = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, written by h5py".ljust(116) + bytes(8) + b"\x00\x02IM"
with open(d + "/py.mat", "r+b") as f:
    f.write(head)
"#;
    let ran = Command::new(&python).arg("-c").arg(script).arg(dir.path()).output().unwrap();
    assert!(ran.status.success(), "h5py script failed: {}", String::from_utf8_lossy(&ran.stderr));
    let path = dir.path().join("py.h5");
    for dataset in ["/c64", "/be128", "/zipped/cir"] {
        let s = sidecar(&format!("{SIDECAR}dataset = \"{dataset}\"\n"));
        check_channel(&read_cir_file(CirFormat::Hdf5, &path, Some(&s)).unwrap().snapshots);
    }
    let s = sidecar(&format!("{SIDECAR}dataset = \"/iq16\"\n"));
    let cirs = read_cir_file(CirFormat::Hdf5, &path, Some(&s)).unwrap().snapshots;
    assert_eq!(cirs[1].taps[2], value(1, 2) * 2.0);
    // MATLAB (2 snapshots, 3 taps) stored as HDF5 (3, 2): axes in MATLAB's order.
    let s = sidecar(&format!("{SIDECAR}variable = \"h\"\naxes = [\"snapshot\", \"tap\"]\n"));
    check_channel(&read_cir_file(CirFormat::Mat, &dir.path().join("py.mat"), Some(&s)).unwrap().snapshots);
}
