//! One entry point for every CIR format: read a file (with its sidecar) into
//! snapshots, and write them into a recording on `/channel/cir`.
//!
//! The whole file is read and checked before the recording is created, so a
//! bad input leaves no output (and the writer renames into place only on
//! success). What the reader assumed goes into the recording metadata
//! (`cir.*` keys): format, domain and the CFR conversion, axes, sidecar,
//! time origin.

use std::collections::BTreeMap;
use std::path::Path;

use mmtrack_core::CirSnapshot;
use mmtrack_io::RecordingOptions;
use mmtrack_io::recording::WriteSummary;
use mmtrack_io::recording::channels::CIR_TOPIC;

use super::array::{NdComplex, cut_snapshots, resolve_axes};
use super::decawave::{DecawaveConfig, DecawaveTimeBase, read_decawave_log};
use super::sidecar::{CirSidecar, Domain, TapSpacing};
use crate::{IngestError, Progress};

/// The formats `mmtrack ingest cir --format` reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CirFormat {
    /// NumPy `.npy`.
    Npy,
    /// NumPy `.npz` archive.
    Npz,
    /// MATLAB `.mat`: v5/v7, and v7.3 (HDF5) with the `hdf5` feature.
    Mat,
    /// HDF5 dataset (needs the `hdf5` feature).
    Hdf5,
    /// SigMF meta + data.
    Sigmf,
    /// CSV, one snapshot per row.
    Csv,
    /// DecaWave DecaRanging accumulator log.
    Decawave,
}

/// Sidecar keys of the sampled axes and timing, used by every array format.
const COMMON_KEYS: &[&str] = &[
    "carrier_hz",
    "tap_spacing_s",
    "bandwidth_hz",
    "subcarrier_spacing_hz",
    "domain",
    "delay_offset_s",
    "t0_ns",
    "snapshot_period_s",
    "snapshots_per_set",
    "set_period_s",
];

impl CirFormat {
    /// The `--format` name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Npy => "npy",
            Self::Npz => "npz",
            Self::Mat => "mat",
            Self::Hdf5 => "hdf5",
            Self::Sigmf => "sigmf",
            Self::Csv => "csv",
            Self::Decawave => "decawave",
        }
    }

    /// Sidecar keys this format uses.
    fn keys(self) -> Vec<&'static str> {
        let extra: &[&str] = match self {
            Self::Npy => &["axes"],
            Self::Npz => &["axes", "variable"],
            Self::Mat => &["axes", "variable", "allow_real"],
            Self::Hdf5 => &["axes", "dataset"],
            Self::Sigmf => &["taps_per_snapshot"],
            Self::Csv => &[],
            Self::Decawave => return vec!["carrier_hz", "tap_spacing_s", "bandwidth_hz", "t0_ns", "snapshot_period_s"],
        };
        COMMON_KEYS.iter().chain(extra).copied().collect()
    }
}

/// Snapshots read from one file, and what the reader assumed.
#[derive(Debug, Clone, PartialEq)]
pub struct CirFile {
    /// In time order, then TX, then RX.
    pub snapshots: Vec<CirSnapshot>,
    /// `cir.*` recording metadata.
    pub metadata: BTreeMap<String, String>,
    /// Receptions the format tolerates and the reader skipped (DecaWave `RX E` frames).
    pub skipped: usize,
}

