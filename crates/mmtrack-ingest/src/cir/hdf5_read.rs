//! The libhdf5 reader behind `hdf5.rs`, compiled with the `hdf5` cargo
//! feature only (the formats, and what is accepted, are documented there).
//!
//! Uses the `hdf5-metno` crate (the maintained fork of the `hdf5` bindings)
//! over the system libhdf5, the format's reference implementation: it reads
//! whatever MATLAB and h5py write (chunked and deflate-compressed datasets,
//! any superblock and object-header version) and converts member types and
//! byte orders itself. Builds against libhdf5 1.10 (Debian 12's `libhdf5-dev`
//! 1.10.8) and newer.
//!
//! libhdf5 reads from a path, so this reader takes paths, not bytes. Its
//! errors are caught and carried into [`IngestError`]s naming the file, the
//! dataset or variable and the field; nothing panics on a bad file (tests cut
//! files at many lengths).

use std::path::Path;

use h5::types::{FixedAscii, TypeDescriptor};
use hdf5_metno as h5;
use mmtrack_core::Complex64;

use super::array::{MatlabArray, NdComplex};
use crate::IngestError;
use crate::error::os_err;

/// Datasets with more elements than this are refused before reading (bounds
/// memory on hostile input: 2^27 complex values are 2 GiB, as the v5 reader's
/// limit; far above any CIR file).
const MAX_ELEMENTS: usize = 1 << 27;

/// Datasets named in a "the file holds ..." message, at most.
const LISTED: usize = 20;

/// MATLAB classes read as numbers (as by the v5 reader).
const NUMERIC_CLASSES: &[&str] =
    &["double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64"];

/// Memory types of complex values, for `H5Dread`: libhdf5 converts a file
/// compound to them member by member, matched by name. `derive(H5Type)`
/// writes the type descriptor from the `#[repr(C)]` layout.
pub(crate) mod element {
    use hdf5_metno::H5Type;

    /// h5py's (and `hdf5-metno`'s) complex compound `{r, i}`.
    #[derive(H5Type, Clone, Copy, Debug, PartialEq)]
    #[repr(C)]
    pub(crate) struct Ri {
        pub r: f64,
        pub i: f64,
    }

    /// MATLAB v7.3's complex compound `{real, imag}`.
    #[derive(H5Type, Clone, Copy, Debug, PartialEq)]
    #[repr(C)]
    pub(crate) struct RealImag {
        pub real: f64,
        pub imag: f64,
    }
}

/// How a dataset's elements are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Element {
    /// Real numbers.
    Real,
    /// Compound `{r, i}`.
    Ri,
    /// Compound `{real, imag}`.
    RealImag,
}

fn bad(path: &Path, record: &str, field: &str, detail: String) -> IngestError {
    IngestError::BadRecord { path: path.to_path_buf(), record: record.into(), field: field.into(), detail }
}

/// The complex array of `dataset` (`None`: the only dataset), C order.
pub(crate) fn read_dataset(path: &Path, dataset: Option<&str>) -> Result<(String, NdComplex), IngestError> {
    let file = open(path)?;
    let ds = find_dataset(path, &file, dataset)?;
    let name = ds.name();
    let record = format!("dataset `{name}`");
    let (dims, real, imag) = read_values(path, &record, &ds)?;
    let array = match imag {
        Some(imag) => {
            NdComplex::new(dims, real.iter().zip(&imag).map(|(&re, &im)| Complex64::new(re, im)).collect(), false)
        }
        None => NdComplex::from_iq(&dims, &real, false)
            .map_err(|detail| bad(path, &record, "shape", format!("{} (real {})", detail, describe_type(&ds))))?,
    };
    Ok((name, array))
}

/// The numeric MATLAB variable `variable` of a v7.3 file, in MATLAB's axis order.
pub(crate) fn read_mat73(path: &Path, variable: &str) -> Result<MatlabArray, IngestError> {
    let file = open(path)?;
    let record = format!("variable `{variable}`");
    let is_variable = !variable.is_empty() && !variable.starts_with('#') && !variable.contains('/');
    let ds = match file.dataset(variable) {
        Ok(ds) if is_variable => ds,
        _ => return Err(no_variable(path, &file, variable, is_variable)),
    };
    let class = matlab_class(&ds);
    if let Some(class) = &class
        && !NUMERIC_CLASSES.contains(&class.as_str())
    {
        return Err(bad(
            path,
            &record,
            "MATLAB_class",
            format!("{class}, expected a numeric (double, single or integer) array"),
        ));
    }
    if ds.attr("MATLAB_empty").and_then(|a| a.read_scalar::<u8>()).is_ok_and(|e| e != 0) {
        return Err(bad(path, &record, "MATLAB_empty", "an empty array; expected at least one tap".into()));
    }
    let (mut dims, real, imag) = read_values(path, &record, &ds)?;
    // HDF5 row-major (n_k, ..., n_0) is MATLAB column-major (n_0, ..., n_k).
    dims.reverse();
    Ok(MatlabArray { class: class.unwrap_or_else(|| "double".into()), dims, real, imag })
}

