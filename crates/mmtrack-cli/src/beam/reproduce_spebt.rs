//! `mmtrack reproduce spebt`: the beam-tracking experiment of Liu et al.
//! 2024 (SPEBT), Sec. IV, Table III and Fig. 5 (PAPERS.md section 1).
//!
//! The vehicle drives a real trajectory (default: the first 6388 poses of
//! the Oxford full-sequence ground truth, one slot per pose) past a base
//! station; the SPEBT EKF (`mmtrack_beam::spebt`) tracks `[|alpha|, AoD,
//! AoA]` from pose estimates that are the truth plus the paper's pose-error
//! model (`mmtrack_sim::beam::spebt_link`), one pilot per slot, and
//! re-initialises from initial access (the true channel) when its estimate
//! leaves the thresholds around the last initial access. Reported: RMSE of
//! `|alpha|` (%), AoD and AoA (deg), re-initialisations per run, against
//! Table III. That is experiment (a), `pose-error-model`; experiment (b),
//! `radar-odometry`, drives the tracker with our own radar odometry on
//! scans simulated along the same trajectory (`spebt_odometry`), as the
//! paper's pipeline does. The experiment, its published numbers and targets
//! are one TOML file (`data/reproduce/spebt.toml`, embedded).
//!
//! Runs are split into fixed chunks computed on rayon and merged in chunk
//! order, so the numbers do not depend on the thread count.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, bail};
use clap::Args;
use mmtrack_analysis::beam::spebt_plots::spebt_tracking_svg;
use mmtrack_beam::{Deviation, SpebtConfig, SpebtEkf, SpebtState};
use mmtrack_core::{Se2, StampedPose, wrap_angle_rad};
use mmtrack_io::Overwrite;
use mmtrack_io::table::{RunInfo, write_table};
use mmtrack_sim::beam::spebt_link::{SpebtLink, SpebtScenario, SpebtSlot};
use rayon::prelude::*;
use serde::Deserialize;

use super::spebt_odometry::{self, OdometryDrive};
use super::spebt_output as output;
use super::spebt_report::{self as report, README_BLOCK};
use crate::ingest::PoseFormat;
use crate::simulate;
use crate::threads::ThreadsArg;

/// The experiment, embedded so it runs from any directory.
pub const SPEBT_EXPERIMENT: &str = include_str!("../../../../data/reproduce/spebt.toml");
/// Default trajectory: the Oxford full-sequence ground truth beside the repository.
const DEFAULT_TRAJECTORY: &str = "../shared/realdata/oxford-gt-full-seq/radar_odometry.csv";
/// Experiment (a): the sequence partition of its tables.
pub(super) const POSE_ERROR_MODEL: &str = "pose-error-model";
/// Experiment (b): the sequence partition of its tables.
pub(super) const RADAR_ODOMETRY: &str = "radar-odometry";

#[derive(Args)]
pub struct SpebtArgs {
    /// Output directory (tables/, fig5_*.svg, reproduce.md).
    #[arg(short, long, default_value = "out/reproduce/spebt")]
    output: PathBuf,
    /// Replace a previous run's output directory.
    #[arg(long)]
    force: bool,
    /// Experiment file (TOML; default: the embedded data/reproduce/spebt.toml).
    #[arg(long, value_name = "EXPERIMENT.toml")]
    experiment: Option<PathBuf>,
    /// Monte Carlo runs of each experiment (default: the experiment file's, 2000 with the
    /// pose-error model and 100 with radar odometry, whose pose estimates are the same in
    /// every run).
    #[arg(long)]
    runs: Option<u64>,
    /// The CI version: 8 runs with the pose-error model, 4 with radar odometry on the
    /// first 480 slots (two minutes of
    /// driving, the first 70 s standing).
    #[arg(long)]
    quick: bool,
    /// Run only experiment (a), the pose-error model (no radar simulation).
    #[arg(long)]
    skip_odometry: bool,
    /// Trajectory to drive along (its first `slots` poses, one slot each). The default is
    /// the Oxford full-sequence ground truth (gt/radar_odometry.csv) among the real-data
    /// samples beside the repository, a path relative to the current directory: run from
    /// the repository root, or pass --trajectory.
    #[arg(long, value_name = "FILE", default_value = DEFAULT_TRAJECTORY)]
    trajectory: PathBuf,
    /// Format of --trajectory.
    #[arg(long, value_enum, default_value_t = PoseFormat::Oxford)]
    trajectory_format: PoseFormat,
    /// Replace the block `<!-- reproduce-spebt:begin -->` ... `end` in this
    /// file with the summary (checked before the run).
    #[arg(long, value_name = "README.md")]
    readme: Option<PathBuf>,
    #[command(flatten)]
    threads: ThreadsArg,
}

