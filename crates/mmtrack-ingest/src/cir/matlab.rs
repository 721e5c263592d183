//! Channel impulse responses stored as numeric arrays in MATLAB v5 `.mat`
//! files (the format of `save` in MATLAB 5 to 7.2 and of `save -v7`, the
//! default; also written by SciPy's `savemat`).
//!
//! A `.mat` file is a 128-byte header (text, version 0x0100, endian mark `IM`
//! or `MI`) followed by one element per variable: either a `miMATRIX` (type 14)
//! or a `miCOMPRESSED` (type 15) element holding a zlib stream of one
//! `miMATRIX`. A `miMATRIX` holds sub-elements: array flags (class, complex
//! bit), dimensions, name, real part, and imaginary part when complex. Data may
//! be stored in a narrower type than the class (MATLAB writes integer-valued
//! doubles as `miINT8`, ...); every numeric storage type is widened to `f64`.
//!
//! MATLAB arrays are column-major: element `(i, j, k)` of an `(n0, n1, n2)`
//! array is at `i + n0 * (j + n1 * k)` (pinned by a test).
//!
//! The file says nothing about what the axes mean, the carrier, the tap spacing
//! or the time, so [`MatCirLayout`] says it (the CLI fills it from a sidecar
//! file). One [`CirSnapshot`] is produced per (TX, RX) antenna pair, TX-major.
//!
//! Choices:
//! - The file structure is read here, by hand: the crate depends on no `.mat`
//!   crate (the `matfile` crate, which reads these files, was dropped from the
//!   workspace as a dependency). MATLAB's default `-v7` files compress every
//!   variable (the real sample below is compressed); the zlib streams are
//!   inflated by `miniz_oxide` (the inflater the `png` crate already brings),
//!   bounded as `inflate.rs` says. Being our own code, errors name the
//!   variable, the byte offset and the sub-element, and big-endian files are
//!   read too.
//! - A real (non-complex) array is refused unless [`MatCirLayout::allow_real`]:
//!   a real "CIR" is usually a magnitude or a power profile, and treating it as
//!   complex amplitudes with zero phase would silently mislabel it.
//! - The array must have exactly as many dimensions as the layout uses (at
//!   least 2, as MATLAB always stores); dimensions the layout does not name
//!   must be 1. MATLAB drops trailing singleton dimensions, so a one-tap
//!   `(4, 4, 1)` array is stored as `(4, 4)` and is refused as 2-D.
//! - Only numeric classes (double, single, integers) are read; cells, structs,
//!   character, logical and sparse arrays are refused.
//! - `-v7.3` files are HDF5 files: [`read_mat_cir_file`] and the sidecar
//!   reader hand them to the HDF5 reader (`hdf5.rs`, in builds with the `hdf5`
//!   cargo feature; without it, an error says how to rebuild), which gives the
//!   same array in the same MATLAB axis order. [`read_mat_cir`], given bytes,
//!   reads v5/v7 only and refuses v7.3 with a message saying so.
//!
//! Real data used by the tests: `CIR.mat` / `CTF.mat` of the measured static
//! indoor 60 GHz 4x4 MIMO channel of Brno University of Technology, from the
//! public repository jirimilos/802.11ad-phy-sim (MIT licence; please cite
//! P. Liu, J. Blumenstein, N. S. Perović, M. Di Renzo and A. Springer,
//! "Performance of Generalized Spatial Modulation MIMO Over Measured 60GHz
//! Indoor Channels", IEEE Trans. Commun. 66(1), 2018). `CIR_mat` is complex
//! double `(4, 4, 1001)` and equals the inverse DFT of `CTF_mat` (1001 bins,
//! 55-65 GHz in 10 MHz steps) to rounding, so its taps are `1 / (1001 * 10 MHz)`
//! = 99.9 ps apart (the authors' scripts round this to 0.1 ns). As the DFT bins
//! are indexed from 55 GHz, tap `n` carries a phase ramp `exp(j pi 1000 n / 1001)`
//! relative to a CIR centred on 60 GHz; magnitudes are unaffected. Neither the
//! data nor its README says which of the first two dimensions is TX.

