//! The extension module `mmtrack._native`: argument conversion around the
//! library calls, nothing else. The Python half (`python/mmtrack`) gives
//! the public names, defaults and docs; `_native.pyi` types this module.
//!
//! Every call releases the GIL while the libraries work, runs on the pool
//! of its `threads` argument where the CLI command has `--threads`
//! ([`mmtrack_process::threads::install`]), and turns an error into
//! `mmtrack.MmtrackError` with the one line the CLI prints after `error: `
//! ([`mmtrack_core::error::one_line`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use mmtrack_analysis::analyze::{AnalyzeOptions, Analyzed, analyze};
use mmtrack_core::progress::NoProgress;
use mmtrack_io::recording::RecordingFlags;
use mmtrack_io::table::{ALL_TABLES, RESULT_TABLES, TableSpec, TableWriteSummary};
use mmtrack_process::output::OutputOptions;
use pyo3::BoundObject;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};

use crate::arrays;

create_exception!(mmtrack, MmtrackError, PyException, "An mmtrack call failed; the message is the CLI's one line.");

/// The CLI's one line of `error`, as a Python exception.
fn py_err(error: anyhow::Error) -> PyErr {
    MmtrackError::new_err(mmtrack_core::error::one_line(error.chain()))
}

/// Runs `work` without the GIL on a pool of `threads` threads.
fn run<R: Send>(py: Python<'_>, threads: usize, work: impl FnOnce() -> anyhow::Result<R> + Send) -> PyResult<R> {
    py.detach(|| mmtrack_process::threads::install(threads, work).and_then(|r| r)).map_err(py_err)
}

fn dict<'py>(py: Python<'py>, items: &[(&str, Bound<'py, PyAny>)]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (key, value) in items {
        d.set_item(*key, value)?;
    }
    Ok(d)
}

fn any<'py, T: IntoPyObject<'py>>(py: Python<'py>, value: T) -> PyResult<Bound<'py, PyAny>> {
    value.into_pyobject(py).map(BoundObject::into_any).map(BoundObject::into_bound).map_err(Into::into)
}

fn path_str(path: &Path) -> String {
    path.display().to_string()
}

/// `[{"path", "rows"}]` of written tables.
fn written_tables<'py>(py: Python<'py>, written: &[TableWriteSummary]) -> PyResult<Bound<'py, PyList>> {
    let list = PyList::empty(py);
    for w in written {
        list.append(dict(py, &[("path", any(py, path_str(&w.path))?), ("rows", any(py, w.rows)?)])?)?;
    }
    Ok(list)
}

/// The recording flags of a dict of the Python wrapper (every key present).
fn recording_flags(flags: &Bound<'_, PyDict>) -> PyResult<RecordingFlags> {
    fn item<'py, T: FromPyObjectOwned<'py>>(flags: &Bound<'py, PyDict>, key: &str) -> PyResult<Option<T>> {
        match flags.get_item(key)? {
            Some(v) if !v.is_none() => Ok(Some(v.extract::<T>().map_err(Into::into)?)),
            _ => Ok(None),
        }
    }
    let d = RecordingFlags::default();
    Ok(RecordingFlags {
        force: item(flags, "force")?.unwrap_or(d.force),
        compression: item(flags, "compression")?.unwrap_or(d.compression),
        zstd_level: item(flags, "zstd_level")?.unwrap_or(d.zstd_level),
        no_foxglove_views: item(flags, "no_foxglove_views")?.unwrap_or(d.no_foxglove_views),
        no_radar_cartesian: item(flags, "no_radar_cartesian")?.unwrap_or(d.no_radar_cartesian),
        radar_cartesian_m_per_px: item(flags, "radar_cartesian_m_per_px")?.unwrap_or(d.radar_cartesian_m_per_px),
        radar_cartesian_size_px: item(flags, "radar_cartesian_size_px")?.unwrap_or(d.radar_cartesian_size_px),
        no_sync: item(flags, "no_sync")?.unwrap_or(d.no_sync),
    })
}