/// The experiment file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Experiment {
    pub seed: u64,
    pub runs: u64,
    pub quick_runs: u64,
    pub slots: usize,
    #[serde(default)]
    pub scenario: SpebtScenario,
    pub tracker: TrackerParams,
    pub odometry: OdometryParams,
    pub paper: Paper,
    pub targets: Targets,
}

/// The filter's model and thresholds.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TrackerParams {
    pub position_sigma_m: f64,
    pub yaw_sigma_deg: f64,
    pub gain_threshold: f64,
    pub angle_threshold_deg: f64,
}

/// Experiment (b): radar odometry on simulated scans.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct OdometryParams {
    pub preset: String,
    pub runs: u64,
    pub quick_runs: u64,
    pub quick_slots: usize,
}

/// The paper's numbers.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Paper {
    pub rmse_gain_pct: f64,
    pub rmse_aod_deg: f64,
    pub rmse_aoa_deg: f64,
    pub reinitialisations: u64,
    pub slots: u64,
}

/// The bounds the verdicts check.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Targets {
    pub max_rmse_aod_deg: f64,
    pub max_rmse_aoa_deg: f64,
    pub max_reinitialisation_share_pct: f64,
}

/// Runs per rayon task: fixed, so partial sums merge in the same order on
/// any number of threads.
const RUNS_PER_CHUNK: u64 = 4;
/// Chunks computed before their partial sums are merged (bounds the memory
/// of per-slot partial sums; the merge order stays the chunk order).
const CHUNKS_PER_BATCH: u64 = 32;

/// What the Monte Carlo runs of one experiment measured.
pub(super) struct ExperimentResult {
    pub runs: u64,
    /// Per slot, per component (|alpha| relative, AoD, AoA): sum over runs
    /// of the squared error.
    pub sum_squared: [Vec<f64>; 3],
    /// Per slot: runs re-initialised there.
    pub reinitialised_runs: Vec<u64>,
    /// Re-initialisations of each run, run order.
    pub reinitialisations: Vec<u64>,
    /// Re-initialisations where the |alpha|, AoD, AoA test fired.
    pub causes: [u64; 3],
    /// Run 0's estimates per slot and whether the slot re-initialised.
    pub run0: Vec<(SpebtState, bool)>,
    /// CPU seconds in the tracker (summed over threads).
    pub tracker_cpu_s: f64,
}

impl ExperimentResult {
    fn new(slots: usize) -> Self {
        Self {
            runs: 0,
            sum_squared: std::array::from_fn(|_| vec![0.0; slots]),
            reinitialised_runs: vec![0; slots],
            reinitialisations: Vec::new(),
            causes: [0; 3],
            run0: Vec::new(),
            tracker_cpu_s: 0.0,
        }
    }

    fn merge(&mut self, other: ExperimentResult) {
        for (mine, theirs) in self.sum_squared.iter_mut().zip(&other.sum_squared) {
            for (a, b) in mine.iter_mut().zip(theirs) {
                *a += b;
            }
        }
        for (a, b) in self.reinitialised_runs.iter_mut().zip(&other.reinitialised_runs) {
            *a += b;
        }
        self.runs += other.runs;
        self.reinitialisations.extend(other.reinitialisations);
        for (a, b) in self.causes.iter_mut().zip(other.causes) {
            *a += b;
        }
        if self.run0.is_empty() {
            self.run0 = other.run0;
        }
        self.tracker_cpu_s += other.tracker_cpu_s;
    }

    /// Tracked slots per run (slot 0 is the initial access).
    pub fn tracked_slots(&self) -> usize {
        self.sum_squared[0].len().saturating_sub(1)
    }

    /// RMSE over every tracked slot and run, per component (relative for
    /// |alpha|, radians for the angles).
    pub fn rmse(&self) -> [f64; 3] {
        let n = (self.tracked_slots() as f64 * self.runs as f64).max(1.0);
        self.sum_squared.each_ref().map(|sums| (sums.iter().skip(1).sum::<f64>() / n).sqrt())
    }

    /// Mean re-initialisations per run.
    pub fn mean_reinitialisations(&self) -> f64 {
        self.reinitialisations.iter().sum::<u64>() as f64 / self.reinitialisations.len().max(1) as f64
    }
}

