//! Integration tests of mmtrack-odometry (one test binary).
#![allow(clippy::unwrap_used)]

mod realdata_oxford;
mod synthetic;
