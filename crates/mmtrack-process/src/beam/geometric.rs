//! The geometric Doppler-bearing tracker of Zoechmann et al. 2019 on a
//! recording's two vehicles (`mmtrack process beam --tracker geometric`).
//!
//! The recording must hold the ground truth of a transmitter and a receiver
//! vehicle (`/ground_truth/tx` and `/ground_truth/rx`, as `mmtrack
//! simulate sounder` writes them). Both are interpolated (linearly; yaw on
//! the shortest arc) every [`GeometricOptions::epoch_ms`] within their common time span; the
//! transmitter's position in the receiver's frame gives the true range and
//! azimuth, and central differences give the relative velocity and range
//! rate. The receiver's 60 GHz UCA codebook and the Doppler measurement
//! (`mmtrack_sim::beam::overtaking`'s defaults: 64 elements, 4-bit, 128
//! beams, 100 Hz noise drawn from [`GeometricOptions::doppler_seed`]) are simulated on those
//! truths, and the tracker measures through the paper's beam schedule (10
//! full scans, then the 3 beams nearest its projected azimuth) or, with
//! [`Schedule::FullScan`], a full scan every epoch. One
//! `geometric_per_epoch` partition per recording.
//!
//! The tracker assumes constant relative velocity; real drives (speed swings,
//! curves) violate it, and the table shows how far the estimate drifts.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail, ensure};
use mmtrack_beam::geometric::{
    BeamSchedule, BeamSelection, DopplerBearing, GeometricTracker, GeometricTrackerConfig, RangeEstimator,
};
use mmtrack_core::random::standard_normal;
use mmtrack_core::{Se2, StampedPose, wrap_angle_rad};
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase};
use mmtrack_io::table::RunInfo;
use mmtrack_io::table::{
    GEOMETRIC_FILTER_H_INFINITY, GEOMETRIC_FILTER_RLS, GEOMETRIC_PER_EPOCH, GeometricEpochRow, TableWriteSummary,
};
use mmtrack_io::{RecordingEvent, RecordingReader};
use mmtrack_sim::beam::overtaking::OvertakingScenario;
use rand::SeedableRng;
use rand_pcg::Pcg64;

use crate::output::RunDir;

/// Which beams the tracker measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Schedule {
    /// 10 full scans, then the 3 beams nearest the projected azimuth (the paper's).
    #[default]
    Paper,
    /// A full scan every epoch.
    FullScan,
}

/// The options of [`process_geometric`] (`--tracker geometric`).
#[derive(Debug, Clone, Default)]
pub struct GeometricOptions {
    /// Beams measured per epoch.
    pub beam_schedule: Option<Schedule>,
    /// Epoch (scan) interval, milliseconds (default 20).
    pub epoch_ms: Option<f64>,
    /// Seed of the simulated Doppler noise (default 2019).
    pub doppler_seed: Option<u64>,
}

impl GeometricOptions {
    /// The flags given (to refuse them with the other trackers).
    #[must_use]
    pub fn given(&self) -> Vec<&'static str> {
        [
            ("--beam-schedule", self.beam_schedule.is_some()),
            ("--epoch-ms", self.epoch_ms.is_some()),
            ("--doppler-seed", self.doppler_seed.is_some()),
        ]
        .into_iter()
        .filter_map(|(flag, given)| given.then_some(flag))
        .collect()
    }
}

/// One recording's result of [`process_geometric`].
#[derive(Debug, Clone)]
pub struct GeometricRecordingResult {
    /// The sequence written.
    pub sequence_id: String,
    /// Epochs tracked.
    pub epochs: usize,
    /// The last epoch's row.
    pub last: GeometricEpochRow,
    /// Beams measured over all epochs.
    pub beams_measured: u64,
}

/// What [`process_geometric`] did.
#[derive(Debug, Clone)]
pub struct GeometricOutput {
    /// Per recording, in the order given.
    pub recordings: Vec<GeometricRecordingResult>,
    /// Each table written, with its row count.
    pub written: Vec<TableWriteSummary>,
}

struct TwoVehicles {
    sequence_id: String,
    time_base: TimeBase,
    tx: Vec<StampedPose>,
    rx: Vec<StampedPose>,
}

