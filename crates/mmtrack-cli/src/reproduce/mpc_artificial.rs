//! `mmtrack reproduce mpc-artificial`: the arguments of
//! [`mmtrack_reproduce::mpc_artificial::run`] (the artificial two-MPC
//! channel of Mahler et al. 2017).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_reproduce::mpc_artificial;
use mmtrack_reproduce::request::{ExperimentRequest, run_experiment};

use super::outcome::finish;
use crate::progress::IndicatifProgress;

#[derive(Args)]
pub struct MpcArtificialArgs {
    /// Output directory (results.csv, results_by_separation.csv, reproduce.md, SVG figures).
    #[arg(short, long, default_value = "out/reproduce/mpc-artificial")]
    output: PathBuf,
    /// Replace a previous run's output directory.
    #[arg(long)]
    force: bool,
    /// Monte Carlo runs per point (different noise and phases).
    #[arg(long, default_value_t = 20)]
    runs: u64,
    /// Sounder pulse of the artificial channel: `measured-like` (band edges
    /// rolled off and a small ripple, as a pulse measured through an RF
    /// cable, which is what the paper used) or `flat` (an ideal band whose
    /// off-grid paths spread over the whole CIR as a sinc).
    #[arg(long, value_enum, default_value_t = PulseChoice::MeasuredLike)]
    pulse: PulseChoice,
    /// Detection variant: keep the CIR taps below floor + 6 dB instead of
    /// zeroing them (the paper's step 1 zeroes them). Zeroing cuts the weak
    /// skirts of each pulse, which costs delay accuracy; this shows how much.
    #[arg(long)]
    keep_taps_below_threshold: bool,
    /// The CI version: 3 runs, powers -100..-130 dB in 6 dB steps plus -116 and -126 dB.
    #[arg(long)]
    quick: bool,
    /// Replace the block `<!-- reproduce-mpc-artificial:begin -->` ... `end`
    /// in this file (docs/results/multipath.md) with the summary (checked
    /// before the run).
    #[arg(long, value_name = "FILE.md")]
    readme: Option<PathBuf>,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum PulseChoice {
    MeasuredLike,
    Flat,
}

impl PulseChoice {
    /// The library's name of the pulse.
    fn name(self) -> &'static str {
        match self {
            Self::MeasuredLike => "measured-like",
            Self::Flat => "flat",
        }
    }
}

pub fn run(args: &MpcArtificialArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let request = ExperimentRequest {
        output_dir: Some(args.output.clone()),
        force: args.force,
        quick: args.quick,
        runs: Some(args.runs),
        readme: args.readme.clone(),
        pulse: Some(args.pulse.name().to_string()),
        keep_taps_below_threshold: args.keep_taps_below_threshold,
        ..ExperimentRequest::default()
    };
    let outcome = run_experiment(mpc_artificial::NAME, &request, &IndicatifProgress::new(quiet))?;
    Ok(finish(&outcome, &args.output, quiet))
}
