//! `mmtrack process beam`: the arguments of the beam trackers, one library
//! call each (`mmtrack_process::beam`), and the summaries printed after it.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use mmtrack_io::table::{BEAM_SWEEPS_TRACKED, SPEBT_PER_SLOT, SPEBT_SUMMARY};
use mmtrack_process::beam::geometric::{GeometricOptions, Schedule};
use mmtrack_process::beam::spebt::{self, SpebtOptions};
use mmtrack_process::beam::sweep::{Reacquire, SweepOutput, SweepTrackerKind};
use mmtrack_process::beam::{BeamOutput, BeamRequest, BeamTracker, process_beam};

use crate::output_args::RunOutputArgs;
use crate::progress::IndicatifProgress;

/// The policies `process beam` runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, ValueEnum)]
pub enum TrackerArg {
    /// Constant-velocity Kalman filter on the beam index, from the measured beams alone.
    Window,
    /// The car's GNSS position through the beam map moves the window (SPEBT with GNSS for radar odometry).
    GnssWindow,
    /// Baseline: every sweep measures all beams and uses the previous sweep's best beam.
    LastFullSweep,
    /// Baseline: the beam nearest the GNSS prediction of the beam map, no beam measured.
    GnssMap,
    /// SPEBT (Liu et al. 2024) on a simulated link along the recording's ground truth, driven by
    /// --odometry or by the pose-error model; runs alone (spebt_per_slot, spebt_summary tables).
    Spebt,
    /// Geometric Doppler-bearing tracking (Zoechmann et al. 2019) between a recording's two vehicles
    /// (sounder ground truth), UCA scans and Doppler simulated along it; runs alone (geometric_per_epoch).
    Geometric,
}

/// How the window trackers find the beam at a pass start and after a loss.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ReacquireArg {
    /// Every 4th beam, then a climb to the local peak.
    Coarse,
    /// A full sweep (every beam).
    Full,
}

#[derive(Args)]
pub struct BeamArgs {
    /// Recordings with beam sweeps (files, or directories whose .mcap files are all read), e.g. from
    /// `mmtrack ingest beams`; one sequence each.
    #[arg(required = true, value_name = "RECORDING")]
    recordings: Vec<PathBuf>,
    /// Output table directory (created if missing).
    #[arg(short, long)]
    output: PathBuf,
    /// Policies to run, comma-separated; all write into the same table, told apart by its `tracker` column.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "window,gnss-window,last-full-sweep,gnss-map")]
    tracker: Vec<TrackerArg>,
    /// Re-acquisition of the window trackers (window, gnss-window).
    #[arg(long, value_enum, default_value_t = ReacquireArg::Coarse)]
    reacquire: ReacquireArg,
    #[command(flatten)]
    output_args: RunOutputArgs,
    #[command(flatten)]
    spebt: SpebtArgs,
    #[command(flatten)]
    geometric: GeometricArgs,
}

/// The options of `--tracker spebt` (refused with the sweep trackers).
#[derive(Args, Debug, Clone, Default)]
pub struct SpebtArgs {
    /// spebt: table directory of `mmtrack process odometry` whose `odometry` table (the
    /// recording's sequence) drives the tracker: the one directly under TABLES, else the one
    /// in its only `run=<ID>/` folder holding it (`process odometry --run-id`; several: pick
    /// one with --odometry-run). Without it, the ground truth plus the pose-error model
    /// (--sigma-r-m, --sigma-theta-deg) drives the tracker.
    #[arg(long, value_name = "TABLES")]
    pub odometry: Option<PathBuf>,
    /// spebt: read the odometry table of run ID, `<TABLES>/run=<ID>/` (written by
    /// `process odometry --run-id ID`), instead of looking for it.
    #[arg(long, value_name = "ID", requires = "odometry")]
    pub odometry_run: Option<String>,
    /// spebt: the link and tracker, a TOML file with a `[scenario]` table (Table I's
    /// fields, e.g. bs_x_m, carrier_hz, bs_elements) and a `[tracker]` table, as in
    /// data/reproduce/spebt.toml (default: that file's values, the paper's Table I).
    #[arg(long, value_name = "LINK.toml")]
    pub link: Option<PathBuf>,
    /// spebt: pose-error model sigma_r, metres per coordinate (eq. (23)); drawn without
    /// --odometry, and the filter's Q in both modes (default: the link file's, 1 m).
    #[arg(long)]
    pub sigma_r_m: Option<f64>,
    /// spebt: pose-error model sigma_theta, degrees (default: the link file's, 3 deg).
    #[arg(long)]
    pub sigma_theta_deg: Option<f64>,
    /// spebt: seed of the receiver noise and the pose errors (default: 2024).
    #[arg(long)]
    pub seed: Option<u64>,
    /// spebt: Monte Carlo runs (noise and pose-error realisations; default 1).
    #[arg(long)]
    pub runs: Option<u64>,
}

impl SpebtArgs {
    fn options(&self) -> SpebtOptions {
        SpebtOptions {
            odometry: self.odometry.clone(),
            odometry_run: self.odometry_run.clone(),
            link: self.link.clone(),
            sigma_r_m: self.sigma_r_m,
            sigma_theta_deg: self.sigma_theta_deg,
            seed: self.seed,
            runs: self.runs,
        }
    }
}

/// Which beams the tracker measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum ScheduleArg {
    /// 10 full scans, then the 3 beams nearest the projected azimuth (the paper's).
    #[default]
    Paper,
    /// A full scan every epoch.
    FullScan,
}

