//! Tests of the MATLAB v5 reader (`matlab.rs`); the helpers build v5 files
//! byte by byte and are shared with the HDF5 tests.

use super::*;

/// Tag + data + padding to 8 bytes (little-endian).
fn element(data_type: u32, data: &[u8]) -> Vec<u8> {
    let mut out = data_type.to_le_bytes().to_vec();
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
    out.resize(out.len().next_multiple_of(8), 0);
    out
}

/// A `miMATRIX` of class double with `miDOUBLE` data.
pub(crate) fn matrix(name: &str, dims: &[i32], real: &[f64], imag: Option<&[f64]>) -> Vec<u8> {
    let flags: u32 = 6 | if imag.is_some() { 0x0800 } else { 0 };
    let mut body = element(6, &[flags.to_le_bytes(), 0u32.to_le_bytes()].concat());
    body.extend(element(5, &dims.iter().flat_map(|d| d.to_le_bytes()).collect::<Vec<_>>()));
    body.extend(element(1, name.as_bytes()));
    body.extend(element(9, &real.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<_>>()));
    if let Some(imag) = imag {
        body.extend(element(9, &imag.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<_>>()));
    }
    element(MI_MATRIX, &body)
}

/// Wraps an element in a `miCOMPRESSED` element (zlib stored blocks).
fn compressed(inner: &[u8]) -> Vec<u8> {
    let mut z = vec![0x78, 0x01];
    let chunks: Vec<&[u8]> = inner.chunks(65_535).collect();
    for (i, chunk) in chunks.iter().enumerate() {
        z.push(u8::from(i + 1 == chunks.len()));
        let len = chunk.len() as u16;
        z.extend_from_slice(&len.to_le_bytes());
        z.extend_from_slice(&(!len).to_le_bytes());
        z.extend_from_slice(chunk);
    }
    z.extend_from_slice(&adler2::adler32_slice(inner).to_be_bytes());
    let mut out = MI_COMPRESSED.to_le_bytes().to_vec();
    out.extend_from_slice(&(z.len() as u32).to_le_bytes());
    out.extend(z);
    out
}

pub(crate) fn mat_file(elements: &[Vec<u8>]) -> Vec<u8> {
    let mut out = format!("{:<116}", "MATLAB 5.0 MAT-file, written by mmtrack tests").into_bytes();
    out.extend_from_slice(&[0; 8]);
    out.extend_from_slice(&0x0100u16.to_le_bytes());
    out.extend_from_slice(b"IM");
    for e in elements {
        out.extend_from_slice(e);
    }
    out
}

fn layout(variable: &str) -> MatCirLayout {
    MatCirLayout {
        variable: variable.into(),
        carrier_hz: 60e9,
        tap_spacing_s: 1e-10,
        delay_offset_s: 0.0,
        t_ns: 5,
        tap_axis: 2,
        tx_axis: Some(1),
        rx_axis: Some(0),
        allow_real: false,
    }
}

/// A (2, 3, 4) array whose element (i, j, k) is i + 10 j + 100 k, minus that as imaginary part.
pub(crate) fn indexed_array() -> (Vec<f64>, Vec<f64>) {
    let mut real = vec![0.0; 24];
    for k in 0..4 {
        for j in 0..3 {
            for i in 0..2 {
                real[i + 2 * j + 6 * k] = (i + 10 * j + 100 * k) as f64;
            }
        }
    }
    let imag = real.iter().map(|v| -v).collect();
    (real, imag)
}

