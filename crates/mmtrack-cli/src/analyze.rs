//! `mmtrack analyze`: metrics, result tables, plots and a report from the
//! tables `mmtrack process` writes. The work is in `mmtrack-analysis`; this
//! module parses arguments and talks to the terminal.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_analysis::analyze::{AnalyzeOptions, Analyzed, analyze};
use mmtrack_analysis::mpc::DEFAULT_FIRST_PATH_DYNAMIC_RANGE_DB;
use mmtrack_analysis::pipeline::RunResults;
use mmtrack_analysis::report::one_line;

#[derive(Args)]
#[command(
    long_about = "Reads a table directory written by `mmtrack process` (any number of sequences), computes the metrics \
that apply and writes result tables (Parquet), SVG plots and a Markdown report.\n\n\
Metrics: tables `odometry` + `ground_truth` of a sequence -> trajectory metrics: KITTI drift exactly as the KITTI \
odometry devkit computes it (translational %, rotational deg/m and deg/100 m; segments of 100..800 m, first frames \
every 10 frames), frame-to-frame relative pose error, absolute trajectory error after SE(2) alignment, and \
unaligned x/y/yaw RMSE. The estimate is associated with ground truth by time (interpolated); estimate poses outside \
the ground-truth span are dropped and counted.\n\n\
Tables of `mmtrack process mpc` (mpc_sets, mpc_detections, mpc_tracks, mpc_long_term) of a sequence -> MPC \
statistics after Mahler et al. 2017: number of MPCs per set and its CDF, birth and death rates per metre travelled by \
both vehicles (ground_truth_tx + ground_truth_rx; else ground_truth or odometry; else per second, and the report says \
which), detection and tracking power loss, per-track power standard deviation, long-term link power per chi class, \
and with mpc_truth: detection precision/recall (0.5 ns), track purity, true birth/death rates. First path of each \
snapshot: the earliest detection within --first-path-range-db of its strongest; where the recording carried the \
receiver's own first-path estimate (e.g. DW1000 HLP), the median and 90th percentile of the difference.\n\n\
Table beam_sweeps_tracked of `mmtrack process beam` -> per sequence and pooled per site, for each tracker: mean, \
median and 90th-percentile received-power loss against each full sweep's best beam, top-1 and within-one-beam \
accuracy, beams measured per sweep and re-initialisations; plots of the beam index over time (best vs chosen) and \
of the loss CDF.\n\n\
Tables spebt_summary + spebt_per_slot of `mmtrack process beam --tracker spebt` (or `mmtrack reproduce spebt`) -> \
per sequence the RMSE of abs(alpha), AoD and AoA and the re-initialisation share (the summary is checked against the \
per-slot RMSEs), pooled per experiment kind weighting each sequence by its (slots - 1) x runs estimates; a plot of \
run 0 against the truth (Liu et al. Fig. 5).\n\n\
Table geometric_per_epoch of `mmtrack process beam --tracker geometric` -> per sequence the hand-over from \
H-infinity to RLS, the share of epochs in RLS, the range and azimuth errors from the hand-over on (null if it never \
hands over), beams measured against a full scan every epoch and the saving (geometric_summary); a plot of range, \
azimuth and beams over time with the H-infinity span shaded.\n\n\
Tables slam_ue + slam_map + slam_true_sources of `mmtrack process slam` -> per sequence the 5G mmWave SLAM metrics \
of Kim et al. 2018 (time-averaged UE position, heading and clock-bias errors, VA and SP localisation errors, the \
epochs when all VAs and all SPs were confirmed) as slam_summary and slam_per_epoch, plots of the map (true and \
estimated sources, true and estimated track), the UE errors and the confirmed sources over the epochs.\n\n\
Output: <OUT>/tables/{trajectory_metrics,drift_per_length,relative_pose_errors,mpc_summary,mpc_set_metrics,\
mpc_count_distribution,mpc_track_power_std,mpc_chi_classes,mpc_first_path,beam_sweep_summary,spebt_summary,\
geometric_summary,slam_summary,slam_per_epoch}/sequence=<id>/part-0.parquet, \
<OUT>/tables/{beam_sweep_pooled,spebt_pooled}/sequence=all/part-0.parquet, \
<OUT>/plots/<id>/*.svg, <OUT>/plots/site=<site>/loss_cdf.svg, <OUT>/report.md and <OUT>/report.html (the same report as one self-contained page: plots inline, a table of contents with anchors, and the provenance: version, build commit, time (SOURCE_DATE_EPOCH when set), command line, inputs and configuration). The directory appears whole or not at all; an existing one is replaced \
only with --force and only if it holds nothing but earlier results.\n\n\
Several runs (several TABLES directories, or run=<ID> folders written by `mmtrack process ... --run-id <ID>`; a \
directory holding tables directly is a run named after the directory): each run is analyzed as above into \
<OUT>/run=<ID>/, then the runs are compared side by side with polars (lazy scans of the runs' result tables, \
group-bys per run): <OUT>/tables/run_comparison/sequence=<id>/part-0.parquet (long format: run, source_table, \
key, metric, unit, value; one partition per sequence, `all` and `mean` for the pooled rows) and <OUT>/report.md / report.html with one table per result table, a \
column per run and the difference of each run to the first (B - A, and relative where meaningful), and the runs' \
curves overlaid per sequence (trajectories, errors against distance, beam-sweep loss CDFs). Pooled trajectory rows per run: `all` pools KITTI drift over the segments of every sequence (as the \
KITTI devkit pools a dataset), RMSEs and ATE over poses, RPE over frame pairs; `mean` is the mean of the \
per-sequence values (in the report where a run has several sequences).",
    after_help = "Examples:\n  mmtrack analyze out/tables -o out/analysis --segment-lengths-m 10,20,30,40,50,60,70,80\n  \
mmtrack process odometry rec.mcap -o out/runs --preset cfear --run-id cfear\n  \
mmtrack process odometry rec.mcap -o out/runs --preset fast-cfear --run-id fast-cfear\n  \
mmtrack analyze out/runs -o out/compare    # cfear and fast-cfear side by side"
)]
pub struct AnalyzeArgs {
    /// Table directories written by `mmtrack process` (any number of sequences each). A directory holding
    /// `run=<ID>` folders (`process --run-id`) gives one run per folder; several runs are compared side by side.
    #[arg(required = true, value_name = "TABLES")]
    tables: Vec<PathBuf>,
    /// Output directory for tables/, plots/, report.md and report.html.
    #[arg(short, long, value_name = "DIR")]
    output: PathBuf,
    /// Replace earlier results in the output directory.
    #[arg(long)]
    force: bool,
    /// KITTI segment lengths in metres, comma-separated [default: 100,200,...,800 as the devkit]. Short simulated
    /// drives need shorter ones, e.g. 10,20,...,80.
    #[arg(long, value_delimiter = ',', value_name = "M,M,...")]
    segment_lengths_m: Option<Vec<f64>>,
    /// Start a KITTI segment every N frames [default: 10, as the devkit].
    #[arg(long, value_name = "N", conflicts_with = "step_m")]
    step_frames: Option<usize>,
    /// Start a KITTI segment every X metres of ground-truth path instead (independent of the frame rate).
    #[arg(long, value_name = "M")]
    step_m: Option<f64>,
    /// MPC first path: the earliest detection of a snapshot at most this far below its strongest detection, dB.
    #[arg(long, value_name = "DB", default_value_t = DEFAULT_FIRST_PATH_DYNAMIC_RANGE_DB)]
    first_path_range_db: f64,
}