fn msg(e: String) -> anyhow::Error {
    anyhow::Error::msg(e)
}

fn recording_written<'py>(
    py: Python<'py>,
    w: &mmtrack_io::recording::WriteSummary,
    counts: &[(&str, u64)],
) -> PyResult<Bound<'py, PyDict>> {
    let d = dict(py, &[("path", any(py, path_str(&w.path))?), ("bytes", any(py, w.file_bytes)?)])?;
    d.set_item("messages", w.message_counts.clone())?;
    for (key, value) in counts {
        d.set_item(*key, *value)?;
    }
    Ok(d)
}

// ---------------------------------------------------------------- ingest

/// `mmtrack ingest oxford`.
#[pyfunction]
#[pyo3(signature = (input, output, flags, threads, range_resolution_m, bins, decode, sequence_id))]
#[allow(clippy::too_many_arguments)]
fn ingest_oxford<'py>(
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
fn ingest_boreas<'py>(
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
fn ingest_mulran<'py>(
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
fn ingest_cir<'py>(
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
fn ingest_nmea<'py>(
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
            ("fixes", log.fixes.len() as u64),
            ("bad_checksum_lines", log.bad_checksum_lines as u64),
            ("unparsable_lines", log.unparsable_lines as u64),
        ],
    )
}

/// `mmtrack ingest beams --format deepsense`.
#[pyfunction]
#[pyo3(signature = (input, output, flags, scenario, positions, sweep_period_s))]
fn ingest_beams<'py>(
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

// ---------------------------------------------------------------- process

fn output_options(sequence: Option<String>, force: bool, run_id: Option<String>) -> OutputOptions {
    OutputOptions { sequence, run_id, force }
}

/// `mmtrack process odometry`.
#[pyfunction]
#[pyo3(signature = (recording, output, preset, config, sequence, force, run_id, threads))]
#[allow(clippy::too_many_arguments)]
fn process_odometry<'py>(
    py: Python<'py>,
    recording: PathBuf,
    output: PathBuf,
    preset: String,
    config: Option<PathBuf>,
    sequence: Option<String>,
    force: bool,
    run_id: Option<String>,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_process::odometry;
    let options = output_options(sequence, force, run_id);
    let done = run(py, threads, || {
        let config = odometry::effective_config(&preset, config.as_deref())?;
        odometry::process_odometry(&recording, &output, &preset, &config, &options, &NoProgress)
    })?;
    let low = done.run.estimates.iter().filter(|e| e.low_confidence).count();
    dict(
        py,
        &[
            ("sequence", any(py, &done.sequence)?),
            ("scans", any(py, done.run.estimates.len())?),
            ("low_confidence", any(py, low)?),
            ("ground_truth_poses", any(py, done.run.ground_truth.len())?),
            ("tables", written_tables(py, &done.written)?.into_any()),
        ],
    )
}

/// `mmtrack process odometry --print-config` / `process mpc --print-config`:
/// the effective configuration as TOML.
#[pyfunction]
#[pyo3(signature = (pipeline, preset, config, gmphd))]
fn effective_config(pipeline: &str, preset: String, config: Option<PathBuf>, gmphd: bool) -> PyResult<String> {
    let text = || -> anyhow::Result<String> {
        Ok(match pipeline {
            "odometry" => toml::to_string(&mmtrack_process::odometry::effective_config(&preset, config.as_deref())?)?,
            "mpc" => {
                let mut c = mmtrack_process::mpc::effective_config(config.as_deref())?;
                c.run_gmphd |= gmphd;
                toml::to_string(&c)?
            }
            other => anyhow::bail!("--print-config: a flag of process odometry and process mpc, not {other}"),
        })
    };
    text().map_err(py_err)
}

