//! NumPy `.npy` arrays and `.npz` archives of them.
//!
//! `.npy` (format versions 1, 2 and 3): the magic `\x93NUMPY`, a version, a
//! header length, then a Python dict literal such as
//! `{'descr': '<c16', 'fortran_order': False, 'shape': (4, 4, 1001), }` and the
//! raw data. Accepted dtypes: complex `c8` / `c16`, and real `f4` / `f8` / `i2`
//! with a trailing I/Q axis of size 2; little or big endian; C or Fortran
//! order. Anything else (object arrays, structured dtypes, `int32`, ...) is an
//! error naming the dtype found.
//!
//! `.npz` is a ZIP archive of `<name>.npy` members (`np.savez` stores them,
//! `np.savez_compressed` deflates them). The ZIP reader is ours, inflating
//! with `miniz_oxide` (`inflate.rs`) rather than adding a ZIP crate for one
//! member of one archive; it checks each member's CRC-32 (`crc32fast`) and
//! reads ZIP64 sizes, which NumPy writes. A deflated member may inflate to 16 MiB plus
//! 100 times its compressed size (`inflate::inflate_limit`: decompression
//! bombs), and is refused before inflating when it declares more.

use std::path::Path;

use super::array::NdComplex;
use super::inflate::{INFLATE_LIMIT_HINT, inflate_limit, inflate_raw};
use crate::IngestError;
use mmtrack_core::Complex64;

/// Refuse arrays larger than this when decompressing (bounds memory on hostile input).
const MAX_MEMBER_BYTES: usize = 1 << 32;

fn bad(path: &Path, record: &str, field: &str, detail: String) -> IngestError {
    IngestError::BadRecord { path: path.to_path_buf(), record: record.into(), field: field.into(), detail }
}

/// The header fields of a `.npy` file and the bytes after the header.
struct NpyHeader<'a> {
    descr: String,
    fortran: bool,
    dims: Vec<usize>,
    data: &'a [u8],
}

/// Parses the magic, version and header dict of a `.npy` file.
fn parse_header<'a>(path: &Path, record: &str, bytes: &'a [u8]) -> Result<NpyHeader<'a>, IngestError> {
    let bad = |field: &str, detail: String| bad(path, record, field, detail);
    if !bytes.starts_with(b"\x93NUMPY") {
        return Err(bad("magic", "expected `\\x93NUMPY` at byte 0 (not a .npy file)".into()));
    }
    let (header_len, start) = match bytes.get(6) {
        Some(1) => (bytes.get(8..10).map(|b| usize::from(u16::from_le_bytes([b[0], b[1]]))), 10),
        Some(2 | 3) => (bytes.get(8..12).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize), 12),
        other => return Err(bad("version", format!("{other:?}, expected format version 1, 2 or 3"))),
    };
    let (header, data) = header_len
        .and_then(|n| Some((bytes.get(start..start + n)?, bytes.get(start + n..)?)))
        .ok_or_else(|| bad("header", format!("truncated: {} bytes, the header runs past the end", bytes.len())))?;
    let header = String::from_utf8_lossy(header);
    let descr = dict_value(&header, "descr").ok_or_else(|| bad("descr", format!("missing in header `{header}`")))?;
    let descr = descr.trim_matches(['\'', '"']);
    let fortran = match dict_value(&header, "fortran_order") {
        Some("True") => true,
        Some("False") => false,
        other => return Err(bad("fortran_order", format!("{other:?}, expected True or False"))),
    };
    let shape = dict_value(&header, "shape").ok_or_else(|| bad("shape", format!("missing in header `{header}`")))?;
    let dims = parse_shape(shape).ok_or_else(|| bad("shape", format!("`{shape}`, expected a tuple of sizes")))?;
    Ok(NpyHeader { descr: descr.to_string(), fortran, dims, data })
}