/// Why `variable` is not a numeric dataset at the root.
fn no_variable(path: &Path, file: &h5::File, variable: &str, is_variable: bool) -> IngestError {
    if is_variable && let Ok(group) = file.group(variable) {
        let class = matlab_class(&group).unwrap_or_else(|| "no MATLAB_class".into());
        let detail =
            format!("{class}, stored as an HDF5 group (a struct, cell or sparse array); expected a numeric array");
        return bad(path, &format!("variable `{variable}`"), "MATLAB_class", detail);
    }
    let detail = format!("no variable `{variable}` in the v7.3 file; it holds {}", list_variables(file));
    IngestError::BadLayout { path: path.to_path_buf(), detail }
}

/// Opens the file; a missing file is an OS error, anything else libhdf5's.
fn open(path: &Path) -> Result<h5::File, IngestError> {
    std::fs::metadata(path).map_err(os_err(path))?;
    h5::File::open(path).map_err(|e| IngestError::BadLayout {
        path: path.to_path_buf(),
        detail: format!("not a readable HDF5 file (libhdf5: {e})"),
    })
}

/// The dataset at `name`, or the file's only dataset.
fn find_dataset(path: &Path, file: &h5::File, name: Option<&str>) -> Result<h5::Dataset, IngestError> {
    let mut all = Vec::new();
    if let Some(name) = name {
        if let Ok(ds) = file.dataset(name) {
            return Ok(ds);
        }
        let what = if file.group(name).is_ok() { "is a group, not a dataset" } else { "no such dataset" };
        walk(file, 0, &mut all);
        let detail = format!("`{name}`: {what}; the file holds {}", list(&all));
        return Err(IngestError::BadLayout { path: path.to_path_buf(), detail });
    }
    walk(file, 0, &mut all);
    if all.len() == 1 {
        return Ok(all.swap_remove(0));
    }
    let detail = if all.is_empty() {
        "holds no dataset".to_string()
    } else {
        format!("holds {}; choose one with `dataset = \"...\"` in the sidecar", list(&all))
    };
    Err(IngestError::BadLayout { path: path.to_path_buf(), detail })
}

/// Every dataset under `group`, depth-first, at most 16 groups deep (a
/// guard against hard-link cycles).
fn walk(group: &h5::Group, depth: usize, out: &mut Vec<h5::Dataset>) {
    if depth > 16 {
        return;
    }
    out.extend(group.datasets().unwrap_or_default());
    for child in group.groups().unwrap_or_default() {
        walk(&child, depth + 1, out);
    }
}

/// "`/a` (compound {r: float32, i: float32} 2x3), ..." sorted, at most [`LISTED`].
fn list(datasets: &[h5::Dataset]) -> String {
    if datasets.is_empty() {
        return "no datasets".into();
    }
    let mut sorted: Vec<(String, &h5::Dataset)> = datasets.iter().map(|ds| (ds.name(), ds)).collect();
    sorted.sort_by(|a, b| a.0.cmp(&b.0));
    let names: Vec<String> =
        sorted.iter().map(|(name, ds)| format!("`{name}` ({} {})", describe_type(ds), shape(ds))).collect();
    join_listed(names)
}

/// The root's MATLAB variables: "`h` (double 2x3x4), ..." in MATLAB's dimension order.
fn list_variables(file: &h5::File) -> String {
    let names: Vec<String> = file
        .member_names()
        .unwrap_or_default()
        .into_iter()
        .filter(|n| !n.starts_with('#'))
        .map(|n| match file.dataset(&n) {
            Ok(ds) => {
                let dims: Vec<String> = ds.shape().iter().rev().map(ToString::to_string).collect();
                let class = matlab_class(&ds).unwrap_or_else(|| describe_type(&ds));
                let complex = if element(&ds).is_ok_and(|e| e != Element::Real) { " complex" } else { "" };
                format!("`{n}` ({class}{complex} {})", dims.join("x"))
            }
            Err(_) => format!("`{n}` (group)"),
        })
        .collect();
    if names.is_empty() {
        return "no variables".into();
    }
    join_listed(names)
}

