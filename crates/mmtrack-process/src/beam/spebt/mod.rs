//! The SPEBT beam tracker (`mmtrack process beam --tracker spebt`; Liu et
//! al. 2024) along a recording's ground-truth trajectory, driven by pose
//! estimates.
//!
//! The link (`mmtrack_sim::beam::spebt_link`, the paper's Table I unless
//! `--link` says otherwise) needs the true trajectory: the pilots are
//! simulated along the recording's ground truth. The tracker predicts its
//! beams from pose estimates, which are either
//!
//! - `--odometry <tables>`: the recording's sequence in an `odometry` table
//!   (from `mmtrack process odometry`; directly under `<tables>`, else in the
//!   `run=<ID>/` folder of `--odometry-run` or the only one holding it,
//!   `find_odometry_table`), one slot per estimate, the ground
//!   truth interpolated at the estimates' times, the estimates moved into the
//!   ground truth's frame at the first slot (as `reproduce spebt` experiment
//!   (b) does, `mmtrack_reproduce::spebt::drive`); or
//! - without `--odometry`: the ground truth plus the paper's pose-error model
//!   (eq. (23), `--sigma-r-m`, `--sigma-theta-deg`, drawn per `--seed` and run),
//!   one slot per ground-truth pose (`reproduce spebt` experiment (a)).
//!
//! Both go through `reproduce spebt`'s Monte Carlo (`--runs` realisations of
//! the receiver noise, and of the pose errors without `--odometry`) with the
//! paper's re-initialisation rule, and write that command's tables, one
//! partition per recording: `spebt_per_slot` (truth, run 0's estimate, RMSE
//! over runs per slot) and `spebt_summary` (RMSE of |alpha|, AoD and AoA,
//! re-initialisations).

pub mod monte_carlo;
pub mod tables;

use std::path::{Path, PathBuf};

use anyhow::{Context, bail, ensure};
use mmtrack_core::progress::Progress;
use mmtrack_core::{OdometryEstimate, Se2, StampedPose, interpolate_pose};
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase};
use mmtrack_io::table::{ODOMETRY, RunInfo, read_table, table_path};
use mmtrack_io::table::{SPEBT_PER_SLOT, SPEBT_SUMMARY, SpebtSummaryRow, TableWriteSummary};
use mmtrack_io::{RecordingEvent, RecordingReader};
use mmtrack_sim::beam::spebt_link::{SpebtLink, SpebtScenario};
use serde::Deserialize;

use self::monte_carlo::{
    ExperimentResult, POSE_ERROR_MODEL, PoseSource, RADAR_ODOMETRY, SPEBT_EXPERIMENT, SpebtExperiment, TrackerParams,
    into_link_frame, into_truth_frame, monte_carlo, tracker_config,
};
use crate::output::{RunDir, is_run_id, run_ids_in};

/// The options of [`process_spebt`] (`--tracker spebt`).
#[derive(Debug, Clone, Default)]
pub struct SpebtOptions {
    /// Table directory of `process odometry` whose `odometry` table (the
    /// recording's sequence) drives the tracker: the one directly under it,
    /// else the one in its only `run=<ID>/` folder holding it. Without it,
    /// the ground truth plus the pose-error model drives the tracker.
    pub odometry: Option<PathBuf>,
    /// Read the odometry table of this run (`<odometry>/run=<ID>/`).
    pub odometry_run: Option<String>,
    /// The link and tracker: a TOML file with `[scenario]` and `[tracker]`
    /// tables as in `data/reproduce/spebt.toml` (default: that file's).
    pub link: Option<PathBuf>,
    /// Pose-error model sigma_r, metres per coordinate (eq. (23)).
    pub sigma_r_m: Option<f64>,
    /// Pose-error model sigma_theta, degrees.
    pub sigma_theta_deg: Option<f64>,
    /// Seed of the receiver noise and the pose errors (default: the file's).
    pub seed: Option<u64>,
    /// Monte Carlo runs (default 1).
    pub runs: Option<u64>,
}

