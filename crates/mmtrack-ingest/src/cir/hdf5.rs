//! HDF5 datasets and MATLAB v7.3 `.mat` files: recognising them, and the
//! entry points of their reader, which exists only in builds with the `hdf5`
//! cargo feature (it links the system libhdf5 through the `hdf5-metno`
//! crate; see `hdf5_read.rs`). Without the feature both entry points return
//! [`IngestError::FeatureMissing`], naming the file and saying how to rebuild.
//!
//! # HDF5 (`--format hdf5`)
//!
//! One dataset holds the array; the sidecar key `dataset` names it by its path
//! (`"/sounder/cir"`; a file holding one dataset needs no key). Its dimensions
//! are used in HDF5's own (C, row-major) order, and the sidecar's `axes` name
//! them as for `.npy` files. Accepted element types:
//! - a compound of two numeric members `r` and `i` (h5py's and `hdf5-metno`'s
//!   complex numbers) or `real` and `imag` (MATLAB's), any member order,
//!   float or integer of any width and byte order;
//! - a real float or integer array whose last dimension has size 2: I then Q.
//!
//! Every value is converted to `f64` by libhdf5 (`H5Dread` with a memory type
//! of doubles). Strings, enums (h5py's booleans), references, arrays and other
//! compounds are refused, naming the type found.
//!
//! # MATLAB v7.3 (`--format mat`)
//!
//! `save -v7.3` writes an HDF5 file with a 512-byte user block. The user block
//! starts with the 128-byte MAT-file header of the v5 format (116 bytes of text
//! beginning `MATLAB 7.3 MAT-file`, 8 bytes of subsystem offset, version
//! `0x0200`, endian mark `IM`; MathWorks, "MAT-File Format", section "MAT-File
//! Header"), and the HDF5 superblock follows at byte 512 (HDF5 File Format
//! Specification version 3.0, section II.A: the signature
//! `\x89HDF\r\n\x1a\n` is looked for at byte 0, 512, 1024, 2048, ...). A file
//! given as `--format mat` is read as v7.3 when its header text says
//! `MATLAB 7.3`, its version field is `0x0200`, or the HDF5 signature is at
//! byte 512; otherwise by the v5 reader (`matlab.rs`).
//!
//! In the file, each variable is a dataset at the root, named as in MATLAB,
//! with a string attribute `MATLAB_class` (`double`, `single`, `int16`, ...;
//! cells, structs, `char` and `logical` are refused as in v5 files). Complex
//! arrays are compounds `{real, imag}`. MATLAB stores its column-major data
//! as is and writes the dimensions reversed: a MATLAB `(n0, n1, n2)` array is
//! an HDF5 `(n2, n1, n0)` dataset whose row-major order is MATLAB's
//! column-major order. The reader reverses the dimensions back, so axes and
//! element order are MATLAB's, exactly as from the v5 reader: the sidecar's
//! `axes` (or [`super::MatCirLayout`]'s axes) mean the same for a v5 and a
//! v7.3 save of the same array, and give the same CIRs (pinned by a test).
//! Read as `--format hdf5` instead, the same file shows the HDF5 dimensions,
//! reversed.

use std::io::Read;
use std::path::Path;

use super::array::{MatlabArray, NdComplex};
use crate::IngestError;
use crate::error::os_err;

/// The 8-byte HDF5 format signature (`\x89HDF\r\n\x1a\n`).
pub(crate) const HDF5_SIGNATURE: [u8; 8] = [0x89, b'H', b'D', b'F', b'\r', b'\n', 0x1a, b'\n'];

/// Whether the start of a `.mat` file (its first 520 bytes suffice) is a
/// MATLAB v7.3 (HDF5) file rather than a v5/v7 one (see the module docs).
pub(crate) fn is_mat73(head: &[u8]) -> bool {
    let text = head.starts_with(b"MATLAB 7.3 MAT-file");
    let version = head.get(124..128).is_some_and(|v| v == [0x00, 0x02, b'I', b'M'] || v == [0x02, 0x00, b'M', b'I']);
    let signature = head.get(512..520).is_some_and(|s| s == HDF5_SIGNATURE);
    text || version || signature
}

/// Reads the first bytes of a file, enough for [`is_mat73`].
pub(crate) fn file_head(path: &Path) -> Result<Vec<u8>, IngestError> {
    let file = std::fs::File::open(path).map_err(os_err(path))?;
    let mut head = Vec::with_capacity(520);
    file.take(520).read_to_end(&mut head).map_err(os_err(path))?;
    Ok(head)
}

/// The complex array in dataset `dataset` (`None`: the file's only dataset)
/// of an HDF5 file, and its path in the file.
pub(crate) fn read_hdf5_array(path: &Path, dataset: Option<&str>) -> Result<(String, NdComplex), IngestError> {
    #[cfg(feature = "hdf5")]
    {
        super::hdf5_read::read_dataset(path, dataset)
    }
    #[cfg(not(feature = "hdf5"))]
    {
        let _ = dataset;
        Err(missing(path, "an HDF5 file"))
    }
}

