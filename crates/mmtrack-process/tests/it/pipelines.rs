//! Each pipeline's library call on a small simulated (or real) recording.

use std::path::{Path, PathBuf};

use mmtrack_core::OdometryEstimate;
use mmtrack_core::progress::NoProgress;
use mmtrack_io::table::{
    GEOMETRIC_FILTER_H_INFINITY, GeometricEpochRow, MPC_DETECTIONS, ODOMETRY, SlamUeRow, SpebtSummaryRow, read_table,
    table_path,
};
use mmtrack_io::{Overwrite, RecordingOptions};
use mmtrack_process::beam::geometric::{GeometricOptions, process_geometric};
use mmtrack_process::beam::spebt::monte_carlo::RADAR_ODOMETRY;
use mmtrack_process::beam::spebt::{SpebtOptions, process_spebt};
use mmtrack_process::beam::sweep::{Reacquire, SweepTrackerKind, process_sweeps};
use mmtrack_process::output::OutputOptions;
use mmtrack_process::simulate::radar::{RadarLayout, RadarSimulation, simulate_radar};
use mmtrack_process::simulate::slam::{SlamSimulation, simulate_slam};
use mmtrack_process::simulate::sounder::{SounderSimulation, simulate_sounder};
use mmtrack_process::slam::{SlamOptions, process_slam};
use mmtrack_process::{mpc, odometry};

fn data(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data").join(relative)
}

fn radar_recording(dir: &Path, scans: usize) -> PathBuf {
    let output = dir.join("radar.mcap");
    let simulation = RadarSimulation {
        scenario: data("demo/fixture-scenario.toml"),
        trajectory: None,
        max_scans: Some(scans),
        max_distance_m: None,
        layout: RadarLayout::Recording,
        output: output.clone(),
        recording: RecordingOptions::default(),
    };
    let done = simulate_radar(&simulation, &NoProgress).expect("simulate the fixture drive");
    assert_eq!(done.scans, scans);
    output
}

/// A front end that asks to stop after `allowed` checks (Python's Ctrl-C).
struct CancelAfter {
    allowed: std::sync::atomic::AtomicUsize,
}

impl mmtrack_core::progress::Progress for CancelAfter {
    fn start(&self, _stage: &str, _total: u64, _unit: &str) {}
    fn set_position(&self, _done: u64) {}
    fn advance(&self, _by: u64) {}
    fn finish(&self) {}
    fn note(&self, _text: &str) {}
    fn check_cancelled(&self) -> Result<(), mmtrack_core::progress::Cancelled> {
        use std::sync::atomic::Ordering;
        let left = self.allowed.load(Ordering::Relaxed);
        if left == 0 {
            return Err(mmtrack_core::progress::Cancelled);
        }
        self.allowed.store(left - 1, Ordering::Relaxed);
        Ok(())
    }
}

/// Before: a library call could not be stopped before its end (Python's
/// Ctrl-C waited for it). Now a cancelled progress stops it at the next
/// item with the `Cancelled` error, and the output folder holds nothing:
/// no table, no partial file.
#[test]
fn a_cancelled_call_stops_early_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let recording = radar_recording(dir.path(), 6);
    let tables = dir.path().join("tables");
    let config = odometry::effective_config("fast-cfear", None).unwrap();
    let progress = CancelAfter { allowed: 2.into() };
    let error =
        odometry::process_odometry(&recording, &tables, "fast-cfear", &config, &OutputOptions::default(), &progress)
            .err()
            .expect("cancelled");
    assert!(error.chain().any(|e| e.is::<mmtrack_core::progress::Cancelled>()), "{error:#}");
    let left: Vec<_> = walk(&tables);
    assert!(left.is_empty(), "{left:?}");
}

/// Every file under `dir` (none when it does not exist).
fn walk(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    entries.flatten().flat_map(|e| if e.path().is_dir() { walk(&e.path()) } else { vec![e.path()] }).collect()
}

