//! DeepSense 6G 60 GHz beam sweeps, as packaged for position-aided beam
//! prediction (Morais and Alkhateeb, ICC 2023): a roadside unit (unit 1)
//! with a 16-element phased array measures the received power of each beam
//! of its codebook (64 beams over about 90 degrees, about 10 sweeps a
//! second) while a car carrying the transmitter (unit 2) and an RTK GPS
//! drives past.
//!
//! # Layout
//! One folder, files named `scenario<S>_<array>_1-<N>.npy`, one row per
//! sweep, rows in time order:
//!
//! | array | dtype, shape | meaning |
//! |---|---|---|
//! | `unit1_pwr_60ghz` | float64 (N, B) | received power per beam, linear, normalised |
//! | `unit1_loc` | float64 (N, 2) | latitude, longitude of the roadside unit, degrees |
//! | `unit2_loc` | float64 (N, 2) | latitude, longitude of the car |
//! | `unit2_loc_cal` | float64 (N, 2) | the car's calibrated positions (some scenarios) |
//! | `seq_index` | int64 (N,) or (N, 1) | the pass each sweep belongs to |
//!
//! The dataset writes float64 and int64; float32 is accepted wherever
//! float64 is and int32 wherever int64 is (widened exactly), in either byte
//! order.
//!
//! # Recordings
//! Each pass becomes its own recording `<out>/scenario<S>-pass<PP>.mcap`
//! (sequence id the same, `PP` the source's pass index, zero-padded to the
//! widest index and at least two digits): sweeps on `/beam/sweeps` (codebook
//! `deepsense-60ghz-<B>`), the car's positions on `/gnss/fix`, the roadside
//! unit's on `/gnss/array`, one of each per sweep. A recording per pass,
//! rather than one per scenario, because a pass is what a tracker starts
//! afresh on and what `process` and `analyze` call a sequence.
//!
//! The arrays carry no timestamps: sweep `r` of the scenario (0-based row)
//! is at `r * sweep_period` from the scenario's first sweep (time base
//! `relative`: real data without a clock, not a simulation), so times
//! increase across passes though the real gaps between passes are unknown.
//! Fix quality is `unknown` (the arrays do not say) and altitude absent.
//!
//! Metadata keys: `beam.site` (`deepsense-scenario<S>`: recordings of one
//! array at one place, within which beam maps may be fitted), `beam.scenario`,
//! `beam.pass`, `beam.codebook`, `beam.sweep_period_s`, `beam.first_row`,
//! `gnss.vehicle_positions` (`raw` or `calibrated`, and the file).
//!
//! # Checks
//! Every array of a scenario must have the same number of rows; power must
//! be finite and non-negative; positions finite latitudes and longitudes;
//! the rows of a pass consecutive and pass indices consecutive (each pass
//! one more than the previous). A violation is an error naming the file, the
//! row and the field; nothing is written until every array has passed.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use mmtrack_core::plausible::{LATITUDE_DEG, LONGITUDE_DEG};
use mmtrack_core::{BeamSweep, GnssFix, GnssFixQuality};
use mmtrack_io::recording::{BEAM_SITE_KEY, RecordingMetadata, TimeBase, WriteSummary};
use mmtrack_io::{IoError, Overwrite, RecordingOptions, RecordingWriter};

use crate::cir::{NpyMatrix, NpyValues, read_npy_matrix};
use crate::error::check_plausible;
use crate::{IngestError, Progress};

/// Which of the car's positions a recording carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VehiclePositions {
    /// `unit2_loc`, as the GPS gave them.
    Raw,
    /// `unit2_loc_cal`; an error where a scenario has none.
    Calibrated,
    /// Calibrated where the scenario has them, raw otherwise.
    Auto,
}

/// How [`ingest_deepsense`] reads and writes.
#[derive(Debug, Clone, PartialEq)]
pub struct DeepsenseOptions {
    /// Only this scenario; every scenario of the folder when `None`.
    pub scenario: Option<u32>,
    /// The car's positions to carry.
    pub positions: VehiclePositions,
    /// Time between consecutive sweeps, nanoseconds (the arrays have no
    /// timestamps); positive.
    pub sweep_period_ns: i64,
}

