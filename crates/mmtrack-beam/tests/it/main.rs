//! Integration tests of mmtrack-beam (one test binary, one module per topic).

#![allow(clippy::unwrap_used)]

mod deepsense;
