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
use mmtrack_core::progress::Progress;
use mmtrack_core::sounder::SounderBand;
use mmtrack_core::{BeamSweep, CirSnapshot, Complex64, MpcDetection, Se2, StampedPose};
use mmtrack_io::table::{RunInfo, TableTimeBase, table_bytes};
use mmtrack_mpc::{Detector, SounderPulse};
use mmtrack_process::beam::sweep::{PassInput, Reacquire, SweepTrackerKind, car_east_north_m, track_site};

/// `f64` values of little-endian bytes.
///
/// # Errors
/// A length that is not a multiple of 8, naming `what`.
pub fn f64s(bytes: &[u8], what: &str) -> anyhow::Result<Vec<f64>> {
    ensure!(bytes.len().is_multiple_of(8), "{what}: {} bytes is not a whole number of float64 values", bytes.len());
    Ok(bytes.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8]))).collect())
}

/// `i64` values of little-endian bytes.
///
/// # Errors
/// A length that is not a multiple of 8, naming `what`.
pub fn i64s(bytes: &[u8], what: &str) -> anyhow::Result<Vec<i64>> {
    ensure!(bytes.len().is_multiple_of(8), "{what}: {} bytes is not a whole number of int64 values", bytes.len());
    Ok(bytes.chunks_exact(8).map(|c| i64::from_le_bytes(c.try_into().unwrap_or([0; 8]))).collect())
}

/// Complex values of interleaved little-endian `f64` pairs (numpy complex128).
///
/// # Errors
/// A length that is not a multiple of 16, naming `what`.
pub fn complexes(bytes: &[u8], what: &str) -> anyhow::Result<Vec<Complex64>> {
    ensure!(bytes.len().is_multiple_of(16), "{what}: {} bytes is not a whole number of complex128 values", bytes.len());
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
/// detector's errors (naming the snapshot); [`Progress::check_cancelled`]'s
/// error, asked once per snapshot.
pub fn detect_mpc(
    cir: &CirArray<'_>,
    config: Option<&Path>,
    pulse: Option<&[Complex64]>,
    progress: &dyn Progress,
) -> anyhow::Result<Vec<u8>> {
    let n = cir.t_ns.len();
    ensure!(cir.taps_per_snapshot > 0, "cir: no taps");
    let rows = cir.taps.len() / cir.taps_per_snapshot;
    ensure!(
        cir.taps.len().is_multiple_of(cir.taps_per_snapshot),
        "cir: {} taps are not snapshots of {} taps",
        cir.taps.len(),
        cir.taps_per_snapshot
    );
    ensure!(
        rows == n && cir.set_index.len() == n && cir.snapshot_index.len() == n,
        "t_ns, set_index and snapshot_index: one per snapshot of cir ({rows}), got {n}, {} and {}",
        cir.set_index.len(),
        cir.snapshot_index.len()
    );
    // The labels name the snapshot of each detection: two rows with the same
    // ones could not be told apart (the detections of both read as the last's).
    let mut seen = std::collections::HashMap::with_capacity(n);
    for i in 0..n {
        let label = (cir.t_ns[i], cir.set_index[i], cir.snapshot_index[i]);
        if let Some(first) = seen.insert(label, i) {
            bail!(
                "t_ns, set_index, snapshot_index: rows {first} and {i} are both ({}, {}, {}); each row is one snapshot",
                label.0,
                label.1,
                label.2
            );
        }
    }
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
        progress.check_cancelled()?;
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

/// Full sweeps as arrays: row `i` of `power` (linear power per beam, `beams`
/// per row) at `t_ns[i]`, in pass `pass_index[i]` (one pass when absent;
/// a pass's sweeps are consecutive rows), the car at `car[i]`.
#[derive(Debug, Clone, Copy)]
pub struct SweepArrays<'a> {
    /// Linear power, sweeps x beams, row-major.
    pub power: &'a [f64],
    /// Beams per sweep.
    pub beams: usize,
    /// Sweep times, ns.
    pub t_ns: &'a [i64],
    /// Pass of each sweep.
    pub pass_index: Option<&'a [i64]>,
    /// The car's position at each sweep (two values per sweep).
    pub car: Option<&'a [f64]>,
    /// What `car` holds.
    pub car_frame: CarFrame<'a>,
}

/// How the car's positions are given.
#[derive(Debug, Clone, Copy)]
pub enum CarFrame<'a> {
    /// East and north metres from the array.
    EastNorthM,
    /// Latitude and longitude, degrees; the array's latitude and longitude
    /// per sweep (two values per sweep) or once (two values).
    LatLonDeg {
        /// The array's position.
        array_lat_lon_deg: &'a [f64],
    },
}