#[test]
fn column_major_order_and_axes() {
    let (real, imag) = indexed_array();
    let other = matrix("note", &[1, 1], &[1.0], None);
    for bytes in [
        mat_file(&[other.clone(), matrix("h", &[2, 3, 4], &real, Some(&imag))]),
        mat_file(&[compressed(&other), compressed(&matrix("h", &[2, 3, 4], &real, Some(&imag)))]),
    ] {
        let cirs = read_mat_cir(Path::new("t.mat"), &bytes, &layout("h")).unwrap();
        assert_eq!(cirs.len(), 6);
        // TX-major: (tx 0, rx 0), (tx 0, rx 1), (tx 1, rx 0), ...
        assert_eq!(
            cirs.iter().map(|c| (c.tx_antenna, c.rx_antenna)).collect::<Vec<_>>()[..3],
            [(0, 0), (0, 1), (1, 0)]
        );
        for c in &cirs {
            let (i, j) = (c.rx_antenna as usize, c.tx_antenna as usize);
            let expected: Vec<Complex64> = (0..4)
                .map(|k| {
                    let v = (i + 10 * j + 100 * k) as f64;
                    Complex64::new(v, -v)
                })
                .collect();
            assert_eq!(c.taps, expected);
            assert_eq!((c.t_ns, c.carrier_hz, c.tap_spacing_s), (5, 60e9, 1e-10));
        }
    }
    // Swapping the antenna axes swaps the roles.
    let bytes = mat_file(&[matrix("h", &[2, 3, 4], &real, Some(&imag))]);
    let swapped = MatCirLayout { tx_axis: Some(0), rx_axis: Some(1), ..layout("h") };
    let cirs = read_mat_cir(Path::new("t.mat"), &bytes, &swapped).unwrap();
    let c = cirs.iter().find(|c| c.tx_antenna == 1 && c.rx_antenna == 2).unwrap();
    assert_eq!(c.taps[3], Complex64::new(321.0, -321.0));
}

#[test]
fn siso_vector_and_narrow_storage_types() {
    // A 1x3 row vector of int16-stored doubles, taps on axis 1, no antennas.
    let mut body = element(6, &[(6u32 | 0x0800).to_le_bytes(), 0u32.to_le_bytes()].concat());
    body.extend(element(5, &[1i32, 3].iter().flat_map(|d| d.to_le_bytes()).collect::<Vec<_>>()));
    // Name in the small element format.
    body.extend_from_slice(&[1, 0, 1, 0, b'v', 0, 0, 0]);
    body.extend(element(3, &[-2i16, 0, 7].iter().flat_map(|d| d.to_le_bytes()).collect::<Vec<_>>()));
    body.extend(element(2, &[1u8, 2, 3]));
    let bytes = mat_file(&[element(MI_MATRIX, &body)]);
    let siso = MatCirLayout { tap_axis: 1, tx_axis: None, rx_axis: None, ..layout("v") };
    let cirs = read_mat_cir(Path::new("t.mat"), &bytes, &siso).unwrap();
    assert_eq!(cirs.len(), 1);
    assert_eq!((cirs[0].tx_antenna, cirs[0].rx_antenna), (0, 0));
    let expected = [Complex64::new(-2.0, 1.0), Complex64::new(0.0, 2.0), Complex64::new(7.0, 3.0)];
    assert_eq!(cirs[0].taps, expected);
    // Taps on axis 0 leave axis 1 (size 3) unnamed: refused.
    let err = read_mat_cir(Path::new("t.mat"), &bytes, &MatCirLayout { tap_axis: 0, ..siso }).unwrap_err();
    assert!(err.to_string().contains("axis 1 (0-based) has size 3"), "{err}");
}