/// The library's options of `args` ([`AnalyzeOptions::from_flags`]).
pub fn options(args: &AnalyzeArgs) -> anyhow::Result<AnalyzeOptions> {
    AnalyzeOptions::from_flags(
        args.segment_lengths_m.clone(),
        args.step_frames,
        args.step_m,
        args.first_path_range_db,
        args.force,
    )
}

pub fn run(args: &AnalyzeArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let analyzed = analyze(&args.tables, &args.output, &options(args)?)?;
    if !quiet {
        print_analyzed(&analyzed);
    }
    Ok(ExitCode::SUCCESS)
}

/// What `analyze` prints after its work.
pub fn print_analyzed(analyzed: &Analyzed) {
    match analyzed {
        Analyzed::Run { results, written } => {
            print_run(results, "");
            println!(
                "wrote {} files: tables {}, plots {}, report {} and {}",
                written.files,
                written.tables_dir.display(),
                written.plots_dir.display(),
                written.report.display(),
                written.report_html.display()
            );
        }
        Analyzed::Campaign { runs, written } => {
            for (run, results) in runs {
                print_run(results, &format!("run {}: ", run.id));
            }
            println!(
                "{} runs side by side: wrote {} files: each run under {}/run=<id>/, the comparison {} and report {} \
                 and {}",
                runs.len(),
                written.files,
                written.out_dir.display(),
                written.tables_dir.join("run_comparison").display(),
                written.report.display(),
                written.report_html.display()
            );
        }
    }
}

/// The one-line summaries of one run's results, each line after `prefix`.
fn print_run(results: &RunResults, prefix: &str) {
    let mut lines: Vec<String> = results.trajectory.iter().map(one_line).collect();
    lines.extend(results.mpc.iter().map(mmtrack_analysis::mpc_report::one_line));
    lines.extend(mmtrack_analysis::beam::sweeps::one_lines(&results.beam.sweeps));
    lines.extend(mmtrack_analysis::beam::spebt_analysis::one_lines(&results.beam.spebt));
    lines.extend(mmtrack_analysis::beam::geometric_analysis::one_lines(&results.beam.geometric));
    lines.extend(mmtrack_analysis::slam::analysis::one_lines(&results.slam));
    lines.extend(results.skipped.iter().map(|(sequence, reason)| format!("{sequence}: not analyzed: {reason}")));
    for line in lines {
        println!("{prefix}{line}");
    }
}