fn read(path: &Path) -> anyhow::Result<TwoVehicles> {
    let mut reader = RecordingReader::open(path)?;
    let (mut tx, mut rx) = (Vec::new(), Vec::new());
    for event in reader.by_ref() {
        match event? {
            RecordingEvent::Pose { stream: PoseStream::GroundTruthTx, pose } => tx.push(pose),
            RecordingEvent::Pose { stream: PoseStream::GroundTruthRx, pose } => rx.push(pose),
            _ => {}
        }
    }
    let metadata = reader.metadata().cloned().unwrap_or_default();
    let (sequence_id, time_base) = RecordingMetadata::from_map(&metadata)
        .map(|m| (m.sequence_id, m.time_base))
        .with_context(|| format!("{}: no mmtrack recording metadata (sequence id)", path.display()))?;
    let names = [PoseStream::GroundTruthTx, PoseStream::GroundTruthRx].map(|s| s.topic());
    for (name, poses) in [(format!("transmitter ({})", names[0]), &tx), (format!("receiver ({})", names[1]), &rx)] {
        if poses.len() < 2 {
            bail!(
                "{}: {} poses of the {name}; --tracker geometric needs both vehicles' ground truth (e.g. from `mmtrack \
                 simulate sounder`)",
                path.display(),
                poses.len()
            );
        }
        if let Some(i) = poses.windows(2).position(|p| p[1].t_ns <= p[0].t_ns) {
            bail!("{}: {name} pose {}: time does not increase", path.display(), i + 1);
        }
        if let Some(i) = poses.iter().position(|p| !p.parent_from_child.is_finite()) {
            bail!("{}: {name} pose {i} is not finite", path.display());
        }
    }
    Ok(TwoVehicles { sequence_id, time_base, tx, rx })
}

/// The pose at `t_ns` (inside the span), linear in x, y and shortest-arc yaw.
fn pose_at(poses: &[StampedPose], t_ns: i64) -> Se2 {
    let after = poses.partition_point(|p| p.t_ns < t_ns).clamp(1, poses.len() - 1);
    let (a, b) = (&poses[after - 1], &poses[after]);
    let f = ((t_ns - a.t_ns) as f64 / (b.t_ns - a.t_ns) as f64).clamp(0.0, 1.0);
    let (pa, pb) = (a.parent_from_child, b.parent_from_child);
    Se2::new(
        pa.x_m + f * (pb.x_m - pa.x_m),
        pa.y_m + f * (pb.y_m - pa.y_m),
        pa.yaw_rad + f * wrap_angle_rad(pb.yaw_rad - pa.yaw_rad),
    )
}

/// The transmitter in the receiver's frame at `t_ns`.
fn relative_m(v: &TwoVehicles, t_ns: i64) -> [f64; 2] {
    let tx = pose_at(&v.tx, t_ns);
    pose_at(&v.rx, t_ns).inverse().transform_point([tx.x_m, tx.y_m])
}