#[test]
fn bad_inputs_are_named() {
    let path = Path::new("x.mat");
    let (real, imag) = indexed_array();
    let good = mat_file(&[matrix("h", &[2, 3, 4], &real, Some(&imag)), matrix("r", &[2, 3, 4], &real, None)]);
    // Unknown variable: the message lists what is there.
    let err = read_mat_cir(path, &good, &layout("CIR")).unwrap_err().to_string();
    assert!(err.contains("no variable `CIR`") && err.contains("`h` (double complex 2x3x4)"), "{err}");
    assert!(err.contains("`r` (double 2x3x4)") && err.starts_with("x.mat"), "{err}");
    // Real array where complex is required, unless allowed.
    let err = read_mat_cir(path, &good, &layout("r")).unwrap_err().to_string();
    assert!(err.contains("variable `r`") && err.contains("complex flag") && err.contains("real array"), "{err}");
    let cirs = read_mat_cir(path, &good, &MatCirLayout { allow_real: true, ..layout("r") }).unwrap();
    assert_eq!(cirs[5].taps[3], Complex64::new(321.0, 0.0));
    // Wrong number of dimensions.
    let flat = mat_file(&[matrix("h", &[6, 4], &real, Some(&imag))]);
    let err = read_mat_cir(path, &flat, &layout("h")).unwrap_err().to_string();
    assert!(err.contains("2 dimensions, expected 3"), "{err}");
    let four = mat_file(&[matrix("h", &[2, 3, 2, 2], &real, Some(&imag))]);
    let err = read_mat_cir(path, &four, &layout("h")).unwrap_err().to_string();
    assert!(err.contains("4 dimensions, expected 3"), "{err}");
    // Truncated, at every length, plain and compressed: an error, never a panic.
    let plain = mat_file(&[matrix("h", &[2, 3, 4], &real, Some(&imag))]);
    let zipped = mat_file(&[compressed(&matrix("h", &[2, 3, 4], &real, Some(&imag)))]);
    for bytes in [&plain, &zipped] {
        for cut in 0..bytes.len() {
            assert!(read_mat_cir(path, &bytes[..cut], &layout("h")).is_err(), "cut at {cut}");
        }
    }
    let err = read_mat_cir(path, &zipped[..zipped.len() - 10], &layout("h")).unwrap_err().to_string();
    assert!(err.contains("truncated") && err.contains("variable 1"), "{err}");
    let err = read_mat_cir(path, &good[..100], &layout("h")).unwrap_err().to_string();
    assert!(err.contains("truncated") && err.contains("file header"), "{err}");
    // Data shorter than the dimensions promise.
    let short = mat_file(&[matrix("h", &[2, 3, 4], &real[..20], Some(&imag[..20]))]);
    let err = read_mat_cir(path, &short, &layout("h")).unwrap_err().to_string();
    assert!(err.contains("real part") && err.contains("promise 24"), "{err}");
    // NaN taps.
    let mut nan = real.clone();
    nan[7] = f64::NAN;
    let err = read_mat_cir(path, &mat_file(&[matrix("h", &[2, 3, 4], &nan, Some(&imag))]), &layout("h"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("taps of TX 0, RX 1"), "{err}");
    // v7.3 and non-MAT files.
    let err = read_mat_cir(path, b"MATLAB 7.3 MAT-file, Platform: GLNXA64", &layout("h")).unwrap_err().to_string();
    assert!(err.contains("HDF5"), "{err}");
    let err = read_mat_cir(path, b"\x89HDF\r\n\x1a\n\0\0", &layout("h")).unwrap_err().to_string();
    assert!(err.contains("an HDF5 file without a MAT-file header") && err.contains("--format hdf5"), "{err}");
    let err = read_mat_cir(path, &[b'x'; 200], &layout("h")).unwrap_err().to_string();
    assert!(err.contains("endian mark"), "{err}");
    // Bad layouts.
    let err = read_mat_cir(path, &good, &MatCirLayout { tx_axis: Some(2), ..layout("h") }).unwrap_err();
    assert!(err.to_string().contains("distinct"), "{err}");
    let err = read_mat_cir(path, &good, &MatCirLayout { tap_spacing_s: 0.0, ..layout("h") }).unwrap_err();
    assert!(err.to_string().contains("tap spacing"), "{err}");
}

#[test]
fn big_endian_files_read() {
    let be = |v: u32| v.to_be_bytes();
    let mut body = Vec::new();
    body.extend([be(6), be(8), be(6), be(0)].concat());
    body.extend([be(5), be(8), 1i32.to_be_bytes(), 2i32.to_be_bytes()].concat());
    body.extend([be(1), be(1)].concat());
    body.extend_from_slice(&[b'b', 0, 0, 0, 0, 0, 0, 0]);
    body.extend([be(9), be(16)].concat());
    body.extend([1.5f64.to_be_bytes(), (-2.0f64).to_be_bytes()].concat());
    let mut bytes = format!("{:<116}", "MATLAB 5.0 MAT-file").into_bytes();
    bytes.extend_from_slice(&[0; 8]);
    bytes.extend_from_slice(&0x0100u16.to_be_bytes());
    bytes.extend_from_slice(b"MI");
    bytes.extend([be(MI_MATRIX), be(body.len() as u32)].concat());
    bytes.extend(body);
    let siso = MatCirLayout { tap_axis: 1, tx_axis: None, rx_axis: None, allow_real: true, ..layout("b") };
    let cirs = read_mat_cir(Path::new("be.mat"), &bytes, &siso).unwrap();
    assert_eq!(cirs[0].taps, [Complex64::new(1.5, 0.0), Complex64::new(-2.0, 0.0)]);
}

const REAL_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/realdata/but-60ghz-mimo");

/// Measured 60 GHz 4x4 MIMO channel, Brno University of Technology, from
/// jirimilos/802.11ad-phy-sim (MIT); cite Liu, Blumenstein, Perović,
/// Di Renzo and Springer, IEEE Trans. Commun. 66(1), 2018.
#[test]
fn real_but_60ghz_mimo_cir_matches_its_ctf() {
    let cir_path = Path::new(REAL_DIR).join("CIR.mat");
    let ctf_path = Path::new(REAL_DIR).join("CTF.mat");
    if !cir_path.exists() || !ctf_path.exists() {
        eprintln!("skipped: real data not found at {REAL_DIR}");
        return;
    }
    // 1001 CTF bins 10 MHz apart: taps 1 / (1001 * 10 MHz) apart; 60 GHz is the band centre.
    let spacing_s = 1.0 / (1001.0 * 10e6);
    let cir_layout = MatCirLayout {
        variable: "CIR_mat".into(),
        carrier_hz: 60e9,
        tap_spacing_s: spacing_s,
        delay_offset_s: 0.0,
        t_ns: 0,
        tap_axis: 2,
        tx_axis: Some(1),
        rx_axis: Some(0),
        allow_real: false,
    };
    let cirs = read_mat_cir_file(&cir_path, &cir_layout).unwrap();
    assert_eq!(cirs.len(), 16);
    assert!(cirs.iter().all(|c| c.taps.len() == 1001));
    // Column-major pinned on the real file: CIR_mat(2, 3, 4) (MATLAB 1-based) = element 1 + 4*2 + 16*3.
    let c = cirs.iter().find(|c| c.rx_antenna == 1 && c.tx_antenna == 2).unwrap();
    assert_eq!(c.taps[3], Complex64::new(-6.543996683095209e-7, 1.0508738127214991e-6));
    assert_eq!(cirs[0].taps[0], Complex64::new(-6.524074846171194e-7, 2.656656347839611e-7));
    // The strongest tap of every link is tap 83 (8.3 ns, about 2.49 m).
    for c in &cirs {
        let peak = (0..c.taps.len()).max_by(|&a, &b| c.taps[a].norm().total_cmp(&c.taps[b].norm())).unwrap();
        assert_eq!(peak, 83, "TX {} RX {}", c.tx_antenna, c.rx_antenna);
    }
    // CIR = inverse DFT of CTF, link by link (a direct O(N^2) DFT: 16 million terms).
    let ctfs = read_mat_cir_file(&ctf_path, &MatCirLayout { variable: "CTF_mat".into(), ..cir_layout }).unwrap();
    let n = 1001;
    let twiddle: Vec<Complex64> =
        (0..n).map(|m| Complex64::from_polar(1.0, 2.0 * std::f64::consts::PI * m as f64 / n as f64)).collect();
    let mut worst = 0.0f64;
    for (cir, ctf) in cirs.iter().zip(&ctfs) {
        assert_eq!((cir.tx_antenna, cir.rx_antenna), (ctf.tx_antenna, ctf.rx_antenna));
        let scale = cir.taps.iter().map(|t| t.norm()).fold(0.0, f64::max);
        for (tap, &h) in cir.taps.iter().enumerate() {
            let sum: Complex64 = ctf.taps.iter().enumerate().map(|(bin, &x)| x * twiddle[(bin * tap) % n]).sum();
            worst = worst.max((sum / n as f64 - h).norm() / scale);
        }
    }
    assert!(worst < 1e-9, "CIR differs from IDFT(CTF) by {worst:e} of the peak");
}

use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    /// Arbitrary bytes, and valid files with bytes flipped or cut, never panic.
    #[test]
    fn reader_never_panics(
        junk in proptest::collection::vec(any::<u8>(), 0..400),
        flips in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..6),
        cut in any::<usize>(),
        zip in any::<bool>(),
    ) {
        let path = Path::new("p.mat");
        let _ = read_mat_cir(path, &junk, &layout("h"));
        let mut with_header = mat_file(&[]);
        with_header.extend_from_slice(&junk);
        let _ = read_mat_cir(path, &with_header, &layout("h"));
        let (real, imag) = indexed_array();
        let m = matrix("h", &[2, 3, 4], &real, Some(&imag));
        let mut bytes = mat_file(&[if zip { compressed(&m) } else { m }]);
        for (at, value) in flips {
            let at = 128 + at % (bytes.len() - 128);
            bytes[at] = value;
        }
        let cut = cut % (bytes.len() + 1);
        let _ = read_mat_cir(path, &bytes[..cut], &layout("h"));
        let _ = read_mat_cir(path, &bytes, &MatCirLayout { tx_axis: None, allow_real: true, ..layout("h") });
    }
}

