//! Integration tests of mmtrack-filter (one test binary, one module per topic).

mod assignment;
mod bad_input;
mod ekf;
mod gmphd;
mod kalman;
mod metrics;
mod support;
