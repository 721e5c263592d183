//! Integration tests of mmtrack-reproduce (one test binary, one module per
//! topic): the experiments called as library functions, no binary.

#![allow(clippy::unwrap_used)]

mod drives;
mod experiments;
mod overpass;
