//! A complex N-dimensional array as the array formats (NumPy, MATLAB, SigMF)
//! give it, and its cutting into [`CirSnapshot`]s by the sidecar's axes.
//!
//! Default axes when the sidecar gives none (taps always last; antenna axes
//! follow the `y = H x` convention of a MIMO channel matrix, `H[rx][tx]`):
//! 1-D `[tap]`, 2-D `[snapshot, tap]`, 3-D `[rx, tx, tap]`, 4-D
//! `[snapshot, rx, tx, tap]`. Snapshots come out time-major, then TX, then RX.

use std::path::Path;

use mmtrack_core::{CirSnapshot, Complex64};
use rustfft::FftPlanner;

use super::sidecar::{AxisRole, CirSidecar, Domain};
use crate::IngestError;

/// A complex array: `values[sum(index[d] * strides[d])]`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct NdComplex {
    pub dims: Vec<usize>,
    pub strides: Vec<usize>,
    pub values: Vec<Complex64>,
}

/// A numeric MATLAB array read from a v7.3 file, in MATLAB's terms (what the
/// libhdf5 reader, `hdf5_read.rs`, gives `hdf5.rs`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MatlabArray {
    /// `MATLAB_class`: `double`, `single`, `int8`, ... (`double` when absent).
    pub class: String,
    /// MATLAB's dimensions (the HDF5 dimensions reversed).
    pub dims: Vec<usize>,
    /// Real parts in MATLAB's column-major order.
    pub real: Vec<f64>,
    /// Imaginary parts, for a complex array.
    pub imag: Option<Vec<f64>>,
}

/// Element strides of an array stored in C (row-major) or Fortran (column-major) order.
pub(crate) fn strides(dims: &[usize], column_major: bool) -> Vec<usize> {
    let mut out = vec![0; dims.len()];
    let mut stride = 1usize;
    let order: Vec<usize> = if column_major { (0..dims.len()).collect() } else { (0..dims.len()).rev().collect() };
    for d in order {
        out[d] = stride;
        stride = stride.saturating_mul(dims[d]);
    }
    out
}

impl NdComplex {
    /// Wraps complex values stored in C or Fortran order.
    pub fn new(dims: Vec<usize>, values: Vec<Complex64>, column_major: bool) -> Self {
        let strides = strides(&dims, column_major);
        Self { dims, strides, values }
    }

    /// Real values whose last dimension (size 2) holds I and Q.
    pub fn from_iq(dims: &[usize], reals: &[f64], column_major: bool) -> Result<Self, String> {
        let Some((&2, outer)) = dims.split_last() else {
            return Err(format!("shape {dims:?}: a real array needs a trailing I/Q axis of size 2"));
        };
        let real_strides = strides(dims, column_major);
        let q_stride = real_strides[dims.len() - 1];
        let count: usize = outer.iter().product();
        let mut values = Vec::with_capacity(count);
        // Walk the outer indices in row-major order.
        let mut index = vec![0usize; outer.len()];
        for _ in 0..count {
            let at: usize = index.iter().zip(&real_strides).map(|(i, s)| i * s).sum();
            let (Some(&i), Some(&q)) = (reals.get(at), reals.get(at + q_stride)) else {
                return Err(format!("{} values, shape {dims:?} needs more", reals.len()));
            };
            values.push(Complex64::new(i, q));
            for d in (0..outer.len()).rev() {
                index[d] += 1;
                if index[d] < outer[d] {
                    break;
                }
                index[d] = 0;
            }
        }
        Ok(Self::new(outer.to_vec(), values, false))
    }
}

/// The axes used when the sidecar names none (see the module docs).
fn default_axes(ndim: usize) -> Option<Vec<AxisRole>> {
    use AxisRole::{Rx, Snapshot, Tap, Tx};
    match ndim {
        1 => Some(vec![Tap]),
        2 => Some(vec![Snapshot, Tap]),
        3 => Some(vec![Rx, Tx, Tap]),
        4 => Some(vec![Snapshot, Rx, Tx, Tap]),
        _ => None,
    }
}

/// The axes the sidecar names, or the default, checked against the array.
pub(crate) fn resolve_axes(
    path: &Path,
    array: &NdComplex,
    sidecar: &CirSidecar,
    record: &str,
) -> Result<Vec<AxisRole>, IngestError> {
    let axes = match &sidecar.axes {
        Some(axes) => axes.clone(),
        None => default_axes(array.dims.len()).ok_or_else(|| {
            sidecar.error("axes", format!("{record} has shape {:?}: name its axes with `axes = [...]`", array.dims))
        })?,
    };
    if axes.len() != array.dims.len() {
        return Err(sidecar.error(
            "axes",
            format!(
                "names {} axes ({}) but {} of {} has shape {:?}",
                axes.len(),
                axes.iter().map(|a| a.as_str()).collect::<Vec<_>>().join(", "),
                record,
                path.display(),
                array.dims
            ),
        ));
    }
    Ok(axes)
}