use std::path::Path;

use mmtrack_core::{CirSnapshot, Complex64};

use super::inflate::{INFLATE_LIMIT_HINT, inflate_limit, zlib_decompress};
use crate::IngestError;

/// What a `.mat` file does not say about a CIR array.
#[derive(Debug, Clone, PartialEq)]
pub struct MatCirLayout {
    /// Name of the MATLAB variable holding the CIRs.
    pub variable: String,
    /// Carrier (centre) frequency, hertz.
    pub carrier_hz: f64,
    /// Delay between consecutive taps, seconds.
    pub tap_spacing_s: f64,
    /// Delay of tap 0, seconds.
    pub delay_offset_s: f64,
    /// Measurement time given to every snapshot, nanoseconds.
    pub t_ns: i64,
    /// 0-based dimension holding the taps (MATLAB dimension `tap_axis + 1`).
    pub tap_axis: usize,
    /// 0-based dimension indexing the transmit antenna; `None`: one TX (index 0).
    pub tx_axis: Option<usize>,
    /// 0-based dimension indexing the receive antenna; `None`: one RX (index 0).
    pub rx_axis: Option<usize>,
    /// Accept a real array as taps with zero imaginary part (see the module docs).
    pub allow_real: bool,
}

/// `miMATRIX`: an array.
const MI_MATRIX: u32 = 14;
/// `miCOMPRESSED`: a zlib stream holding one element.
const MI_COMPRESSED: u32 = 15;
/// Decompressed variables larger than this are refused (bounds memory on
/// hostile input; far above any CIR file). Below it, a variable may inflate
/// to 16 MiB plus 100 times its compressed size (`inflate::inflate_limit`).
const MAX_VARIABLE_BYTES: usize = 1 << 31;

/// Reads the CIRs of `layout.variable` from the bytes of a `.mat` file.
pub fn read_mat_cir(path: &Path, bytes: &[u8], layout: &MatCirLayout) -> Result<Vec<CirSnapshot>, IngestError> {
    check_layout(path, layout)?;
    let array = find_variable(path, bytes, &layout.variable)?;
    snapshots(path, &array, layout)
}

/// Reads a `.mat` file and its CIRs (see [`read_mat_cir`]); v7.3 files too,
/// in builds with the `hdf5` feature.
pub fn read_mat_cir_file(path: &Path, layout: &MatCirLayout) -> Result<Vec<CirSnapshot>, IngestError> {
    check_layout(path, layout)?;
    let array = load_variable(path, &layout.variable)?;
    snapshots(path, &array, layout)
}

/// Variable `variable` of the `.mat` file at `path`, decoded: v5/v7 files
/// here, v7.3 files by the HDF5 reader.
fn load_variable(path: &Path, variable: &str) -> Result<MatArray, IngestError> {
    if super::hdf5::is_mat73(&super::hdf5::file_head(path)?) {
        let array = super::hdf5::read_mat73_variable(path, variable)?;
        let class = (6..=15).find(|&c| class_name(c) == array.class).unwrap_or(6);
        return Ok(MatArray {
            name: variable.to_string(),
            class,
            complex: array.imag.is_some(),
            logical: false,
            dims: array.dims,
            real: array.real,
            imag: array.imag,
        });
    }
    let bytes = crate::error::read_capped(path, &mmtrack_core::limits::ARRAY_FILE_BYTES)?;
    find_variable(path, &bytes, variable)
}

/// The numeric array `variable` as a complex array in MATLAB's column-major
/// order, for the sidecar-driven reader ([`super::read_cir_file`]). A real
/// array is refused unless `allow_real` (see the module docs).
pub(crate) fn read_mat_array(
    path: &Path,
    variable: &str,
    allow_real: bool,
) -> Result<super::array::NdComplex, IngestError> {
    let array = load_variable(path, variable)?;
    if array.imag.is_none() && !allow_real {
        return Err(IngestError::BadRecord {
            path: path.to_path_buf(),
            record: format!("variable `{variable}` ({})", array.describe()),
            field: "complex flag".into(),
            detail: "a real array; expected complex taps (set `allow_real = true` in the sidecar to read it with \
                     zero imaginary part)"
                .into(),
        });
    }
    let imag = array.imag.as_deref();
    let values =
        array.real.iter().enumerate().map(|(i, &re)| Complex64::new(re, imag.map_or(0.0, |im| im[i]))).collect();
    Ok(super::array::NdComplex::new(array.dims, values, true))
}