/// `mmtrack process mpc`.
#[pyfunction]
#[pyo3(signature = (recording, output, config, pulse, link, gmphd, sequence, force, run_id, threads))]
#[allow(clippy::too_many_arguments)]
fn process_mpc<'py>(
    py: Python<'py>,
    recording: PathBuf,
    output: PathBuf,
    config: Option<PathBuf>,
    pulse: Option<String>,
    link: Option<String>,
    gmphd: bool,
    sequence: Option<String>,
    force: bool,
    run_id: Option<String>,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_process::mpc;
    let output_options = output_options(sequence, force, run_id);
    let done = run(py, threads, || {
        let mut config = mpc::effective_config(config.as_deref())?;
        config.run_gmphd |= gmphd;
        let options =
            mpc::MpcOptions { pulse, link: link.as_deref().map(mpc::parse_link).transpose()?, output: output_options };
        mpc::process_mpc(&recording, &output, &config, &options, &NoProgress)
    })?;
    let links = PyList::empty(py);
    for l in &done.links {
        links.append(dict(
            py,
            &[
                ("partition", any(py, &l.partition)?),
                ("link", any(py, l.link)?),
                ("sets", any(py, l.sets)?),
                ("detections", any(py, l.detections)?),
                ("tracks", any(py, l.tracks)?),
                ("long_term", any(py, l.long_term)?),
            ],
        )?)?;
    }
    dict(py, &[("links", links.into_any()), ("tables", written_tables(py, &done.written)?.into_any())])
}

/// `mmtrack process beam`.
#[pyfunction]
#[pyo3(signature = (recordings, output, tracker, reacquire, force, run_id, spebt, geometric))]
#[allow(clippy::too_many_arguments)]
fn process_beam<'py>(
    py: Python<'py>,
    recordings: Vec<PathBuf>,
    output: PathBuf,
    tracker: Vec<String>,
    reacquire: String,
    force: bool,
    run_id: Option<String>,
    spebt: &Bound<'py, PyDict>,
    geometric: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_process::beam::geometric::{GeometricOptions, Schedule};
    use mmtrack_process::beam::spebt::SpebtOptions;
    use mmtrack_process::beam::sweep::Reacquire;
    use mmtrack_process::beam::{BeamOutput, BeamRequest, BeamTracker};
    let get = |d: &Bound<'py, PyDict>, key: &str| -> PyResult<Option<Bound<'py, PyAny>>> {
        Ok(d.get_item(key)?.filter(|v| !v.is_none()))
    };
    let spebt = SpebtOptions {
        odometry: get(spebt, "odometry")?.map(|v| v.extract()).transpose()?,
        odometry_run: get(spebt, "odometry_run")?.map(|v| v.extract()).transpose()?,
        link: get(spebt, "link")?.map(|v| v.extract()).transpose()?,
        sigma_r_m: get(spebt, "sigma_r_m")?.map(|v| v.extract()).transpose()?,
        sigma_theta_deg: get(spebt, "sigma_theta_deg")?.map(|v| v.extract()).transpose()?,
        seed: get(spebt, "seed")?.map(|v| v.extract()).transpose()?,
        runs: get(spebt, "runs")?.map(|v| v.extract()).transpose()?,
    };
    let schedule: Option<String> = get(geometric, "beam_schedule")?.map(|v| v.extract()).transpose()?;
    let geometric_options = GeometricOptions {
        beam_schedule: None,
        epoch_ms: get(geometric, "epoch_ms")?.map(|v| v.extract()).transpose()?,
        doppler_seed: get(geometric, "doppler_seed")?.map(|v| v.extract()).transpose()?,
    };
    let done = run(py, 0, || {
        let beam_schedule = match schedule.as_deref() {
            None => None,
            Some("paper") => Some(Schedule::Paper),
            Some("full-scan") => Some(Schedule::FullScan),
            Some(other) => anyhow::bail!("--beam-schedule '{other}': expected paper or full-scan"),
        };
        let request = BeamRequest {
            recordings,
            trackers: tracker.iter().map(|t| BeamTracker::parse(t)).collect::<anyhow::Result<_>>()?,
            reacquire: Reacquire::parse(&reacquire)?,
            output: output_options(None, force, run_id),
            spebt,
            geometric: GeometricOptions { beam_schedule, ..geometric_options },
        };
        mmtrack_process::beam::process_beam(&output, &request, &NoProgress)
    })?;
    let written = match &done {
        BeamOutput::Sweeps(d) => &d.written,
        BeamOutput::Spebt(d) => &d.written,
        BeamOutput::Geometric(d) => &d.written,
    };
    let kind = match &done {
        BeamOutput::Sweeps(_) => "sweeps",
        BeamOutput::Spebt(_) => "spebt",
        BeamOutput::Geometric(_) => "geometric",
    };
    dict(py, &[("kind", any(py, kind)?), ("tables", written_tables(py, written)?.into_any())])
}

