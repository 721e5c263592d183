//! Integration tests of mmtrack-reproduce (one test binary, one module per
//! topic): the experiments and benchmarks called as library functions, no
//! binary.

#![allow(clippy::unwrap_used)]

mod bench;
mod drives;
mod experiments;
mod overpass;
