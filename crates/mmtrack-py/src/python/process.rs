//! `mmtrack process <pipeline>` and `mmtrack analyze`.

use super::*;

/// `mmtrack process odometry`.
#[pyfunction]
#[pyo3(signature = (recording, output, preset, config, sequence, force, run_id, threads))]
#[allow(clippy::too_many_arguments)]
pub(super) fn process_odometry<'py>(
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
    let done = interruptible(py, threads, |progress| {
        let config = odometry::effective_config(&preset, config.as_deref())?;
        odometry::process_odometry(&recording, &output, &preset, &config, &options, progress)
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

/// `mmtrack process poses`.
#[pyfunction]
#[pyo3(signature = (recording, output, sequence, force, run_id))]
pub(super) fn process_poses<'py>(
    py: Python<'py>,
    recording: PathBuf,
    output: PathBuf,
    sequence: Option<String>,
    force: bool,
    run_id: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = output_options(sequence, force, run_id);
    let done = interruptible(py, 1, |progress| {
        mmtrack_process::poses::process_poses(&recording, &output, &options, progress)
    })?;
    dict(
        py,
        &[
            ("sequence", any(py, &done.sequence)?),
            ("estimate_poses", any(py, done.poses.estimate.len())?),
            ("ground_truth_poses", any(py, done.poses.ground_truth.len())?),
            ("tables", written_tables(py, &done.written)?.into_any()),
        ],
    )
}

/// `mmtrack process raw`.
#[pyfunction]
#[pyo3(signature = (recording, output, sequence, force, run_id))]
pub(super) fn process_raw<'py>(
    py: Python<'py>,
    recording: PathBuf,
    output: PathBuf,
    sequence: Option<String>,
    force: bool,
    run_id: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = output_options(sequence, force, run_id);
    let done =
        interruptible(py, 0, |progress| mmtrack_process::raw::process_raw(&recording, &output, &options, progress))?;
    let c = done.counts;
    dict(
        py,
        &[
            ("sequence", any(py, &done.sequence)?),
            ("radar_scans", any(py, c.radar_scans)?),
            ("cir_snapshots", any(py, c.cir_snapshots)?),
            ("gnss_fixes", any(py, c.gnss_fixes)?),
            ("ground_truth_poses", any(py, c.ground_truth)?),
            ("tables", written_tables(py, &done.written)?.into_any()),
        ],
    )
}

/// `mmtrack process odometry --print-config` / `process mpc --print-config`:
/// the effective configuration as TOML.
#[pyfunction]
#[pyo3(signature = (pipeline, preset, config, gmphd))]
pub(super) fn effective_config(
    pipeline: &str,
    preset: String,
    config: Option<PathBuf>,
    gmphd: bool,
) -> PyResult<String> {
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
pub(super) fn process_mpc<'py>(
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
    let done = interruptible(py, threads, |progress| {
        let mut config = mpc::effective_config(config.as_deref())?;
        config.run_gmphd |= gmphd;
        let options =
            mpc::MpcOptions { pulse, link: link.as_deref().map(mpc::parse_link).transpose()?, output: output_options };
        mpc::process_mpc(&recording, &output, &config, &options, progress)
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
pub(super) fn process_beam<'py>(
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
    let done = interruptible(py, 0, |progress| {
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
        mmtrack_process::beam::process_beam(&output, &request, progress)
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
pub(super) fn process_slam<'py>(
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

/// `mmtrack analyze`.
#[pyfunction]
#[pyo3(signature = (tables, output, force, segment_lengths_m, step_frames, step_m, first_path_range_db))]
#[allow(clippy::too_many_arguments)]
pub(super) fn analyze_tables<'py>(
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