/// As for npz: a compressed variable may inflate to 16 MiB plus 100 times
/// its compressed size (found by fuzzing the npy reader, which shares the
/// bound; a 1 MiB `.mat` could otherwise become a 2 GiB buffer).
#[test]
fn compressed_variable_bomb_is_refused() {
    // 32 MiB of zeros deflate about 1000-fold, past the 100-fold bound.
    let zeros = vec![0u8; 32 << 20];
    let z = miniz_oxide::deflate::compress_to_vec_zlib(&zeros, 6);
    assert!(super::super::inflate::inflate_limit(z.len(), MAX_VARIABLE_BYTES) < zeros.len(), "{}", z.len());
    let mut element = MI_COMPRESSED.to_le_bytes().to_vec();
    element.extend_from_slice(&(z.len() as u32).to_le_bytes());
    element.extend(z);
    let file = mat_file(&[element]);
    let e = read_mat_cir(Path::new("b.mat"), &file, &layout("h")).unwrap_err().to_string();
    assert!(e.contains("b.mat") && e.contains("variable 1 (byte 128)") && e.contains("data element"), "{e}");
    assert!(e.contains("compressed variable: decompresses to more than"), "{e}");
    assert!(e.contains("more than 100 times its compressed size") && e.contains("save -v6"), "{e}");
}

/// Without a sidecar naming the variable, the error lists the file's
/// variables and shows the sidecar line that picks one (the real BUT file:
/// one variable, `CIR_mat`).
#[test]
fn a_mat_file_without_a_variable_named_lists_its_variables() {
    let cir_path = Path::new(REAL_DIR).join("CIR.mat");
    assert!(cir_path.exists(), "real data not found at {REAL_DIR}");
    let err = crate::cir::read_cir_file(crate::cir::CirFormat::Mat, &cir_path, None).unwrap_err().to_string();
    assert!(err.contains("key `variable`") && err.contains("it holds `CIR_mat` (double complex"), "{err}");
    assert!(err.contains("`variable = \"CIR_mat\"`") && err.contains("--sidecar"), "{err}");
}