/// Cuts an array into snapshots (time-major, then TX, then RX), converting a
/// CFR into a CIR when the sidecar says so. Needs `carrier_hz` and a tap spacing.
pub(crate) fn cut_snapshots(
    path: &Path,
    array: &NdComplex,
    sidecar: &CirSidecar,
    record: &str,
    default_spacing: Option<f64>,
) -> Result<Vec<CirSnapshot>, IngestError> {
    let axes = resolve_axes(path, array, sidecar, record)?;
    let axis = |role| axes.iter().position(|&a| a == role).map(|d| (array.dims[d], array.strides[d]));
    let (n_taps, tap_stride) = axis(AxisRole::Tap).unwrap_or((1, 0));
    let (n_snap, snap_stride) = axis(AxisRole::Snapshot).unwrap_or((1, 0));
    let (n_tx, tx_stride) = axis(AxisRole::Tx).unwrap_or((1, 0));
    let (n_rx, rx_stride) = axis(AxisRole::Rx).unwrap_or((1, 0));
    if n_taps == 0 || n_snap == 0 || n_tx == 0 || n_rx == 0 {
        return Err(IngestError::BadRecord {
            path: path.to_path_buf(),
            record: record.into(),
            field: "shape".into(),
            detail: format!("{:?}: an empty array; expected at least one tap per snapshot", array.dims),
        });
    }
    let (carrier_hz, tap_spacing_s) = carrier_and_spacing(path, sidecar, n_taps, default_spacing)?;
    let mut planner = FftPlanner::<f64>::new();
    let mut out = Vec::with_capacity(n_snap * n_tx * n_rx);
    for s in 0..n_snap {
        let (t_ns, set_index, snapshot_index) = sidecar.snapshot_time(s, n_snap)?;
        for tx in 0..n_tx {
            for rx in 0..n_rx {
                let base = s * snap_stride + tx * tx_stride + rx * rx_stride;
                let mut taps: Vec<Complex64> = (0..n_taps).map(|k| array.values[base + k * tap_stride]).collect();
                if sidecar.domain == Domain::Cfr {
                    inverse_dft(&mut planner, &mut taps);
                }
                let snapshot = CirSnapshot {
                    t_ns,
                    set_index,
                    snapshot_index,
                    tx_antenna: u32::try_from(tx).unwrap_or(u32::MAX),
                    rx_antenna: u32::try_from(rx).unwrap_or(u32::MAX),
                    carrier_hz,
                    tap_spacing_s,
                    delay_offset_s: sidecar.delay_offset_s,
                    taps,
                    first_path_hint_s: None,
                };
                snapshot.validate().map_err(|e| IngestError::BadRecord {
                    path: path.to_path_buf(),
                    record: format!("{record}, snapshot {s}, TX {tx}, RX {rx}"),
                    field: if sidecar.domain == Domain::Cfr { "CFR bins" } else { "taps" }.into(),
                    detail: e.to_string(),
                })?;
                out.push(snapshot);
            }
        }
    }
    Ok(out)
}

/// Carrier and tap spacing from the sidecar, else from the file (`default_spacing`).
pub(crate) fn carrier_and_spacing(
    path: &Path,
    sidecar: &CirSidecar,
    n_taps: usize,
    default_spacing: Option<f64>,
) -> Result<(f64, f64), IngestError> {
    let carrier_hz = sidecar.carrier_hz.ok_or_else(|| {
        sidecar.error("carrier_hz", format!("required: {} does not give the carrier", path.display()))
    })?;
    let tap_spacing_s = match (sidecar.tap_spacing, default_spacing) {
        (Some(spacing), _) => spacing.seconds(n_taps),
        (None, Some(s)) => s,
        (None, None) => {
            return Err(sidecar.error(
                "tap_spacing_s",
                format!("required (or bandwidth_hz): {} does not give the tap spacing", path.display()),
            ));
        }
    };
    Ok((carrier_hz, tap_spacing_s))
}

