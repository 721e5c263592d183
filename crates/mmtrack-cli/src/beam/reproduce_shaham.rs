//! `mmtrack reproduce shaham`: the valid-tracking experiment of Shaham et al.
//! 2020, Sec. IV (PAPERS.md section 3).
//!
//! On the simulated overpass link (`mmtrack_sim::beam::overpass`), three
//! trackers run on the same Monte Carlo realisations of each scenario point
//! (SNR 0/5/10 dB at 60 km/h; 50/60/70/80 km/h at 0 dB): the proposed
//! position-velocity EKF (`pv-ekf`, the kinematic process model), the same
//! filter with eq. (14)-(15) as printed (`pv-ekf-paper-table`), and the
//! angle-state EKF of Va et al. 2016 (`angle-ekf`). Per block, the RMS over
//! runs of the transmit beam's pointing error; valid tracking ends at the
//! first block where it exceeds half the beamwidth. The experiment, its
//! published numbers and tolerances are one TOML file
//! (`data/reproduce/shaham.toml`, embedded).
//!
//! Runs are split into fixed chunks computed on rayon and merged in chunk
//! order, so the numbers do not depend on the thread count.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use mmtrack_analysis::beam::plots::{RmsCurve, rms_curves_svg};
use mmtrack_beam::valid_tracking::{RmsPerBlock, valid_tracking_blocks};
use mmtrack_beam::{
    AngleEkf, AngleEkfConfig, PilotTracker, PositionVelocityEkf, PositionVelocityEkfConfig, ProcessModel,
};
use mmtrack_io::Overwrite;
use mmtrack_io::table::{BeamRmsRow, BeamValidTrackingRow};
use mmtrack_io::table::{RunInfo, write_table};
use mmtrack_sim::beam::overpass::{OverpassRun, OverpassScenario};
use rayon::prelude::*;
use serde::Deserialize;

use super::shaham_report::{self as report, README_BLOCK};
use crate::threads::ThreadsArg;

/// The experiment, embedded so it runs from any directory.
pub const SHAHAM_EXPERIMENT: &str = include_str!("../../../../data/reproduce/shaham.toml");

#[derive(Args)]
pub struct ShahamArgs {
    /// Output directory (tables/, three SVG figures, reproduce.md).
    #[arg(short, long, default_value = "out/reproduce/shaham")]
    output: PathBuf,
    /// Replace a previous run's output directory.
    #[arg(long)]
    force: bool,
    /// Experiment file (TOML; default: the embedded data/reproduce/shaham.toml).
    #[arg(long, value_name = "EXPERIMENT.toml")]
    experiment: Option<PathBuf>,
    /// Monte Carlo runs per scenario point (default: the experiment's, 3000).
    #[arg(long)]
    runs: Option<u64>,
    /// The CI version: the experiment's quick_runs (200) runs per point.
    #[arg(long)]
    quick: bool,
    /// Replace the block `<!-- reproduce-shaham:begin -->` ... `end` in this
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
    pub blocks: usize,
    pub angle_sigma_deg: f64,
    pub tolerance: f64,
    pub paper_gain_pct: f64,
    #[serde(default)]
    pub scenario: OverpassScenario,
    pub targets: Vec<Target>,
}

/// A published valid-tracking duration of the proposed EKF.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Target {
    pub figure: String,
    pub snr_db: f64,
    pub speed_kmh: f64,
    pub paper_blocks: u64,
}

/// The trackers, in table order; the targets apply to the first.
pub(super) const TRACKERS: [&str; 3] = ["pv-ekf", "pv-ekf-paper-table", "angle-ekf"];

/// Runs per rayon task: fixed, so partial sums merge in the same order on
/// any number of threads.
const RUNS_PER_CHUNK: u64 = 25;

/// What one scenario point measured.
pub(super) struct PointResult {
    pub snr_db: f64,
    pub speed_kmh: f64,
    /// RMS AoD error per block, radians, per tracker.
    pub rms_rad: [Vec<f64>; 3],
    /// Valid-tracking blocks per tracker.
    pub valid_blocks: [Option<usize>; 3],
    /// Seconds spent in each tracker, summed over threads (wall time inside
    /// each run: other load on the machine inflates it).
    pub tracker_cpu_s: [f64; 3],
}