fn check_layout(path: &Path, layout: &MatCirLayout) -> Result<(), IngestError> {
    let bad = |detail: String| Err(IngestError::BadLayout { path: path.to_path_buf(), detail });
    if !(layout.tap_spacing_s.is_finite() && layout.tap_spacing_s > 0.0) {
        return bad(format!("layout: tap spacing {} s, expected a positive finite value", layout.tap_spacing_s));
    }
    if !(layout.carrier_hz.is_finite() && layout.carrier_hz >= 0.0) {
        return bad(format!("layout: carrier {} Hz, expected a finite value >= 0", layout.carrier_hz));
    }
    if !layout.delay_offset_s.is_finite() {
        return bad(format!("layout: delay offset {} s, expected a finite value", layout.delay_offset_s));
    }
    let axes = [Some(layout.tap_axis), layout.tx_axis, layout.rx_axis];
    for (i, a) in axes.iter().enumerate() {
        if a.is_some() && axes[..i].contains(a) {
            return bad(format!("layout: {} must be distinct dimensions", describe_axes(layout)));
        }
    }
    Ok(())
}

/// "taps on axis 2, TX on axis 1, RX on axis 0" for messages.
fn describe_axes(layout: &MatCirLayout) -> String {
    let axis = |a: Option<usize>| a.map_or("no axis (one antenna)".to_string(), |a| format!("axis {a}"));
    format!("taps on axis {}, TX on {}, RX on {}", layout.tap_axis, axis(layout.tx_axis), axis(layout.rx_axis))
}

/// An array's header, and its data once decoded.
#[derive(Debug, Clone)]
struct MatArray {
    name: String,
    class: u8,
    complex: bool,
    logical: bool,
    dims: Vec<usize>,
    real: Vec<f64>,
    imag: Option<Vec<f64>>,
}

impl MatArray {
    /// "double complex 4x4x1001" for messages.
    fn describe(&self) -> String {
        let dims = self.dims.iter().map(ToString::to_string).collect::<Vec<_>>().join("x");
        let complex = if self.complex { " complex" } else { "" };
        let logical = if self.logical { " logical" } else { "" };
        format!("{}{logical}{complex} {dims}", class_name(self.class))
    }
}

fn class_name(class: u8) -> &'static str {
    match class {
        1 => "cell",
        2 => "struct",
        3 => "object",
        4 => "char",
        5 => "sparse",
        6 => "double",
        7 => "single",
        8 => "int8",
        9 => "uint8",
        10 => "int16",
        11 => "uint16",
        12 => "int32",
        13 => "uint32",
        14 => "int64",
        15 => "uint64",
        16 => "function handle",
        17 => "opaque object",
        _ => "unknown class",
    }
}

fn is_numeric_class(class: u8) -> bool {
    (6..=15).contains(&class)
}

#[derive(Clone, Copy)]
struct Endian {
    big: bool,
}

impl Endian {
    fn u32_at(self, bytes: &[u8], at: usize) -> Option<u32> {
        let raw: [u8; 4] = bytes.get(at..at.checked_add(4)?)?.try_into().ok()?;
        Some(if self.big { u32::from_be_bytes(raw) } else { u32::from_le_bytes(raw) })
    }

    fn u16_at(self, bytes: &[u8], at: usize) -> Option<u16> {
        let raw: [u8; 2] = bytes.get(at..at.checked_add(2)?)?.try_into().ok()?;
        Some(if self.big { u16::from_be_bytes(raw) } else { u16::from_le_bytes(raw) })
    }
}

/// One data element: its type, its data and where the next one starts.
struct Element<'a> {
    data_type: u32,
    data: &'a [u8],
    next: usize,
}

