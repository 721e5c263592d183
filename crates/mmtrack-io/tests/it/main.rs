//! Integration tests of mmtrack-io (one binary: every test binary links the world).

mod bad_input;
mod roundtrip;
mod samples;
mod schemas;
