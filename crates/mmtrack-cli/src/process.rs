//! `mmtrack process <pipeline>`: the arguments of each pipeline, one call
//! of `mmtrack_process` each, and the summary printed after it.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::bail;
use clap::{Args, Subcommand};
use mmtrack_core::words::counted_as;
use mmtrack_io::table::TableWriteSummary;
use mmtrack_odometry::OdometryConfig;
use mmtrack_process::{mpc, odometry, poses, slam};

use crate::output_args::OutputArgs;
use crate::progress::IndicatifProgress;
use crate::threads::ThreadsArg;

#[derive(Args)]
pub struct ProcessArgs {
    #[command(subcommand)]
    pipeline: Pipeline,
}

#[derive(Subcommand)]
enum Pipeline {
    /// Radar odometry (Fast-CFEAR / CFEAR) on the recording's radar scans.
    ///
    /// Writes, under the output directory, `odometry/sequence=<id>/part-0.parquet`
    /// (one pose per scan with registration diagnostics), `odometry_timing/...`
    /// (time per stage; not deterministic, so kept apart) and, when the
    /// recording has ground truth, `ground_truth/...`. Then run
    /// `mmtrack analyze <out>` for drift and error metrics, or
    /// `mmtrack export --format tum|kitti|boreas <out>` for evo / the KITTI
    /// devkit / pyboreas.
    #[command(verbatim_doc_comment)]
    Odometry(OdometryArgs),
    /// The recording's own estimate (/estimate/pose) and ground truth as tables, to score another odometry.
    ///
    /// Writes `poses/sequence=<id>/part-0.parquet` (the estimate: /odom of a ROS 2 bag
    /// from `mmtrack ingest ros2`, a CSV from `mmtrack ingest poses --estimate`) and,
    /// when the recording has it, `ground_truth/...`. `mmtrack analyze <out>` scores it
    /// as our radar odometry (drift per length, RPE, ATE); `--run-id` compares runs.
    #[command(verbatim_doc_comment)]
    Poses(RecordingArgs),
    /// The recording's radar scans, CIR snapshots, GNSS fixes and ground truth as tables, for pandas / polars / DuckDB.
    ///
    /// Writes those it has, one row per message as recorded (memory stays bounded): `radar_scans`,
    /// `cir_snapshots`, `gnss_fixes`, `ground_truth` (`<table>/sequence=<id>/part-0.parquet`; schemas/).
    #[command(verbatim_doc_comment)]
    Raw(RecordingArgs),
    /// Multipath-component detection and tracking (Mahler et al. 2017) on the recording's CIR snapshots.
    ///
    /// Writes, under the output directory, per sequence partition:
    /// `mpc_detections` (one row per detected MPC), `mpc_tracks` (short-term
    /// tracks within a set), `mpc_long_term` (full-lifetime tracks related
    /// across sets, with their confidence class chi), `mpc_sets` (per-set
    /// counts and channel gains), with `--gmphd` `mpc_tracks_gmphd` (the
    /// GM-PHD baseline on the same detections), and when the recording has
    /// them `mpc_truth` and `ground_truth_tx` / `ground_truth_rx`.
    /// Several TX/RX links: each is its own partition `<sequence>-tx<T>-rx<R>`
    /// unless `--link T:R` picks one. Then run `mmtrack analyze <out>`.
    #[command(verbatim_doc_comment)]
    Mpc(MpcArgs),
    /// Beam trackers: sweep trackers on measured beam sweeps, or SPEBT on a recording with ground truth.
    ///
    /// Sweep trackers (window, gnss-window, last-full-sweep, gnss-map) on
    /// recordings of measured beam sweeps (e.g. from `mmtrack ingest beams`)
    /// write `beam_sweeps_tracked/sequence=<id>/part-0.parquet` per
    /// recording: per sweep and tracker the chosen and best beam, beams
    /// measured, re-initialisation and received-power loss. The GNSS policies
    /// (gnss-window, gnss-map) fit the beam map leave-one-pass-out over the
    /// recordings of each site given together (at least two). Then run
    /// `mmtrack analyze <out>`.
    /// `--tracker spebt` simulates the SPEBT link along a recording's ground
    /// truth and tracks it with poses from `--odometry <tables>` (from
    /// `mmtrack process odometry`) or from the ground truth plus the
    /// pose-error model; it writes `spebt_per_slot` and `spebt_summary`.
    #[command(verbatim_doc_comment)]
    Beam(crate::process_beam::BeamArgs),
    /// 5G mmWave SLAM (Kim et al. 2018) on the recording's per-epoch path measurements.
    ///
    /// Runs the particle belief-propagation SLAM filter over /slam/paths (from
    /// `mmtrack simulate slam`) and writes per sequence partition: `slam_ue`
    /// (UE estimate per epoch, beside the truth when the recording has it),
    /// `slam_map` (every map source after every epoch: bs, va, sp or
    /// unconfirmed, position, spread, confirmation), `slam_associations` (the
    /// source each path was given, beside its true source) and
    /// `slam_true_sources`. Unusable paths are skipped and counted, or refused
    /// with --strict. Then run `mmtrack analyze <out>`.
    #[command(verbatim_doc_comment)]
    Slam(SlamArgs),
    /// A campaign: the ingest, process and analyze tasks of a manifest, each an independent task.
    ///
    /// The manifest (TOML) lists `[[task]]` tables, each with `args`: the
    /// words after `mmtrack process` (default), `mmtrack ingest` or
    /// `mmtrack analyze` (`step = "ingest"` / `"analyze"`), e.g.
    /// `args = ["odometry", "runs/a.mcap", "--preset", "cfear"]`. Process
    /// tasks get `-o <output>`; ingest and analyze tasks give their own -o;
    /// `{tables}` stands for the output. `name` and `needs = ["<name>", ..]`
    /// order tasks: a task runs after those it needs (ingest, then process,
    /// then analyze; cycles and unknown keys are refused).
    /// Tasks run level by level as independent tasks on the thread pool; the
    /// tables do not depend on the order or the thread count. A failed task
    /// is reported, the tasks needing it are not run, the others finish
    /// (exit 1). `--skip-existing` resumes an interrupted campaign.
    /// `--task N` runs one task (a cluster job: examples/ray_process.py,
    /// examples/slurm_campaign.sh); `--print-commands`, `--print-tasks` and
    /// `--print-levels` show the tasks; `--from <dataset> --layout ...`
    /// writes a manifest from a dataset folder. See docs/campaigns.md.
    #[command(verbatim_doc_comment)]
    Manifest(crate::manifest::ManifestArgs),
}

