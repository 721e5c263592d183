//! Integration tests of mmtrack-filter.
