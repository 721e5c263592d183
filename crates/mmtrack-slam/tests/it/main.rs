//! Integration tests of mmtrack-slam (one test binary, one module per topic).

#![allow(clippy::unwrap_used)]

mod filter;