/// Parses the bytes of a `.npy` file. `record` names it in messages (e.g. the npz member).
pub(crate) fn parse_npy(path: &Path, record: &str, bytes: &[u8]) -> Result<NdComplex, IngestError> {
    let header = parse_header(path, record, bytes)?;
    decode(&header.descr, &header.dims, header.fortran, header.data)
        .map_err(|(field, detail)| bad(path, record, field, detail))
}

/// Values of a real `.npy` matrix: floating point or integer, as the file's
/// dtype (float32 and int32 widened exactly).
#[derive(Debug, Clone, PartialEq)]
pub enum NpyValues {
    /// float64 (`f8`) or float32 (`f4`).
    F64(Vec<f64>),
    /// int64 (`i8`) or int32 (`i4`).
    I64(Vec<i64>),
}

/// The dtypes [`parse_npy_matrix`] reads, for messages.
pub const NPY_MATRIX_DTYPES: &str =
    "float64 (`<f8`), float32 (`<f4`), int64 (`<i8`) or int32 (`<i4`), either byte order";

/// A real 2-D array from a `.npy` file, row-major whatever the file's order.
#[derive(Debug, Clone, PartialEq)]
pub struct NpyMatrix {
    /// Rows (the first dimension).
    pub rows: usize,
    /// Columns (1 for a one-dimensional array).
    pub columns: usize,
    /// `rows * columns` values, row-major.
    pub values: NpyValues,
    /// The file's dtype (`descr`), e.g. `<f4`, for messages.
    pub dtype: String,
}

/// Reads a `.npy` file holding a float64, float32, int64 or int32 array of
/// one dimension (`(N,)`, read as `N x 1`) or two (`(N, M)`), either byte
/// order, C or Fortran order. Other dtypes and shapes are errors naming the file and the
/// header field.
///
/// # Errors
/// [`IngestError::Os`] when the file cannot be read; [`IngestError::BadRecord`]
/// for a bad magic, header, dtype, shape or truncated data.
pub fn read_npy_matrix(path: &Path) -> Result<NpyMatrix, IngestError> {
    let bytes = crate::error::read_capped(path, &mmtrack_core::limits::ARRAY_FILE_BYTES)?;
    parse_npy_matrix(path, &bytes)
}

/// [`read_npy_matrix`] on the bytes of a file already read.
///
/// # Errors
/// As [`read_npy_matrix`].
pub fn parse_npy_matrix(path: &Path, bytes: &[u8]) -> Result<NpyMatrix, IngestError> {
    let header = parse_header(path, "header", bytes)?;
    let bad = |field: &str, detail: String| bad(path, "header", field, detail);
    let (big, kind) = match header.descr.as_bytes().first() {
        Some(b'<' | b'|' | b'=') => (false, &header.descr[1..]),
        Some(b'>') => (true, &header.descr[1..]),
        _ => (false, header.descr.as_str()),
    };
    let size = match kind {
        "f8" | "i8" => 8,
        "f4" | "i4" => 4,
        _ => return Err(bad("descr", format!("dtype `{}`, expected {NPY_MATRIX_DTYPES}", header.descr))),
    };
    let (rows, columns) = match header.dims.as_slice() {
        [n] => (*n, 1),
        [n, m] => (*n, *m),
        other => return Err(bad("shape", format!("{other:?}, expected one or two dimensions"))),
    };
    let count = rows.checked_mul(columns).ok_or_else(|| bad("shape", format!("{:?} overflows", header.dims)))?;
    let needed = count.checked_mul(size).ok_or_else(|| bad("shape", format!("{:?} overflows", header.dims)))?;
    let Some(data) = header.data.get(..needed) else {
        return Err(bad_data(path, &header, needed));
    };
    let values = match kind {
        "f8" => NpyValues::F64(words::<8>(data, big).map(f64::from_le_bytes).collect()),
        "f4" => NpyValues::F64(words::<4>(data, big).map(|w| f64::from(f32::from_le_bytes(w))).collect()),
        "i8" => NpyValues::I64(words::<8>(data, big).map(i64::from_le_bytes).collect()),
        _ => NpyValues::I64(words::<4>(data, big).map(|w| i64::from(i32::from_le_bytes(w))).collect()),
    };
    let fortran = header.fortran;
    let values = match values {
        NpyValues::F64(v) => NpyValues::F64(row_major(v, rows, columns, fortran)),
        NpyValues::I64(v) => NpyValues::I64(row_major(v, rows, columns, fortran)),
    };
    Ok(NpyMatrix { rows, columns, values, dtype: header.descr.clone() })
}

