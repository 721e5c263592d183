//! End-to-end tests of the `mmtrack` binary and workspace-wide checks (one
//! binary: every test binary links the world).

#![allow(clippy::unwrap_used)]

mod analyze;
mod architecture;
mod bad_png;
mod bench_mpc;
mod bounds;
mod check;
mod cli;
mod common;
mod doc_links;
mod error_lines;
mod file_cycles;
mod fixtures;
mod foxglove_views;
mod independent_readers;
mod ingest_navtech;
mod interrupt;
mod odometry_frames;
mod output_safety;
mod process_beam_geometric;
mod process_beam_spebt;
mod process_manifest;
mod process_mpc;
mod process_odometry;
mod process_raw;
mod python_package;
mod realdata_beams;
mod realdata_nmea;
mod realdata_oxford;
mod realdata_ros2;
mod report_browser;
mod reproduce;
mod reproduce_kim;
mod reproduce_shaham;
mod reproduce_spebt;
mod reproduce_zoechmann;
mod run_ids;
mod simulate_radar;
mod simulate_sounder;
mod slam_pipeline;
mod table_metadata;
mod threads;
