//! Integration tests of mmtrack-mpc.

mod common;
mod detect;
mod gmphd;
mod realdata_cir;
mod short_term;
