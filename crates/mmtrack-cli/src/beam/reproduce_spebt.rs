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
use mmtrack_beam::SpebtConfig;
use mmtrack_core::StampedPose;
use mmtrack_io::Overwrite;
use mmtrack_io::table::{RunInfo, write_table};
use mmtrack_process::beam::spebt::monte_carlo::{
    ExperimentResult, POSE_ERROR_MODEL, PoseSource, RADAR_ODOMETRY, SPEBT_EXPERIMENT, SpebtExperiment as Experiment,
    into_link_frame, monte_carlo, tracker_config,
};
use mmtrack_process::beam::spebt::tables::{slot_rows, summary_row};
use mmtrack_sim::beam::spebt_link::SpebtLink;

use super::spebt_odometry::{self, OdometryDrive};
use super::spebt_output as output;
use super::spebt_report::{self as report, README_BLOCK};
use crate::ingest::PoseFormat;
use crate::progress::IndicatifProgress;
use crate::threads::ThreadsArg;
use mmtrack_process::simulate::radar::read_trajectory;

/// Default trajectory: the Oxford full-sequence ground truth beside the repository.
const DEFAULT_TRAJECTORY: &str = "../shared/realdata/oxford-gt-full-seq/radar_odometry.csv";

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
        let result = monte_carlo(
            &link,
            &config,
            experiment.seed,
            runs_a,
            PoseSource::ErrorModel,
            &IndicatifProgress::new(quiet),
        )?;
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
    let estimates = into_link_frame(drive.ground_truth[0].parent_from_child, &drive.estimates);
    let result = monte_carlo(
        &link,
        config,
        experiment.seed,
        runs,
        PoseSource::Fixed(&estimates),
        &IndicatifProgress::new(quiet),
    )?;
    let verdicts = report::verdicts(experiment, &result);
    Ok(Outcome { name: RADAR_ODOMETRY, link, drive: Some(drive), result, verdicts })
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
    let mut poses = read_trajectory(&args.trajectory, args.trajectory_format.trajectory_format(), None, 0)?;
    poses.truncate(experiment.slots);
    Ok(poses)
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
        let summary_row = summary_row(experiment, &args.trajectory, outcome.name, &outcome.link, &outcome.result);
        write_table(&tables, outcome.name, &[summary_row], &info, Overwrite::Refuse)?;
        write_table(&tables, outcome.name, &slot_rows(&outcome.link, &outcome.result), &info, Overwrite::Refuse)?;
        let (file, title) = match outcome.drive {
            None => ("fig5_tracking.svg", "SPEBT run 0 against the truth (Liu et al. Fig. 5): pose-error model"),
            Some(_) => ("fig5_tracking_odometry.svg", "SPEBT run 0 against the truth: poses from radar odometry"),
        };
        let svg = spebt_tracking_svg(title, &output::tracking_series(outcome))?;
        std::fs::write(staging.path().join(file), svg).context(file)?;
    }
    std::fs::write(staging.path().join("reproduce.md"), summary)?;
    let metrics: Vec<_> = outcomes
        .iter()
        .flat_map(|o| output::metrics(&summary_row(experiment, &args.trajectory, o.name, &o.link, &o.result)))
        .collect();
    crate::reproduce_all::write_metrics(staging.path(), &metrics)?;
    staging.publish()
}
