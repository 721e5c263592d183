//! Channel-sounder impulse responses (CIRs) from the files sounders and radios
//! write, as [`mmtrack_core::CirSnapshot`]s.
//!
//! - [`decawave`]: DecaWave DecaRanging accumulator logs (DW1000 UWB radios),
//!   one CIR per received frame, with the chip's first-path index.
//! - [`matlab`]: numeric arrays in MATLAB v5/v7 `.mat` files (compressed or
//!   not), one CIR per antenna pair, with a caller-given [`matlab::MatCirLayout`]
//!   saying which dimension holds the taps and the antennas.
//! - NumPy `.npy` / `.npz`, SigMF and CSV files, read through
//!   [`read_cir_file`] with a [`CirSidecar`] (TOML) giving what the file lacks;
//!   `.mat` files go the same way there.
//! - HDF5 datasets and MATLAB v7.3 `.mat` files (which are HDF5), in builds
//!   with the `hdf5` cargo feature (`hdf5.rs`; it links libhdf5); without it,
//!   they are recognised and refused with an error saying how to rebuild.
//! - [`ingest_cir`] writes any of them into a recording on `/channel/cir`.
//!
//! All are pure parse functions on text or bytes, plus helpers reading the
//! file; errors name the file, the record and the field.

mod array;
mod csv_cir;
pub mod decawave;
mod hdf5;
#[cfg(feature = "hdf5")]
mod hdf5_read;
#[cfg(test)]
#[cfg(feature = "hdf5")]
mod hdf5_tests;
mod inflate;
mod ingest;
pub mod matlab;
mod npy;
pub mod sidecar;
mod sigmf;

pub use decawave::{
    DecawaveConfig, DecawaveDelayReference, DecawaveFrame, DecawaveLog, DecawaveTimeBase, parse_decawave_log,
    parse_decawave_log_detailed, read_decawave_log,
};
pub use ingest::{CirFile, CirFormat, CirIngestReport, ingest_cir, read_cir_file};
pub use matlab::{MatCirLayout, read_mat_cir, read_mat_cir_file};
pub use npy::{NpyMatrix, NpyValues, parse_npy_matrix, read_npy_matrix};
pub use sidecar::{AxisRole, CirSidecar, Domain, TapSpacing};