#[test]
fn odometry_writes_one_pose_per_scan_refuses_existing_tables_and_keeps_runs_apart() {
    let dir = tempfile::tempdir().unwrap();
    let recording = radar_recording(dir.path(), 6);
    let tables = dir.path().join("tables");
    let config = odometry::effective_config("fast-cfear", None).unwrap();
    let options = OutputOptions::default();
    let done = odometry::process_odometry(&recording, &tables, "fast-cfear", &config, &options, &NoProgress).unwrap();
    assert_eq!(done.run.estimates.len(), 6);
    let file = table_path(&tables, ODOMETRY.name, &done.sequence).unwrap();
    let rows: Vec<OdometryEstimate> = read_table(&file).unwrap();
    assert_eq!(rows.len(), 6);
    // Nothing is replaced without force; another run id writes beside it.
    let err = odometry::process_odometry(&recording, &tables, "fast-cfear", &config, &options, &NoProgress)
        .err()
        .map(|e| format!("{e:#}"))
        .unwrap_or_default();
    assert!(err.contains("exists; use --force"), "{err}");
    let run_b = OutputOptions { run_id: Some("b".into()), ..OutputOptions::default() };
    odometry::process_odometry(&recording, &tables, "fast-cfear", &config, &run_b, &NoProgress).unwrap();
    assert!(table_path(&tables.join("run=b"), ODOMETRY.name, &done.sequence).unwrap().exists());

    // SPEBT along the same recording, driven by that odometry table.
    let out = OutputOptions::default().resolve(&tables).unwrap();
    let options = SpebtOptions { odometry: Some(tables.clone()), runs: Some(2), ..SpebtOptions::default() };
    let spebt = process_spebt(std::slice::from_ref(&recording), &out, &options, &NoProgress).unwrap();
    assert_eq!(spebt.recordings[0].pose_source, RADAR_ODOMETRY);
    let rows: Vec<SpebtSummaryRow> = read_table(&spebt.written[0].path).unwrap();
    assert_eq!((rows[0].slots, rows[0].runs), (6, 2));
    assert!(rows[0].rmse_aod_rad.is_finite());
}

#[test]
fn mpc_and_geometric_run_on_a_simulated_convoy() {
    let dir = tempfile::tempdir().unwrap();
    let recording = dir.path().join("sounder.mcap");
    let simulation = SounderSimulation {
        scenario: data("sounder/convoy-tunnel.toml"),
        sets: Some(20),
        output: recording.clone(),
        recording: RecordingOptions::default(),
    };
    let written = simulate_sounder(&simulation, &NoProgress).unwrap();
    assert_eq!(written.sets, 20);
    let tables = dir.path().join("tables");
    let config = mmtrack_mpc::MpcConfig { run_gmphd: true, ..mpc::effective_config(None).unwrap() };
    let done = mpc::process_mpc(&recording, &tables, &config, &mpc::MpcOptions::default(), &NoProgress).unwrap();
    assert_eq!(done.links.len(), 1);
    assert_eq!(done.links[0].sets, 20);
    assert!(done.links[0].detections > 0);
    assert!(done.written.iter().any(|w| w.path.starts_with(tables.join(MPC_DETECTIONS.name))));

    let out = OutputOptions::default().resolve(&tables).unwrap();
    let geometric = process_geometric(std::slice::from_ref(&recording), &out, &GeometricOptions::default()).unwrap();
    let rows: Vec<GeometricEpochRow> = read_table(&geometric.written[0].path).unwrap();
    assert_eq!(rows.len(), geometric.recordings[0].epochs);
    assert!(rows.iter().all(|r| r.true_range_m > 0.0 && r.range_m.is_finite()));
    // 20 sets span 190 ms: 8 epochs of 20 ms with a margin for the central differences, all inside the
    // paper's 10 full scans of 128 beams, so still H-infinity.
    assert_eq!(rows.len(), 8);
    assert!(rows.iter().all(|r| r.beams_measured == 128 && r.filter == GEOMETRIC_FILTER_H_INFINITY), "{rows:?}");
}

#[test]
fn slam_tracks_every_epoch_of_a_simulated_world() {
    let dir = tempfile::tempdir().unwrap();
    let recording = dir.path().join("slam.mcap");
    let simulation = SlamSimulation {
        scenario: None,
        seed: 3,
        epochs: Some(8),
        output: recording.clone(),
        recording: RecordingOptions::default(),
    };
    assert_eq!(simulate_slam(&simulation).unwrap().epochs, 8);
    let tables = dir.path().join("tables");
    let options = SlamOptions { particles: Some(200), ..SlamOptions::default() };
    let done = process_slam(&recording, &tables, &options).unwrap();
    assert_eq!(done.tables.ue.len(), 8);
    let rows: Vec<SlamUeRow> = read_table(&done.written[0].path).unwrap();
    assert_eq!(rows, done.tables.ue);
}