/// The `N`-byte words of `data`, each in little-endian order (reversed when
/// the file is big-endian).
fn words<const N: usize>(data: &[u8], big_endian: bool) -> impl Iterator<Item = [u8; N]> + '_ {
    data.chunks_exact(N).map(move |chunk| {
        let mut raw = [0u8; N];
        raw.copy_from_slice(chunk);
        if big_endian {
            raw.reverse();
        }
        raw
    })
}

/// `values` of a `rows x columns` array in row-major order. Fortran order
/// stores columns first: position `k` of the file is row `k % rows`, column
/// `k / rows`.
fn row_major<T: Copy>(values: Vec<T>, rows: usize, columns: usize, fortran: bool) -> Vec<T> {
    if !fortran || columns == 1 || rows == 1 {
        return values;
    }
    (0..values.len()).map(|i| values[(i % columns) * rows + i / columns]).collect()
}

fn bad_data(path: &Path, header: &NpyHeader<'_>, needed: usize) -> IngestError {
    bad(
        path,
        "data",
        "data",
        format!(
            "truncated: shape {:?} of `{}` needs {needed} bytes of data, the file has {}",
            header.dims,
            header.descr,
            header.data.len()
        ),
    )
}

/// The value text of `'key': value` in a Python dict literal (tuples kept whole).
fn dict_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let at = header.find(&format!("'{key}'")).or_else(|| header.find(&format!("\"{key}\"")))?;
    let rest = header[at + key.len() + 2..].trim_start().strip_prefix(':')?.trim_start();
    let end = if rest.starts_with('(') { rest.find(')')? + 1 } else { rest.find([',', '}'])? };
    Some(rest[..end].trim())
}

fn parse_shape(text: &str) -> Option<Vec<usize>> {
    let inner = text.strip_prefix('(')?.strip_suffix(')')?;
    inner.split(',').map(str::trim).filter(|s| !s.is_empty()).map(|s| s.trim_end_matches('L').parse().ok()).collect()
}

/// Decodes the data of dtype `descr`.
fn decode(descr: &str, dims: &[usize], fortran: bool, data: &[u8]) -> Result<NdComplex, (&'static str, String)> {
    let (big, kind) = match descr.as_bytes().first() {
        Some(b'<' | b'|' | b'=') => (false, &descr[1..]),
        Some(b'>') => (true, &descr[1..]),
        _ => (false, descr),
    };
    let (width, complex) = match kind {
        "c8" => (4, true),
        "c16" => (8, true),
        "f4" => (4, false),
        "f8" => (8, false),
        "i2" => (2, false),
        _ => {
            return Err((
                "descr",
                format!(
                    "dtype `{descr}`, expected complex64 (`<c8`), complex128 (`<c16`), or float32/float64/int16 \
                     (`<f4`, `<f8`, `<i2`) with a trailing I/Q axis of size 2"
                ),
            ));
        }
    };
    let count = dims
        .iter()
        .try_fold(1usize, |acc, &d| acc.checked_mul(d))
        .and_then(|n| n.checked_mul(if complex { 2 } else { 1 }))
        .ok_or_else(|| ("shape", format!("{dims:?} overflows")))?;
    let needed = count.checked_mul(width).ok_or_else(|| ("shape", format!("{dims:?} overflows")))?;
    if data.len() < needed {
        return Err((
            "data",
            format!("truncated: shape {dims:?} of `{descr}` needs {needed} bytes of data, the file has {}", data.len()),
        ));
    }
    let reals: Vec<f64> = data[..needed]
        .chunks_exact(width)
        .map(|chunk| {
            let mut raw = [0u8; 8];
            raw[..width].copy_from_slice(chunk);
            if big {
                raw[..width].reverse();
            }
            match width {
                2 => f64::from(i16::from_le_bytes([raw[0], raw[1]])),
                4 => f64::from(f32::from_le_bytes([raw[0], raw[1], raw[2], raw[3]])),
                _ => f64::from_le_bytes(raw),
            }
        })
        .collect();
    if complex {
        let values = reals.chunks_exact(2).map(|p| Complex64::new(p[0], p[1])).collect();
        Ok(NdComplex::new(dims.to_vec(), values, fortran))
    } else {
        NdComplex::from_iq(dims, &reals, fortran)
            .map_err(|e| ("shape", format!("real dtype `{descr}`: {e} (or save a complex array)")))
    }
}