pub fn run(args: &ShahamArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    crate::reproduce_common::check_start(&args.output, args.force, args.readme.as_deref(), README_BLOCK)?;
    let (source, experiment): (String, Experiment) = crate::reproduce_common::load_experiment(
        args.experiment.as_deref(),
        SHAHAM_EXPERIMENT,
        "data/reproduce/shaham.toml",
    )?;
    let runs = crate::reproduce_common::run_count(args.runs, args.quick, experiment.quick_runs, experiment.runs)?;
    anyhow::ensure!(!experiment.targets.is_empty(), "{source}: no [[targets]] (nothing was done)");
    let points = scenario_points(&experiment);
    let threshold_rad = threshold_rad(&experiment.scenario).with_context(|| source.clone())?;

    let load_before = crate::bench_mpc::load_average();
    let started = Instant::now();
    let (results, threads) = args.threads.install(|| -> anyhow::Result<(Vec<PointResult>, usize)> {
        let chunks = runs.div_ceil(RUNS_PER_CHUNK);
        let bar =
            crate::progress::bar(chunks * points.len() as u64 * RUNS_PER_CHUNK, "reproduce shaham", "runs", quiet);
        let mut results = Vec::new();
        for &(snr_db, speed_kmh) in &points {
            let scenario = OverpassScenario {
                snr_db,
                initial_speed_kmh: speed_kmh,
                blocks: experiment.blocks,
                ..experiment.scenario.clone()
            };
            scenario.validate().with_context(|| format!("{source}: [scenario]"))?;
            let partials: Vec<Chunk> = (0..chunks)
                .into_par_iter()
                .map(|c| {
                    let range = c * RUNS_PER_CHUNK..((c + 1) * RUNS_PER_CHUNK).min(runs);
                    let chunk = run_chunk(&scenario, &experiment, range);
                    bar.inc(RUNS_PER_CHUNK);
                    chunk
                })
                .collect::<anyhow::Result<_>>()
                .with_context(|| format!("SNR {snr_db} dB, {speed_kmh} km/h"))?;
            let mut total = Chunk::new(experiment.blocks);
            for part in &partials {
                total.merge(part);
            }
            let rms_rad = total.rms.map(|acc| acc.rms_rad());
            let valid_blocks = [0, 1, 2].map(|t| valid_tracking_blocks(&rms_rad[t], threshold_rad));
            results.push(PointResult { snr_db, speed_kmh, rms_rad, valid_blocks, tracker_cpu_s: total.cpu_s });
        }
        bar.finish_and_clear();
        Ok((results, rayon::current_num_threads()))
    })??;
    let elapsed_s = started.elapsed().as_secs_f64();
    let load = (load_before, crate::bench_mpc::load_average());

    let verdicts = report::verdicts(&experiment, &results);
    let summary = report::summary(&experiment, &results, &verdicts, runs, threshold_rad, (elapsed_s, threads, load));
    write_outputs(args, &experiment, &source, &results, runs, threshold_rad, &summary)?;
    if let Some(readme) = &args.readme {
        crate::readme_block::replace_block(readme, README_BLOCK, &summary)?;
    }
    if !quiet {
        print!("{summary}");
        println!("\noutputs: {}", args.output.display());
    }
    Ok(if verdicts.iter().all(|v| v.met) { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// The distinct (SNR, speed) points of the targets, in first-seen order.
fn scenario_points(experiment: &Experiment) -> Vec<(f64, f64)> {
    let mut points: Vec<(f64, f64)> = Vec::new();
    for t in &experiment.targets {
        if !points.contains(&(t.snr_db, t.speed_kmh)) {
            points.push((t.snr_db, t.speed_kmh));
        }
    }
    points
}

/// Half of the half-power beamwidth at the initial AoD, radians.
fn threshold_rad(scenario: &OverpassScenario) -> anyhow::Result<f64> {
    let array = scenario.array()?;
    Ok(0.5 * array.half_power_beamwidth_rad(scenario.initial_aod_deg.to_radians().abs()))
}

/// Partial sums of a chunk of runs.
struct Chunk {
    rms: [RmsPerBlock; 3],
    cpu_s: [f64; 3],
}

impl Chunk {
    fn new(blocks: usize) -> Self {
        Self { rms: std::array::from_fn(|_| RmsPerBlock::new(blocks + 1)), cpu_s: [0.0; 3] }
    }

    fn merge(&mut self, other: &Chunk) {
        for t in 0..3 {
            self.rms[t].merge(&other.rms[t]);
            self.cpu_s[t] += other.cpu_s[t];
        }
    }
}

fn run_chunk(
    scenario: &OverpassScenario,
    experiment: &Experiment,
    runs: std::ops::Range<u64>,
) -> anyhow::Result<Chunk> {
    let mut chunk = Chunk::new(scenario.blocks);
    for run_index in runs {
        let run = scenario.realise(experiment.seed, run_index)?;
        for (t, name) in TRACKERS.iter().enumerate() {
            let started = Instant::now();
            let errors = match *name {
                "pv-ekf" => track(scenario, &run, &mut pv_ekf(scenario, &run, ProcessModel::Kinematic)?),
                "pv-ekf-paper-table" => track(scenario, &run, &mut pv_ekf(scenario, &run, ProcessModel::PaperTable)?),
                _ => track(scenario, &run, &mut angle_ekf(scenario, &run, experiment.angle_sigma_deg)?),
            }
            .with_context(|| format!("{name}, run {run_index}"))?;
            chunk.cpu_s[t] += started.elapsed().as_secs_f64();
            chunk.rms[t].add_run(&errors);
        }
    }
    Ok(chunk)
}

fn pv_ekf(scenario: &OverpassScenario, run: &OverpassRun, model: ProcessModel) -> anyhow::Result<PositionVelocityEkf> {
    let start = run.states()[0];
    let config = PositionVelocityEkfConfig {
        height_m: scenario.height_m,
        elements: scenario.elements,
        block_s: scenario.block_s,
        rho: scenario.rho,
        speed_sigma_mps: scenario.speed_sigma_mps,
        noise_variance: scenario.noise_variance(),
        process_model: model,
    };
    Ok(PositionVelocityEkf::new(&config, start.distance_m, start.speed_mps, start.alpha)?)
}

fn angle_ekf(scenario: &OverpassScenario, run: &OverpassRun, angle_sigma_deg: f64) -> anyhow::Result<AngleEkf> {
    let start = run.states()[0];
    let config = AngleEkfConfig {
        elements: scenario.elements,
        rho: scenario.rho,
        angle_sigma_rad: angle_sigma_deg.to_radians(),
        noise_variance: scenario.noise_variance(),
    };
    let h = scenario.height_m;
    Ok(AngleEkf::new(&config, start.aoa_rad(h), start.aod_rad(h), start.alpha)?)
}

/// Pointing error of the transmit beam per block (block 0: the channel
/// estimate, error 0), radians.
fn track(scenario: &OverpassScenario, run: &OverpassRun, tracker: &mut impl PilotTracker) -> anyhow::Result<Vec<f64>> {
    let mut errors = Vec::with_capacity(scenario.blocks + 1);
    errors.push(0.0);
    for block in 1..=scenario.blocks {
        let beams = tracker.predict()?;
        tracker.update(run.pilot(block, beams.rx_steer_u, beams.tx_steer_u))?;
        errors.push(beams.tx_angle_rad() - run.states()[block].aod_rad(scenario.height_m));
    }
    Ok(errors)
}

fn write_outputs(
    args: &ShahamArgs,
    experiment: &Experiment,
    source: &str,
    results: &[PointResult],
    runs: u64,
    threshold_rad: f64,
    summary: &str,
) -> anyhow::Result<()> {
    let staging = crate::reproduce_common::Staged::new(&args.output, "shaham")?;
    let tables = staging.path().join("tables");
    let info = RunInfo {
        config_json: serde_json::json!({
            "command": "reproduce shaham",
            "experiment": source,
            "runs": runs,
            "seed": experiment.seed,
            "blocks": experiment.blocks,
            "angle_sigma_deg": experiment.angle_sigma_deg,
            "mmtrack_version": env!("CARGO_PKG_VERSION"),
        })
        .to_string(),
    };
    let mut rms_rows = Vec::new();
    let mut valid_rows = Vec::new();
    for point in results {
        for (t, tracker) in TRACKERS.iter().enumerate() {
            for (block, rms) in point.rms_rad[t].iter().enumerate() {
                rms_rows.push(BeamRmsRow {
                    tracker: tracker.to_string(),
                    snr_db: point.snr_db,
                    speed_kmh: point.speed_kmh,
                    block: block as u64,
                    rms_aod_deg: rms.to_degrees(),
                });
            }
            let paper = experiment
                .targets
                .iter()
                .filter(|g| t == 0 && g.snr_db == point.snr_db && g.speed_kmh == point.speed_kmh)
                .map(|g| g.paper_blocks)
                .next();
            valid_rows.push(BeamValidTrackingRow {
                tracker: tracker.to_string(),
                snr_db: point.snr_db,
                speed_kmh: point.speed_kmh,
                runs,
                blocks_simulated: experiment.blocks as u64,
                threshold_deg: threshold_rad.to_degrees(),
                valid_blocks: point.valid_blocks[t].map(|b| b as u64),
                paper_blocks: paper,
            });
        }
    }
    write_table(&tables, "shaham", &rms_rows, &info, Overwrite::Refuse)?;
    write_table(&tables, "shaham", &valid_rows, &info, Overwrite::Refuse)?;
    for (file, title, curves) in figures(results) {
        let svg = rms_curves_svg(title, &curves, threshold_rad.to_degrees())?;
        std::fs::write(staging.path().join(file), svg).with_context(|| file.to_string())?;
    }
    std::fs::write(staging.path().join("reproduce.md"), summary)?;
    crate::reproduce_all::write_metrics(staging.path(), &report::metrics(experiment, results))?;
    staging.publish()
}

/// The paper's three figures: the proposed EKF over SNR at 60 km/h (Fig. 2),
/// over speed at 0 dB (Fig. 3), and both EKFs at 0 dB, 60 km/h (Fig. 4).
fn figures(results: &[PointResult]) -> Vec<(&'static str, &'static str, Vec<RmsCurve>)> {
    let curve = |p: &PointResult, t: usize, label: String| RmsCurve {
        label,
        rms_deg: p.rms_rad[t].iter().map(|v| v.to_degrees()).collect(),
    };
    let sorted = |filter: &dyn Fn(&PointResult) -> bool, key: &dyn Fn(&PointResult) -> f64| {
        let mut points: Vec<&PointResult> = results.iter().filter(|p| filter(p)).collect();
        points.sort_by(|a, b| key(a).total_cmp(&key(b)));
        points
    };
    let by_snr = sorted(&|p| p.speed_kmh == 60.0, &|p| p.snr_db)
        .into_iter()
        .map(|p| curve(p, 0, format!("pv-ekf, SNR {} dB", p.snr_db)))
        .collect();
    let by_speed = sorted(&|p| p.snr_db == 0.0, &|p| p.speed_kmh)
        .into_iter()
        .map(|p| curve(p, 0, format!("pv-ekf, {} km/h", p.speed_kmh)))
        .collect();
    let comparison = results
        .iter()
        .filter(|p| p.snr_db == 0.0 && p.speed_kmh == 60.0)
        .flat_map(|p| (0..3).map(move |t| curve(p, t, TRACKERS[t].to_string())))
        .collect();
    vec![
        ("fig2_rms_by_snr.svg", "RMS AoD error, 60 km/h (Shaham et al. Fig. 2)", by_snr),
        ("fig3_rms_by_speed.svg", "RMS AoD error, SNR 0 dB (Fig. 3)", by_speed),
        ("fig4_rms_trackers.svg", "RMS AoD error, SNR 0 dB, 60 km/h: trackers (Fig. 4)", comparison),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_experiment_parses_and_has_the_papers_points() {
        let experiment: Experiment = toml::from_str(SHAHAM_EXPERIMENT).unwrap();
        assert_eq!(experiment.runs, 3000);
        assert_eq!(scenario_points(&experiment).len(), 6);
        let threshold = threshold_rad(&experiment.scenario).unwrap().to_degrees();
        assert!((threshold - 4.51).abs() < 0.01, "{threshold}");
    }
}