#[derive(Args)]
pub struct OdometryArgs {
    /// Recording with radar scans (from `mmtrack ingest` or `mmtrack simulate`); not needed with `--print-config`.
    #[arg(required_unless_present = "print_config")]
    pub recording: Option<PathBuf>,
    /// Output table directory (created if missing); not needed with `--print-config`.
    #[arg(short, long, required_unless_present = "print_config")]
    pub output: Option<PathBuf>,
    /// Parameter preset: `fast-cfear` (Liu et al., SPEBT Table I: scan-to-scan) or
    /// `cfear` (CFEAR-3: keyframe submap, motion compensation, re-association).
    #[arg(long, default_value = "cfear", value_parser = clap::builder::PossibleValuesParser::new(OdometryConfig::PRESETS))]
    pub preset: String,
    /// TOML file overriding single fields of the preset (see `--print-config`).
    #[arg(long, value_name = "TOML")]
    pub config: Option<PathBuf>,
    /// Print the effective configuration (the preset with `--config` on top) as TOML and exit.
    #[arg(long)]
    pub print_config: bool,
    #[command(flatten)]
    pub output_args: OutputArgs,
    #[command(flatten)]
    pub threads: ThreadsArg,
}

#[derive(Args)]
pub struct RecordingArgs {
    /// Recording (from `mmtrack ingest` or `mmtrack simulate`).
    pub recording: PathBuf,
    /// Output table directory (created if missing).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub output_args: OutputArgs,
}

