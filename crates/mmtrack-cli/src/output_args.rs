//! The output flags every `mmtrack process` pipeline shares (`--sequence`,
//! `--force`, `--run-id`), turned into the library's
//! [`OutputOptions`](mmtrack_process::output::OutputOptions).

use clap::Args;
use mmtrack_process::output::OutputOptions;

/// The output flags of the single-recording pipelines (odometry, mpc, slam).
#[derive(Args, Clone, Debug, Default)]
pub struct OutputArgs {
    /// Sequence id of the output partitions (default: the recording's).
    ///
    /// The tables go to `<table>/sequence=<SEQUENCE>/part-0.parquet` under the output (or run) directory.
    #[arg(long)]
    pub sequence: Option<String>,
    #[command(flatten)]
    pub run: RunOutputArgs,
}

impl OutputArgs {
    /// The library's output options.
    #[must_use]
    pub fn options(&self) -> OutputOptions {
        OutputOptions { sequence: self.sequence.clone(), ..self.run.options() }
    }
}

/// `--force` and `--run-id`: the output flags of every pipeline, also of
/// those whose sequences come from their recordings (`process beam`).
#[derive(Args, Clone, Debug, Default)]
pub struct RunOutputArgs {
    /// Replace existing output tables of the sequences written.
    ///
    /// Only this run's tables are replaced (those under `<output>/run=<ID>/` with --run-id). Without --force, an
    /// existing table stops the command and nothing is written.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub run_id: RunIdArg,
}

impl RunOutputArgs {
    /// The library's output options (no sequence override).
    #[must_use]
    pub fn options(&self) -> OutputOptions {
        OutputOptions { sequence: None, run_id: self.run_id.run_id.clone(), force: self.force }
    }
}

/// The `--run-id` flag of the `mmtrack process` pipelines.
#[derive(Args, Clone, Debug, Default)]
pub struct RunIdArg {
    /// Name of this run: the tables go to `<output>/run=<ID>/`, so runs written under one directory read back
    /// together with a `run` column (DuckDB/polars Hive partitioning) instead of overwriting each other.
    #[arg(long, value_name = "ID")]
    pub run_id: Option<String>,
}