/// The sweep policies `trackers` (window, gnss-window, last-full-sweep,
/// gnss-map) on the passes of `sweeps` at one site: per pass (in order of
/// first appearance), its `pass_index` value and the `beam_sweeps_tracked`
/// rows `process beam` writes for a recording of that pass, policy after
/// policy. The GNSS policies fit the beam map leave-one-pass-out over the
/// passes given, as `process beam` does over the recordings of a site
/// ([`track_site`]).
///
/// # Errors
/// A power array that is not `t_ns.len() x beams`; pass indices, car or
/// array positions of the wrong length or not finite; a pass split into
/// pieces; an unknown policy; bad sweeps, and the trackers' errors;
/// [`Progress::check_cancelled`]'s error, asked per sweep read and per pass
/// and policy tracked.
pub fn track_beams(
    sweeps: &SweepArrays<'_>,
    trackers: &[String],
    reacquire: &str,
    site: &str,
    progress: &dyn Progress,
) -> anyhow::Result<Vec<(i64, Vec<u8>)>> {
    let SweepArrays { power, beams, t_ns, pass_index, car, car_frame } = *sweeps;
    let n = t_ns.len();
    ensure!(beams > 0, "power: no beams");
    ensure!(power.len() == n * beams, "power: {} values for {n} sweeps of {beams} beams", power.len());
    let reacquire = Reacquire::parse(reacquire)?;
    let kinds = trackers.iter().map(|t| SweepTrackerKind::parse(t)).collect::<anyhow::Result<Vec<_>>>()?;
    let pass_of = |i: usize| pass_index.map_or(0, |p| p[i]);
    if let Some(p) = pass_index {
        ensure!(p.len() == n, "pass_index: {} values for {n} sweeps", p.len());
    }
    let positions: Option<Vec<[f64; 2]>> = match car {
        None => None,
        Some(car) => {
            ensure!(car.len() == 2 * n, "car positions: {} values for {n} sweeps (expected 2 per sweep)", car.len());
            if let Some(i) = car.iter().position(|v| !v.is_finite()) {
                bail!("car positions: sweep {}: {} is not finite", i / 2, car[i]);
            }
            Some(match car_frame {
                CarFrame::EastNorthM => car.chunks_exact(2).map(|c| [c[0], c[1]]).collect(),
                CarFrame::LatLonDeg { array_lat_lon_deg: array } => {
                    ensure!(
                        array.len() == 2 || array.len() == 2 * n,
                        "array_lat_lon_deg: {} values (expected 2, or 2 per sweep for {n} sweeps)",
                        array.len()
                    );
                    if let Some(i) = array.iter().position(|v| !v.is_finite()) {
                        bail!("array_lat_lon_deg: value {i} ({}) is not finite", array[i]);
                    }
                    let array_at = |i: usize| {
                        if array.len() == 2 { [array[0], array[1]] } else { [array[2 * i], array[2 * i + 1]] }
                    };
                    car.chunks_exact(2).enumerate().map(|(i, c)| car_east_north_m([c[0], c[1]], array_at(i))).collect()
                }
            })
        }
    };
    let sweeps = power
        .chunks_exact(beams)
        .zip(t_ns)
        .enumerate()
        .map(|(i, (row, &t))| {
            progress.check_cancelled()?;
            BeamSweep::new(t, row.to_vec(), vec![true; beams]).with_context(|| format!("power: sweep {i} (t_ns {t})"))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    // Passes: runs of equal pass_index, each appearing once.
    let mut spans: Vec<(i64, std::ops::Range<usize>)> = Vec::new();
    for i in 0..n {
        match spans.last_mut() {
            Some((pass, range)) if *pass == pass_of(i) => range.end = i + 1,
            _ => {
                if let Some((_, earlier)) = spans.iter().find(|(pass, _)| *pass == pass_of(i)) {
                    bail!(
                        "pass_index: pass {} holds sweeps {}..{} and again sweep {i}; a pass's sweeps must be \
                         consecutive rows",
                        pass_of(i),
                        earlier.start,
                        earlier.end - 1
                    );
                }
                spans.push((pass_of(i), i..i + 1));
            }
        }
    }
    ensure!(!spans.is_empty(), "power: no sweeps");
    let labels: Vec<String> =
        spans.iter().map(|(pass, range)| format!("pass {pass} (sweeps {}..{})", range.start, range.end - 1)).collect();
    let inputs: Vec<PassInput<'_>> = spans
        .iter()
        .zip(&labels)
        .map(|((_, range), label)| PassInput {
            label,
            sweeps: &sweeps[range.clone()],
            east_north_m: positions.as_deref().map(|p| &p[range.clone()]),
        })
        .collect();
    let run = track_site(&kinds, reacquire, site, &inputs, progress)?;
    // The policies run, once each, in `process beam`'s order.
    let names: Vec<&str> = run.summaries.iter().map(|(kind, _)| kind.name()).collect();
    let info = run_info(
        "mmtrack.track_beams",
        serde_json::json!({ "trackers": names, "reacquire": format!("{reacquire:?}"), "beam_map": "fitted leave-one-pass-out over the passes given" }),
    );
    spans.iter().zip(run.rows).map(|((pass, _), rows)| Ok((*pass, table_bytes(&rows, &info)?))).collect()
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
    let info = run_info("mmtrack.trajectory_metrics", serde_json::Value::Object(options.drift.config_fields()));
    Ok([
        table_bytes(std::slice::from_ref(&result.metrics), &info)?,
        table_bytes(&result.drift_rows(), &info)?,
        table_bytes(&result.rpe_rows(), &info)?,
    ])
}
