//! `mmtrack ingest <kind>`: one function per kind.

use super::*;

/// `mmtrack ingest oxford`.
#[pyfunction]
#[pyo3(signature = (input, output, flags, threads, range_resolution_m, bins, decode, sequence_id))]
#[allow(clippy::too_many_arguments)]
pub(super) fn ingest_oxford<'py>(
    py: Python<'py>,
    input: PathBuf,
    output: PathBuf,
    flags: &Bound<'py, PyDict>,
    threads: usize,
    range_resolution_m: Option<f64>,
    bins: String,
    decode: bool,
    sequence_id: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_ingest::oxford::{self, OXFORD, OxfordFolder, OxfordOptions};
    let flags = recording_flags(flags)?;
    let report = run(py, threads, || {
        let expected_bins = mmtrack_ingest::flags::parse_bins(&bins).map_err(msg)?;
        let range_resolution_m = range_resolution_m.unwrap_or(OXFORD.range_resolution_m);
        mmtrack_ingest::flags::positive_metres("--range-resolution-m", range_resolution_m).map_err(msg)?;
        let options = OxfordOptions {
            layout: oxford::NavtechLayout { range_resolution_m, expected_bins, ..OXFORD },
            carry_png: !decode,
            sequence_id,
        };
        let folder = OxfordFolder::open(&input)?;
        Ok(oxford::ingest_oxford(&folder, &output, &options, &options_of(&flags)?, &mut |_, _| {})?)
    })?;
    let d = recording_written(
        py,
        &report.output,
        &[
            ("scans", report.scans),
            ("skipped_invalid_scans", report.skipped_invalid_scans),
            ("ground_truth_poses", report.ground_truth_poses),
            ("gnss_fixes", report.gnss_fixes),
            ("unlisted_pngs", report.unlisted_pngs.len() as u64),
        ],
    )?;
    Ok(d)
}

fn options_of(flags: &RecordingFlags) -> anyhow::Result<mmtrack_io::RecordingOptions> {
    flags.options().map_err(msg)
}

/// `mmtrack ingest boreas`.
#[pyfunction]
#[pyo3(signature = (input, output, flags, threads, range_resolution_m, decode, sequence_id))]
#[allow(clippy::too_many_arguments)]
pub(super) fn ingest_boreas<'py>(
    py: Python<'py>,
    input: PathBuf,
    output: PathBuf,
    flags: &Bound<'py, PyDict>,
    threads: usize,
    range_resolution_m: Option<f64>,
    decode: bool,
    sequence_id: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_ingest::boreas::{BoreasFolder, BoreasOptions, ingest_boreas};
    let flags = recording_flags(flags)?;
    let report = run(py, threads, || {
        if let Some(r) = range_resolution_m {
            mmtrack_ingest::flags::positive_metres("--range-resolution-m", r).map_err(msg)?;
        }
        let options = BoreasOptions { range_resolution_m, decode, sequence_id };
        let folder = BoreasFolder::open(&input)?;
        Ok(ingest_boreas(&folder, &output, &options, &options_of(&flags)?, &mut |_, _| {})?)
    })?;
    let d = recording_written(
        py,
        &report.output,
        &[
            ("scans", report.scans),
            ("ground_truth_poses", report.ground_truth_poses),
            ("gnss_fixes", report.gnss_fixes),
        ],
    )?;
    d.set_item("range_resolution_m", report.range_resolution_m)?;
    Ok(d)
}

