//! The flags every `mmtrack reproduce <experiment>` shares, declared once
//! with their one conversion to the library's [`ExperimentRequest`]. Each
//! experiment gives the texts that name its own files and counts (its
//! default output directory, what `--quick` and `--runs` mean for it) by
//! implementing [`ExperimentTexts`] (and [`MonteCarloTexts`]) on a marker
//! type.

use std::marker::PhantomData;
use std::path::PathBuf;

use clap::Args;
use mmtrack_reproduce::Tier;
use mmtrack_reproduce::request::ExperimentRequest;

use crate::threads::ThreadsArg;

/// What an experiment's shared flags say.
pub trait ExperimentTexts: Send + Sync + 'static {
    /// Default of `--output`.
    const OUTPUT_DIR: &'static str;
    /// Help of `--output`: what the directory holds.
    const OUTPUT_HELP: &'static str;
    /// Help of `--quick`: what the CI version runs.
    const QUICK_HELP: &'static str;
}

/// What a Monte Carlo experiment's `--runs` and `--readme` say.
pub trait MonteCarloTexts: Send + Sync + 'static {
    /// Help of `--runs`: runs of what, and the experiment's count.
    const RUNS_HELP: &'static str;
    /// Help of `--readme`: the block it replaces.
    const README_HELP: &'static str;
}

/// `-o`, `--force`, `--quick`, `--threads`: every experiment's.
#[derive(Args)]
pub struct ExperimentArgs<T: ExperimentTexts> {
    #[arg(short, long, default_value = T::OUTPUT_DIR, help = T::OUTPUT_HELP)]
    pub output: PathBuf,
    /// Replace a previous run's output directory.
    #[arg(long)]
    pub force: bool,
    #[arg(long, help = T::QUICK_HELP)]
    pub quick: bool,
    #[command(flatten)]
    pub threads: ThreadsArg,
    #[arg(skip)]
    texts: PhantomData<T>,
}

/// `--runs` and `--readme`: the Monte Carlo experiments' (all but odometry).
#[derive(Args)]
pub struct MonteCarloArgs<T: MonteCarloTexts> {
    #[arg(long, help = T::RUNS_HELP)]
    pub runs: Option<u64>,
    #[arg(long, value_name = "FILE.md", help = T::README_HELP)]
    pub readme: Option<PathBuf>,
    #[arg(skip)]
    texts: PhantomData<T>,
}

impl<T: ExperimentTexts> ExperimentArgs<T> {
    /// The library's request with `-o`, `--force` and `--quick`; the
    /// experiment adds its own flags.
    pub fn request(&self) -> ExperimentRequest {
        ExperimentRequest {
            output_dir: Some(self.output.clone()),
            force: self.force,
            quick: self.quick,
            ..ExperimentRequest::default()
        }
    }
}

/// The tier of `--quick`.
pub fn tier(quick: bool) -> Tier {
    if quick { Tier::Smoke } else { Tier::Full }
}