impl SpebtOptions {
    /// The options given, by flag name (the sweep trackers refuse them).
    #[must_use]
    pub fn given(&self) -> Vec<&'static str> {
        [
            ("--odometry", self.odometry.is_some()),
            ("--odometry-run", self.odometry_run.is_some()),
            ("--link", self.link.is_some()),
            ("--sigma-r-m", self.sigma_r_m.is_some()),
            ("--sigma-theta-deg", self.sigma_theta_deg.is_some()),
            ("--seed", self.seed.is_some()),
            ("--runs", self.runs.is_some()),
        ]
        .into_iter()
        .filter_map(|(flag, given)| given.then_some(flag))
        .collect()
    }
}

/// The `--link` file: `[scenario]` and `[tracker]` of the experiment file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LinkFile {
    scenario: Option<SpebtScenario>,
    tracker: Option<TrackerParams>,
}

/// A recording's sequence id and ground truth.
struct TruthRecording {
    path: PathBuf,
    sequence_id: String,
    time_base: TimeBase,
    ground_truth: Vec<StampedPose>,
}

fn read_truth(path: &Path) -> anyhow::Result<TruthRecording> {
    let mut reader = RecordingReader::open(path)?;
    let mut ground_truth = Vec::new();
    for event in reader.by_ref() {
        if let RecordingEvent::Pose { stream: PoseStream::GroundTruth, pose } = event? {
            ground_truth.push(pose);
        }
    }
    let metadata = reader.metadata().cloned().unwrap_or_default();
    let (sequence_id, time_base) = RecordingMetadata::from_map(&metadata)
        .map(|m| (m.sequence_id, m.time_base))
        .with_context(|| format!("{}: no mmtrack recording metadata (sequence id)", path.display()))?;
    if ground_truth.len() < 2 {
        bail!(
            "{}: {} ground-truth poses; spebt simulates the link along the true trajectory and needs the recording's \
             ground truth (e.g. from `mmtrack simulate radar` or `mmtrack ingest oxford`)",
            path.display(),
            ground_truth.len()
        );
    }
    if let Some(i) = ground_truth.windows(2).position(|p| p[1].t_ns <= p[0].t_ns) {
        bail!(
            "{}: ground-truth pose {}: time {} ns does not increase (previous {} ns)",
            path.display(),
            i + 1,
            ground_truth[i + 1].t_ns,
            ground_truth[i].t_ns
        );
    }
    Ok(TruthRecording { path: path.to_path_buf(), sequence_id, time_base, ground_truth })
}

/// The file of the recording's sequence of the `odometry` table under `dir`
/// (`--odometry`): in `dir/run=<ID>/` for `run` (`--odometry-run`), else
/// directly under `dir`, else in the only `run=<ID>/` folder of `dir` that
/// holds it. Several such runs are refused, naming their ids.
fn find_odometry_table(dir: &Path, run: Option<&str>, recording: &TruthRecording) -> anyhow::Result<PathBuf> {
    let sequence = &recording.sequence_id;
    let in_run = |id: &str| table_path(&dir.join(format!("run={id}")), ODOMETRY.name, sequence);
    let mut holding = Vec::new();
    for id in run_ids_in(dir)? {
        if in_run(&id)?.exists() {
            holding.push(id);
        }
    }
    let listed = if holding.is_empty() { "none".to_string() } else { holding.join(", ") };
    if let Some(id) = run {
        ensure!(
            is_run_id(id),
            "--odometry-run '{id}': not a valid run id (letters, digits, '-', '_', '.'; it names the directory \
             run=<ID> under {})",
            dir.display()
        );
        let file = in_run(id)?;
        ensure!(
            file.exists(),
            "{}: not found; --odometry-run {id}: run {id} has no `{}` table of sequence {sequence} (the recording {}); \
             runs under {} holding one: {listed}",
            file.display(),
            ODOMETRY.name,
            recording.path.display(),
            dir.display()
        );
        return Ok(file);
    }
    let file = table_path(dir, ODOMETRY.name, sequence)?;
    if file.exists() {
        return Ok(file);
    }
    match &holding[..] {
        [id] => Ok(in_run(id)?),
        [] => bail!(
            "{}: not found, nor in a run=<ID>/ folder of {}; --odometry needs the `{}` table of sequence {sequence} \
             (the recording {}), as written by `mmtrack process odometry`",
            file.display(),
            dir.display(),
            ODOMETRY.name,
            recording.path.display()
        ),
        _ => bail!(
            "{}: {} runs hold an `{}` table of sequence {sequence} (the recording {}), run ids {listed}; pick one with \
             --odometry-run <ID>",
            dir.display(),
            holding.len(),
            ODOMETRY.name,
            recording.path.display()
        ),
    }
}

