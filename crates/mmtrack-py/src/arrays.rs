//! The array-level calls of the Python package, without files: MPC
//! detection on CIR arrays, the beam-sweep trackers on a power array, and
//! trajectory metrics on two pose arrays. Each calls the library function
//! the pipeline of the same name calls and returns the rows of the table
//! the CLI would write, as the bytes of a Parquet file of that table
//! ([`mmtrack_io::table::table_bytes`]: the same columns, types and units),
//! so a notebook reads them with `polars.read_parquet` and compares them
//! with the CLI's tables column for column.
//!
//! Arrays arrive as little-endian bytes (numpy `tobytes()` of a C-ordered
//! array of the named dtype): exact, and no numpy C API in the module.

use std::path::Path;

use anyhow::{Context, bail, ensure};
use mmtrack_analysis::analyze::AnalyzeOptions;
use mmtrack_analysis::pipeline::analyze_trajectory;
use mmtrack_core::sounder::SounderBand;
use mmtrack_core::{BeamSweep, CirSnapshot, Complex64, MpcDetection, Se2, StampedPose};
use mmtrack_io::table::{BeamSweepTracked, RunInfo, TableTimeBase, table_bytes};
use mmtrack_mpc::{Detector, SounderPulse};
use mmtrack_process::beam::sweep::{Reacquire, SweepTrackerKind, track_pass};

/// `f64` values of little-endian bytes.
///
/// # Errors
/// A length that is not a multiple of 8, naming `what`.
pub fn f64s(bytes: &[u8], what: &str) -> anyhow::Result<Vec<f64>> {
    ensure!(bytes.len() % 8 == 0, "{what}: {} bytes is not a whole number of float64 values", bytes.len());
    Ok(bytes.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8]))).collect())
}

/// `i64` values of little-endian bytes.
///
/// # Errors
/// A length that is not a multiple of 8, naming `what`.
pub fn i64s(bytes: &[u8], what: &str) -> anyhow::Result<Vec<i64>> {
    ensure!(bytes.len() % 8 == 0, "{what}: {} bytes is not a whole number of int64 values", bytes.len());
    Ok(bytes.chunks_exact(8).map(|c| i64::from_le_bytes(c.try_into().unwrap_or([0; 8]))).collect())
}

/// Complex values of interleaved little-endian `f64` pairs (numpy complex128).
///
/// # Errors
/// A length that is not a multiple of 16, naming `what`.
pub fn complexes(bytes: &[u8], what: &str) -> anyhow::Result<Vec<Complex64>> {
    ensure!(bytes.len() % 16 == 0, "{what}: {} bytes is not a whole number of complex128 values", bytes.len());
    let values = f64s(bytes, what)?;
    Ok(values.chunks_exact(2).map(|c| Complex64::new(c[0], c[1])).collect())
}

fn run_info(call: &str, config: serde_json::Value) -> RunInfo {
    RunInfo {
        config_json: serde_json::json!({
            "command": call,
            "config": config,
            "mmtrack_version": env!("CARGO_PKG_VERSION"),
        })
        .to_string(),
        // No recording: t_ns is whatever the caller's array holds.
        time_base: TableTimeBase {
            name: "caller".to_string(),
            meaning: "t_ns as the caller's array gives it (an array call on no recording)".to_string(),
        },
        frame: None,
    }
}

/// What [`detect_mpc`] is given besides the taps.
#[derive(Debug, Clone)]
pub struct CirArray<'a> {
    /// Taps, snapshot after snapshot (`snapshots x taps`).
    pub taps: &'a [Complex64],
    /// Taps per snapshot.
    pub taps_per_snapshot: usize,
    /// Time of each snapshot, ns.
    pub t_ns: &'a [i64],
    /// Set of each snapshot.
    pub set_index: &'a [u64],
    /// Index of each snapshot within its set.
    pub snapshot_index: &'a [u32],
    /// Tap spacing, seconds.
    pub tap_spacing_s: f64,
}

/// CLEAN detection (Mahler et al. 2017, Sec. III-A) of every snapshot of
/// `cir` with the detection settings of the MPC configuration (the
/// defaults, or the TOML file `config` on top, as `process mpc --config`)
/// and the sounder pulse `pulse` (a back-to-back CIR of the sounder), or the
/// band's flat spectrum: the `mpc_detections` rows `process mpc` writes for
/// the same CIRs.
///
/// # Errors
/// Arrays of different lengths, a bad configuration or pulse, and the
/// detector's errors (naming the snapshot).
pub fn detect_mpc(cir: &CirArray<'_>, config: Option<&Path>, pulse: Option<&[Complex64]>) -> anyhow::Result<Vec<u8>> {
    let n = cir.t_ns.len();
    ensure!(cir.taps_per_snapshot > 0, "cir: no taps");
    ensure!(
        cir.taps.len() == n * cir.taps_per_snapshot,
        "cir: {} taps for {n} snapshots of {} taps",
        cir.taps.len(),
        cir.taps_per_snapshot
    );
    ensure!(
        cir.set_index.len() == n && cir.snapshot_index.len() == n,
        "t_ns, set_index and snapshot_index: one per snapshot ({n}, {}, {})",
        cir.set_index.len(),
        cir.snapshot_index.len()
    );
    let mpc_config = mmtrack_process::mpc::effective_config(config)?;
    let pulse = match pulse {
        Some(b2b) => SounderPulse::from_back_to_back_cir(b2b).context("pulse: back-to-back CIR")?,
        None => SounderPulse::flat(
            &SounderBand::new(cir.taps_per_snapshot, cir.tap_spacing_s).context("cir: tap spacing and taps")?,
        ),
    };
    let detector = Detector::new(mpc_config.detection.clone(), cir.tap_spacing_s, &pulse)?;
    let mut rows: Vec<MpcDetection> = Vec::new();
    for (i, taps) in cir.taps.chunks_exact(cir.taps_per_snapshot).enumerate() {
        let snapshot = CirSnapshot {
            t_ns: cir.t_ns[i],
            set_index: cir.set_index[i],
            snapshot_index: cir.snapshot_index[i],
            tx_antenna: 0,
            rx_antenna: 0,
            // Detection does not use the carrier (only the trackers' Doppler does).
            carrier_hz: 0.0,
            tap_spacing_s: cir.tap_spacing_s,
            delay_offset_s: 0.0,
            taps: taps.to_vec(),
            first_path_hint_s: None,
        };
        rows.extend(detector.detect(&snapshot, i)?.detections);
    }
    let info = run_info("mmtrack.detect_mpc", serde_json::json!({ "detection": mpc_config.detection }));
    Ok(table_bytes(&rows, &info)?)
}