/// The options of `--tracker geometric` (refused with the other trackers).
#[derive(Args, Debug, Clone, Default)]
pub struct GeometricArgs {
    /// geometric: beams measured per epoch (default: paper).
    #[arg(long, value_enum)]
    pub beam_schedule: Option<ScheduleArg>,
    /// geometric: epoch (scan) interval, milliseconds (default 20).
    #[arg(long, value_name = "MS")]
    pub epoch_ms: Option<f64>,
    /// geometric: seed of the simulated Doppler noise (default 2019).
    #[arg(long, value_name = "SEED")]
    pub doppler_seed: Option<u64>,
}

impl GeometricArgs {
    fn options(&self) -> GeometricOptions {
        GeometricOptions {
            beam_schedule: self.beam_schedule.map(|s| match s {
                ScheduleArg::Paper => Schedule::Paper,
                ScheduleArg::FullScan => Schedule::FullScan,
            }),
            epoch_ms: self.epoch_ms,
            doppler_seed: self.doppler_seed,
        }
    }
}

/// Runs `process beam`; returns the table files written.
pub fn run(args: &BeamArgs, quiet: bool) -> anyhow::Result<Vec<std::path::PathBuf>> {
    let request = BeamRequest {
        recordings: args.recordings.clone(),
        trackers: args
            .tracker
            .iter()
            .map(|k| match k {
                TrackerArg::Window => BeamTracker::Sweep(SweepTrackerKind::Window),
                TrackerArg::GnssWindow => BeamTracker::Sweep(SweepTrackerKind::GnssWindow),
                TrackerArg::LastFullSweep => BeamTracker::Sweep(SweepTrackerKind::LastFullSweep),
                TrackerArg::GnssMap => BeamTracker::Sweep(SweepTrackerKind::GnssMap),
                TrackerArg::Spebt => BeamTracker::Spebt,
                TrackerArg::Geometric => BeamTracker::Geometric,
            })
            .collect(),
        reacquire: match args.reacquire {
            ReacquireArg::Coarse => Reacquire::Coarse,
            ReacquireArg::Full => Reacquire::Full,
        },
        output: args.output_args.options(),
        spebt: args.spebt.options(),
        geometric: args.geometric.options(),
    };
    let done = process_beam(&args.output, &request, &IndicatifProgress::new(quiet))?;
    let written = match &done {
        BeamOutput::Geometric(d) => &d.written,
        BeamOutput::Spebt(d) => &d.written,
        BeamOutput::Sweeps(d) => &d.written,
    };
    let written = written.iter().map(|w| w.path.clone()).collect();
    if quiet {
        return Ok(written);
    }
    match done {
        BeamOutput::Geometric(done) => {
            for r in &done.recordings {
                // As analyze says it: before the hand-over to RLS the range is unobservable.
                let state = if r.last.filter == "rls" {
                    r.last.filter.clone()
                } else {
                    format!("{} (not converged: never handed over to RLS)", r.last.filter)
                };
                println!(
                    "{}: {} epochs, {state}; last epoch range {:.2} m (true {:.2} m), {} beams measured in all",
                    r.sequence_id, r.epochs, r.last.range_m, r.last.true_range_m, r.beams_measured
                );
            }
        }
        BeamOutput::Spebt(done) => print_spebt(&done),
        BeamOutput::Sweeps(done) => {
            print_summary(&done);
            println!(
                "wrote {} {} partitions under {}",
                done.written.len(),
                BEAM_SWEEPS_TRACKED.name,
                done.dir.display()
            );
        }
    }
    Ok(written)
}

fn print_spebt(done: &spebt::SpebtOutput) {
    for r in &done.recordings {
        let summary = &r.summary;
        println!(
            "{} ({}, {} slots, {} run{}): RMSE |alpha| {:.3} %, AoD {:.3} deg, AoA {:.3} deg; \
             re-initialisations {:.1} per run ({:.2} % of slots)",
            r.sequence_id,
            r.pose_source,
            summary.slots,
            summary.runs,
            if summary.runs == 1 { "" } else { "s" },
            summary.rmse_gain_pct,
            summary.rmse_aod_rad.to_degrees(),
            summary.rmse_aoa_rad.to_degrees(),
            summary.reinitialisations_mean,
            summary.reinitialisation_share_pct
        );
        if let Some(file) = &r.odometry_file {
            println!("  poses from {}", file.display());
        }
    }
    println!(
        "wrote {} {} and {} partitions under {}",
        done.recordings.len(),
        SPEBT_PER_SLOT.name,
        SPEBT_SUMMARY.name,
        done.dir.display()
    );
}

fn print_summary(done: &SweepOutput) {
    for site in &done.sites {
        println!("{}: {} passes, {} sweeps", site.name, site.passes, site.sweeps);
        if let Some(m) = &site.map {
            println!(
                "  beam map (all passes): boresight {:.1} deg from north, {:.3} deg per beam ({}), GNSS offset {:+.1} s, \
                 RMS residual {:.2} beams",
                m.boresight_bearing_rad().to_degrees(),
                m.beam_spacing_rad().to_degrees(),
                if m.beams_per_rad() < 0.0 { "index falls clockwise" } else { "index rises clockwise" },
                m.gnss_time_offset_s(),
                m.rms_residual_beams()
            );
        }
        println!(
            "  {:<16} {:>9} {:>9} {:>6} {:>6} {:>6} {:>6}",
            "tracker", "mean dB", "median dB", "top1", "+-1", "beams", "reinit"
        );
        for (_, kind, s) in done.summaries.iter().filter(|(name, ..)| *name == site.name) {
            println!(
                "  {:<16} {:>9.3} {:>9.3} {:>6.3} {:>6.3} {:>6.2} {:>6}",
                kind.name(),
                s.mean_loss_db,
                s.median_loss_db,
                s.top1,
                s.within_one,
                s.mean_beams_per_sweep,
                s.reinitialisations
            );
        }
    }
}
