//! Integration tests of mmtrack-io (one binary: every test binary links the world).

#![allow(clippy::unwrap_used)]

mod bad_input;
mod roundtrip;
mod roundtrip_beam;
mod roundtrip_mpc;
mod roundtrip_slam;
mod samples;
mod schemas;