/// The recording's sequence of the `odometry` table `file`, checked:
/// finite rows, increasing times without gaps (a step above `max_step_ratio`
/// times the median), inside the ground truth's time span.
fn read_estimates(
    file: &Path,
    recording: &TruthRecording,
    max_step_ratio: f64,
) -> anyhow::Result<Vec<OdometryEstimate>> {
    let rows = read_table::<OdometryEstimate>(file)?;
    let name = file.display();
    ensure!(rows.len() >= 2, "{name}: {} rows; need at least 2 estimates to track", rows.len());
    for (row, e) in rows.iter().enumerate() {
        let p = &e.world_from_vehicle;
        for (field, value) in [("x_m", p.x_m), ("y_m", p.y_m), ("yaw_rad", p.yaw_rad)] {
            ensure!(
                value.is_finite(),
                "{name}: row {row} (t_ns {}): {field} is {value}; estimates must be finite",
                e.t_ns
            );
        }
        if row > 0 && e.t_ns <= rows[row - 1].t_ns {
            bail!("{name}: row {row}: t_ns {} does not increase (previous row {} ns)", e.t_ns, rows[row - 1].t_ns);
        }
    }
    let mut steps: Vec<i64> = rows.windows(2).map(|w| w[1].t_ns - w[0].t_ns).collect();
    steps.sort_unstable();
    let median_ns = steps[steps.len() / 2] as f64;
    for (i, pair) in rows.windows(2).enumerate() {
        let step_ns = (pair[1].t_ns - pair[0].t_ns) as f64;
        ensure!(
            step_ns <= max_step_ratio * median_ns,
            "{name}: row {}: t_ns gap of {:.3} s after the previous row, {:.1} times the median step of {:.3} s (more \
             than max_step_ratio = {max_step_ratio}); the tracker has one slot per estimate and cannot span a gap",
            i + 1,
            step_ns * 1e-9,
            step_ns / median_ns,
            median_ns * 1e-9
        );
    }
    let truth = &recording.ground_truth;
    let (first, last) = (truth[0].t_ns, truth[truth.len() - 1].t_ns);
    if let Some((row, e)) = rows.iter().enumerate().find(|(_, e)| e.t_ns < first || e.t_ns > last) {
        bail!(
            "{name}: row {row}: t_ns {} lies outside the ground truth's time span [{first}, {last}] ns of {}; the \
             link needs the true pose at every estimate",
            e.t_ns,
            recording.path.display()
        );
    }
    Ok(rows)
}

/// The ground truth at `t_ns` (inside its span): the pose with that time,
/// else interpolated between its neighbours.
fn truth_at(truth: &[StampedPose], t_ns: i64) -> StampedPose {
    let after = truth.partition_point(|p| p.t_ns < t_ns).min(truth.len() - 1);
    let parent_from_child = if truth[after].t_ns == t_ns || after == 0 {
        truth[after].parent_from_child
    } else {
        interpolate_pose(&truth[after - 1], &truth[after], t_ns)
    };
    StampedPose { t_ns, parent_from_child }
}