impl Default for DeepsenseOptions {
    /// Every scenario, calibrated positions where present, 0.1 s sweeps.
    fn default() -> Self {
        Self { scenario: None, positions: VehiclePositions::Auto, sweep_period_ns: 100_000_000 }
    }
}

/// The files of one scenario in a folder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScenarioFiles {
    /// Scenario number `S`.
    pub scenario: u32,
    /// `unit1_pwr_60ghz`.
    pub power: PathBuf,
    /// `unit1_loc`.
    pub array_position: PathBuf,
    /// `unit2_loc`.
    pub vehicle_raw: PathBuf,
    /// `unit2_loc_cal`, when present.
    pub vehicle_calibrated: Option<PathBuf>,
    /// `seq_index`.
    pub pass_index: PathBuf,
}

const POWER: &str = "unit1_pwr_60ghz";
const ARRAY_LOC: &str = "unit1_loc";
const VEHICLE_LOC: &str = "unit2_loc";
const VEHICLE_LOC_CAL: &str = "unit2_loc_cal";
const PASS_INDEX: &str = "seq_index";

/// `(scenario, array name)` of `scenario<S>_<array>_1-<N>.npy`.
fn parse_name(name: &str) -> Option<(u32, &str)> {
    let rest = name.strip_prefix("scenario")?.strip_suffix(".npy")?;
    let digits = rest.find(|c: char| !c.is_ascii_digit())?;
    let scenario = rest[..digits].parse().ok()?;
    let (array, rows) = rest[digits..].strip_prefix('_')?.rsplit_once('_')?;
    let (first, last) = rows.split_once('-')?;
    (first.chars().all(|c| c.is_ascii_digit()) && last.chars().all(|c| c.is_ascii_digit())).then_some((scenario, array))
}

/// The scenarios of `folder`, by number. Files of other arrays (e.g.
/// camera or radar data of the same scenarios) are ignored.
///
/// # Errors
/// [`IngestError::BadLayout`] when the folder cannot be listed, holds no
/// scenario, holds two files of one array of a scenario, or a scenario lacks
/// a required array.
pub fn find_scenarios(folder: &Path) -> Result<Vec<ScenarioFiles>, IngestError> {
    let entries = std::fs::read_dir(folder).map_err(|source| IngestError::Os { path: folder.to_path_buf(), source })?;
    let mut found: BTreeMap<u32, BTreeMap<String, PathBuf>> = BTreeMap::new();
    for entry in entries {
        let path = entry.map_err(|source| IngestError::Os { path: folder.to_path_buf(), source })?.path();
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let Some((scenario, array)) = parse_name(&name) else { continue };
        let arrays = found.entry(scenario).or_default();
        if let Some(other) = arrays.insert(array.to_string(), path.clone()) {
            let (a, b) = if other < path { (other, path) } else { (path, other) };
            return Err(IngestError::BadLayout {
                path: folder.to_path_buf(),
                detail: format!(
                    "two `{array}` arrays of scenario {scenario}: {} and {}; keep one",
                    file_name(&a),
                    file_name(&b)
                ),
            });
        }
    }
    if found.is_empty() {
        return Err(IngestError::BadLayout {
            path: folder.to_path_buf(),
            detail: format!(
                "no DeepSense beam arrays (expected files like scenario1_{POWER}_1-2422.npy, scenario1_{ARRAY_LOC}_..., \
                 scenario1_{VEHICLE_LOC}_..., scenario1_{PASS_INDEX}_...)"
            ),
        });
    }
    found
        .into_iter()
        .map(|(scenario, mut arrays)| {
            let mut take = |array: &str| {
                arrays.remove(array).ok_or_else(|| IngestError::BadLayout {
                    path: folder.to_path_buf(),
                    detail: format!(
                        "scenario {scenario} has no `{array}` array (scenario{scenario}_{array}_1-<N>.npy)"
                    ),
                })
            };
            Ok(ScenarioFiles {
                scenario,
                power: take(POWER)?,
                array_position: take(ARRAY_LOC)?,
                vehicle_raw: take(VEHICLE_LOC)?,
                vehicle_calibrated: take(VEHICLE_LOC_CAL).ok(),
                pass_index: take(PASS_INDEX)?,
            })
        })
        .collect()
}

fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned())
}

/// One scenario's arrays, checked: `rows` sweeps of `beams` beams.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioArrays {
    /// The files read.
    pub files: ScenarioFiles,
    /// Sweeps (rows of every array).
    pub rows: usize,
    /// Beams of the codebook (columns of the power array).
    pub beams: usize,
    /// Power, `rows x beams`, row-major, linear.
    pub power: Vec<f64>,
    /// The roadside unit's latitude and longitude per sweep, degrees.
    pub array_lat_lon_deg: Vec<[f64; 2]>,
    /// The car's latitude and longitude per sweep, degrees.
    pub vehicle_lat_lon_deg: Vec<[f64; 2]>,
    /// The car's position file used.
    pub vehicle_file: PathBuf,
    /// Whether those are the calibrated positions.
    pub calibrated: bool,
    /// Pass index per sweep.
    pub pass: Vec<i64>,
}

impl ScenarioArrays {
    /// The passes: `(pass index, first row, rows)` in row order.
    #[must_use]
    pub fn passes(&self) -> Vec<(i64, usize, usize)> {
        let mut out: Vec<(i64, usize, usize)> = Vec::new();
        for (row, &pass) in self.pass.iter().enumerate() {
            match out.last_mut() {
                Some((index, _, count)) if *index == pass => *count += 1,
                _ => out.push((pass, row, 1)),
            }
        }
        out
    }
}

fn bad(path: &Path, record: impl Into<String>, field: impl Into<String>, detail: String) -> IngestError {
    IngestError::BadRecord { path: path.to_path_buf(), record: record.into(), field: field.into(), detail }
}

/// The floating-point values (float64 or float32) of `matrix` with `columns`
/// columns (any when `None`).
fn floats(path: &Path, matrix: NpyMatrix, columns: Option<usize>, what: &str) -> Result<Vec<f64>, IngestError> {
    if let Some(columns) = columns
        && matrix.columns != columns
    {
        return Err(bad(
            path,
            "header",
            "shape",
            format!("{} x {}, expected N x {columns} ({what})", matrix.rows, matrix.columns),
        ));
    }
    match matrix.values {
        NpyValues::F64(values) => Ok(values),
        NpyValues::I64(_) => Err(bad(
            path,
            "header",
            "descr",
            format!("dtype `{}`, expected float64 (`<f8`) or float32 (`<f4`) ({what})", matrix.dtype),
        )),
    }
}

/// The farthest a car may be from the roadside unit: a 60 GHz link spans
/// tens to hundreds of metres (DeepSense's sites: under 100 m); 10 km is far
/// beyond any link. (A position of (0, 0), a GPS log's "no fix", is refused
/// before, in its own file.)
pub const MAX_LINK_DISTANCE_M: f64 = 10_000.0;

/// Refuses a sweep whose car is farther than [`MAX_LINK_DISTANCE_M`] from
/// the roadside unit (before, such positions were ingested and the beam map
/// fit failed later without naming a file or row).
fn check_link_distance(vehicle_file: &Path, array: &[[f64; 2]], vehicle: &[[f64; 2]]) -> Result<(), IngestError> {
    for (row, (a, v)) in array.iter().zip(vehicle).enumerate() {
        let origin = crate::nmea::EnuOrigin { latitude_deg: a[0], longitude_deg: a[1], altitude_m: 0.0 };
        let [east_m, north_m, _] = crate::nmea::geodetic_to_enu_m(&origin, v[0], v[1], 0.0);
        let distance_m = east_m.hypot(north_m);
        if distance_m.is_nan() || distance_m > MAX_LINK_DISTANCE_M {
            return Err(bad(
                vehicle_file,
                format!("row {row}"),
                "latitude, longitude",
                format!(
                    "({}, {}) is {:.0} km from the roadside unit at ({}, {}); a link spans at most {} km",
                    v[0],
                    v[1],
                    distance_m / 1000.0,
                    a[0],
                    a[1],
                    MAX_LINK_DISTANCE_M / 1000.0
                ),
            ));
        }
    }
    Ok(())
}

