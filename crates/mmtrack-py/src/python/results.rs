//! `mmtrack reproduce`, the table declarations and metadata, and the array-level calls.

use super::*;
use crate::arrays;

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
pub(super) fn reproduce_experiment<'py>(
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
    let outcome = interruptible(py, threads, |progress| run_experiment(&experiment, &request, progress))?;
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
pub(super) fn reproduce_all<'py>(
    py: Python<'py>,
    output: PathBuf,
    smoke: bool,
    readme: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    use mmtrack_reproduce::Tier;
    use mmtrack_reproduce::all::{AllOptions, run_all};
    let options = AllOptions { tier: if smoke { Tier::Smoke } else { Tier::Full }, output_dir: output, readme };
    let outcome = interruptible(py, 0, |progress| run_all(&options, progress))?;
    dict(
        py,
        &[
            ("claims", verdicts(py, outcome.claims.iter().cloned())?.into_any()),
            ("misses", any(py, outcome.misses())?),
            ("summary", any(py, &outcome.summary)?),
        ],
    )
}

fn spec_dict<'py>(py: Python<'py>, spec: &TableSpec) -> PyResult<Bound<'py, PyDict>> {
    let columns = PyList::empty(py);
    for c in spec.columns {
        columns.append(dict(
            py,
            &[
                ("name", any(py, c.name)?),
                ("type", any(py, c.ty.doc_name())?),
                ("nullable", any(py, c.nullable)?),
                ("unit", any(py, c.unit_label())?),
                ("meaning", any(py, c.meaning)?),
            ],
        )?)?;
    }
    dict(
        py,
        &[
            ("name", any(py, spec.name)?),
            ("description", any(py, spec.description)?),
            ("frame", any(py, spec.frame.doc())?),
            ("columns", columns.into_any()),
        ],
    )
}

/// Every table declaration of mmtrack-io: the tables `process` writes
/// and the result tables of `analyze`.
#[pyfunction]
pub(super) fn table_specs(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let list = PyList::empty(py);
    for spec in ALL_TABLES.iter().chain(RESULT_TABLES) {
        list.append(spec_dict(py, spec)?)?;
    }
    Ok(list)
}

/// The key-value metadata of a table file's footer.
#[pyfunction]
pub(super) fn table_file_metadata(py: Python<'_>, path: PathBuf) -> PyResult<BTreeMap<String, String>> {
    run(py, 0, || Ok(mmtrack_io::table_kv::read_key_value_metadata(&path)?))
}

/// Each field's metadata (`unit`, `description`) of a table file, in file order.
#[pyfunction]
pub(super) fn table_field_metadata(py: Python<'_>, path: PathBuf) -> PyResult<Vec<(String, BTreeMap<String, String>)>> {
    run(py, 0, || Ok(mmtrack_io::table_kv::read_field_metadata(&path)?))
}

/// The metadata of a recording (sequence id, time base, sensors).
#[pyfunction]
pub(super) fn recording_metadata(py: Python<'_>, path: PathBuf) -> PyResult<BTreeMap<String, String>> {
    run(py, 0, || {
        let mut reader = mmtrack_io::RecordingReader::open(&path)?;
        // Complete once the first item is read (writers put it first).
        if let Some(item) = reader.next_item() {
            item?;
        }
        Ok(reader.metadata().cloned().unwrap_or_default())
    })
}

/// MPC detection on CIR snapshots (arrays as little-endian bytes).
#[pyfunction]
#[pyo3(signature = (taps, taps_per_snapshot, t_ns, set_index, snapshot_index, tap_spacing_s, config, pulse))]
#[allow(clippy::too_many_arguments)]
pub(super) fn detect_mpc<'py>(
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
    let bytes = interruptible(py, 0, |progress| {
        let cir = arrays::CirArray {
            taps: &taps,
            taps_per_snapshot,
            t_ns: &t_ns,
            set_index: &set_index,
            snapshot_index: &snapshot_index,
            tap_spacing_s,
        };
        arrays::detect_mpc(&cir, config.as_deref(), pulse.as_deref(), progress)
    })?;
    Ok(PyBytes::new(py, &bytes))
}

/// The beam-sweep trackers on an (N, beams) power array: per pass, its
/// index and table bytes.
#[pyfunction]
#[pyo3(signature = (power, beams, t_ns, tracker, reacquire, site, pass_index=None, car=None, car_frame="east_north_m", array_lat_lon_deg=None))]
#[allow(clippy::too_many_arguments)]
pub(super) fn track_beams<'py>(
    py: Python<'py>,
    power: &Bound<'py, PyBytes>,
    beams: usize,
    t_ns: &Bound<'py, PyBytes>,
    tracker: Vec<String>,
    reacquire: String,
    site: String,
    pass_index: Option<&Bound<'py, PyBytes>>,
    car: Option<&Bound<'py, PyBytes>>,
    car_frame: &str,
    array_lat_lon_deg: Option<&Bound<'py, PyBytes>>,
) -> PyResult<Vec<(i64, Bound<'py, PyBytes>)>> {
    let read = || -> anyhow::Result<_> {
        let power = arrays::f64s(power.as_bytes(), "power")?;
        let t_ns = arrays::i64s(t_ns.as_bytes(), "t_ns")?;
        let pass_index = pass_index.map(|b| arrays::i64s(b.as_bytes(), "pass_index")).transpose()?;
        let car = car.map(|b| arrays::f64s(b.as_bytes(), "car positions")).transpose()?;
        let array = array_lat_lon_deg.map(|b| arrays::f64s(b.as_bytes(), "array_lat_lon_deg")).transpose()?;
        Ok((power, t_ns, pass_index, car, array))
    };
    let (power, t_ns, pass_index, car, array) = read().map_err(py_err)?;
    let tables = interruptible(py, 0, |progress| {
        let car_frame = match (car_frame, array.as_deref()) {
            ("east_north_m", None) => arrays::CarFrame::EastNorthM,
            ("lat_lon_deg", Some(array_lat_lon_deg)) => arrays::CarFrame::LatLonDeg { array_lat_lon_deg },
            ("east_north_m", Some(_)) => anyhow::bail!("array_lat_lon_deg: only with car positions in lat_lon_deg"),
            ("lat_lon_deg", None) => {
                anyhow::bail!("car_lat_lon_deg: give array_lat_lon_deg too (the array's position)")
            }
            (other, _) => anyhow::bail!("car_frame '{other}': expected east_north_m or lat_lon_deg"),
        };
        let sweeps = arrays::SweepArrays {
            power: &power,
            beams,
            t_ns: &t_ns,
            pass_index: pass_index.as_deref(),
            car: car.as_deref(),
            car_frame,
        };
        arrays::track_beams(&sweeps, &tracker, &reacquire, &site, progress)
    })?;
    Ok(tables.into_iter().map(|(pass, bytes)| (pass, PyBytes::new(py, &bytes))).collect())
}

/// Trajectory metrics of two pose arrays.
#[pyfunction]
#[pyo3(signature = (sequence, estimate_t_ns, estimate, ground_truth_t_ns, ground_truth, segment_lengths_m, step_frames, step_m))]
#[allow(clippy::too_many_arguments)]
pub(super) fn trajectory_metrics<'py>(
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