/// The first [`LISTED`] names, and how many more.
fn join_listed(mut names: Vec<String>) -> String {
    let more = names.len().saturating_sub(LISTED);
    names.truncate(LISTED);
    if more > 0 {
        names.push(format!("and {more} more"));
    }
    names.join(", ")
}

/// The string attribute `MATLAB_class`, if present and readable.
fn matlab_class(location: &h5::Location) -> Option<String> {
    let value = location.attr("MATLAB_class").ok()?.read_scalar::<FixedAscii<64>>().ok()?;
    Some(value.as_str().trim_end_matches(['\0', ' ']).to_string())
}

/// "2x3x4", or "scalar".
fn shape(ds: &h5::Dataset) -> String {
    let dims = ds.shape();
    if dims.is_empty() {
        return "scalar".into();
    }
    dims.iter().map(ToString::to_string).collect::<Vec<_>>().join("x")
}

/// The element type for messages: "float32", "compound {r: float32, i: float32}".
fn describe_type(ds: &h5::Dataset) -> String {
    match ds.dtype().and_then(|t| t.to_descriptor()) {
        Ok(TypeDescriptor::Compound(c)) => {
            let fields: Vec<String> = c.fields.iter().map(|f| format!("{}: {}", f.name, f.ty)).collect();
            format!("compound {{{}}}", fields.join(", "))
        }
        Ok(other) => other.to_string(),
        Err(_) => "an HDF5 type without a Rust equivalent".into(),
    }
}

fn is_number(ty: &TypeDescriptor) -> bool {
    matches!(ty, TypeDescriptor::Integer(_) | TypeDescriptor::Unsigned(_) | TypeDescriptor::Float(_))
}

/// How `ds` is read, or what is wrong with its element type.
fn element(ds: &h5::Dataset) -> Result<Element, String> {
    let expected = "expected numbers with a trailing I/Q axis of 2, or a complex compound {r, i} or {real, imag} \
                    of numbers";
    let descriptor = ds.dtype().and_then(|t| t.to_descriptor());
    let compound = match descriptor {
        Ok(ty) if is_number(&ty) => return Ok(Element::Real),
        Ok(TypeDescriptor::Compound(c)) => c,
        _ => return Err(format!("{}, {expected}", describe_type(ds))),
    };
    let mut names: Vec<&str> = compound.fields.iter().map(|f| f.name.as_str()).collect();
    names.sort_unstable();
    let kind = match names[..] {
        ["i", "r"] => Element::Ri,
        ["imag", "real"] => Element::RealImag,
        _ => return Err(format!("{}, {expected}", describe_type(ds))),
    };
    if compound.fields.iter().all(|f| is_number(&f.ty)) {
        Ok(kind)
    } else {
        Err(format!("{}, members must be numbers", describe_type(ds)))
    }
}

/// The dataset's HDF5 dimensions, real parts and imaginary parts (`None` for
/// a real array), in row-major order, as `f64`.
#[allow(clippy::type_complexity)]
fn read_values(
    path: &Path,
    record: &str,
    ds: &h5::Dataset,
) -> Result<(Vec<usize>, Vec<f64>, Option<Vec<f64>>), IngestError> {
    let kind = element(ds).map_err(|detail| bad(path, record, "element type", detail))?;
    let dims = ds.shape();
    if dims.is_empty() {
        return Err(bad(path, record, "shape", format!("a scalar ({}); expected an array", describe_type(ds))));
    }
    let count = dims.iter().try_fold(1usize, |acc, &d| acc.checked_mul(d)).filter(|&n| n <= MAX_ELEMENTS);
    if count.is_none() {
        return Err(bad(path, record, "shape", format!("{dims:?}: more than {MAX_ELEMENTS} elements")));
    }
    let data_err = |e: h5::Error| bad(path, record, "data", format!("libhdf5 cannot read it: {e}"));
    let (real, imag) = match kind {
        Element::Real => (ds.read_raw::<f64>().map_err(data_err)?, None),
        Element::Ri => {
            let values = ds.read_raw::<element::Ri>().map_err(data_err)?;
            (values.iter().map(|v| v.r).collect(), Some(values.iter().map(|v| v.i).collect()))
        }
        Element::RealImag => {
            let values = ds.read_raw::<element::RealImag>().map_err(data_err)?;
            (values.iter().map(|v| v.real).collect(), Some(values.iter().map(|v| v.imag).collect()))
        }
    };
    Ok((dims, real, imag))
}