/// CFR bins (in file order) to CIR taps, in place:
/// `h[n] = (1/N) sum_k H[k] exp(+j 2 pi k n / N)`.
pub(crate) fn inverse_dft(planner: &mut FftPlanner<f64>, bins: &mut [Complex64]) {
    planner.plan_fft_inverse(bins.len()).process(bins);
    let scale = 1.0 / bins.len() as f64;
    bins.iter_mut().for_each(|t| *t *= scale);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sidecar(text: &str) -> CirSidecar {
        CirSidecar::parse(Path::new("s.toml"), text).unwrap()
    }

    #[test]
    fn axes_orders_and_iq() {
        // (2, 3) C order vs the same values in Fortran order.
        let values: Vec<Complex64> = (0..6).map(|v| Complex64::new(f64::from(v), 0.0)).collect();
        let c = NdComplex::new(vec![2, 3], values.clone(), false);
        let f = NdComplex::new(vec![2, 3], values, true);
        let s = sidecar("carrier_hz = 1e9\ntap_spacing_s = 1e-9\nsnapshot_period_s = 0.5\nt0_ns = 7");
        let cs = cut_snapshots(Path::new("a"), &c, &s, "array", None).unwrap();
        assert_eq!(cs[1].taps.iter().map(|t| t.re).collect::<Vec<_>>(), [3.0, 4.0, 5.0]);
        assert_eq!((cs[1].t_ns, cs[1].set_index), (500_000_007, 1));
        let fs = cut_snapshots(Path::new("a"), &f, &s, "array", None).unwrap();
        assert_eq!(fs[1].taps.iter().map(|t| t.re).collect::<Vec<_>>(), [1.0, 3.0, 5.0]);
        // I/Q pairs, C and Fortran: (2 taps, 2) -> 2 complex taps.
        let iq = NdComplex::from_iq(&[2, 2], &[1.0, 2.0, 3.0, 4.0], false).unwrap();
        assert_eq!(iq.values, [Complex64::new(1.0, 2.0), Complex64::new(3.0, 4.0)]);
        let iq = NdComplex::from_iq(&[2, 2], &[1.0, 2.0, 3.0, 4.0], true).unwrap();
        assert_eq!(iq.values, [Complex64::new(1.0, 3.0), Complex64::new(2.0, 4.0)]);
        assert!(NdComplex::from_iq(&[2, 3], &[0.0; 6], false).unwrap_err().contains("trailing I/Q axis"));
        // 3-D default: [rx, tx, tap]; TX-major output.
        let v: Vec<Complex64> = (0..8).map(|v| Complex64::new(f64::from(v), 0.0)).collect();
        let a = NdComplex::new(vec![2, 2, 2], v, false);
        let cs = cut_snapshots(Path::new("a"), &a, &s, "array", None).unwrap();
        // TX 0, RX 1 = element (1, 0, :) = 4, 5.
        assert_eq!((cs[1].tx_antenna, cs[1].rx_antenna, cs[1].taps[0].re), (0, 1, 4.0));
    }

    #[test]
    fn cfr_becomes_cir_by_inverse_dft() {
        // H[k] = exp(-j 2 pi k 3 / 8): a single path at tap 3.
        let n = 8;
        let bins: Vec<Complex64> =
            (0..n).map(|k| Complex64::from_polar(2.0, -2.0 * std::f64::consts::PI * (3 * k) as f64 / 8.0)).collect();
        let s = sidecar("carrier_hz = 60e9\ndomain = \"cfr\"\nsubcarrier_spacing_hz = 10e6");
        let cs = cut_snapshots(Path::new("a"), &NdComplex::new(vec![n], bins, false), &s, "array", None).unwrap();
        for (k, tap) in cs[0].taps.iter().enumerate() {
            let expected = if k == 3 { 2.0 } else { 0.0 };
            // 1e-12: rounding of an 8-point FFT of unit-scale values.
            assert!((tap - Complex64::new(expected, 0.0)).norm() < 1e-12, "tap {k}: {tap}");
        }
        assert!((cs[0].tap_spacing_s - 1.0 / 80e6).abs() < 1e-20);
    }

    #[test]
    fn missing_keys_and_bad_values_are_errors() {
        let a = NdComplex::new(vec![4], vec![Complex64::new(1.0, 0.0); 4], false);
        let err = cut_snapshots(Path::new("a.npy"), &a, &sidecar("tap_spacing_s = 1e-9"), "array", None).unwrap_err();
        assert!(err.to_string().contains("key `carrier_hz`: required: a.npy"), "{err}");
        let err = cut_snapshots(Path::new("a.npy"), &a, &sidecar("carrier_hz = 1"), "array", None).unwrap_err();
        assert!(err.to_string().contains("key `tap_spacing_s`"), "{err}");
        let s = sidecar("carrier_hz = 1\ntap_spacing_s = 1e-9\naxes = [\"snapshot\", \"tap\"]");
        let err = cut_snapshots(Path::new("a.npy"), &a, &s, "array", None).unwrap_err();
        assert!(err.to_string().contains("names 2 axes (snapshot, tap) but array of a.npy has shape [4]"), "{err}");
        let mut nan = a.clone();
        nan.values[2].im = f64::NAN;
        let s = sidecar("carrier_hz = 1\ntap_spacing_s = 1e-9");
        let err = cut_snapshots(Path::new("a.npy"), &nan, &s, "array", None).unwrap_err();
        assert!(err.to_string().contains("a.npy: array, snapshot 0, TX 0, RX 0: taps:"), "{err}");
        let five = NdComplex::new(vec![1, 1, 1, 1, 4], a.values.clone(), false);
        let err = cut_snapshots(Path::new("a.npy"), &five, &s, "array", None).unwrap_err();
        assert!(err.to_string().contains("name its axes"), "{err}");
    }
}