/// Latitude/longitude pairs of a `N x 2` position array, checked.
fn positions(path: &Path, what: &str) -> Result<(usize, Vec<[f64; 2]>), IngestError> {
    let matrix = read_npy_matrix(path)?;
    let rows = matrix.rows;
    let values = floats(path, matrix, Some(2), what)?;
    let pairs: Vec<[f64; 2]> = values.chunks_exact(2).map(|p| [p[0], p[1]]).collect();
    for (row, &[lat, lon]) in pairs.iter().enumerate() {
        check_plausible(path, || format!("row {row}"), "latitude (column 0)", &LATITUDE_DEG, lat)?;
        check_plausible(path, || format!("row {row}"), "longitude (column 1)", &LONGITUDE_DEG, lon)?;
        // Named in its own file (the link-distance check below could not tell which unit is wrong).
        if lat == 0.0 && lon == 0.0 {
            let detail = format!("(0, 0), a GPS log's \"no fix\", not a position ({what})");
            return Err(bad(path, format!("row {row}"), "latitude, longitude", detail));
        }
    }
    Ok((rows, pairs))
}

/// Pass indices of a `N` or `N x 1` int64 array, checked: non-negative, the
/// rows of a pass consecutive, each pass one more than the previous.
fn pass_indices(path: &Path) -> Result<(usize, Vec<i64>), IngestError> {
    let matrix = read_npy_matrix(path)?;
    let rows = matrix.rows;
    if matrix.columns != 1 {
        return Err(bad(
            path,
            "header",
            "shape",
            format!("{rows} x {}, expected N or N x 1 (pass index)", matrix.columns),
        ));
    }
    let NpyValues::I64(pass) = matrix.values else {
        return Err(bad(
            path,
            "header",
            "descr",
            format!("dtype `{}`, expected int64 (`<i8`) or int32 (`<i4`) (pass index)", matrix.dtype),
        ));
    };
    for (row, &index) in pass.iter().enumerate() {
        if index < 0 {
            return Err(bad(path, format!("row {row}"), "pass index", format!("{index}, expected >= 0")));
        }
        let Some(&previous) = row.checked_sub(1).and_then(|r| pass.get(r)) else { continue };
        if index != previous && index != previous + 1 {
            return Err(bad(
                path,
                format!("row {row}"),
                "pass index",
                format!(
                    "pass {index} follows pass {previous}; expected {previous} or {}: the rows of a pass are consecutive \
                     and passes are numbered consecutively",
                    previous + 1
                ),
            ));
        }
    }
    Ok((rows, pass))
}

/// Reads and checks the arrays of one scenario.
///
/// # Errors
/// [`IngestError::BadRecord`] naming the file, row and field for a wrong
/// dtype or shape, a row count that differs from the power array's, a NaN,
/// infinite or negative power, a position that is not a latitude/longitude,
/// or pass indices that are not consecutive; [`IngestError::BadLayout`] for
/// calibrated positions the scenario lacks.
pub fn read_scenario(files: &ScenarioFiles, positions_wanted: VehiclePositions) -> Result<ScenarioArrays, IngestError> {
    let power_matrix = read_npy_matrix(&files.power)?;
    let (rows, beams) = (power_matrix.rows, power_matrix.columns);
    let power = floats(&files.power, power_matrix, None, "power per beam")?;
    if rows == 0 || beams == 0 {
        return Err(bad(
            &files.power,
            "header",
            "shape",
            format!("{rows} x {beams}, expected at least one sweep of one beam"),
        ));
    }
    for (index, &p) in power.iter().enumerate() {
        if !(p.is_finite() && p >= 0.0) {
            return Err(bad(
                &files.power,
                format!("row {}", index / beams),
                format!("beam {} power", index % beams),
                format!("{p}, expected a finite, non-negative linear power"),
            ));
        }
    }
    let (vehicle_file, calibrated) = match (positions_wanted, &files.vehicle_calibrated) {
        (VehiclePositions::Raw, _) | (VehiclePositions::Auto, None) => (files.vehicle_raw.clone(), false),
        (VehiclePositions::Calibrated | VehiclePositions::Auto, Some(cal)) => (cal.clone(), true),
        (VehiclePositions::Calibrated, None) => {
            return Err(IngestError::BadLayout {
                path: files.power.parent().unwrap_or(Path::new(".")).to_path_buf(),
                detail: format!(
                    "scenario {} has no calibrated car positions (scenario{}_{VEHICLE_LOC_CAL}_1-<N>.npy); use raw positions",
                    files.scenario, files.scenario
                ),
            });
        }
    };
    let (array_rows, array_lat_lon_deg) = positions(&files.array_position, "roadside unit latitude, longitude")?;
    let (vehicle_rows, vehicle_lat_lon_deg) = positions(&vehicle_file, "car latitude, longitude")?;
    let (pass_rows, pass) = pass_indices(&files.pass_index)?;
    for (path, found) in
        [(&files.array_position, array_rows), (&vehicle_file, vehicle_rows), (&files.pass_index, pass_rows)]
    {
        if found != rows {
            return Err(bad(
                path,
                format!("row {}", found.min(rows)),
                "rows",
                format!(
                    "{found} rows, but {} has {rows}: every array of a scenario has one row per sweep",
                    file_name(&files.power)
                ),
            ));
        }
    }
    check_link_distance(&vehicle_file, &array_lat_lon_deg, &vehicle_lat_lon_deg)?;
    Ok(ScenarioArrays {
        files: files.clone(),
        rows,
        beams,
        power,
        array_lat_lon_deg,
        vehicle_lat_lon_deg,
        vehicle_file,
        calibrated,
        pass,
    })
}