/// Reads a CIR file of `format`, with its sidecar (`None`: no sidecar).
pub fn read_cir_file(format: CirFormat, input: &Path, sidecar: Option<&CirSidecar>) -> Result<CirFile, IngestError> {
    let empty = CirSidecar::empty();
    let sidecar = sidecar.unwrap_or(&empty);
    sidecar.check_keys_apply(format.name(), &format.keys())?;
    let mut metadata = BTreeMap::new();
    metadata.insert("cir.format".to_string(), format.name().to_string());
    let sidecar_name =
        if sidecar.path.as_os_str().is_empty() { "none".into() } else { mmtrack_io::paths::canonical(&sidecar.path) };
    metadata.insert("cir.sidecar".into(), sidecar_name);
    let domain = match sidecar.domain {
        Domain::Cir => "cir: the file holds impulse responses".to_string(),
        Domain::Cfr => "cfr: frequency responses turned into CIRs by the inverse DFT h[n] = (1/N) sum_k H[k] \
                        exp(+j 2 pi k n / N), bins in file order"
            .to_string(),
    };
    metadata.insert("cir.domain".into(), domain);
    let origin = if sidecar.t0_ns.is_some() { "t0_ns of the sidecar" } else { "none given: snapshot 0 at t = 0" };
    metadata.insert("cir.time_origin".into(), origin.into());
    let (snapshots, skipped) = match format {
        CirFormat::Decawave => return read_decawave(input, sidecar, metadata),
        CirFormat::Csv => {
            let text = crate::error::read_line_records(input)?;
            (super::csv_cir::parse_cir_csv(input, &text, sidecar)?, 0)
        }
        CirFormat::Sigmf => {
            let s = super::sigmf::read_sigmf(input, sidecar)?;
            let mut filled = sidecar.clone();
            filled.carrier_hz = filled.carrier_hz.or(s.frequency_hz);
            if filled.t0_ns.is_none() && s.t0_ns.is_some() {
                filled.t0_ns = s.t0_ns;
                metadata.insert("cir.time_origin".into(), "SigMF captures[0].core:datetime".into());
            }
            metadata.insert("cir.sigmf_datatype".into(), s.datatype.clone());
            let rate = s.sample_rate_hz.map(|r| 1.0 / r);
            (cut_snapshots(input, &s.array, &filled, "data", rate)?, 0)
        }
        CirFormat::Npy | CirFormat::Npz | CirFormat::Mat | CirFormat::Hdf5 => {
            if format == CirFormat::Mat {
                let version = if super::hdf5::is_mat73(&super::hdf5::file_head(input)?) {
                    "7.3 (HDF5; dimensions reversed back to MATLAB's order)"
                } else {
                    "5 (v5/v7)"
                };
                metadata.insert("cir.mat_version".into(), version.into());
            }
            let (record, array) = read_array(format, input, sidecar)?;
            let axes = resolve_axes(input, &array, sidecar, &record)?;
            let axes: Vec<&str> = axes.iter().map(|a| a.as_str()).collect();
            metadata.insert("cir.axes".into(), format!("{} (shape {:?})", axes.join(", "), array.dims));
            metadata.insert("cir.array".into(), record.clone());
            (cut_snapshots(input, &array, sidecar, &record, None)?, 0)
        }
    };
    Ok(CirFile { snapshots, metadata, skipped })
}

fn read_array(format: CirFormat, input: &Path, sidecar: &CirSidecar) -> Result<(String, NdComplex), IngestError> {
    match format {
        CirFormat::Npy => {
            let bytes = crate::error::read_capped(input, &mmtrack_core::limits::ARRAY_FILE_BYTES)?;
            Ok(("array".into(), super::npy::parse_npy(input, "array", &bytes)?))
        }
        CirFormat::Npz => {
            let bytes = crate::error::read_capped(input, &mmtrack_core::limits::ARRAY_FILE_BYTES)?;
            let (name, array) = super::npy::parse_npz(input, &bytes, sidecar.variable.as_deref())?;
            Ok((format!("member `{name}.npy`"), array))
        }
        CirFormat::Hdf5 => {
            let (name, array) = super::hdf5::read_hdf5_array(input, sidecar.dataset.as_deref())?;
            Ok((format!("dataset `{name}`"), array))
        }
        _ => {
            let Some(variable) = sidecar.variable.as_deref() else {
                let held = super::matlab::list_variables(input)?;
                let example = held.first().map_or("CIR", |(name, _)| name.as_str());
                let present = if held.is_empty() {
                    String::new()
                } else {
                    format!("; it holds {}", super::matlab::describe_variables(&held))
                };
                return Err(sidecar.error(
                    "variable",
                    format!(
                        "required: name the MATLAB variable of {}{present} (a sidecar TOML with `variable = \"{example}\"`, \
                         passed with --sidecar)",
                        input.display()
                    ),
                ));
            };
            let array = super::matlab::read_mat_array(input, variable, sidecar.allow_real)?;
            Ok((format!("variable `{variable}`"), array))
        }
    }
}

fn read_decawave(
    input: &Path,
    sidecar: &CirSidecar,
    mut metadata: BTreeMap<String, String>,
) -> Result<CirFile, IngestError> {
    let mut config = DecawaveConfig::default();
    if let Some(carrier) = sidecar.carrier_hz {
        config.carrier_hz = carrier;
    }
    if let Some(spacing) = sidecar.tap_spacing {
        config.tap_spacing_s = match spacing {
            TapSpacing::Seconds(s) => s,
            TapSpacing::Bandwidth(b) => 1.0 / b,
            TapSpacing::SubcarrierSpacing(_) => config.tap_spacing_s,
        };
    }
    config.t0_ns = sidecar.t0_ns.unwrap_or(0);
    let time_base = if let Some(period) = sidecar.snapshot_period_s {
        let period_ns = (period * 1e9).round();
        if period_ns >= i64::MAX as f64 {
            return Err(sidecar.error("snapshot_period_s", format!("{period} s is beyond the i64 nanosecond range")));
        }
        let period_ns = period_ns as i64;
        if period_ns <= 0 {
            return Err(sidecar.error("snapshot_period_s", format!("{period} s rounds to 0 ns")));
        }
        config.time_base = DecawaveTimeBase::FramePeriod { period_ns };
        "frame period of the sidecar (snapshot_period_s)"
    } else {
        "DW1000 RX timestamp (RC), unwrapped; first frame at t0_ns"
    };
    let log = read_decawave_log(input, &config)?;
    metadata.insert("cir.decawave_time_base".into(), time_base.into());
    metadata.insert(
        "cir.first_path_hint".into(),
        "DW1000 HLP (hardware leading-edge index) as first_path_hint_s = HLP * tap_spacing_s".into(),
    );
    if let Some(channel) = log.channel {
        metadata.insert("cir.decawave_channel".into(), channel.to_string());
    }
    let skipped = log.skipped_receptions.len();
    Ok(CirFile { snapshots: log.frames.into_iter().map(|f| f.cir).collect(), metadata, skipped })
}

