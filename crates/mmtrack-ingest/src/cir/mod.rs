//! Channel-sounder impulse responses (CIRs) from the files sounders and radios
//! write, as [`mmtrack_core::CirSnapshot`]s.
//!
//! - [`decawave`]: DecaWave DecaRanging accumulator logs (DW1000 UWB radios),
//!   one CIR per received frame, with the chip's first-path index.
//! - [`matlab`]: numeric arrays in MATLAB v5/v7 `.mat` files (compressed or
//!   not), one CIR per antenna pair, with a caller-given [`matlab::MatCirLayout`]
//!   saying which dimension holds the taps and the antennas.
//!
//! Both are pure parse functions on text or bytes, plus a helper reading the
//! file; errors name the file, the record and the field.

pub mod decawave;
mod inflate;
pub mod matlab;

pub use decawave::{
    DecawaveConfig, DecawaveDelayReference, DecawaveFrame, DecawaveLog, DecawaveTimeBase, parse_decawave_log,
    parse_decawave_log_detailed, read_decawave_log,
};
pub use matlab::{MatCirLayout, read_mat_cir, read_mat_cir_file};