/// One experiment: its link, where its pose estimates come from, and what
/// its runs measured.
pub(super) struct Outcome {
    /// Sequence partition of its tables (`pose-error-model`, `radar-odometry`).
    pub name: &'static str,
    pub link: SpebtLink,
    /// Experiment (b)'s drive; `None` for the pose-error model.
    pub drive: Option<OdometryDrive>,
    pub result: ExperimentResult,
    pub verdicts: Vec<report::Verdict>,
}

/// Where the tracker's pose estimates come from.
#[derive(Clone, Copy)]
pub(super) enum PoseSource<'a> {
    /// Each run's own draw of the pose-error model.
    ErrorModel,
    /// The same estimates in every run (radar odometry), one per slot.
    Fixed(&'a [Se2]),
}

pub fn run(args: &SpebtArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    crate::reproduce_common::check_start(&args.output, args.force, args.readme.as_deref(), README_BLOCK)?;
    let (source, experiment): (String, Experiment) = crate::reproduce_common::load_experiment(
        args.experiment.as_deref(),
        SPEBT_EXPERIMENT,
        "data/reproduce/spebt.toml",
    )?;
    let runs = |full: u64, quick: u64| crate::reproduce_common::run_count(args.runs, args.quick, quick, full);
    let (runs_a, runs_b) = (
        runs(experiment.runs, experiment.quick_runs)?,
        runs(experiment.odometry.runs, experiment.odometry.quick_runs)?,
    );
    anyhow::ensure!(experiment.slots >= 2, "{source}: slots = {} (need at least 2)", experiment.slots);
    let poses = load_poses(args, &experiment)?;
    let link = SpebtLink::new(&experiment.scenario, &poses)
        .with_context(|| args.trajectory.display().to_string())
        .with_context(|| format!("{source}: [scenario]"))?;
    let config = tracker_config(&experiment);

    let started = Instant::now();
    let (outcomes, threads) = args.threads.install(|| -> anyhow::Result<(Vec<Outcome>, usize)> {
        let result = monte_carlo(&link, &config, experiment.seed, runs_a, PoseSource::ErrorModel, quiet)?;
        let verdicts = report::verdicts(&experiment, &result);
        let mut outcomes = vec![Outcome { name: POSE_ERROR_MODEL, link, drive: None, result, verdicts }];
        if !args.skip_odometry {
            outcomes.push(radar_odometry(args, &experiment, &config, poses, runs_b, quiet)?);
        }
        Ok((outcomes, rayon::current_num_threads()))
    })??;
    let elapsed_s = started.elapsed().as_secs_f64();

    let context = report::Context { experiment: &experiment, trajectory: &args.trajectory, elapsed_s, threads };
    let summary = report::summary(&context, &outcomes);
    write_outputs(args, &experiment, &source, &outcomes, &summary)?;
    if let Some(readme) = &args.readme {
        crate::readme_block::replace_block(readme, README_BLOCK, &summary)?;
    }
    if !quiet {
        print!("{summary}");
        println!("\noutputs: {}", args.output.display());
    }
    let met = outcomes.iter().flat_map(|o| &o.verdicts).all(|v| v.met);
    Ok(if met { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// Experiment (b): radar odometry along the first slots of the trajectory
/// (`quick_slots` with `--quick`), then the Monte Carlo runs on its link.
fn radar_odometry(
    args: &SpebtArgs,
    experiment: &Experiment,
    config: &SpebtConfig,
    mut poses: Vec<StampedPose>,
    runs: u64,
    quiet: bool,
) -> anyhow::Result<Outcome> {
    if args.quick {
        poses.truncate(experiment.odometry.quick_slots);
    }
    let drive = spebt_odometry::drive(poses, &experiment.odometry.preset, quiet)
        .with_context(|| format!("radar odometry along {}", args.trajectory.display()))?;
    let link = SpebtLink::new(&experiment.scenario, &drive.ground_truth)
        .with_context(|| format!("the simulated drive along {}", args.trajectory.display()))?;
    // The link's positions are relative to the first true position: so are the estimates'.
    let estimates = spebt_odometry::into_link_frame(drive.ground_truth[0].parent_from_child, &drive.estimates);
    let result = monte_carlo(&link, config, experiment.seed, runs, PoseSource::Fixed(&estimates), quiet)?;
    let verdicts = report::verdicts(experiment, &result);
    Ok(Outcome { name: RADAR_ODOMETRY, link, drive: Some(drive), result, verdicts })
}

/// `runs` Monte Carlo runs on `link` in fixed chunks on rayon, merged in
/// chunk order.
pub(super) fn monte_carlo(
    link: &SpebtLink,
    config: &SpebtConfig,
    seed: u64,
    runs: u64,
    source: PoseSource<'_>,
    quiet: bool,
) -> anyhow::Result<ExperimentResult> {
    let chunks = runs.div_ceil(RUNS_PER_CHUNK);
    let label = match source {
        PoseSource::ErrorModel => "spebt: tracking, pose-error model",
        PoseSource::Fixed(_) => "spebt: tracking on radar odometry",
    };
    let bar = crate::progress::bar(runs, label, "runs", quiet);
    let mut total = ExperimentResult::new(link.len());
    for batch in (0..chunks).step_by(CHUNKS_PER_BATCH as usize) {
        let partials: Vec<ExperimentResult> = (batch..(batch + CHUNKS_PER_BATCH).min(chunks))
            .into_par_iter()
            .map(|c| {
                let range = c * RUNS_PER_CHUNK..((c + 1) * RUNS_PER_CHUNK).min(runs);
                let count = range.end - range.start;
                let chunk = run_chunk(link, config, seed, range, source);
                bar.inc(count);
                chunk
            })
            .collect::<anyhow::Result<_>>()?;
        for part in partials {
            total.merge(part);
        }
    }
    bar.finish_and_clear();
    Ok(total)
}

/// The first `slots` poses of `--trajectory`.
fn load_poses(args: &SpebtArgs, experiment: &Experiment) -> anyhow::Result<Vec<StampedPose>> {
    if !args.trajectory.exists() {
        if args.trajectory == Path::new(DEFAULT_TRAJECTORY) {
            bail!(
                "default {DEFAULT_TRAJECTORY} not found (the Oxford full-sequence ground truth among the real-data \
                 samples beside the repository; run from the repository root); pass --trajectory PATH"
            );
        }
        bail!("{}: not found (--trajectory)", args.trajectory.display());
    }
    let mut poses = simulate::read_trajectory(&args.trajectory, args.trajectory_format, None, 0)?;
    poses.truncate(experiment.slots);
    Ok(poses)
}

/// The filter's parameters: the link's Table I values and the [tracker] table.
pub(super) fn tracker_config(experiment: &Experiment) -> SpebtConfig {
    let (s, t) = (&experiment.scenario, &experiment.tracker);
    SpebtConfig {
        bs_elements: s.bs_elements,
        vehicle_elements: s.vehicle_elements,
        spacing_wavelengths: s.spacing_wavelengths,
        path_loss_exponent: s.path_loss_exponent,
        bs_x_m: s.bs_x_m,
        bs_y_m: s.bs_y_m,
        pilot_power_w: s.pilot_power_w(),
        noise_variance_w: s.noise_variance_w(),
        position_sigma_m: t.position_sigma_m,
        yaw_sigma_rad: t.yaw_sigma_deg.to_radians(),
        gain_threshold: t.gain_threshold,
        aod_threshold_rad: t.angle_threshold_deg.to_radians(),
        aoa_threshold_rad: t.angle_threshold_deg.to_radians(),
    }
}

/// Initial access: the true channel of a slot.
pub(super) fn initial_access(slot: &SpebtSlot) -> SpebtState {
    SpebtState { gain_magnitude: slot.gain.norm(), aod_rad: slot.aod_rad, aoa_rad: slot.aoa_rad }
}

fn run_chunk(
    link: &SpebtLink,
    config: &SpebtConfig,
    seed: u64,
    runs: std::ops::Range<u64>,
    source: PoseSource<'_>,
) -> anyhow::Result<ExperimentResult> {
    let mut chunk = ExperimentResult::new(link.len());
    for run_index in runs {
        let realisation = link.realise(seed, run_index);
        let poses = match source {
            PoseSource::ErrorModel => &realisation.pose_estimates[..],
            PoseSource::Fixed(poses) => poses,
        };
        anyhow::ensure!(poses.len() == link.len(), "{} pose estimates for {} slots", poses.len(), link.len());
        let started = Instant::now();
        let truth = link.slots();
        let mut ekf =
            SpebtEkf::new(config, initial_access(&truth[0]), &poses[0]).with_context(|| format!("run {run_index}"))?;
        let keep = run_index == 0;
        if keep {
            chunk.run0.push((ekf.estimate(), false));
        }
        let mut reinitialisations = 0;
        for (k, slot) in truth.iter().enumerate().skip(1) {
            let beams = ekf.predict(&poses[k]).with_context(|| format!("run {run_index}"))?;
            let pilot = link.pilot(k, beams.rx_steer_u, beams.tx_steer_u, realisation.noise[k]);
            let deviation = ekf.update(pilot).with_context(|| format!("run {run_index}"))?;
            let reinitialised = if let Deviation::Exceeded { gain, aod, aoa } = deviation {
                ekf.reinitialise(initial_access(slot))?;
                for (count, fired) in chunk.causes.iter_mut().zip([gain, aod, aoa]) {
                    *count += u64::from(fired);
                }
                chunk.reinitialised_runs[k] += 1;
                reinitialisations += 1;
                true
            } else {
                false
            };
            let estimate = ekf.estimate();
            let true_gain = slot.gain.norm();
            let errors = [
                (estimate.gain_magnitude - true_gain) / true_gain,
                wrap_angle_rad(estimate.aod_rad - slot.aod_rad),
                wrap_angle_rad(estimate.aoa_rad - slot.aoa_rad),
            ];
            for (sums, e) in chunk.sum_squared.iter_mut().zip(errors) {
                sums[k] += e * e;
            }
            if keep {
                chunk.run0.push((estimate, reinitialised));
            }
        }
        chunk.tracker_cpu_s += started.elapsed().as_secs_f64();
        chunk.reinitialisations.push(reinitialisations);
        chunk.runs += 1;
    }
    Ok(chunk)
}

fn write_outputs(
    args: &SpebtArgs,
    experiment: &Experiment,
    source: &str,
    outcomes: &[Outcome],
    summary: &str,
) -> anyhow::Result<()> {
    let staging = crate::reproduce_common::Staged::new(&args.output, "spebt")?;
    let tables = staging.path().join("tables");
    for outcome in outcomes {
        let info = RunInfo {
            config_json: serde_json::json!({
                "command": "reproduce spebt",
                "experiment_file": source,
                "experiment": outcome.name,
                "trajectory": args.trajectory.display().to_string(),
                "runs": outcome.result.runs,
                "seed": experiment.seed,
                "slots": outcome.link.len(),
                "scenario": experiment.scenario,
                "odometry_preset": outcome.drive.as_ref().map(|d| d.preset.clone()),
                "tracker": {
                    "position_sigma_m": experiment.tracker.position_sigma_m,
                    "yaw_sigma_deg": experiment.tracker.yaw_sigma_deg,
                    "gain_threshold": experiment.tracker.gain_threshold,
                    "angle_threshold_deg": experiment.tracker.angle_threshold_deg,
                },
                "mmtrack_version": env!("CARGO_PKG_VERSION"),
            })
            .to_string(),
        };
        let summary_row = output::summary_row(experiment, &args.trajectory, outcome);
        write_table(&tables, outcome.name, &[summary_row], &info, Overwrite::Refuse)?;
        write_table(&tables, outcome.name, &output::slot_rows(outcome), &info, Overwrite::Refuse)?;
        let (file, title) = match outcome.drive {
            None => ("fig5_tracking.svg", "SPEBT run 0 against the truth (Liu et al. Fig. 5): pose-error model"),
            Some(_) => ("fig5_tracking_odometry.svg", "SPEBT run 0 against the truth: poses from radar odometry"),
        };
        let svg = spebt_tracking_svg(title, &output::tracking_series(outcome))?;
        std::fs::write(staging.path().join(file), svg).context(file)?;
    }
    std::fs::write(staging.path().join("reproduce.md"), summary)?;
    let metrics: Vec<_> =
        outcomes.iter().flat_map(|o| output::metrics(&output::summary_row(experiment, &args.trajectory, o))).collect();
    crate::reproduce_all::write_metrics(staging.path(), &metrics)?;
    staging.publish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_experiment_parses_with_table_i() {
        let experiment: Experiment = toml::from_str(SPEBT_EXPERIMENT).unwrap();
        assert_eq!(experiment.scenario, SpebtScenario::default(), "[scenario] spells out Table I");
        assert_eq!((experiment.slots, experiment.paper.slots), (6388, 6388));
        let config = tracker_config(&experiment);
        assert!((config.noise_variance_w - 1e-12).abs() < 1e-24);
        assert!((config.aoa_threshold_rad.to_degrees() - 7.5).abs() < 1e-12);
    }
}