/// What [`ingest_cir`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct CirIngestReport {
    /// The recording written.
    pub output: WriteSummary,
    /// Snapshots written (one per time, TX and RX antenna).
    pub snapshots: usize,
    /// Distinct snapshot times, TX antennas and RX antennas among them: what
    /// the snapshots are. A 3-D array without `axes` is `[rx, tx, tap]`
    /// (see [`super::array`]): 252 snapshots of it are 252 RX antennas at
    /// one time, not 252 times.
    pub times_tx_rx: (usize, usize, usize),
    /// Fewest and most taps of a snapshot.
    pub taps: (usize, usize),
    /// Tap spacing of the first snapshot, seconds.
    pub tap_spacing_s: f64,
    /// Snapshots carrying a first-path hint.
    pub with_first_path_hint: usize,
    /// Receptions skipped (DecaWave `RX E`).
    pub skipped: usize,
    /// The `cir.*` metadata written.
    pub metadata: BTreeMap<String, String>,
}

impl CirIngestReport {
    /// The one-line summary the CLI prints: what the snapshots are, their
    /// taps and spacing, first-path hints, skipped receptions and domain.
    #[must_use]
    pub fn summary(&self) -> String {
        let (fewest, most) = self.taps;
        let taps = if fewest == most { format!("{most}") } else { format!("{fewest}-{most}") };
        let (times, tx, rx) = self.times_tx_rx;
        let times = if times == 1 { "1 time".to_string() } else { format!("{times} times") };
        format!(
            "{}: {} CIR snapshots ({times} x {tx} TX x {rx} RX antennas) of {taps} taps, {:.4} ns apart; {} with \
             a first-path hint; {} skipped; domain {}",
            self.output.path.display(),
            self.snapshots,
            self.tap_spacing_s * 1e9,
            self.with_first_path_hint,
            mmtrack_core::words::counted(self.skipped as u64, "reception"),
            self.metadata.get("cir.domain").and_then(|d| d.split(':').next()).unwrap_or("cir"),
        )
    }
}

/// Distinct times, TX antennas and RX antennas of `snapshots`.
fn times_tx_rx(snapshots: &[mmtrack_core::CirSnapshot]) -> (usize, usize, usize) {
    use std::collections::BTreeSet;
    let times: BTreeSet<i64> = snapshots.iter().map(|s| s.t_ns).collect();
    let tx: BTreeSet<u32> = snapshots.iter().map(|s| s.tx_antenna).collect();
    let rx: BTreeSet<u32> = snapshots.iter().map(|s| s.rx_antenna).collect();
    (times.len(), tx.len(), rx.len())
}

/// Reads `input` and writes its snapshots into a new recording `out`.
pub fn ingest_cir(
    format: CirFormat,
    input: &Path,
    sidecar: Option<&Path>,
    out: &Path,
    recording: &RecordingOptions,
    progress: Progress<'_>,
) -> Result<CirIngestReport, IngestError> {
    let sidecar = sidecar.map(CirSidecar::read).transpose()?;
    let file = read_cir_file(format, input, sidecar.as_ref())?;
    let Some(first) = file.snapshots.first() else {
        return Err(IngestError::BadLayout { path: input.to_path_buf(), detail: "holds no CIR snapshots".into() });
    };
    let tap_spacing_s = first.tap_spacing_s;
    let source = format!("cir-{}:{}", format.name(), mmtrack_io::paths::canonical(input));
    let mut target = crate::target::open_writer(
        out,
        None,
        &source,
        file.metadata.clone(),
        file.snapshots.first().map(|c| c.t_ns),
        &[CIR_TOPIC],
        recording,
    )?;
    let total = file.snapshots.len() as u64;
    for (i, snapshot) in file.snapshots.iter().enumerate() {
        target.writer().write_cir(snapshot)?;
        progress(i as u64 + 1, total);
    }
    let output = target.finish(input, "CIR snapshots")?;
    let taps = file.snapshots.iter().map(|s| s.taps.len());
    Ok(CirIngestReport {
        output,
        snapshots: file.snapshots.len(),
        times_tx_rx: times_tx_rx(&file.snapshots),
        taps: (taps.clone().min().unwrap_or(0), taps.max().unwrap_or(0)),
        tap_spacing_s,
        with_first_path_hint: file.snapshots.iter().filter(|s| s.first_path_hint_s.is_some()).count(),
        skipped: file.skipped,
        metadata: file.metadata,
    })
}