/// Runs the tracker on each recording; one partition per recording.
///
/// `out` is the run directory ([`crate::output::OutputOptions::resolve`]):
/// refusals look there and the tables go there.
///
/// # Errors
/// An existing table (without `force`), a recording without both vehicles'
/// ground truth (or with too short an overlap), a bad epoch, or a table that
/// cannot be written.
pub fn process_geometric(
    recordings: &[PathBuf],
    out: &RunDir,
    options: &GeometricOptions,
) -> anyhow::Result<GeometricOutput> {
    let scenario = OvertakingScenario::default();
    let epoch_s = options.epoch_ms.unwrap_or(1e3 * scenario.epoch_s) * 1e-3;
    ensure!(epoch_s.is_finite() && epoch_s > 0.0, "--epoch-ms must be positive (nothing was done)");
    let schedule_arg = options.beam_schedule.unwrap_or_default();
    let seed = options.doppler_seed.unwrap_or(2019);
    let receiver = scenario.receiver()?;
    let lambda = scenario.wavelength_m();
    let schedule = match schedule_arg {
        Schedule::Paper => BeamSchedule::paper(scenario.beams),
        Schedule::FullScan => BeamSchedule { full_scan_epochs: usize::MAX, ..BeamSchedule::paper(scenario.beams) },
    };
    let inputs = recordings.iter().map(|p| read(p).map(|r| (p, r))).collect::<anyhow::Result<Vec<_>>>()?;
    super::refuse_repeated_sequences(inputs.iter().map(|(p, r)| (r.sequence_id.as_str(), p.as_path())))?;
    for (_, r) in &inputs {
        out.refuse_existing(&[GEOMETRIC_PER_EPOCH.name], &r.sequence_id)?;
    }
    let step_ns = (epoch_s * 1e9).round() as i64;
    let (mut results, mut tables) = (Vec::new(), out.tables());
    for (path, vehicles) in &inputs {
        let start = vehicles.tx[0].t_ns.max(vehicles.rx[0].t_ns);
        let end = vehicles.tx[vehicles.tx.len() - 1].t_ns.min(vehicles.rx[vehicles.rx.len() - 1].t_ns);
        // One epoch of margin on each side for the central differences.
        let epochs = if end - start > 2 * step_ns { ((end - start) / step_ns - 1) as usize } else { 0 };
        ensure!(epochs >= 2, "{}: the two vehicles' ground truth overlap for less than 3 epochs", path.display());
        let config = GeometricTrackerConfig { wavelength_m: lambda, ..GeometricTrackerConfig::default() };
        let mut tracker = GeometricTracker::new(config)?;
        let mut rng = Pcg64::seed_from_u64(seed);
        let mut rows = Vec::with_capacity(epochs);
        for k in 0..epochs {
            let t_ns = start + (k as i64 + 1) * step_ns;
            let t_s = (t_ns - start) as f64 * 1e-9;
            let p = relative_m(vehicles, t_ns);
            let (before, after) = (relative_m(vehicles, t_ns - step_ns), relative_m(vehicles, t_ns + step_ns));
            let v = [(after[0] - before[0]) / (2.0 * epoch_s), (after[1] - before[1]) / (2.0 * epoch_s)];
            let range_m = p[0].hypot(p[1]);
            ensure!(range_m > 0.0, "{}: the vehicles coincide at t = {t_ns} ns", path.display());
            let azimuth_rad = p[1].atan2(p[0]);
            let range_rate = (after[0].hypot(after[1]) - before[0].hypot(before[1])) / (2.0 * epoch_s);
            let doppler_hz = range_rate / lambda + scenario.doppler_sigma_hz * standard_normal(&mut rng);
            let best = receiver.strongest_beam(azimuth_rad);
            let projected = if k > 0 { tracker.state().map(|s| s.azimuth_rad(t_s)) } else { None };
            let selection = schedule.select(k, projected);
            let (beam, beams_measured) = match &selection {
                BeamSelection::FullScan => (best, scenario.beams as u64),
                BeamSelection::Window(w) => (receiver.strongest_of(w, azimuth_rad).unwrap_or(best), w.len() as u64),
            };
            let measured_azimuth_rad = receiver.beam_azimuth_rad(beam);
            tracker
                .update(&DopplerBearing { t_s, azimuth_rad: measured_azimuth_rad, doppler_hz })
                .with_context(|| format!("{}: epoch {k}", path.display()))?;
            let state = tracker.state().context("tracker state after an update")?;
            let velocity = state.velocity_mps();
            rows.push(GeometricEpochRow {
                epoch: k as u64,
                t_ns,
                filter: if tracker.converged() { GEOMETRIC_FILTER_RLS } else { GEOMETRIC_FILTER_H_INFINITY }
                    .to_string(),
                beams_measured,
                measured_azimuth_rad,
                measured_doppler_hz: doppler_hz,
                range_m: state.range_m(t_s),
                true_range_m: range_m,
                azimuth_rad: state.azimuth_rad(t_s),
                true_azimuth_rad: azimuth_rad,
                vx_mps: velocity[0],
                vy_mps: velocity[1],
                true_vx_mps: v[0],
                true_vy_mps: v[1],
            });
        }
        let info = RunInfo {
            config_json: serde_json::json!({
                "command": "process beam",
                "tracker": "geometric",
                "recording": crate::provenance::canonical(path),
                "inputs": crate::provenance::input_files(&[path])?,
                "beam_schedule": format!("{schedule_arg:?}"),
                "epoch_s": epoch_s,
                "doppler_seed": seed,
                "scenario": scenario,
                "run_id": out.run_id(),
                "mmtrack_version": env!("CARGO_PKG_VERSION"),
            })
            .to_string(),
            time_base: vehicles.time_base.into(),
            frame: None,
        };
        tables.write(&vehicles.sequence_id, &rows, &info)?;
        results.push(GeometricRecordingResult {
            sequence_id: vehicles.sequence_id.clone(),
            epochs: rows.len(),
            last: rows.last().cloned().context("no epochs")?,
            beams_measured: rows.iter().map(|r| r.beams_measured).sum(),
        });
    }
    Ok(GeometricOutput { recordings: results, written: tables.publish()? })
}