/// `mmtrack ingest mulran`.
#[pyfunction]
#[pyo3(signature = (input, output, flags, threads, range_resolution_m, stamp_at, scan_period_s, sequence_id))]
#[allow(clippy::too_many_arguments)]
pub(super) fn ingest_mulran<'py>(
    py: Python<'py>,
    input: PathBuf,
    output: PathBuf,
    flags: &Bound<'py, PyDict>,
    threads: usize,
    range_resolution_m: Option<f64>,
    stamp_at: String,
    scan_period_s: f64,
    sequence_id: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_ingest::mulran::{self, MulranFolder, MulranOptions, ingest_mulran};
    let flags = recording_flags(flags)?;
    let report = run(py, threads, || {
        let range_resolution_m = range_resolution_m.unwrap_or(mulran::RANGE_RESOLUTION_M);
        mmtrack_ingest::flags::positive_metres("--range-resolution-m", range_resolution_m).map_err(msg)?;
        let timing = mmtrack_ingest::flags::sweep_timing(&stamp_at, scan_period_s).map_err(msg)?;
        let options = MulranOptions { range_resolution_m, timing, sequence_id };
        let folder = MulranFolder::open(&input)?;
        Ok(ingest_mulran(&folder, &output, &options, &options_of(&flags)?, &mut |_, _| {})?)
    })?;
    recording_written(
        py,
        &report.output,
        &[
            ("scans", report.scans),
            ("ground_truth_poses", report.ground_truth_poses),
            ("gnss_fixes", report.gnss_fixes),
        ],
    )
}

/// `mmtrack ingest cir`.
#[pyfunction]
#[pyo3(signature = (input, output, flags, format, sidecar))]
pub(super) fn ingest_cir<'py>(
    py: Python<'py>,
    input: PathBuf,
    output: PathBuf,
    flags: &Bound<'py, PyDict>,
    format: String,
    sidecar: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let flags = recording_flags(flags)?;
    let report = run(py, 0, || {
        let format = mmtrack_ingest::flags::cir_format(&format).map_err(msg)?;
        Ok(mmtrack_ingest::cir::ingest_cir(
            format,
            &input,
            sidecar.as_deref(),
            &output,
            &options_of(&flags)?,
            &mut |_, _| {},
        )?)
    })?;
    let d = recording_written(
        py,
        &report.output,
        &[
            ("snapshots", report.snapshots as u64),
            ("with_first_path_hint", report.with_first_path_hint as u64),
            ("skipped", report.skipped as u64),
        ],
    )?;
    d.set_item("tap_spacing_s", report.tap_spacing_s)?;
    Ok(d)
}

/// `mmtrack ingest nmea`.
#[pyfunction]
#[pyo3(signature = (input, output, flags, add_to))]
pub(super) fn ingest_nmea<'py>(
    py: Python<'py>,
    input: PathBuf,
    output: PathBuf,
    flags: &Bound<'py, PyDict>,
    add_to: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut flags = recording_flags(flags)?;
    let report = run(py, 0, || {
        flags.force = mmtrack_ingest::flags::replaces_output(add_to.as_deref(), &output, flags.force);
        Ok(mmtrack_ingest::nmea::ingest_nmea(&input, &output, add_to.as_deref(), &options_of(&flags)?)?)
    })?;
    let log = &report.log;
    recording_written(
        py,
        &report.output,
        &[
            ("fixes", log.fix_count),
            ("bad_checksum_lines", log.bad_checksum_lines as u64),
            ("unparsable_lines", log.unparsable_lines as u64),
        ],
    )
}

/// `mmtrack ingest poses`.
#[pyfunction]
#[pyo3(signature = (input, output, flags, format, add_to, estimate, times, t0_ns, plane))]
#[allow(clippy::too_many_arguments)]
pub(super) fn ingest_poses<'py>(
    py: Python<'py>,
    input: PathBuf,
    output: PathBuf,
    flags: &Bound<'py, PyDict>,
    format: String,
    add_to: Option<PathBuf>,
    estimate: bool,
    times: Option<PathBuf>,
    t0_ns: i64,
    plane: String,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_ingest::poses::{self, Plane, TrajectoryFormat};
    use mmtrack_io::recording::PoseStream;
    let mut flags = recording_flags(flags)?;
    let (summary, poses) = run(py, 0, || {
        let format = TrajectoryFormat::parse(&format).map_err(|e| msg(format!("--format {e}")))?;
        let plane = Plane::parse(&plane).map_err(msg)?;
        let file = poses::PoseFile { path: &input, format, times: times.as_deref(), t0_ns, plane };
        flags.force = mmtrack_ingest::flags::replaces_output(add_to.as_deref(), &output, flags.force);
        let stream = if estimate { PoseStream::Estimate } else { PoseStream::GroundTruth };
        Ok(poses::ingest_poses(&file, stream, add_to.as_deref(), &output, &options_of(&flags)?)?)
    })?;
    recording_written(py, &summary, &[("poses", poses as u64)])
}

