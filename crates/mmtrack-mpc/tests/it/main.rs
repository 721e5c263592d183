//! Integration tests of mmtrack-mpc.