#[derive(Args)]
pub struct MpcArgs {
    /// Recording with CIR snapshots on /channel/cir (from `mmtrack ingest cir` or `mmtrack simulate sounder`); not
    /// needed with `--print-config`.
    #[arg(required_unless_present = "print_config")]
    pub recording: Option<PathBuf>,
    /// Output table directory (created if missing); not needed with `--print-config`.
    #[arg(short, long, required_unless_present = "print_config")]
    pub output: Option<PathBuf>,
    /// TOML file overriding single fields of the default configuration (see `--print-config`).
    #[arg(long, value_name = "TOML")]
    pub config: Option<PathBuf>,
    /// Print the effective configuration (the defaults with `--config` and `--gmphd` on top) as TOML and exit.
    #[arg(long)]
    pub print_config: bool,
    /// Sounder pulse: `flat` (the band's flat spectrum), or a `.npy` file holding a back-to-back calibration CIR
    /// [default: the pulse spectrum in the recording's metadata (`sounder.pulse_spectrum`), else flat].
    #[arg(long, value_name = "flat|FILE.npy")]
    pub pulse: Option<String>,
    /// Process only the link TX:RX (antenna indices), written as the sequence itself. Without it every link is
    /// processed, each as partition `<sequence>-tx<T>-rx<R>` when there are several.
    #[arg(long, value_name = "TX:RX")]
    pub link: Option<String>,
    /// Also run the GM-PHD baseline (Mahler et al. 2017, Table I) on the same detections, set by set (table
    /// mpc_tracks_gmphd); the same as `run_gmphd = true` in the configuration.
    #[arg(long)]
    pub gmphd: bool,
    #[command(flatten)]
    pub output_args: OutputArgs,
    #[command(flatten)]
    pub threads: ThreadsArg,
}

#[derive(Args)]
pub struct SlamArgs {
    /// Recording with /slam/paths and /slam/sources (from `mmtrack simulate slam`).
    pub recording: PathBuf,
    /// Output table directory (created if missing).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Filter parameters (TOML: any field of the SLAM filter configuration, e.g. particles = 500,
    /// toa_std_m = 0.1); the others keep their defaults (the paper's). bs_m is the recording's base station.
    #[arg(long, value_name = "TOML")]
    pub config: Option<PathBuf>,
    /// UE particles (overrides the configuration's, 2000).
    #[arg(long)]
    pub particles: Option<usize>,
    /// Seed of the filter's random streams.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Prior UE state x,y,z,heading,speed,turn_rate,clock_bias (m, rad, m/s, rad/s, m) for recordings without
    /// ground truth (default: the recording's first true state).
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        value_name = "X,Y,Z,HEADING,SPEED,TURN_RATE,BIAS"
    )]
    pub prior: Option<Vec<f64>>,
    /// Refuse a recording with an unusable path (NaN, elevation out of range) instead of skipping and counting it.
    #[arg(long)]
    pub strict: bool,
    #[command(flatten)]
    pub output_args: OutputArgs,
    #[command(flatten)]
    pub threads: ThreadsArg,
}

pub fn run(args: &ProcessArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    if let Pipeline::Manifest(manifest_args) = &args.pipeline {
        return crate::manifest::run(manifest_args, quiet);
    }
    run_pipeline(args, quiet)?;
    Ok(ExitCode::SUCCESS)
}

/// Runs one pipeline (not a manifest); returns the table files written.
pub fn run_pipeline(args: &ProcessArgs, quiet: bool) -> anyhow::Result<Vec<PathBuf>> {
    let written = |w: Vec<TableWriteSummary>| w.into_iter().map(|w| w.path).collect();
    Ok(match &args.pipeline {
        Pipeline::Odometry(odometry_args) => written(run_odometry(odometry_args, quiet)?),
        Pipeline::Poses(a) => {
            let progress = IndicatifProgress::new(quiet);
            let done = poses::process_poses(&a.recording, &a.output, &a.output_args.options(), &progress)?;
            if !quiet {
                println!("{}", done.poses.summary());
                print_written(&done.written);
            }
            written(done.written)
        }
        Pipeline::Raw(a) => {
            let progress = IndicatifProgress::new(quiet);
            let done = mmtrack_process::raw::process_raw(&a.recording, &a.output, &a.output_args.options(), &progress)?;
            if !quiet {
                println!("{}", done.summary());
                print_written(&done.written);
            }
            written(done.written)
        }
        Pipeline::Mpc(mpc_args) => written(run_mpc(mpc_args, quiet)?),
        Pipeline::Beam(beam_args) => crate::process_beam::run(beam_args, quiet)?,
        Pipeline::Slam(slam_args) => written(run_slam(slam_args, quiet)?),
        Pipeline::Manifest(_) => bail!("a manifest cannot run a manifest"),
    })
}