/// Reads the element at `at`, in the normal (8-byte tag) or small (4-byte tag,
/// data in the same 8 bytes) format. `pad` rounds the next position up to 8
/// bytes (not done after `miCOMPRESSED`, whose size is exact).
fn element(bytes: &[u8], at: usize, endian: Endian) -> Result<Element<'_>, String> {
    let Some(first) = endian.u32_at(bytes, at) else {
        return Err(format!("truncated: element tag at byte {at} runs past the end ({} bytes)", bytes.len()));
    };
    let small_size = first >> 16;
    if small_size != 0 {
        if small_size > 4 {
            return Err(format!("small element at byte {at} claims {small_size} bytes, at most 4 fit"));
        }
        let Some(data) = bytes.get(at + 4..at + 4 + small_size as usize) else {
            return Err(format!("truncated: small element at byte {at} runs past the end"));
        };
        return Ok(Element { data_type: first & 0xffff, data, next: at + 8 });
    }
    let Some(size) = endian.u32_at(bytes, at + 4) else {
        return Err(format!("truncated: element tag at byte {at} runs past the end ({} bytes)", bytes.len()));
    };
    let size = size as usize;
    let start = at + 8;
    let Some(data) = start.checked_add(size).and_then(|end| bytes.get(start..end)) else {
        return Err(format!(
            "truncated: element at byte {at} declares {size} bytes, only {} remain",
            bytes.len().saturating_sub(start)
        ));
    };
    let next = if first == MI_COMPRESSED { start + size } else { start + size.next_multiple_of(8) };
    Ok(Element { data_type: first, data, next })
}

/// Walks the top-level elements until `variable` is found.
fn find_variable(path: &Path, bytes: &[u8], variable: &str) -> Result<MatArray, IngestError> {
    match walk_variables(path, bytes, Some(variable))? {
        Ok(array) => Ok(array),
        Err(seen) => {
            let present = if seen.is_empty() { "no variables".to_string() } else { describe_variables(&seen) };
            Err(IngestError::BadLayout {
                path: path.to_path_buf(),
                detail: format!("no variable `{variable}` in the file; it holds {present}"),
            })
        }
    }
}

/// The variables of the v5/v7 `.mat` file at `path` as (name, class and
/// dims), in file order (none listed for a v7.3 file), for the error that
/// asks which one to read.
pub(crate) fn list_variables(path: &Path) -> Result<Vec<(String, String)>, IngestError> {
    if super::hdf5::is_mat73(&super::hdf5::file_head(path)?) {
        return Ok(Vec::new());
    }
    let bytes = crate::error::read_capped(path, &mmtrack_core::limits::ARRAY_FILE_BYTES)?;
    Ok(walk_variables(path, &bytes, None)?.err().unwrap_or_default())
}