/// `mmtrack process slam`.
#[pyfunction]
#[pyo3(signature = (recording, output, config, particles, seed, prior, strict, sequence, force, run_id, threads))]
#[allow(clippy::too_many_arguments)]
fn process_slam<'py>(
    py: Python<'py>,
    recording: PathBuf,
    output: PathBuf,
    config: Option<PathBuf>,
    particles: Option<usize>,
    seed: u64,
    prior: Option<Vec<f64>>,
    strict: bool,
    sequence: Option<String>,
    force: bool,
    run_id: Option<String>,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_process::slam;
    let options =
        slam::SlamOptions { config, particles, seed, prior, strict, output: output_options(sequence, force, run_id) };
    let done = run(py, threads, || slam::process_slam(&recording, &output, &options))?;
    let (va, sp) = done.confirmed_at_end();
    dict(
        py,
        &[
            ("epochs", any(py, done.tables.ue.len())?),
            ("confirmed_vas", any(py, va)?),
            ("confirmed_sps", any(py, sp)?),
            ("tables", written_tables(py, &done.written)?.into_any()),
        ],
    )
}

// ---------------------------------------------------------------- analyze

/// `mmtrack analyze`.
#[pyfunction]
#[pyo3(signature = (tables, output, force, segment_lengths_m, step_frames, step_m, first_path_range_db))]
#[allow(clippy::too_many_arguments)]
fn analyze_tables<'py>(
    py: Python<'py>,
    tables: Vec<PathBuf>,
    output: PathBuf,
    force: bool,
    segment_lengths_m: Option<Vec<f64>>,
    step_frames: Option<usize>,
    step_m: Option<f64>,
    first_path_range_db: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let first_path_range_db = first_path_range_db.unwrap_or(mmtrack_analysis::mpc::DEFAULT_FIRST_PATH_DYNAMIC_RANGE_DB);
    let analyzed = run(py, 0, || {
        if tables.is_empty() {
            anyhow::bail!("give at least one TABLES directory");
        }
        let options = AnalyzeOptions::from_flags(segment_lengths_m, step_frames, step_m, first_path_range_db, force)?;
        analyze(&tables, &output, &options)
    })?;
    let (runs, written) = match &analyzed {
        Analyzed::Run { written, .. } => (Vec::new(), written),
        Analyzed::Campaign { runs, written } => (runs.iter().map(|(r, _)| r.id.clone()).collect(), written),
    };
    dict(
        py,
        &[
            ("output", any(py, path_str(&output))?),
            ("files", any(py, written.files)?),
            ("tables", any(py, path_str(&written.tables_dir))?),
            ("plots", any(py, path_str(&written.plots_dir))?),
            ("report", any(py, path_str(&written.report))?),
            ("report_html", any(py, path_str(&written.report_html))?),
            ("runs", any(py, runs)?),
        ],
    )
}

// ---------------------------------------------------------------- reproduce