/// Reads member `variable` (name without `.npy`; the only member when `None`) of an `.npz`.
pub(crate) fn parse_npz(path: &Path, bytes: &[u8], variable: Option<&str>) -> Result<(String, NdComplex), IngestError> {
    let members = zip_members(bytes).map_err(|detail| bad(path, "ZIP archive", "central directory", detail))?;
    let names: Vec<&str> = members.iter().map(|m| m.name.trim_end_matches(".npy")).collect();
    let chosen = match variable {
        Some(v) => members.iter().find(|m| m.name.trim_end_matches(".npy") == v),
        None if members.len() == 1 => members.first(),
        None => None,
    };
    let Some(member) = chosen else {
        let detail = match variable {
            Some(v) => format!("no array `{v}`; the archive holds {names:?}"),
            None => format!("holds {names:?}; choose one with `variable = \"...\"` in the sidecar"),
        };
        return Err(IngestError::BadLayout { path: path.to_path_buf(), detail });
    };
    let record = format!("member `{}`", member.name);
    let data = member_data(bytes, member).map_err(|detail| bad(path, &record, "ZIP member", detail))?;
    let array = parse_npy(path, &record, &data)?;
    Ok((member.name.trim_end_matches(".npy").to_string(), array))
}

struct Member {
    name: String,
    method: u16,
    crc: u32,
    compressed: u64,
    uncompressed: u64,
    local_offset: u64,
}

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(at..at + 2)?.try_into().ok()?))
}
fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}
fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