/// The sweep policies `trackers` (window, last-full-sweep) on full sweeps
/// of `beams` beams: row `i` of `power` (linear power per beam) at
/// `t_ns[i]`. The `beam_sweeps_tracked` rows `process beam` writes for a
/// recording of the same sweeps (site `site`), policy after policy.
///
/// # Errors
/// A power array that is not `t_ns.len() x beams`, an unknown or GNSS
/// policy, bad sweeps, and the trackers' errors.
pub fn track_beams(
    power: &[f64],
    beams: usize,
    t_ns: &[i64],
    trackers: &[String],
    reacquire: &str,
    site: &str,
) -> anyhow::Result<Vec<u8>> {
    ensure!(beams > 0, "power: no beams");
    ensure!(
        power.len() == t_ns.len() * beams,
        "power: {} values for {} sweeps of {beams} beams",
        power.len(),
        t_ns.len()
    );
    let reacquire = Reacquire::parse(reacquire)?;
    let mut kinds = trackers.iter().map(|t| SweepTrackerKind::parse(t)).collect::<anyhow::Result<Vec<_>>>()?;
    kinds.sort();
    kinds.dedup();
    if kinds.is_empty() {
        bail!("--tracker: name at least one of window, last-full-sweep");
    }
    let sweeps = power
        .chunks_exact(beams)
        .zip(t_ns)
        .enumerate()
        .map(|(i, (row, &t))| {
            BeamSweep::new(t, row.to_vec(), vec![true; beams]).with_context(|| format!("power: sweep {i} (t_ns {t})"))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut rows: Vec<BeamSweepTracked> = Vec::new();
    for kind in &kinds {
        rows.extend(track_pass(*kind, reacquire, site, &sweeps)?);
    }
    let info = run_info(
        "mmtrack.track_beams",
        serde_json::json!({ "trackers": kinds.iter().map(|k| k.name()).collect::<Vec<_>>(), "reacquire": format!("{reacquire:?}") }),
    );
    Ok(table_bytes(&rows, &info)?)
}

/// Poses of `t_ns` and `x_y_yaw` (`x_m, y_m, yaw_rad` per row).
///
/// # Errors
/// Arrays of different lengths, naming `which`.
pub fn poses(which: &str, t_ns: &[i64], x_y_yaw: &[f64]) -> anyhow::Result<Vec<StampedPose>> {
    ensure!(
        x_y_yaw.len() == 3 * t_ns.len(),
        "{which}: {} pose values for {} times (expected x_m, y_m, yaw_rad per time)",
        x_y_yaw.len(),
        t_ns.len()
    );
    Ok(t_ns
        .iter()
        .zip(x_y_yaw.chunks_exact(3))
        .map(|(&t, p)| StampedPose { t_ns: t, parent_from_child: Se2::new(p[0], p[1], p[2]) })
        .collect())
}

/// Trajectory metrics of `estimate` against `ground_truth` as `analyze`
/// computes them for one sequence ([`analyze_trajectory`]): the rows of
/// `trajectory_metrics`, `drift_per_length` and `relative_pose_errors`,
/// each as table bytes.
///
/// # Errors
/// Bad options or trajectories, as `analyze` reports them.
pub fn trajectory_metrics(
    sequence: &str,
    estimate: &[StampedPose],
    ground_truth: &[StampedPose],
    options: &AnalyzeOptions,
) -> anyhow::Result<[Vec<u8>; 3]> {
    // The option check of `analyze` (segment lengths, step).
    mmtrack_analysis::trajectory::kitti_drift(&[], &[], &options.drift).context("--segment-lengths-m / --step-*")?;
    let result = analyze_trajectory(sequence, estimate, ground_truth, &options.drift)?;
    let info = run_info(
        "mmtrack.trajectory_metrics",
        serde_json::json!({ "segment_lengths_m": options.drift.segment_lengths_m, "step": format!("{:?}", options.drift.step) }),
    );
    Ok([
        table_bytes(std::slice::from_ref(&result.metrics), &info)?,
        table_bytes(&result.drift_rows(), &info)?,
        table_bytes(&result.rpe_rows(), &info)?,
    ])
}