fn verdicts<'py>(
    py: Python<'py>,
    verdicts: impl IntoIterator<Item = (&'static str, mmtrack_reproduce::Verdict)>,
) -> PyResult<Bound<'py, PyList>> {
    let list = PyList::empty(py);
    for (experiment, v) in verdicts {
        list.append(dict(
            py,
            &[
                ("experiment", any(py, experiment)?),
                ("claim", any(py, &v.claim.what)?),
                ("unit", any(py, &v.claim.unit)?),
                ("paper_value", any(py, v.claim.paper_value)?),
                ("paper", any(py, &v.claim.paper_text)?),
                ("measured", any(py, v.measured)?),
                ("measured_text", any(py, &v.note)?),
                ("met", any(py, v.met)?),
                ("informational", any(py, v.claim.informational)?),
                ("verdict", any(py, v.word().replace("**", ""))?),
            ],
        )?)?;
    }
    Ok(list)
}

/// `mmtrack reproduce <experiment>`.
#[pyfunction]
#[pyo3(signature = (experiment, threads, request))]
fn reproduce_experiment<'py>(
    py: Python<'py>,
    experiment: String,
    threads: usize,
    request: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_reproduce::request::{ExperimentRequest, run_experiment};
    let get =
        |key: &str| -> PyResult<Option<Bound<'py, PyAny>>> { Ok(request.get_item(key)?.filter(|v| !v.is_none())) };
    let flag = |key: &str| -> PyResult<bool> { Ok(get(key)?.map(|v| v.extract()).transpose()?.unwrap_or(false)) };
    let request = ExperimentRequest {
        output_dir: get("output")?.map(|v| v.extract()).transpose()?,
        force: flag("force")?,
        quick: flag("quick")?,
        runs: get("runs")?.map(|v| v.extract()).transpose()?,
        readme: get("readme")?.map(|v| v.extract()).transpose()?,
        experiment_file: get("experiment_file")?.map(|v| v.extract()).transpose()?,
        scenario: get("scenario")?.map(|v| v.extract()).transpose()?,
        trajectory: get("trajectory")?.map(|v| v.extract()).transpose()?,
        trajectory_format: get("trajectory_format")?.map(|v| v.extract()).transpose()?,
        max_distance_m: get("max_distance_m")?.map(|v| v.extract()).transpose()?,
        skip_odometry: flag("skip_odometry")?,
        particles: get("particles")?.map(|v| v.extract()).transpose()?,
        pulse: get("pulse")?.map(|v| v.extract()).transpose()?,
        keep_taps_below_threshold: flag("keep_taps_below_threshold")?,
    };
    let outcome = run(py, threads, || run_experiment(&experiment, &request, &NoProgress))?;
    let metrics = PyList::empty(py);
    for m in &outcome.metrics {
        metrics.append(dict(
            py,
            &[
                ("key", any(py, &m.key)?),
                ("value", any(py, m.value)?),
                ("unit", any(py, &m.unit)?),
                ("paper", any(py, m.paper)?),
            ],
        )?)?;
    }
    let files: Vec<String> = outcome.files.iter().map(|f| path_str(f)).collect();
    dict(
        py,
        &[
            ("experiment", any(py, outcome.experiment)?),
            ("targets_met", any(py, outcome.targets_met())?),
            ("claims", verdicts(py, outcome.verdicts.iter().map(|v| (outcome.experiment, v.clone())))?.into_any()),
            ("metrics", metrics.into_any()),
            ("files", any(py, files)?),
            ("report", any(py, &outcome.report)?),
        ],
    )
}

/// `mmtrack reproduce --all [--smoke]`.
#[pyfunction]
#[pyo3(signature = (output, smoke, readme))]
fn reproduce_all<'py>(
    py: Python<'py>,
    output: PathBuf,
    smoke: bool,
    readme: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_reproduce::Tier;
    use mmtrack_reproduce::all::{AllOptions, run_all};
    let options = AllOptions { tier: if smoke { Tier::Smoke } else { Tier::Full }, output_dir: output, readme };
    let outcome = run(py, 0, || run_all(&options, &NoProgress))?;
    dict(
        py,
        &[
            ("claims", verdicts(py, outcome.claims.iter().cloned())?.into_any()),
            ("misses", any(py, outcome.misses())?),
            ("summary", any(py, &outcome.summary)?),
        ],
    )
}