/// The experiment: the embedded `reproduce spebt` file with the `--link`
/// file's tables and the flags over it.
fn experiment(options: &SpebtOptions) -> anyhow::Result<(SpebtExperiment, String)> {
    let mut experiment: SpebtExperiment =
        toml::from_str(SPEBT_EXPERIMENT).context("embedded data/reproduce/spebt.toml")?;
    let mut source = "embedded data/reproduce/spebt.toml".to_string();
    if let Some(path) = &options.link {
        let text = mmtrack_io::paths::read_config_text(path)?;
        let link: LinkFile = toml::from_str(&text).with_context(|| path.display().to_string())?;
        if let Some(scenario) = link.scenario {
            experiment.scenario = scenario;
        }
        if let Some(tracker) = link.tracker {
            experiment.tracker = tracker;
        }
        source = crate::provenance::canonical(path);
    }
    if let Some(sigma_r_m) = options.sigma_r_m {
        // A position error beyond a kilometre is no pose estimate; squared, 1e300 overflowed the filter.
        if !(0.0..=1000.0).contains(&sigma_r_m) {
            let message = format!("--sigma-r-m {sigma_r_m}: need a value in [0, 1000] m");
            return Err(mmtrack_core::error::UsageError(message).into());
        }
        experiment.scenario.position_sigma_m = sigma_r_m;
        experiment.tracker.position_sigma_m = sigma_r_m;
    }
    if let Some(sigma_theta_deg) = options.sigma_theta_deg {
        if !(0.0..=180.0).contains(&sigma_theta_deg) {
            let message = format!("--sigma-theta-deg {sigma_theta_deg}: need a value in [0, 180] deg");
            return Err(mmtrack_core::error::UsageError(message).into());
        }
        experiment.scenario.yaw_sigma_deg = sigma_theta_deg;
        experiment.tracker.yaw_sigma_deg = sigma_theta_deg;
    }
    experiment.scenario.validate().with_context(|| format!("{source}: [scenario]"))?;
    if let Some(seed) = options.seed {
        experiment.seed = seed;
    }
    Ok((experiment, source))
}

/// One recording's result of [`process_spebt`].
#[derive(Debug, Clone)]
pub struct SpebtRecordingResult {
    /// The recording's sequence id (the partition written).
    pub sequence_id: String,
    /// Where the pose estimates came from ([`POSE_ERROR_MODEL`] or [`RADAR_ODOMETRY`]).
    pub pose_source: &'static str,
    /// The odometry table read, with `odometry`.
    pub odometry_file: Option<PathBuf>,
    /// The `spebt_summary` row written.
    pub summary: SpebtSummaryRow,
}

/// What [`process_spebt`] did.
#[derive(Debug, Clone)]
pub struct SpebtOutput {
    /// Per recording, in the order given.
    pub recordings: Vec<SpebtRecordingResult>,
    /// Each table written, with its row count.
    pub written: Vec<TableWriteSummary>,
    /// The run directory written.
    pub dir: PathBuf,
}