/// Walks the top-level elements until `wanted` is found (decoded) or the
/// file ends: then the variables seen, described.
fn walk_variables(
    path: &Path,
    bytes: &[u8],
    wanted: Option<&str>,
) -> Result<Result<MatArray, Vec<(String, String)>>, IngestError> {
    let endian = file_header(path, bytes)?;
    let bad = |record: String, detail: String| IngestError::BadRecord {
        path: path.to_path_buf(),
        record,
        field: "data element".into(),
        detail,
    };
    let mut seen: Vec<(String, String)> = Vec::new();
    let mut at = 128;
    while at < bytes.len() {
        let record = format!("variable {} (byte {at})", seen.len() + 1);
        let top = element(bytes, at, endian).map_err(|detail| bad(record.clone(), detail))?;
        let decompressed;
        let matrix_body = match top.data_type {
            MI_MATRIX => top.data,
            MI_COMPRESSED => {
                let limit = inflate_limit(top.data.len(), MAX_VARIABLE_BYTES);
                decompressed = zlib_decompress(top.data, limit).map_err(|detail| {
                    let hint = if detail.contains("more than") {
                        format!(" ({INFLATE_LIMIT_HINT}, save -v6)")
                    } else {
                        String::new()
                    };
                    bad(record.clone(), format!("compressed variable: {detail}{hint}"))
                })?;
                let inner = element(&decompressed, 0, endian)
                    .map_err(|detail| bad(record.clone(), format!("inside the compressed variable: {detail}")))?;
                if inner.data_type != MI_MATRIX {
                    return Err(bad(
                        record,
                        format!("compressed element holds type {}, expected miMATRIX (14)", inner.data_type),
                    ));
                }
                inner.data
            }
            other => {
                return Err(bad(record, format!("type {other}, expected miMATRIX (14) or miCOMPRESSED (15)")));
            }
        };
        let mut array = array_header(matrix_body, endian).map_err(|(field, detail)| IngestError::BadRecord {
            path: path.to_path_buf(),
            record: record.clone(),
            field: field.into(),
            detail,
        })?;
        if let Some(variable) = wanted.filter(|&v| v == array.name) {
            let record = format!("variable `{variable}`");
            decode_data(matrix_body, endian, &mut array).map_err(|(field, detail)| IngestError::BadRecord {
                path: path.to_path_buf(),
                record,
                field: field.into(),
                detail,
            })?;
            return Ok(Ok(array));
        }
        let description = array.describe();
        seen.push((array.name, description));
        at = top.next;
    }
    Ok(Err(seen))
}

/// "`name` (class, dims)" for each variable, comma-separated.
pub(crate) fn describe_variables(variables: &[(String, String)]) -> String {
    variables.iter().map(|(name, what)| format!("`{name}` ({what})")).collect::<Vec<_>>().join(", ")
}

/// Checks the 128-byte header; returns the byte order.
fn file_header(path: &Path, bytes: &[u8]) -> Result<Endian, IngestError> {
    let bad = |detail: String| IngestError::BadRecord {
        path: path.to_path_buf(),
        record: "file header (bytes 0-127)".into(),
        field: "MAT-file header".into(),
        detail,
    };
    if super::hdf5::is_mat73(bytes) {
        return Err(bad("a MATLAB v7.3 (HDF5) file; bytes are read as v5/v7 only: read the file by its path \
                        (with the `hdf5` feature) or re-save with `save -v7`"
            .into()));
    }
    if bytes.starts_with(&super::hdf5::HDF5_SIGNATURE) {
        return Err(bad("an HDF5 file without a MAT-file header: read it as HDF5 (`--format hdf5`)".into()));
    }
    let Some(header) = bytes.get(..128) else {
        return Err(bad(format!("truncated: {} bytes, a MAT-file header alone is 128", bytes.len())));
    };
    let endian = match &header[126..128] {
        b"IM" => Endian { big: false },
        b"MI" => Endian { big: true },
        other => {
            return Err(bad(format!(
                "endian mark {:?} at bytes 126-127, expected \"IM\" or \"MI\" (not a MATLAB v5/v7 file)",
                String::from_utf8_lossy(other)
            )));
        }
    };
    match endian.u16_at(header, 124) {
        Some(0x0100) => Ok(endian),
        version => Err(bad(format!("version {version:04x?} at bytes 124-125, expected 0x0100 (MATLAB v5/v7)"))),
    }
}