// ---------------------------------------------------------------- tables

fn spec_dict<'py>(py: Python<'py>, spec: &TableSpec) -> PyResult<Bound<'py, PyDict>> {
    let columns = PyList::empty(py);
    for c in spec.columns {
        columns.append(dict(
            py,
            &[
                ("name", any(py, c.name)?),
                ("type", any(py, c.ty.doc_name())?),
                ("nullable", any(py, c.nullable)?),
                ("unit", any(py, c.unit)?),
                ("meaning", any(py, c.meaning)?),
            ],
        )?)?;
    }
    dict(
        py,
        &[("name", any(py, spec.name)?), ("description", any(py, spec.description)?), ("columns", columns.into_any())],
    )
}

/// Every table declaration of mmtrack-io: the tables `process` writes
/// and the result tables of `analyze`.
#[pyfunction]
fn table_specs(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let list = PyList::empty(py);
    for spec in ALL_TABLES.iter().chain(RESULT_TABLES) {
        list.append(spec_dict(py, spec)?)?;
    }
    Ok(list)
}

/// The key-value metadata of a table file's footer.
#[pyfunction]
fn table_file_metadata(py: Python<'_>, path: PathBuf) -> PyResult<BTreeMap<String, String>> {
    run(py, 0, || Ok(mmtrack_io::table_kv::read_key_value_metadata(&path)?))
}

/// The metadata of a recording (sequence id, time base, sensors).
#[pyfunction]
fn recording_metadata(py: Python<'_>, path: PathBuf) -> PyResult<BTreeMap<String, String>> {
    run(py, 0, || {
        let mut reader = mmtrack_io::RecordingReader::open(&path)?;
        // Complete once the first item is read (writers put it first).
        if let Some(item) = reader.next_item() {
            item?;
        }
        Ok(reader.metadata().cloned().unwrap_or_default())
    })
}

// ---------------------------------------------------------------- arrays

/// MPC detection on CIR snapshots (arrays as little-endian bytes).
#[pyfunction]
#[pyo3(signature = (taps, taps_per_snapshot, t_ns, set_index, snapshot_index, tap_spacing_s, config, pulse))]
#[allow(clippy::too_many_arguments)]
fn detect_mpc<'py>(
    py: Python<'py>,
    taps: &Bound<'py, PyBytes>,
    taps_per_snapshot: usize,
    t_ns: &Bound<'py, PyBytes>,
    set_index: Vec<u64>,
    snapshot_index: Vec<u32>,
    tap_spacing_s: f64,
    config: Option<PathBuf>,
    pulse: Option<&Bound<'py, PyBytes>>,
) -> PyResult<Bound<'py, PyBytes>> {
    let taps = arrays::complexes(taps.as_bytes(), "cir").map_err(py_err)?;
    let t_ns = arrays::i64s(t_ns.as_bytes(), "t_ns").map_err(py_err)?;
    let pulse = pulse.map(|p| arrays::complexes(p.as_bytes(), "pulse")).transpose().map_err(py_err)?;
    let bytes = run(py, 0, || {
        let cir = arrays::CirArray {
            taps: &taps,
            taps_per_snapshot,
            t_ns: &t_ns,
            set_index: &set_index,
            snapshot_index: &snapshot_index,
            tap_spacing_s,
        };
        arrays::detect_mpc(&cir, config.as_deref(), pulse.as_deref())
    })?;
    Ok(PyBytes::new(py, &bytes))
}

/// The beam-sweep trackers on an (N, beams) power array.
#[pyfunction]
#[pyo3(signature = (power, beams, t_ns, tracker, reacquire, site))]
fn track_beams<'py>(
    py: Python<'py>,
    power: &Bound<'py, PyBytes>,
    beams: usize,
    t_ns: &Bound<'py, PyBytes>,
    tracker: Vec<String>,
    reacquire: String,
    site: String,
) -> PyResult<Bound<'py, PyBytes>> {
    let power = arrays::f64s(power.as_bytes(), "power").map_err(py_err)?;
    let t_ns = arrays::i64s(t_ns.as_bytes(), "t_ns").map_err(py_err)?;
    let bytes = run(py, 0, || arrays::track_beams(&power, beams, &t_ns, &tracker, &reacquire, &site))?;
    Ok(PyBytes::new(py, &bytes))
}