/// `mmtrack ingest ros2`.
#[pyfunction]
#[pyo3(signature = (
    input, output, flags, pose_topic, poses_are_ground_truth, ground_truth_topic, gnss_topic, radar_topic,
    radar_range_resolution_m, stamp_at, scan_period_s
))]
#[allow(clippy::too_many_arguments)]
pub(super) fn ingest_ros2<'py>(
    py: Python<'py>,
    input: PathBuf,
    output: PathBuf,
    flags: &Bound<'py, PyDict>,
    pose_topic: String,
    poses_are_ground_truth: bool,
    ground_truth_topic: Option<String>,
    gnss_topic: Option<String>,
    radar_topic: Option<String>,
    radar_range_resolution_m: Option<f64>,
    stamp_at: String,
    scan_period_s: f64,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_ingest::ros2::{Ros2Topics, ingest_ros2};
    let flags = recording_flags(flags)?;
    let report = run(py, 0, || {
        let timing = mmtrack_ingest::flags::sweep_timing(&stamp_at, scan_period_s).map_err(msg)?;
        let topics = Ros2Topics::from_flags(
            &pose_topic,
            poses_are_ground_truth,
            ground_truth_topic,
            gnss_topic,
            radar_topic,
            radar_range_resolution_m,
            timing,
        )
        .map_err(msg)?;
        Ok(ingest_ros2(&input, &output, &topics, &options_of(&flags)?, &mut |_, _| {})?)
    })?;
    recording_written(
        py,
        &report.output,
        &[
            ("poses", report.poses),
            ("ground_truth_poses", report.ground_truth_poses),
            ("gnss_fixes", report.gnss_fixes),
            ("no_fix", report.no_fix),
            ("radar_scans", report.radar_scans),
        ],
    )
}

/// `mmtrack ingest beams --format deepsense`.
#[pyfunction]
#[pyo3(signature = (input, output, flags, scenario, positions, sweep_period_s))]
pub(super) fn ingest_beams<'py>(
    py: Python<'py>,
    input: PathBuf,
    output: PathBuf,
    flags: &Bound<'py, PyDict>,
    scenario: Option<u32>,
    positions: String,
    sweep_period_s: f64,
) -> PyResult<Bound<'py, PyList>> {
    use mmtrack_ingest::beams::{DeepsenseOptions, ingest_deepsense};
    let mut flags = recording_flags(flags)?;
    // Beam recordings have no radar view (as the CLI's).
    flags.no_radar_cartesian = true;
    let written = run(py, 0, || {
        let options = DeepsenseOptions {
            scenario,
            positions: mmtrack_ingest::flags::vehicle_positions(&positions).map_err(msg)?,
            sweep_period_ns: mmtrack_ingest::flags::sweep_period_ns(sweep_period_s).map_err(msg)?,
        };
        Ok(ingest_deepsense(&input, &output, &options, &options_of(&flags)?, &mut |_, _| {})?)
    })?;
    let list = PyList::empty(py);
    for w in &written {
        let d = recording_written(py, &w.output, &[("sweeps", w.sweeps as u64), ("beams", w.beams as u64)])?;
        d.set_item("scenario", w.scenario)?;
        d.set_item("pass", w.pass)?;
        d.set_item("sequence_id", &w.sequence_id)?;
        d.set_item("calibrated", w.calibrated)?;
        list.append(d)?;
    }
    Ok(list)
}