/// `mmtrack process beam --tracker spebt`: SPEBT on each recording, one
/// partition of `spebt_summary` and `spebt_per_slot` per recording.
///
/// `out` is the run directory ([`crate::output::OutputOptions::resolve`]):
/// refusals look there and the tables go there. Every recording and odometry
/// table is found and checked before any work.
///
/// # Errors
/// An existing table (without `force`), a recording without usable ground
/// truth, a missing or bad odometry table, a bad link file or option, or a
/// table that cannot be written.
pub fn process_spebt(
    recordings: &[PathBuf],
    out: &RunDir,
    options: &SpebtOptions,
    progress: &dyn Progress,
) -> anyhow::Result<SpebtOutput> {
    let (experiment, link_source) = experiment(options)?;
    let runs = options.runs.unwrap_or(1);
    let limit = mmtrack_core::limits::MONTE_CARLO_RUNS;
    if !(runs >= 1 && limit.allows_count(runs)) {
        let message = format!("--runs {runs}: expected {} (nothing was done)", limit.expected);
        return Err(mmtrack_core::error::UsageError(message).into());
    }
    let config = tracker_config(&experiment);
    let recordings = recordings.iter().map(|p| read_truth(p)).collect::<anyhow::Result<Vec<_>>>()?;
    super::refuse_repeated_sequences(recordings.iter().map(|r| (r.sequence_id.as_str(), r.path.as_path())))?;
    for r in &recordings {
        out.refuse_existing(&[SPEBT_SUMMARY.name, SPEBT_PER_SLOT.name], &r.sequence_id)?;
    }
    // Every odometry table found before any work.
    let odometry_files = recordings
        .iter()
        .map(|r| {
            let dir = options.odometry.as_deref();
            dir.map(|dir| find_odometry_table(dir, options.odometry_run.as_deref(), r)).transpose()
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut results: Vec<(&TruthRecording, Option<PathBuf>, &'static str, SpebtLink, ExperimentResult)> = Vec::new();
    for (recording, odometry_file) in recordings.iter().zip(odometry_files) {
        let (name, slots, estimates, odometry_file) = match odometry_file {
            Some(file) => {
                let rows = read_estimates(&file, recording, experiment.scenario.max_step_ratio)?;
                let slots: Vec<StampedPose> = rows.iter().map(|e| truth_at(&recording.ground_truth, e.t_ns)).collect();
                let first_truth = slots[0].parent_from_child;
                let raw: Vec<Se2> = rows.iter().map(|e| e.world_from_vehicle).collect();
                let estimates = into_link_frame(first_truth, &into_truth_frame(first_truth, &raw));
                (RADAR_ODOMETRY, slots, Some(estimates), Some(file))
            }
            None => (POSE_ERROR_MODEL, recording.ground_truth.clone(), None, None),
        };
        let link = SpebtLink::new(&experiment.scenario, &slots)
            .with_context(|| format!("{}: ground truth", recording.path.display()))
            .with_context(|| format!("{link_source}: [scenario]"))?;
        let source = estimates.as_deref().map_or(PoseSource::ErrorModel, PoseSource::Fixed);
        let result = monte_carlo(&link, &config, experiment.seed, runs, source, progress)
            .with_context(|| recording.path.display().to_string())?;
        results.push((recording, odometry_file, name, link, result));
    }
    let mut staged = out.tables();
    let mut reports = Vec::new();
    for (recording, odometry_file, name, link, result) in results {
        let info = RunInfo {
            config_json: serde_json::json!({
                "command": "process beam",
                "tracker": "spebt",
                "recording": crate::provenance::canonical(&recording.path),
                "odometry": odometry_file.as_deref().map(crate::provenance::canonical),
                "inputs": crate::provenance::input_files(&[Some(recording.path.as_path()), odometry_file.as_deref()].into_iter().flatten().collect::<Vec<_>>())?,
                "pose_source": name,
                "link_file": link_source,
                "runs": result.runs,
                "seed": experiment.seed,
                "slots": link.len(),
                "scenario": experiment.scenario,
                "tracker_params": {
                    "position_sigma_m": experiment.tracker.position_sigma_m,
                    "yaw_sigma_deg": experiment.tracker.yaw_sigma_deg,
                    "gain_threshold": experiment.tracker.gain_threshold,
                    "angle_threshold_deg": experiment.tracker.angle_threshold_deg,
                },
                "run_id": out.run_id(),
                "mmtrack_version": env!("CARGO_PKG_VERSION"),
            })
            .to_string(),
            time_base: recording.time_base.into(),
            frame: None,
        };
        let summary = tables::summary_row(&experiment, &recording.path, name, &link, &result);
        staged.write(&recording.sequence_id, std::slice::from_ref(&summary), &info)?;
        staged.write(&recording.sequence_id, &tables::slot_rows(&link, &result), &info)?;
        reports.push(SpebtRecordingResult {
            sequence_id: recording.sequence_id.clone(),
            pose_source: name,
            odometry_file,
            summary,
        });
    }
    Ok(SpebtOutput { recordings: reports, written: staged.publish()?, dir: out.path.clone() })
}