/// Reads flags, dimensions and name of a `miMATRIX` body.
fn array_header(body: &[u8], endian: Endian) -> Result<MatArray, (&'static str, String)> {
    let flags = element(body, 0, endian).map_err(|e| ("array flags", e))?;
    let Some(flag_word) = endian.u32_at(flags.data, 0).filter(|_| flags.data_type == 6 && flags.data.len() == 8) else {
        return Err((
            "array flags",
            format!("type {} of {} bytes, expected miUINT32 (6) of 8 bytes", flags.data_type, flags.data.len()),
        ));
    };
    let class = (flag_word & 0xff) as u8;
    let mut array = MatArray {
        name: String::new(),
        class,
        complex: flag_word & 0x0800 != 0,
        logical: flag_word & 0x0200 != 0,
        dims: Vec::new(),
        real: Vec::new(),
        imag: None,
    };
    if class == 17 {
        // Opaque objects (classdef, strings) have no dimensions sub-element.
        let name = element(body, flags.next, endian).map_err(|e| ("array name", e))?;
        array.name = String::from_utf8_lossy(name.data).into_owned();
        return Ok(array);
    }
    let dims = element(body, flags.next, endian).map_err(|e| ("dimensions", e))?;
    if dims.data_type != 5 || !dims.data.len().is_multiple_of(4) || dims.data.is_empty() {
        return Err((
            "dimensions",
            format!(
                "type {} of {} bytes, expected miINT32 (5), 4 bytes per dimension",
                dims.data_type,
                dims.data.len()
            ),
        ));
    }
    for k in 0..dims.data.len() / 4 {
        let value = endian.u32_at(dims.data, 4 * k).unwrap_or(0) as i32;
        let Ok(size) = usize::try_from(value) else {
            return Err(("dimensions", format!("dimension {k} is {value}, expected >= 0")));
        };
        array.dims.push(size);
    }
    let name = element(body, dims.next, endian).map_err(|e| ("array name", e))?;
    if name.data_type != 1 {
        return Err(("array name", format!("type {}, expected miINT8 (1)", name.data_type)));
    }
    array.name = String::from_utf8_lossy(name.data).into_owned();
    Ok(array)
}

/// Decodes the real and imaginary parts of a numeric array whose header
/// [`array_header`] has read.
fn decode_data(body: &[u8], endian: Endian, array: &mut MatArray) -> Result<(), (&'static str, String)> {
    if !is_numeric_class(array.class) || array.logical {
        return Err(("class", format!("{}, expected a numeric (double, single or integer) array", array.describe())));
    }
    let count = array
        .dims
        .iter()
        .try_fold(1usize, |acc, &d| acc.checked_mul(d))
        .ok_or_else(|| ("dimensions", format!("{} elements overflow", array.describe())))?;
    // Skip flags, dimensions and name again to reach the data.
    let mut at = 0;
    for _ in 0..3 {
        at = element(body, at, endian).map_err(|e| ("array header", e))?.next;
    }
    let real = element(body, at, endian).map_err(|e| ("real part", e))?;
    array.real = numbers(real.data_type, real.data, count, endian).map_err(|e| ("real part", e))?;
    if array.complex {
        let imag = element(body, real.next, endian).map_err(|e| ("imaginary part", e))?;
        array.imag = Some(numbers(imag.data_type, imag.data, count, endian).map_err(|e| ("imaginary part", e))?);
    }
    Ok(())
}

/// Widens `count` stored numbers of MAT data type `data_type` to `f64`.
fn numbers(data_type: u32, data: &[u8], count: usize, endian: Endian) -> Result<Vec<f64>, String> {
    let (width, name) = match data_type {
        1 => (1, "miINT8"),
        2 => (1, "miUINT8"),
        3 => (2, "miINT16"),
        4 => (2, "miUINT16"),
        5 => (4, "miINT32"),
        6 => (4, "miUINT32"),
        7 => (4, "miSINGLE"),
        9 => (8, "miDOUBLE"),
        12 => (8, "miINT64"),
        13 => (8, "miUINT64"),
        other => return Err(format!("storage type {other}, expected a numeric MAT data type")),
    };
    if data.len() / width != count || !data.len().is_multiple_of(width) {
        return Err(format!(
            "{} bytes of {name} hold {} values, the dimensions promise {count}",
            data.len(),
            data.len() / width
        ));
    }
    let value = |chunk: &[u8]| -> f64 {
        let mut raw = [0u8; 8];
        raw[..width].copy_from_slice(chunk);
        if endian.big {
            raw[..width].reverse();
        }
        match data_type {
            1 => f64::from(raw[0] as i8),
            2 => f64::from(raw[0]),
            3 => f64::from(i16::from_le_bytes([raw[0], raw[1]])),
            4 => f64::from(u16::from_le_bytes([raw[0], raw[1]])),
            5 => f64::from(i32::from_le_bytes([raw[0], raw[1], raw[2], raw[3]])),
            6 => f64::from(u32::from_le_bytes([raw[0], raw[1], raw[2], raw[3]])),
            7 => f64::from(f32::from_le_bytes([raw[0], raw[1], raw[2], raw[3]])),
            9 => f64::from_le_bytes(raw),
            12 => i64::from_le_bytes(raw) as f64,
            _ => u64::from_le_bytes(raw) as f64,
        }
    };
    Ok(data.chunks_exact(width).map(value).collect())
}

