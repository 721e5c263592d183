//! # mmtrack-fuzz
//!
//! Bounded-time mutation fuzzing of mmtrack's byte-level readers, on stable
//! Rust and without libFuzzer: a deterministic mutator ([`mutate`]) seeded
//! from the real samples and from small inputs our own writers make
//! ([`seeds`], [`writers`]), one target per reader ([`targets`]), and a loop
//! ([`runner`]) that runs each input under `catch_unwind` with an allocator
//! that notes any single allocation above a cap ([`alloc`]).
//!
//! Two uses: CI runs every target for a fixed number of executions
//! (`tests/it`, deterministic, asserts no findings); `cargo run --profile
//! fuzz -p mmtrack-fuzz -- <target>|all --seconds N` runs as long as wanted
//! and saves findings under `target/fuzz-findings/<target>/` (the `fuzz`
//! profile is release with overflow checks and debug assertions, so an
//! integer overflow panics as in the tests instead of wrapping).
//!
//! A dev-only crate (`publish = false`): it depends on the readers
//! (`mmtrack-ingest`, `mmtrack-io`, `mmtrack-core`) and nothing depends on
//! it. Linking it installs its global allocator.

pub mod alloc;
pub mod mutate;
pub mod runner;
pub mod seeds;
pub mod targets;
pub mod writers;

use std::path::{Path, PathBuf};

/// Where findings go: `$CARGO_TARGET_DIR/fuzz-findings`, else the
/// workspace's `target/fuzz-findings`.
#[must_use]
pub fn findings_dir() -> PathBuf {
    // The workspace root is two levels above this crate's manifest directory.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).ancestors().nth(2).unwrap_or(Path::new("."));
    let target = std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from);
    target.join("fuzz-findings")
}