/// Trajectory metrics of two pose arrays.
#[pyfunction]
#[pyo3(signature = (sequence, estimate_t_ns, estimate, ground_truth_t_ns, ground_truth, segment_lengths_m, step_frames, step_m))]
#[allow(clippy::too_many_arguments)]
fn trajectory_metrics<'py>(
    py: Python<'py>,
    sequence: String,
    estimate_t_ns: &Bound<'py, PyBytes>,
    estimate: &Bound<'py, PyBytes>,
    ground_truth_t_ns: &Bound<'py, PyBytes>,
    ground_truth: &Bound<'py, PyBytes>,
    segment_lengths_m: Option<Vec<f64>>,
    step_frames: Option<usize>,
    step_m: Option<f64>,
) -> PyResult<(Bound<'py, PyBytes>, Bound<'py, PyBytes>, Bound<'py, PyBytes>)> {
    let read = || -> anyhow::Result<_> {
        let est = arrays::poses(
            "estimate",
            &arrays::i64s(estimate_t_ns.as_bytes(), "estimate t_ns")?,
            &arrays::f64s(estimate.as_bytes(), "estimate")?,
        )?;
        let gt = arrays::poses(
            "ground truth",
            &arrays::i64s(ground_truth_t_ns.as_bytes(), "ground truth t_ns")?,
            &arrays::f64s(ground_truth.as_bytes(), "ground truth")?,
        )?;
        Ok((est, gt))
    };
    let (est, gt) = read().map_err(py_err)?;
    let [metrics, drift, rpe] = run(py, 0, || {
        let options = AnalyzeOptions::from_flags(segment_lengths_m, step_frames, step_m, 0.0, false)?;
        arrays::trajectory_metrics(&sequence, &est, &gt, &options)
    })?;
    Ok((PyBytes::new(py, &metrics), PyBytes::new(py, &drift), PyBytes::new(py, &rpe)))
}

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("MmtrackError", m.py().get_type::<MmtrackError>())?;
    m.add_function(wrap_pyfunction!(ingest_oxford, m)?)?;
    m.add_function(wrap_pyfunction!(ingest_boreas, m)?)?;
    m.add_function(wrap_pyfunction!(ingest_mulran, m)?)?;
    m.add_function(wrap_pyfunction!(ingest_cir, m)?)?;
    m.add_function(wrap_pyfunction!(ingest_nmea, m)?)?;
    m.add_function(wrap_pyfunction!(ingest_beams, m)?)?;
    m.add_function(wrap_pyfunction!(process_odometry, m)?)?;
    m.add_function(wrap_pyfunction!(effective_config, m)?)?;
    m.add_function(wrap_pyfunction!(process_mpc, m)?)?;
    m.add_function(wrap_pyfunction!(process_beam, m)?)?;
    m.add_function(wrap_pyfunction!(process_slam, m)?)?;
    m.add_function(wrap_pyfunction!(analyze_tables, m)?)?;
    m.add_function(wrap_pyfunction!(reproduce_experiment, m)?)?;
    m.add_function(wrap_pyfunction!(reproduce_all, m)?)?;
    m.add_function(wrap_pyfunction!(table_specs, m)?)?;
    m.add_function(wrap_pyfunction!(table_file_metadata, m)?)?;
    m.add_function(wrap_pyfunction!(recording_metadata, m)?)?;
    m.add_function(wrap_pyfunction!(detect_mpc, m)?)?;
    m.add_function(wrap_pyfunction!(track_beams, m)?)?;
    m.add_function(wrap_pyfunction!(trajectory_metrics, m)?)?;
    Ok(())
}
