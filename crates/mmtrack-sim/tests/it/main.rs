//! Integration tests of mmtrack-sim (one test binary per crate).

#![allow(clippy::unwrap_used)]

mod radar;
mod sounder;