#[test]
fn sweep_trackers_run_on_real_deepsense_passes() {
    let realdata = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/realdata/deepsense-60ghz-beams");
    assert!(realdata.is_dir(), "{}: the real-data samples beside the repository", realdata.display());
    let dir = tempfile::tempdir().unwrap();
    let options = mmtrack_ingest::beams::DeepsenseOptions { scenario: Some(1), ..Default::default() };
    let passes = mmtrack_ingest::beams::ingest_deepsense(
        &realdata,
        &dir.path().join("rec"),
        &options,
        &RecordingOptions { overwrite: Overwrite::Refuse, ..RecordingOptions::default() },
        &mut |_, _| {},
    )
    .unwrap();
    let files: Vec<PathBuf> =
        passes.iter().take(3).map(|p| dir.path().join("rec").join(format!("{}.mcap", p.sequence_id))).collect();
    let kinds = [SweepTrackerKind::Window, SweepTrackerKind::LastFullSweep, SweepTrackerKind::GnssMap];
    let done = process_sweeps(
        &files,
        &dir.path().join("tables"),
        &kinds,
        Reacquire::Coarse,
        &OutputOptions::default(),
        &NoProgress,
    )
    .unwrap();
    assert_eq!(done.sites.len(), 1);
    assert_eq!(done.sites[0].passes, 3);
    assert_eq!(done.summaries.len(), 3);
    assert_eq!(done.written.len(), 3);
    // The last full sweep measures every beam; the window fewer.
    let beams = |k: SweepTrackerKind| done.summaries.iter().find(|s| s.1 == k).map(|s| s.2.mean_beams_per_sweep);
    assert!(beams(SweepTrackerKind::Window) < beams(SweepTrackerKind::LastFullSweep));
}

#[test]
fn ground_truth_that_goes_back_in_time_is_refused_by_every_pipeline_that_writes_it() {
    use mmtrack_core::{Se2, StampedPose};
    use mmtrack_io::recording::{PoseStream, TimeBase};
    use mmtrack_io::{RecordingMetadata, RecordingWriter};
    let dir = tempfile::tempdir().unwrap();
    let recording = dir.path().join("backwards.mcap");
    let metadata = RecordingMetadata {
        sequence_id: "backwards".into(),
        source: "test".into(),
        time_base: TimeBase::Relative,
        extra: Default::default(),
    };
    let mut writer = RecordingWriter::create(&recording, &metadata, &RecordingOptions::default()).unwrap();
    // The estimate is in order, the ground truth's third pose goes back.
    for (estimate_t_ns, truth_t_ns) in [(1_000, 1_000), (2_000, 2_000), (2_500, 1_500), (3_000, 3_000)] {
        let pose = |t_ns: i64| StampedPose { t_ns, parent_from_child: Se2::new(t_ns as f64 * 1e-3, 0.0, 0.0) };
        writer.write_pose(PoseStream::Estimate, &pose(estimate_t_ns), "world").unwrap();
        writer.write_pose(PoseStream::GroundTruth, &pose(truth_t_ns), "world").unwrap();
    }
    writer.finish().unwrap();
    let tables = dir.path().join("tables");
    let options = OutputOptions::default();
    let config = odometry::effective_config("cfear", None).unwrap();
    let refusals = [
        mmtrack_process::raw::process_raw(&recording, &tables, &options, &NoProgress).err(),
        odometry::process_odometry(&recording, &tables, "cfear", &config, &options, &NoProgress).err(),
        mmtrack_process::poses::process_poses(&recording, &tables, &options, &NoProgress).err(),
    ];
    for err in refusals {
        let err = err.map(|e| format!("{e:#}")).unwrap_or_default();
        assert!(err.contains("backwards.mcap"), "names the file: {err}");
        assert!(
            err.contains(
                "/ground_truth/pose: pose 2 (counted from 0) has t_ns 1500 at or before the previous pose's 2000"
            ),
            "{err}"
        );
    }
    assert!(!tables.exists(), "nothing written");

    // A sounder's transmitter and receiver truth: process mpc writes them as tables.
    let recording = dir.path().join("backwards-tx.mcap");
    let mut writer = RecordingWriter::create(&recording, &metadata, &RecordingOptions::default()).unwrap();
    // The receiver's poses are in order, the transmitter's third goes back.
    for (rx_t_ns, tx_t_ns) in [(1_000, 1_000), (2_000, 2_000), (3_000, 1_500)] {
        let pose = |t_ns: i64| StampedPose { t_ns, parent_from_child: Se2::IDENTITY };
        writer.write_pose(PoseStream::GroundTruthRx, &pose(rx_t_ns), "world").unwrap();
        writer.write_pose(PoseStream::GroundTruthTx, &pose(tx_t_ns), "world").unwrap();
    }
    writer.finish().unwrap();
    let config = mpc::effective_config(None).unwrap();
    let err = mpc::process_mpc(&recording, &tables, &config, &mpc::MpcOptions::default(), &NoProgress)
        .err()
        .map(|e| format!("{e:#}"))
        .unwrap_or_default();
    assert!(
        err.contains("backwards-tx.mcap") && err.contains("/ground_truth/tx: pose 2 (counted from 0) has t_ns 1500"),
        "{err}"
    );
    assert!(!tables.exists(), "nothing written");
}
