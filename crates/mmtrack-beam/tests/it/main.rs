//! Integration tests of mmtrack-beam (one test binary, one module per topic).

mod overpass;