/// Cuts the decoded array into one snapshot per antenna pair.
fn snapshots(path: &Path, array: &MatArray, layout: &MatCirLayout) -> Result<Vec<CirSnapshot>, IngestError> {
    let record = format!("variable `{}` ({})", layout.variable, array.describe());
    let bad = |field: &str, detail: String| IngestError::BadRecord {
        path: path.to_path_buf(),
        record: record.clone(),
        field: field.into(),
        detail,
    };
    let named = [Some(layout.tap_axis), layout.tx_axis, layout.rx_axis];
    let wanted_dims = named.iter().flatten().max().map_or(2, |&m| (m + 1).max(2));
    if array.dims.len() != wanted_dims {
        return Err(bad(
            "dimensions",
            format!(
                "{} dimensions, expected {wanted_dims} ({}, 0-based; other axes of size 1)",
                array.dims.len(),
                describe_axes(layout)
            ),
        ));
    }
    if let Some(axis) = (0..wanted_dims).find(|&a| !named.contains(&Some(a)) && array.dims[a] != 1) {
        return Err(bad(
            "dimensions",
            format!("axis {axis} (0-based) has size {} but the layout does not name it; expected 1", array.dims[axis]),
        ));
    }
    let imag = match (&array.imag, layout.allow_real) {
        (Some(imag), _) => Some(imag.as_slice()),
        (None, true) => None,
        (None, false) => {
            return Err(bad(
                "complex flag",
                "a real array; expected complex taps (set allow_real to read it with zero imaginary part)".into(),
            ));
        }
    };
    // Column-major strides.
    let mut strides = Vec::with_capacity(array.dims.len());
    let mut stride = 1usize;
    for &d in &array.dims {
        strides.push(stride);
        stride = stride.saturating_mul(d);
    }
    let size_stride = |axis: Option<usize>| axis.map_or((1, 0), |a| (array.dims[a], strides[a]));
    let (n_taps, tap_stride) = size_stride(Some(layout.tap_axis));
    let (n_tx, tx_stride) = size_stride(layout.tx_axis);
    let (n_rx, rx_stride) = size_stride(layout.rx_axis);
    if n_taps == 0 || n_tx == 0 || n_rx == 0 {
        return Err(bad("dimensions", "an empty array; expected at least one tap per antenna pair".into()));
    }
    let mut out = Vec::with_capacity(n_tx.saturating_mul(n_rx));
    for tx in 0..n_tx {
        for rx in 0..n_rx {
            let base = tx * tx_stride + rx * rx_stride;
            let taps = (0..n_taps)
                .map(|k| {
                    let i = base + k * tap_stride;
                    Complex64::new(array.real[i], imag.map_or(0.0, |im| im[i]))
                })
                .collect();
            let antenna = |i: usize| u32::try_from(i).map_err(|_| bad("dimensions", format!("antenna index {i}")));
            let snapshot = CirSnapshot {
                t_ns: layout.t_ns,
                set_index: 0,
                snapshot_index: 0,
                tx_antenna: antenna(tx)?,
                rx_antenna: antenna(rx)?,
                carrier_hz: layout.carrier_hz,
                tap_spacing_s: layout.tap_spacing_s,
                delay_offset_s: layout.delay_offset_s,
                taps,
                first_path_hint_s: None,
            };
            snapshot.validate().map_err(|e| bad(&format!("taps of TX {tx}, RX {rx}"), e.to_string()))?;
            out.push(snapshot);
        }
    }
    Ok(out)
}

#[cfg(test)]
#[path = "matlab_tests.rs"]
pub(crate) mod tests;