/// One recording written by [`ingest_deepsense`].
#[derive(Debug, Clone, PartialEq)]
pub struct PassRecording {
    /// Scenario number.
    pub scenario: u32,
    /// The source's pass index.
    pub pass: i64,
    /// Sequence id (also the file stem).
    pub sequence_id: String,
    /// Sweeps in the pass.
    pub sweeps: usize,
    /// Beams per sweep.
    pub beams: usize,
    /// Whether the car's positions are the calibrated ones.
    pub calibrated: bool,
    /// What the writer reports.
    pub output: WriteSummary,
}

fn fix(t_ns: i64, [latitude_deg, longitude_deg]: [f64; 2]) -> GnssFix {
    GnssFix {
        t_ns,
        latitude_deg,
        longitude_deg,
        altitude_m: None,
        horizontal_sigma_m: None,
        num_satellites: None,
        quality: GnssFixQuality::Unknown,
    }
}

/// Reads the scenarios of `folder` (all, or `options.scenario`) and writes
/// one recording per pass into `out_dir` (module docs). Every scenario is
/// read and checked, and no existing file is in the way (unless
/// `recording.overwrite` replaces), before the first recording is written.
/// `progress` counts sweeps.
///
/// # Errors
/// Those of [`find_scenarios`] and [`read_scenario`]; [`IngestError::BadLayout`]
/// for a scenario the folder lacks or a bad sweep period; the writer's
/// errors ([`IoError::OutputExists`] for an existing recording without
/// `Overwrite::Replace`).
pub fn ingest_deepsense(
    folder: &Path,
    out_dir: &Path,
    options: &DeepsenseOptions,
    recording: &RecordingOptions,
    progress: Progress<'_>,
) -> Result<Vec<PassRecording>, IngestError> {
    if options.sweep_period_ns <= 0 {
        return Err(IngestError::BadLayout {
            path: folder.to_path_buf(),
            detail: format!("sweep period {} ns, expected a positive period", options.sweep_period_ns),
        });
    }
    let mut scenarios = find_scenarios(folder)?;
    if let Some(wanted) = options.scenario {
        let numbers: Vec<u32> = scenarios.iter().map(|s| s.scenario).collect();
        scenarios.retain(|s| s.scenario == wanted);
        if scenarios.is_empty() {
            return Err(IngestError::BadLayout {
                path: folder.to_path_buf(),
                detail: format!("no scenario {wanted}; the folder holds scenarios {numbers:?}"),
            });
        }
    }
    let arrays = scenarios.iter().map(|s| read_scenario(s, options.positions)).collect::<Result<Vec<_>, _>>()?;
    let mut plans = Vec::new();
    for scenario in &arrays {
        let passes = scenario.passes();
        let widest = passes.iter().map(|p| p.0.to_string().len()).max().unwrap_or(1).max(2);
        for (pass, first_row, rows) in passes {
            let sequence_id = format!("scenario{}-pass{pass:0widest$}", scenario.files.scenario);
            let path = out_dir.join(format!("{sequence_id}.mcap"));
            if recording.overwrite == Overwrite::Refuse && path.exists() {
                return Err(IoError::OutputExists { path }.into());
            }
            plans.push((scenario, pass, first_row, rows, sequence_id, path));
        }
    }
    std::fs::create_dir_all(out_dir).map_err(|source| IngestError::Os { path: out_dir.to_path_buf(), source })?;
    let total: usize = arrays.iter().map(|a| a.rows).sum();
    let mut done = 0;
    let mut out = Vec::with_capacity(plans.len());
    for (scenario, pass, first_row, rows, sequence_id, path) in plans {
        let output =
            write_pass(folder, scenario, pass, first_row..first_row + rows, &sequence_id, &path, options, recording)?;
        done += rows;
        progress(done as u64, total as u64);
        out.push(PassRecording {
            scenario: scenario.files.scenario,
            pass,
            sequence_id,
            sweeps: rows,
            beams: scenario.beams,
            calibrated: scenario.calibrated,
            output,
        });
    }
    Ok(out)
}

