//! Integration tests of mmtrack-mpc.
#![allow(clippy::unwrap_used)]

mod common;
mod detect;
mod gmphd;
mod gmphd_generic;
mod long_term;
mod pipeline;
mod realdata_cir;
mod short_term;
