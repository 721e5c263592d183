//! The extension module `mmtrack._native`: argument conversion around the
//! library calls, nothing else. The Python half (`python/mmtrack`) gives
//! the public names, defaults and docs; `_native.pyi` types this module.
//!
//! Every call releases the GIL while the libraries work ([`interruptible`]:
//! Ctrl-C stops the long loops and raises `KeyboardInterrupt`), runs on the pool
//! of its `threads` argument where the CLI command has `--threads`
//! ([`mmtrack_process::threads::install`]), and turns an error into
//! `mmtrack.MmtrackError` with the one line the CLI prints after `error: `
//! ([`mmtrack_core::error::one_line`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use mmtrack_analysis::analyze::{AnalyzeOptions, Analyzed, analyze};
use mmtrack_core::progress::{Cancelled, Progress};
use mmtrack_io::recording::RecordingFlags;
use mmtrack_io::table::{ALL_TABLES, RESULT_TABLES, TableSpec, TableWriteSummary};
use mmtrack_process::output::OutputOptions;
use pyo3::BoundObject;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};

mod ingest;
mod process;
mod results;

create_exception!(mmtrack, MmtrackError, PyException, "An mmtrack call failed; the message is the CLI's one line.");

/// The CLI's one line of `error`, as a Python exception.
fn py_err(error: anyhow::Error) -> PyErr {
    MmtrackError::new_err(mmtrack_core::error::one_line(error.chain()))
}

/// Runs `work` without the GIL on a pool of `threads` threads
/// ([`interruptible`]; `work` has no hook to stop early, so an interruption
/// waits for it).
fn run<R: Send>(py: Python<'_>, threads: usize, work: impl FnOnce() -> anyhow::Result<R> + Send) -> PyResult<R> {
    interruptible(py, threads, |_| work())
}

/// The [`Progress`] of a Python call: draws nothing, and is cancelled once
/// the calling thread has seen a signal handler raise (Ctrl-C).
#[derive(Debug, Default)]
struct Interruption {
    requested: AtomicBool,
}

impl Progress for Interruption {
    fn start(&self, _stage: &str, _total: u64, _unit: &str) {}
    fn set_position(&self, _done: u64) {}
    fn advance(&self, _by: u64) {}
    fn finish(&self) {}
    fn note(&self, _text: &str) {}
    fn check_cancelled(&self) -> Result<(), Cancelled> {
        if self.requested.load(Ordering::Relaxed) { Err(Cancelled) } else { Ok(()) }
    }
}

/// How often the waiting thread takes the GIL back to run signal handlers.
const SIGNAL_CHECK_PERIOD: Duration = Duration::from_millis(50);

/// Runs `work` on a thread of its own, on a pool of `threads` threads,
/// while the calling thread waits without the GIL and every
/// [`SIGNAL_CHECK_PERIOD`] takes it back to run Python's signal handlers
/// (`Python::check_signals`; they run on the main thread only). When one
/// raises (Ctrl-C: `KeyboardInterrupt`), `work`'s [`Progress`] is cancelled,
/// the library stops at its next check and drops its partial outputs as on
/// any error, and the handler's exception is raised once `work` has
/// returned, as the CLI removes its partial outputs before it exits.
fn interruptible<R: Send>(
    py: Python<'_>,
    threads: usize,
    work: impl FnOnce(&dyn Progress) -> anyhow::Result<R> + Send,
) -> PyResult<R> {
    let interruption = Interruption::default();
    let (done_tx, mut done_rx) = mpsc::channel::<()>();
    let (interrupt, result) = std::thread::scope(|scope| {
        let progress = &interruption;
        let worker = scope.spawn(move || {
            let result = mmtrack_process::threads::install(threads, || work(progress)).and_then(|r| r);
            // The waiting thread may be gone only after a panic of its own.
            let _ = done_tx.send(());
            result
        });
        let mut interrupt: Option<PyErr> = None;
        loop {
            let (rx, waited) = py.detach(move || {
                let waited = done_rx.recv_timeout(SIGNAL_CHECK_PERIOD);
                (done_rx, waited)
            });
            done_rx = rx;
            if !matches!(waited, Err(mpsc::RecvTimeoutError::Timeout)) {
                break;
            }
            if interrupt.is_none()
                && let Err(e) = py.check_signals()
            {
                interruption.requested.store(true, Ordering::Relaxed);
                interrupt = Some(e);
            }
        }
        let result = worker.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (interrupt, result)
    });
    match (interrupt, result) {
        (Some(interrupt), _) => Err(interrupt),
        (None, result) => result.map_err(py_err),
    }
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

fn output_options(sequence: Option<String>, force: bool, run_id: Option<String>) -> OutputOptions {
    OutputOptions { sequence, run_id, force }
}

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("MmtrackError", m.py().get_type::<MmtrackError>())?;
    m.add_function(wrap_pyfunction!(ingest::ingest_oxford, m)?)?;
    m.add_function(wrap_pyfunction!(ingest::ingest_boreas, m)?)?;
    m.add_function(wrap_pyfunction!(ingest::ingest_mulran, m)?)?;
    m.add_function(wrap_pyfunction!(ingest::ingest_cir, m)?)?;
    m.add_function(wrap_pyfunction!(ingest::ingest_nmea, m)?)?;
    m.add_function(wrap_pyfunction!(ingest::ingest_ros2, m)?)?;
    m.add_function(wrap_pyfunction!(ingest::ingest_poses, m)?)?;
    m.add_function(wrap_pyfunction!(ingest::ingest_beams, m)?)?;
    m.add_function(wrap_pyfunction!(process::process_odometry, m)?)?;
    m.add_function(wrap_pyfunction!(process::process_poses, m)?)?;
    m.add_function(wrap_pyfunction!(process::process_raw, m)?)?;
    m.add_function(wrap_pyfunction!(process::effective_config, m)?)?;
    m.add_function(wrap_pyfunction!(process::process_mpc, m)?)?;
    m.add_function(wrap_pyfunction!(process::process_beam, m)?)?;
    m.add_function(wrap_pyfunction!(process::process_slam, m)?)?;
    m.add_function(wrap_pyfunction!(process::analyze_tables, m)?)?;
    m.add_function(wrap_pyfunction!(results::reproduce_experiment, m)?)?;
    m.add_function(wrap_pyfunction!(results::reproduce_all, m)?)?;
    m.add_function(wrap_pyfunction!(results::table_specs, m)?)?;
    m.add_function(wrap_pyfunction!(results::table_file_metadata, m)?)?;
    m.add_function(wrap_pyfunction!(results::table_field_metadata, m)?)?;
    m.add_function(wrap_pyfunction!(results::recording_metadata, m)?)?;
    m.add_function(wrap_pyfunction!(results::detect_mpc, m)?)?;
    m.add_function(wrap_pyfunction!(results::track_beams, m)?)?;
    m.add_function(wrap_pyfunction!(results::trajectory_metrics, m)?)?;
    Ok(())
}