#[allow(clippy::too_many_arguments)] // one call site; the pieces of one pass
fn write_pass(
    folder: &Path,
    scenario: &ScenarioArrays,
    pass: i64,
    rows: std::ops::Range<usize>,
    sequence_id: &str,
    path: &Path,
    options: &DeepsenseOptions,
    recording: &RecordingOptions,
) -> Result<WriteSummary, IngestError> {
    let number = scenario.files.scenario;
    let codebook = format!("deepsense-60ghz-{}", scenario.beams);
    let period_s = options.sweep_period_ns as f64 * 1e-9;
    let extra = BTreeMap::from([
        (BEAM_SITE_KEY.to_string(), format!("deepsense-scenario{number}")),
        ("beam.scenario".to_string(), number.to_string()),
        ("beam.pass".to_string(), pass.to_string()),
        ("beam.codebook".to_string(), codebook.clone()),
        ("beam.sweep_period_s".to_string(), format!("{period_s}")),
        ("beam.first_row".to_string(), rows.start.to_string()),
        (
            "gnss.vehicle_positions".to_string(),
            format!(
                "{} ({})",
                if scenario.calibrated { "calibrated" } else { "raw" },
                file_name(&scenario.vehicle_file)
            ),
        ),
        (
            "time.note".to_string(),
            "the arrays carry no timestamps: t_ns = row index of the scenario x beam.sweep_period_s".to_string(),
        ),
    ]);
    let metadata = RecordingMetadata {
        sequence_id: sequence_id.to_string(),
        source: format!("deepsense:{}", mmtrack_io::paths::canonical(folder)),
        time_base: TimeBase::Relative,
        extra,
    };
    let mut writer = RecordingWriter::create(path, &metadata, recording)?;
    for row in rows {
        let t_ns = i64::try_from(row).ok().and_then(|r| r.checked_mul(options.sweep_period_ns)).ok_or_else(|| {
            bad(
                &scenario.files.power,
                format!("row {row}"),
                "time",
                "row x sweep period overflows 64-bit nanoseconds".into(),
            )
        })?;
        let power = scenario.power[row * scenario.beams..(row + 1) * scenario.beams].to_vec();
        // Checked in `read_scenario`: finite, non-negative, at least one beam.
        let sweep = BeamSweep::full(t_ns, power)
            .map_err(|e| bad(&scenario.files.power, format!("row {row}"), "power", e.to_string()))?;
        writer.write_beam_sweep(&sweep, Some(&codebook))?;
        writer.write_gnss_fix(&fix(t_ns, scenario.vehicle_lat_lon_deg[row]))?;
        writer.write_array_gnss_fix(&fix(t_ns, scenario.array_lat_lon_deg[row]))?;
    }
    Ok(writer.finish()?)
}

#[cfg(test)]
#[path = "deepsense_tests.rs"]
mod tests;