/// The numeric MATLAB variable `variable` of a v7.3 `.mat` file.
pub(crate) fn read_mat73_variable(path: &Path, variable: &str) -> Result<MatlabArray, IngestError> {
    #[cfg(feature = "hdf5")]
    {
        super::hdf5_read::read_mat73(path, variable)
    }
    #[cfg(not(feature = "hdf5"))]
    {
        let _ = variable;
        Err(missing(path, "a MATLAB v7.3 (HDF5) .mat file (or re-save it with `save -v7`)"))
    }
}

/// The error of a build without the `hdf5` feature.
#[cfg(not(feature = "hdf5"))]
fn missing(path: &Path, input: &str) -> IngestError {
    IngestError::FeatureMissing {
        path: path.to_path_buf(),
        input: input.into(),
        feature: "hdf5",
        needs: "it links libhdf5 1.10 or newer; Debian: `apt-get install libhdf5-dev`",
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A 512-byte v7.3 user block (the MAT header padded) and the HDF5 signature.
    pub(crate) fn mat73_head() -> Vec<u8> {
        let mut head = format!("{:<116}", "MATLAB 7.3 MAT-file, Platform: GLNXA64, HDF5 schema 1.00 .").into_bytes();
        head.extend_from_slice(&[0; 8]);
        head.extend_from_slice(&0x0200u16.to_le_bytes());
        head.extend_from_slice(b"IM");
        head.resize(512, 0);
        head.extend_from_slice(&HDF5_SIGNATURE);
        head
    }

    #[test]
    fn v73_files_are_recognised_by_text_version_or_signature() {
        let head = mat73_head();
        assert!(is_mat73(&head));
        // Any one of the three marks suffices; a v5 header has none.
        let mut by_signature = vec![b' '; 124];
        by_signature.extend_from_slice(&[0, 1, b'I', b'M']);
        assert!(!is_mat73(&by_signature));
        by_signature.resize(512, 0);
        by_signature.extend_from_slice(&HDF5_SIGNATURE);
        assert!(is_mat73(&by_signature));
        let mut by_version = head[..128].to_vec();
        by_version[..6].copy_from_slice(b"MATLAB");
        by_version[7..10].copy_from_slice(b"x.y");
        assert!(is_mat73(&by_version));
        assert!(is_mat73(b"MATLAB 7.3 MAT-file"));
        assert!(!is_mat73(b"MATLAB 5.0 MAT-file"));
    }

    /// The default build (what CI runs) names the file and the feature.
    #[cfg(not(feature = "hdf5"))]
    #[test]
    fn without_the_feature_hdf5_inputs_say_how_to_rebuild() {
        use super::super::{CirFormat, CirSidecar, ingest_cir, read_cir_file};
        let dir = tempfile::tempdir().unwrap();
        let mat = dir.path().join("v73.mat");
        std::fs::write(&mat, mat73_head()).unwrap();
        let sidecar = CirSidecar::parse(Path::new("s.toml"), "variable = \"h\"\ncarrier_hz = 1e9").unwrap();
        let err = read_cir_file(CirFormat::Mat, &mat, Some(&sidecar)).unwrap_err().to_string();
        assert!(err.starts_with(&format!("{}: a MATLAB v7.3 (HDF5) .mat file", mat.display())), "{err}");
        assert!(err.contains("`hdf5` cargo feature") && err.contains("--features hdf5"), "{err}");
        assert!(err.contains("libhdf5") && err.contains("save -v7"), "{err}");
        // The MatCirLayout reader too; the byte reader refuses v7.3 as before.
        let layout = super::super::MatCirLayout {
            variable: "h".into(),
            carrier_hz: 1e9,
            tap_spacing_s: 1e-9,
            delay_offset_s: 0.0,
            t_ns: 0,
            tap_axis: 1,
            tx_axis: None,
            rx_axis: None,
            allow_real: false,
        };
        let err = super::super::read_mat_cir_file(&mat, &layout).unwrap_err().to_string();
        assert!(err.contains("--features hdf5"), "{err}");
        // --format hdf5, also through ingest_cir: no output is left behind.
        let h5 = dir.path().join("cir.h5");
        std::fs::write(&h5, HDF5_SIGNATURE).unwrap();
        let out = dir.path().join("out.mcap");
        let err =
            ingest_cir(CirFormat::Hdf5, &h5, None, &out, &Default::default(), &mut |_, _| {}).unwrap_err().to_string();
        assert!(err.starts_with(&format!("{}: an HDF5 file needs", h5.display())), "{err}");
        assert!(err.contains("--features hdf5"), "{err}");
        assert!(!out.exists());
        // A missing file is still an OS error naming it.
        let err = read_cir_file(CirFormat::Mat, &dir.path().join("none.mat"), Some(&sidecar)).unwrap_err();
        assert!(matches!(err, IngestError::Os { .. }), "{err}");
    }
}