fn run_odometry(args: &OdometryArgs, quiet: bool) -> anyhow::Result<Vec<TableWriteSummary>> {
    let config = odometry::effective_config(&args.preset, args.config.as_deref())?;
    if args.print_config {
        print!("{}", toml::to_string(&config)?);
        return Ok(Vec::new());
    }
    // clap requires both unless --print-config.
    let (Some(recording), Some(output)) = (&args.recording, &args.output) else {
        bail!("a recording and --output are required (unless --print-config)");
    };
    let options = args.output_args.options();
    let progress = IndicatifProgress::new(quiet);
    let done = args
        .threads
        .install(|| odometry::process_odometry(recording, output, &args.preset, &config, &options, &progress))??;
    if !quiet {
        print_odometry(&done.run, &args.preset, &done.written);
    }
    Ok(done.written)
}

pub(crate) fn print_odometry(run: &odometry::OdometryRun, preset: &str, written: &[TableWriteSummary]) {
    run.summary(preset).iter().for_each(|line| println!("{line}"));
    print_written(written);
}

fn print_written(written: &[TableWriteSummary]) {
    for w in written {
        println!("  wrote {} ({} rows)", w.path.display(), w.rows);
    }
}

fn run_mpc(args: &MpcArgs, quiet: bool) -> anyhow::Result<Vec<TableWriteSummary>> {
    let mut config = mpc::effective_config(args.config.as_deref())?;
    config.run_gmphd |= args.gmphd;
    if args.print_config {
        print!("{}", toml::to_string(&config)?);
        return Ok(Vec::new());
    }
    // clap requires both unless --print-config.
    let (Some(recording), Some(output)) = (&args.recording, &args.output) else {
        bail!("a recording and --output are required (unless --print-config)");
    };
    let options = mpc::MpcOptions {
        pulse: args.pulse.clone(),
        link: args.link.as_deref().map(mpc::parse_link).transpose()?,
        output: args.output_args.options(),
    };
    let progress = IndicatifProgress::new(quiet);
    let done = args.threads.install(|| mpc::process_mpc(recording, output, &config, &options, &progress))??;
    // A warning, so on stderr and also with -q: once for the run, not per link.
    let capped_links = done.links.iter().filter(|l| l.snapshots_at_max_mpcs > 0).count();
    if capped_links > 0 {
        let at_cap = done.links.iter().map(|l| l.snapshots_at_max_mpcs).sum();
        let snapshots = done.links.iter().map(|l| l.snapshots_with_detections).sum();
        let links = (capped_links, done.links.len());
        eprintln!("warning: {}", max_mpcs_note(at_cap, snapshots, links, config.detection.max_mpcs));
    }
    if quiet {
        return Ok(done.written);
    }
    for link in &done.links {
        link.summary(config.short_term.min_track_length).iter().for_each(|line| println!("{line}"));
    }
    for w in &done.written {
        let (one, many) = mpc::record_noun(&w.path);
        println!("  wrote {} ({})", w.path.display(), counted_as(w.rows, one, many));
    }
    Ok(done.written)
}

/// The warning for snapshots whose detection stopped at the cap, over
/// `links` = (links with such snapshots, links).
fn max_mpcs_note(at_cap: usize, snapshots: usize, links: (usize, usize), max_mpcs: usize) -> String {
    let (capped, all) = links;
    format!(
        "{at_cap} of {snapshots} snapshots ({capped} of {all} links) stopped at [detection] max_mpcs = {max_mpcs} \
         detections before the residual fell below the threshold: weaker paths were not searched; raise max_mpcs in \
         the [detection] table of the --config file to detect them"
    )
}

fn run_slam(args: &SlamArgs, quiet: bool) -> anyhow::Result<Vec<TableWriteSummary>> {
    let options = slam::SlamOptions {
        config: args.config.clone(),
        particles: args.particles,
        seed: args.seed,
        prior: args.prior.clone(),
        strict: args.strict,
        output: args.output_args.options(),
    };
    let done = args.threads.install(|| slam::process_slam(&args.recording, &args.output, &options))??;
    if !quiet {
        let (va, sp) = done.confirmed_at_end();
        let ue = &done.tables.ue;
        let skipped: u64 = ue.iter().map(|r| r.skipped_paths).sum();
        let empty = ue.iter().filter(|r| r.paths == 0).count();
        println!(
            "slam ({} particles): {} epochs ({empty} without paths, {skipped} paths skipped), {va} VAs and {sp} SPs \
             confirmed at the end",
            done.config.particles,
            ue.len()
        );
        print_written(&done.written);
    }
    Ok(done.written)
}