/// The central directory's entries.
fn zip_members(b: &[u8]) -> Result<Vec<Member>, String> {
    let search_from = b.len().saturating_sub(22 + 65_535);
    let eocd = (search_from..b.len().saturating_sub(21))
        .rev()
        .find(|&i| u32_at(b, i) == Some(0x0605_4b50))
        .ok_or("no end-of-central-directory record (not a ZIP archive, or truncated)")?;
    let truncated = || "truncated central directory".to_string();
    let mut entries = u64::from(u16_at(b, eocd + 10).ok_or_else(truncated)?);
    let mut offset = u64::from(u32_at(b, eocd + 16).ok_or_else(truncated)?);
    if (entries == 0xffff || offset == 0xffff_ffff) && eocd >= 20 && u32_at(b, eocd - 20) == Some(0x0706_4b50) {
        let z64 = u64_at(b, eocd - 12).ok_or_else(truncated)? as usize;
        if u32_at(b, z64) != Some(0x0606_4b50) {
            return Err("bad ZIP64 end-of-central-directory record".into());
        }
        entries = u64_at(b, z64 + 32).ok_or_else(truncated)?;
        offset = u64_at(b, z64 + 48).ok_or_else(truncated)?;
    }
    let mut at = usize::try_from(offset).map_err(|_| truncated())?;
    let mut out = Vec::new();
    for _ in 0..entries {
        if u32_at(b, at) != Some(0x0201_4b50) {
            return Err(format!("central directory entry at byte {at} has a bad signature"));
        }
        let field = |o: usize| u16_at(b, at + o).ok_or_else(truncated);
        let (name_len, extra_len, comment_len) = (field(28)? as usize, field(30)? as usize, field(32)? as usize);
        let name = b.get(at + 46..at + 46 + name_len).ok_or_else(truncated)?;
        let extra = b.get(at + 46 + name_len..at + 46 + name_len + extra_len).ok_or_else(truncated)?;
        let mut m = Member {
            name: String::from_utf8_lossy(name).into_owned(),
            method: field(10)?,
            crc: u32_at(b, at + 16).ok_or_else(truncated)?,
            compressed: u64::from(u32_at(b, at + 20).ok_or_else(truncated)?),
            uncompressed: u64::from(u32_at(b, at + 24).ok_or_else(truncated)?),
            local_offset: u64::from(u32_at(b, at + 42).ok_or_else(truncated)?),
        };
        apply_zip64(&mut m, extra);
        out.push(m);
        at += 46 + name_len + extra_len + comment_len;
    }
    Ok(out)
}

/// ZIP64 extra field (id 1): the 64-bit values of the fields set to 0xffffffff, in order.
fn apply_zip64(m: &mut Member, mut extra: &[u8]) {
    while let (Some(id), Some(len)) = (u16_at(extra, 0), u16_at(extra, 2)) {
        let body = extra.get(4..4 + len as usize).unwrap_or(&[]);
        if id == 1 {
            let mut at = 0;
            for value in [&mut m.uncompressed, &mut m.compressed, &mut m.local_offset] {
                if *value == 0xffff_ffff
                    && let Some(v) = u64_at(body, at)
                {
                    *value = v;
                    at += 8;
                }
            }
        }
        extra = extra.get(4 + len as usize..).unwrap_or(&[]);
    }
}

fn member_data(b: &[u8], m: &Member) -> Result<Vec<u8>, String> {
    let at = usize::try_from(m.local_offset).map_err(|_| "offset overflows".to_string())?;
    if u32_at(b, at) != Some(0x0403_4b50) {
        return Err(format!("local header at byte {at} has a bad signature"));
    }
    let lens = u16_at(b, at + 26).zip(u16_at(b, at + 28)).ok_or("truncated local header")?;
    let start = at + 30 + lens.0 as usize + lens.1 as usize;
    let size = usize::try_from(m.compressed).map_err(|_| "size overflows".to_string())?;
    let raw = start
        .checked_add(size)
        .and_then(|end| b.get(start..end))
        .ok_or_else(|| format!("truncated: {size} bytes of data at byte {start}, the file has {}", b.len()))?;
    let data = match m.method {
        0 => raw.to_vec(),
        8 => {
            let limit = inflate_limit(raw.len(), MAX_MEMBER_BYTES);
            if m.uncompressed > limit as u64 {
                return Err(format!(
                    "{} bytes when inflated from {} compressed bytes: {INFLATE_LIMIT_HINT} (np.savez)",
                    m.uncompressed,
                    raw.len()
                ));
            }
            inflate_raw(raw, limit.min(m.uncompressed as usize))?
        }
        other => return Err(format!("compression method {other}, expected stored (0) or deflate (8)")),
    };
    if data.len() as u64 != m.uncompressed {
        return Err(format!("{} bytes after decompression, the directory says {}", data.len(), m.uncompressed));
    }
    let crc = crc32fast::hash(&data);
    if crc != m.crc {
        return Err(format!("CRC-32 0x{crc:08x} of the data, expected 0x{:08x}", m.crc));
    }
    Ok(data)
}

#[cfg(test)]
#[path = "npy_tests.rs"]
mod tests;
