//! # mmtrack-py
//!
//! The Python package `mmtrack`: a thin front end over the libraries, as the
//! CLI is. [`arrays`] holds the array-level calls (plain Rust over the
//! libraries); the pyo3 bindings (module `python`) only convert arguments
//! and results.

pub mod arrays;
mod python;
