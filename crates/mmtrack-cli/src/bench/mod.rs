//! `mmtrack bench`: throughput measured against a baseline in the same run,
//! by the benchmarks of [`mmtrack_reproduce::bench`]. Each subcommand is its
//! arguments, one library call, the printed table, the README block and the
//! exit code (`--check`: 1 when a target is missed).

mod ingest;
mod io;
mod mpc;
mod odometry;
mod output;
mod slam;

use std::process::ExitCode;

use clap::{Args, Subcommand};

#[derive(Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    kind: Kind,
}

#[derive(Subcommand)]
enum Kind {
    /// MPC detection plus short- and long-term tracking snapshots/s on simulated 2048-tap CIRs; GM-PHD ratio.
    Mpc(mpc::MpcBenchArgs),
    /// End-to-end radar odometry scans/s on real Oxford scans (PNG decode included), per stage.
    Odometry(odometry::OdometryBenchArgs),
    /// 5G mmWave SLAM filter: time per 200 ms epoch (2000 particles, 10 iterations) vs real time and one thread.
    Slam(slam::SlamBenchArgs),
    /// Oxford-folder ingest (PNG bytes carried) in scans/s vs copying the folder; peak memory at two folder sizes.
    Ingest(ingest::IngestBenchArgs),
    /// MCAP write/read throughput of 1.5 MB radar-scan messages vs std::fs::copy.
    Io(io::IoBenchArgs),
}

pub fn run(args: &BenchArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    match &args.kind {
        Kind::Odometry(odometry) => odometry::run(odometry, quiet),
        Kind::Mpc(mpc) => mpc::run(mpc, quiet),
        Kind::Slam(slam) => slam::run(slam, quiet),
        Kind::Ingest(ingest) => ingest::run(ingest, quiet),
        Kind::Io(io) => io::run(io, quiet),
    }
}
