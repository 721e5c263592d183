//! Several runs at once: `mmtrack analyze <DIR>...` over the table
//! directories of many runs (e.g. `process odometry --preset cfear` and
//! `--preset fast-cfear`, or MPC tracking with two configurations), each
//! analyzed as usual into `<out>/run=<id>/`, then compared side by side.
//!
//! The comparison is a polars query over the Hive-partitioned result tables
//! the runs just wrote: the files
//! `<out>/run=*/tables/<table>/sequence=*/part-0.parquet` of each result
//! table, read with the `parquet` crate into one polars frame (the `run` and
//! `sequence` columns come from the paths, as in a Hive scan), group-bys per run
//! for the pooled rows, and one long table `run_comparison` (run, table,
//! sequence, key, metric, unit, value; declared in `mmtrack_io::table`) that
//! the report turns into one side-by-side table per result table.
//!
//! Pooling rules (the same for one run's report, [`pooled_trajectory_metrics`]):
//! - sequence `all`: KITTI drift pooled over segments, as the KITTI devkit
//!   pools a dataset (the mean over every segment of every sequence, so a long
//!   sequence weighs more); position/yaw RMSEs and the ATE pooled over the
//!   associated poses (the RMS over all poses); the RPE over the frame pairs;
//! - sequence `mean`: the plain mean of the per-sequence values (each sequence
//!   weighs the same, as papers that report one number per sequence average).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use mmtrack_io::table::{RunComparisonRow, TableSpec, TrajectoryMetrics};
use polars::df;
use polars::prelude::{
    Column, DataFrame, DataType, Expr, IntoLazy, LazyFrame, NULL, PlSmallStr, SortMultipleOptions, col, lit, when,
};

pub use crate::compared::{COMPARED, ComparedTable, Metric, TRAJECTORY_COMPARED};

/// One run's table directory, as named on the command line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunTables {
    /// Run id: the `run=<id>` folder's id, else the directory's name.
    pub id: String,
    /// The table directory (`<table>/sequence=<id>/part-0.parquet` inside).
    pub tables: PathBuf,
}

fn has_tables(dir: &Path) -> anyhow::Result<bool> {
    Ok(!crate::pipeline::inventory(dir)?.tables.is_empty())
}

/// The runs under `inputs`: each input's `run=<id>` folders (what `process
/// --run-id` writes), and the input itself when it holds tables directly
/// (named after the directory), or when it holds neither. Errors name the
/// input: not a directory, or two runs with the same id.
pub fn discover_runs(inputs: &[PathBuf]) -> anyhow::Result<Vec<RunTables>> {
    let mut runs: Vec<RunTables> = Vec::new();
    for input in inputs {
        if !input.is_dir() {
            bail!("{}: not a directory (expected a table directory written by `mmtrack process`)", input.display());
        }
        let mut found = Vec::new();
        let mut entries: Vec<PathBuf> = std::fs::read_dir(input)
            .with_context(|| format!("{}: cannot read table directory", input.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_dir())
            .collect();
        entries.sort();
        for path in entries {
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            if let Some(id) = name.strip_prefix("run=") {
                if id.is_empty() {
                    bail!("{}: empty run id", path.display());
                }
                found.push(RunTables { id: id.to_string(), tables: path });
            }
        }
        // The input is a run itself when it holds tables, or when it holds no
        // runs either (analyzing it then says what was looked for).
        if has_tables(input)? || found.is_empty() {
            let name = input
                .canonicalize()
                .ok()
                .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                .unwrap_or_else(|| input.display().to_string());
            found.insert(0, RunTables { id: name, tables: input.clone() });
        }
        for run in found {
            if let Some(other) = runs.iter().find(|r| r.id == run.id) {
                bail!(
                    "run id `{}` twice: {} and {}; give runs distinct names (`mmtrack process ... --run-id <ID>`) \
                     or directories with distinct names",
                    run.id,
                    other.tables.display(),
                    run.tables.display()
                );
            }
            runs.push(run);
        }
    }
    Ok(runs)
}

/// The `part-0.parquet` files of `<out>/run=*/tables/<table>/sequence=*/`
/// as (run, sequence, file), sorted.
fn run_partitions(out: &Path, table: &str) -> anyhow::Result<Vec<(String, String, PathBuf)>> {
    let prefixed = |dir: &Path, prefix: &str| -> anyhow::Result<Vec<(String, PathBuf)>> {
        let mut found = Vec::new();
        for entry in std::fs::read_dir(dir).with_context(|| dir.display().to_string())? {
            let entry = entry.with_context(|| dir.display().to_string())?;
            let name = entry.file_name().to_string_lossy().into_owned();
            if let Some(value) = name.strip_prefix(prefix)
                && entry.path().is_dir()
            {
                found.push((value.to_string(), entry.path()));
            }
        }
        found.sort();
        Ok(found)
    };
    let mut files = Vec::new();
    for (run, run_dir) in prefixed(out, "run=")? {
        let table_dir = run_dir.join("tables").join(table);
        if !table_dir.is_dir() {
            continue;
        }
        for (sequence, dir) in prefixed(&table_dir, "sequence=")? {
            let file = dir.join("part-0.parquet");
            if file.is_file() {
                files.push((run.clone(), sequence, file));
            }
        }
    }
    Ok(files)
}

/// One Arrow column as a polars column; `None` for the types the
/// comparison never reads (lists, binary).
fn polars_column(name: &str, array: &dyn arrow_array::Array) -> Option<Column> {
    use arrow_array::cast::AsArray;
    use arrow_array::types::{Float64Type, Int64Type, UInt32Type, UInt64Type};
    use arrow_schema::DataType as Arrow;
    let name = PlSmallStr::from(name);
    Some(match array.data_type() {
        Arrow::Int64 => Column::new(name, array.as_primitive::<Int64Type>().iter().collect::<Vec<_>>()),
        Arrow::UInt64 => Column::new(name, array.as_primitive::<UInt64Type>().iter().collect::<Vec<_>>()),
        Arrow::UInt32 => Column::new(name, array.as_primitive::<UInt32Type>().iter().collect::<Vec<_>>()),
        Arrow::Float64 => Column::new(name, array.as_primitive::<Float64Type>().iter().collect::<Vec<_>>()),
        Arrow::Boolean => Column::new(name, array.as_boolean().iter().collect::<Vec<_>>()),
        Arrow::Utf8 => Column::new(name, array.as_string::<i32>().iter().collect::<Vec<_>>()),
        Arrow::LargeUtf8 => Column::new(name, array.as_string::<i64>().iter().collect::<Vec<_>>()),
        _ => return None,
    })
}

/// One Parquet file as a polars frame of its scalar columns (read with the
/// `parquet` crate: polars itself is built without Parquet support).
fn read_frame(path: &Path) -> anyhow::Result<DataFrame> {
    use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
    let file = std::fs::File::open(path).with_context(|| path.display().to_string())?;
    let builder = ParquetRecordBatchReaderBuilder::try_new(file).with_context(|| path.display().to_string())?;
    // Starting from an empty batch keeps the columns of a file without rows.
    let empty = arrow_array::RecordBatch::new_empty(builder.schema().clone());
    let reader = builder.build().with_context(|| path.display().to_string())?;
    let mut frame: Option<DataFrame> = None;
    for batch in std::iter::once(Ok(empty)).chain(reader) {
        let batch = batch.with_context(|| path.display().to_string())?;
        let columns: Vec<Column> = batch
            .schema()
            .fields()
            .iter()
            .zip(batch.columns())
            .filter_map(|(field, array)| polars_column(field.name(), array.as_ref()))
            .collect();
        let part = DataFrame::new(columns).with_context(|| path.display().to_string())?;
        match frame.as_mut() {
            None => frame = Some(part),
            Some(frame) => {
                frame.vstack_mut(&part).with_context(|| path.display().to_string())?;
            }
        }
    }
    frame.with_context(|| format!("{}: no columns", path.display()))
}

/// The rows of `<out>/run=*/tables/<table>/sequence=*/part-0.parquet`,
/// with `run` and `sequence` as string columns from the paths (as a Hive
/// scan gives them), as a lazy frame for the comparison queries; `None`
/// when no run has the table. The files are read into memory (a few rows
/// per run and sequence).
pub fn read_runs(out: &Path, table: &str) -> anyhow::Result<Option<LazyFrame>> {
    let mut frame: Option<DataFrame> = None;
    for (run, sequence, file) in run_partitions(out, table)? {
        let mut part = read_frame(&file)?;
        let height = part.height();
        for (name, value) in [("run", &run), ("sequence", &sequence)] {
            part.with_column(Column::new(name.into(), vec![value.as_str(); height]))
                .with_context(|| file.display().to_string())?;
        }
        match frame.as_mut() {
            None => frame = Some(part),
            Some(frame) => {
                frame
                    .vstack_mut(&part)
                    .with_context(|| format!("{}: columns differ from the other runs' {table}", file.display()))?;
            }
        }
    }
    Ok(frame.map(IntoLazy::lazy))
}

/// `sqrt(sum(w v^2) / sum(w))`, 0 when the weights sum to 0.
fn weighted_rms(value: &str, weight: Expr) -> Expr {
    let total = weight.clone().sum();
    when(total.clone().gt(lit(0.0)))
        .then(((weight * col(value).pow(2)).sum() / total).sqrt())
        .otherwise(lit(0.0))
        .alias(value)
}

/// `sum(v segments) / sum(segments)` over the sequences with segments; null
/// without any.
fn by_segments(value: &str) -> Expr {
    let segments = col("kitti_segments").cast(DataType::Float64);
    let total = segments.clone().sum();
    when(total.clone().gt(lit(0.0))).then((col(value) * segments).sum() / total).otherwise(lit(NULL)).alias(value)
}

/// The pooled trajectory metrics as polars aggregations over rows of
/// `trajectory_metrics` (module docs: KITTI drift over segments, RMSEs and
/// ATE over poses, RPE over frame pairs, counts and lengths summed, the
/// largest ATE error).
#[must_use]
pub fn pooled_trajectory_exprs() -> Vec<Expr> {
    let poses = col("associated_poses").cast(DataType::Float64);
    let pairs = when(col("associated_poses").gt(lit(0u64)))
        .then(col("associated_poses").cast(DataType::Float64) - lit(1.0))
        .otherwise(lit(0.0));
    let mut exprs: Vec<Expr> =
        ["estimate_poses", "associated_poses", "interpolated_poses", "dropped_poses", "kitti_segments"]
            .into_iter()
            .map(|c| col(c).sum())
            .collect();
    exprs.extend(["path_length_m", "estimate_path_length_m"].into_iter().map(|c| col(c).sum()));
    exprs.extend(["kitti_translational_pct", "kitti_rotational_deg_per_100m"].into_iter().map(by_segments));
    exprs.extend(
        ["ate_rmse_m", "x_rmse_m", "y_rmse_m", "position_rmse_m", "yaw_rmse_rad"]
            .into_iter()
            .map(|c| weighted_rms(c, poses.clone())),
    );
    exprs.push(col("ate_max_m").max());
    exprs.extend(["rpe_translation_rmse_m", "rpe_yaw_rmse_rad"].into_iter().map(|c| weighted_rms(c, pairs.clone())));
    exprs
}

fn f64_at(df: &DataFrame, name: &str, row: usize) -> anyhow::Result<Option<f64>> {
    let column = df.column(name).with_context(|| format!("column {name}"))?;
    let column = column.cast(&DataType::Float64).with_context(|| format!("column {name}"))?;
    Ok(column.f64().with_context(|| format!("column {name}"))?.get(row))
}

fn u64_at(df: &DataFrame, name: &str, row: usize) -> anyhow::Result<u64> {
    let column = df.column(name).with_context(|| format!("column {name}"))?;
    let column = column.cast(&DataType::UInt64).with_context(|| format!("column {name}"))?;
    Ok(column.u64().with_context(|| format!("column {name}"))?.get(row).unwrap_or(0))
}

/// One run's sequences pooled (module docs); `None` for no sequences.
/// Fields without a pooled meaning (times, step, the end-point error) are
/// the first sequence's or zero.
pub fn pooled_trajectory_metrics(ms: &[&TrajectoryMetrics]) -> anyhow::Result<Option<TrajectoryMetrics>> {
    let Some(first) = ms.first() else { return Ok(None) };
    let u = |f: fn(&TrajectoryMetrics) -> u64| ms.iter().map(|m| f(m)).collect::<Vec<u64>>();
    let v = |f: fn(&TrajectoryMetrics) -> f64| ms.iter().map(|m| f(m)).collect::<Vec<f64>>();
    let o = |f: fn(&TrajectoryMetrics) -> Option<f64>| ms.iter().map(|m| f(m)).collect::<Vec<Option<f64>>>();
    let frame = df!(
        "estimate_poses" => u(|m| m.estimate_poses),
        "associated_poses" => u(|m| m.associated_poses),
        "interpolated_poses" => u(|m| m.interpolated_poses),
        "dropped_poses" => u(|m| m.dropped_poses),
        "kitti_segments" => u(|m| m.kitti_segments),
        "path_length_m" => v(|m| m.path_length_m),
        "estimate_path_length_m" => v(|m| m.estimate_path_length_m),
        "kitti_translational_pct" => o(|m| m.kitti_translational_pct),
        "kitti_rotational_deg_per_100m" => o(|m| m.kitti_rotational_deg_per_100m),
        "ate_rmse_m" => v(|m| m.ate_rmse_m),
        "x_rmse_m" => v(|m| m.x_rmse_m),
        "y_rmse_m" => v(|m| m.y_rmse_m),
        "position_rmse_m" => v(|m| m.position_rmse_m),
        "yaw_rmse_rad" => v(|m| m.yaw_rmse_rad),
        "ate_max_m" => v(|m| m.ate_max_m),
        "rpe_translation_rmse_m" => v(|m| m.rpe_translation_rmse_m),
        "rpe_yaw_rmse_rad" => v(|m| m.rpe_yaw_rmse_rad),
    )?;
    let pooled = frame.lazy().select(pooled_trajectory_exprs()).collect()?;
    let f = |name: &str| f64_at(&pooled, name, 0);
    let n = |name: &str| u64_at(&pooled, name, 0);
    Ok(Some(TrajectoryMetrics {
        estimate_poses: n("estimate_poses")?,
        associated_poses: n("associated_poses")?,
        interpolated_poses: n("interpolated_poses")?,
        dropped_poses: n("dropped_poses")?,
        path_length_m: f("path_length_m")?.unwrap_or(0.0),
        estimate_path_length_m: f("estimate_path_length_m")?.unwrap_or(0.0),
        kitti_segments: n("kitti_segments")?,
        kitti_translational_pct: f("kitti_translational_pct")?,
        kitti_rotational_deg_per_100m: f("kitti_rotational_deg_per_100m")?,
        ate_rmse_m: f("ate_rmse_m")?.unwrap_or(0.0),
        ate_max_m: f("ate_max_m")?.unwrap_or(0.0),
        x_rmse_m: f("x_rmse_m")?.unwrap_or(0.0),
        y_rmse_m: f("y_rmse_m")?.unwrap_or(0.0),
        position_rmse_m: f("position_rmse_m")?.unwrap_or(0.0),
        yaw_rmse_rad: f("yaw_rmse_rad")?.unwrap_or(0.0),
        final_position_error_m: 0.0,
        rpe_translation_rmse_m: f("rpe_translation_rmse_m")?.unwrap_or(0.0),
        rpe_yaw_rmse_rad: f("rpe_yaw_rmse_rad")?.unwrap_or(0.0),
        ..(*first).clone()
    }))
}

fn unit_of(spec: &TableSpec, column: &str) -> String {
    spec.columns.iter().find(|c| c.name == column).map_or("", |c| c.unit).to_string()
}

fn string_at(df: &DataFrame, name: &str, row: usize) -> anyhow::Result<String> {
    let column = df.column(name).with_context(|| format!("column {name}"))?;
    Ok(column.str().with_context(|| format!("column {name}"))?.get(row).unwrap_or("").to_string())
}

/// One `run_comparison` row and its sequence: the partition
/// (`sequence=<id>`, `all` or `mean`) it is written to.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparedRow {
    /// Sequence id; `all` and `mean` for the pooled trajectory rows.
    pub sequence: String,
    /// The row.
    pub row: RunComparisonRow,
}

/// Wide rows (run, sequence, keys, metrics) into long rows.
fn long_rows(
    df: &DataFrame,
    compared: &ComparedTable,
    sequence: Option<&str>,
    rows: &mut Vec<ComparedRow>,
) -> anyhow::Result<()> {
    for row in 0..df.height() {
        let run = string_at(df, "run", row)?;
        let sequence_id = match sequence {
            Some(s) => s.to_string(),
            None => string_at(df, "sequence", row)?,
        };
        let key = compared.keys.iter().map(|k| string_at(df, k, row)).collect::<anyhow::Result<Vec<_>>>()?.join(" / ");
        for metric in compared.metrics.iter().map(|m| m.column) {
            rows.push(ComparedRow {
                sequence: sequence_id.clone(),
                row: RunComparisonRow {
                    run: run.clone(),
                    source_table: compared.spec.name.to_string(),
                    key: key.clone(),
                    metric: metric.to_string(),
                    unit: unit_of(compared.spec, metric),
                    value: f64_at(df, metric, row)?,
                },
            });
        }
    }
    Ok(())
}

/// A comparison query's error in the user's terms: the table compared and
/// the first line of the engine's message (never its query plan).
fn query_error(error: &polars::error::PolarsError, compared: &ComparedTable) -> anyhow::Error {
    let message = error.to_string();
    let first = message.split("Resolved plan").next().unwrap_or(&message).lines().next().unwrap_or("").trim();
    anyhow::anyhow!(
        "comparing table `{}` across runs (columns {}): {}",
        compared.spec.name,
        compared.metrics.iter().map(|m| m.column).collect::<Vec<_>>().join(", "),
        first.trim_end_matches([':', ' '])
    )
}

fn query(frame: LazyFrame, compared: &ComparedTable) -> anyhow::Result<DataFrame> {
    frame.collect().map_err(|e| query_error(&e, compared))
}

/// Every compared key and metric is a column of the runs' table; else an
/// error naming the table, the column and the columns there are.
fn check_columns(frame: &LazyFrame, compared: &ComparedTable) -> anyhow::Result<()> {
    let schema = frame.clone().collect_schema().map_err(|e| query_error(&e, compared))?;
    let wanted = compared.keys.iter().copied().chain(compared.metrics.iter().map(|m| m.column));
    for column in wanted {
        if schema.get(column).is_none() {
            bail!(
                "comparing table `{}` across runs: the runs' tables have no column `{column}` (they have: {})",
                compared.spec.name,
                schema.iter_names().map(|n| n.as_str()).collect::<Vec<_>>().join(", ")
            );
        }
    }
    Ok(())
}

/// The `run_comparison` rows of the runs written under `out`
/// (`<out>/run=<id>/tables/...`): every compared table's metrics per run and
/// sequence, and for `trajectory_metrics` the pooled rows `all` and `mean`
/// per run (module docs). Sorted by table, sequence, key, metric order, run.
pub fn compare_runs(out: &Path) -> anyhow::Result<Vec<ComparedRow>> {
    let mut rows = Vec::new();
    for compared in &COMPARED {
        let Some(frame) = read_runs(out, compared.spec.name)? else { continue };
        check_columns(&frame, compared)?;
        let mut select: Vec<Expr> = vec![col("run"), col("sequence")];
        select.extend(compared.keys.iter().map(|k| col(*k)));
        select.extend(compared.metrics.iter().map(|m| col(m.column).cast(DataType::Float64)));
        let mut order: Vec<PlSmallStr> = vec!["sequence".into()];
        order.extend(compared.keys.iter().map(|k| PlSmallStr::from(*k)));
        order.push("run".into());
        let wide = query(frame.clone().select(select).sort(order, SortMultipleOptions::default()), compared)?;
        let first_of_table = rows.len();
        long_rows(&wide, compared, None, &mut rows)?;
        // The pooled rows only of runs with several sequences: with one they
        // would repeat its row, and a query summing the table without a
        // `sequence` filter would count it three times.
        let mut sequences_of_run: std::collections::BTreeMap<String, std::collections::BTreeSet<String>> =
            std::collections::BTreeMap::new();
        for r in &rows[first_of_table..] {
            sequences_of_run.entry(r.row.run.clone()).or_default().insert(r.sequence.clone());
        }
        let several = |run: &str| sequences_of_run.get(run).is_some_and(|s| s.len() > 1);
        if compared.spec.name == mmtrack_io::table::TRAJECTORY_METRICS.name {
            let pooled_from = rows.len();
            let mut pooled = query(
                frame.clone().group_by([col("run")]).agg(pooled_trajectory_exprs()).sort(["run"], Default::default()),
                compared,
            )?;
            // The pooled row has no end point (as in a run's report).
            let height = pooled.height();
            pooled
                .with_column(Column::full_null("final_position_error_m".into(), height, &DataType::Float64))
                .map_err(|e| query_error(&e, compared))?;
            long_rows(&pooled, compared, Some("all"), &mut rows)?;
            let means = query(
                frame
                    .group_by([col("run")])
                    .agg(
                        compared
                            .metrics
                            .iter()
                            .map(|m| col(m.column).cast(DataType::Float64).mean())
                            .collect::<Vec<_>>(),
                    )
                    .sort(["run"], SortMultipleOptions::default()),
                compared,
            )?;
            long_rows(&means, compared, Some("mean"), &mut rows)?;
            let pooled_rows = rows.split_off(pooled_from);
            rows.extend(pooled_rows.into_iter().filter(|r| several(&r.row.run)));
        }
    }
    let metric_rank = |row: &ComparedRow| {
        let row = &row.row;
        COMPARED
            .iter()
            .find(|c| c.spec.name == row.source_table)
            .and_then(|c| c.metrics.iter().position(|m| m.column == row.metric))
            .unwrap_or(usize::MAX)
    };
    let sequence_rank = |s: &str| match s {
        "all" => 1,
        "mean" => 2,
        _ => 0,
    };
    rows.sort_by(|a, b| {
        let table = |r: &ComparedRow| COMPARED.iter().position(|c| c.spec.name == r.row.source_table);
        (table(a), sequence_rank(&a.sequence), &a.sequence, &a.row.key, metric_rank(a), &a.row.run).cmp(&(
            table(b),
            sequence_rank(&b.sequence),
            &b.sequence,
            &b.row.key,
            metric_rank(b),
            &b.row.run,
        ))
    });
    Ok(rows)
}

/// (sequence, key, metric column) of one line of the side-by-side table.
type LineId = (String, String, String);

/// `(B - A) / |A|` in percent, where meaningful: both values there, `A`
/// not 0, and a unit on a ratio scale (a difference of dB values is already
/// a ratio, so dB metrics get none).
fn relative(a: Option<f64>, b: Option<f64>, unit: &str) -> String {
    match (a, b) {
        (Some(a), Some(b)) if a != 0.0 && !unit.contains("dB") => {
            let text = crate::compared::fixed(100.0 * (b - a) / a.abs(), 1);
            let sign = if text.starts_with('-') || !text.chars().any(|c| matches!(c, '1'..='9')) { "" } else { "+" };
            format!("{sign}{text} %")
        }
        _ => "-".into(),
    }
}

/// The intro of the side-by-side section, with the pooling rules only when
/// trajectory tables are compared.
fn section_intro(runs: &[String], tables: &BTreeSet<&str>) -> String {
    let baseline = runs.first().cloned().unwrap_or_default();
    let mut text = format!(
        "Runs: {}. Every value is the run's own result table (`run=<id>/tables/...`), in the units and with the \
         decimals of the run's own report; `tables/run_comparison` holds the same values in the tables' stored units \
         (long format). Differences are against the first run, `{baseline}`: `B - A` in the shown unit, and relative \
         to `{baseline}`'s value where that is meaningful (not for dB values, whose difference is already a ratio, \
         nor against 0).",
        runs.iter().map(|r| format!("`{r}`")).collect::<Vec<_>>().join(", ")
    );
    if tables.contains(mmtrack_io::table::TRAJECTORY_METRICS.name) {
        text.push_str(
            " Pooled trajectory rows (runs with several sequences): `all` pools KITTI drift over the segments of \
             every sequence (as the KITTI devkit pools a dataset), the RMSEs and ATE over the associated poses and \
             the RPE over the frame pairs (no end point); `mean` is the plain mean of the per-sequence values.",
        );
    }
    if tables.contains(mmtrack_io::table::BEAM_SWEEP_POOLED.name) {
        text.push_str(
            " Beam sweeps: the pooled rows per site and tracker (`beam_sweep_pooled`, every sweep weighted once); \
             the per-pass rows are in `tables/run_comparison` (`source_table = 'beam_sweep_summary'`) and in each \
             run's report.",
        );
    }
    text.push_str("\n\n");
    text
}

/// The header and rule of one compared table.
fn table_header(compared: &ComparedTable, runs: &[String]) -> String {
    let baseline = runs.first().cloned().unwrap_or_default();
    let mut header = String::from("| sequence |");
    let mut rule = String::from("|---|");
    if !compared.keys.is_empty() {
        header.push_str(&format!(" {} |", compared.keys.join(" / ")));
        rule.push_str("---|");
    }
    header.push_str(" metric |");
    rule.push_str("---|");
    for (k, run) in runs.iter().enumerate() {
        header.push_str(&format!(" {run} |"));
        rule.push_str("---:|");
        if k > 0 {
            header.push_str(&format!(" {run} - {baseline} | {run} vs {baseline} |"));
            rule.push_str("---:|---:|");
        }
    }
    format!("{header}\n{rule}\n")
}

/// The side-by-side section of the campaign report: one Markdown table per
/// compared result table shown in the report, a column per run and, for
/// every run after the first, its difference to the first (`B - A`) and the
/// relative difference where meaningful ([`relative`]); values in the units,
/// headers and decimals of the single-run report ([`Metric::cell`]). The
/// pooled rows `all` and `mean` are left out of a table where no run has
/// more than one sequence (they would repeat the sequence's row).
#[must_use]
pub fn section(rows: &[ComparedRow], runs: &[String]) -> String {
    use std::fmt::Write;
    let mut text = String::from("## Runs side by side\n\n");
    let baseline = runs.first().cloned().unwrap_or_default();
    let tables: BTreeSet<&str> = rows.iter().map(|r| r.row.source_table.as_str()).collect();
    text.push_str(&section_intro(runs, &tables));
    let pooled = |s: &str| s == "all" || s == "mean";
    for compared in COMPARED.iter().filter(|c| c.in_report && tables.contains(c.spec.name)) {
        let _ = writeln!(text, "### {}\n", compared.spec.name);
        let of_table: Vec<&ComparedRow> = rows.iter().filter(|r| r.row.source_table == compared.spec.name).collect();
        let mut sequences_per_run: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
        for compared_row in of_table.iter().filter(|r| !pooled(&r.sequence)) {
            sequences_per_run.entry(compared_row.row.run.as_str()).or_default().insert(compared_row.sequence.as_str());
        }
        let show_pooled = sequences_per_run.values().any(|s| s.len() > 1);
        text.push_str(&table_header(compared, runs));
        // (sequence, key, metric) in row order -> run -> value.
        let mut lines: Vec<(LineId, String, BTreeMap<String, Option<f64>>)> = Vec::new();
        for ComparedRow { sequence, row } in of_table.into_iter().filter(|r| show_pooled || !pooled(&r.sequence)) {
            let id = (sequence.clone(), row.key.clone(), row.metric.clone());
            match lines.last_mut() {
                Some((last, _, values)) if *last == id => {
                    values.insert(row.run.clone(), row.value);
                }
                _ => lines.push((id, row.unit.clone(), BTreeMap::from([(row.run.clone(), row.value)]))),
            }
        }
        for ((sequence, key, column), unit, values) in lines {
            let Some(metric) = compared.metrics.iter().find(|m| m.column == column) else { continue };
            let mut line = format!("| {sequence} |");
            if !compared.keys.is_empty() {
                line.push_str(&format!(" {key} |"));
            }
            line.push_str(&format!(" {} |", metric.label));
            let a = values.get(&baseline).copied().flatten();
            for (k, run) in runs.iter().enumerate() {
                let value = values.get(run).map_or_else(|| "-".to_string(), |v| metric.cell(*v));
                line.push_str(&format!(" {value} |"));
                if k > 0 {
                    let (difference, relative) = match (values.get(&baseline), values.get(run)) {
                        (Some(_), Some(b)) => (metric.difference(a, *b), relative(a, *b, &unit)),
                        // Either run has no such row: no difference either.
                        _ => ("-".to_string(), "-".to_string()),
                    };
                    line.push_str(&format!(" {difference} | {relative} |"));
                }
            }
            let _ = writeln!(text, "{line}");
        }
        text.push('\n');
    }
    if tables.is_empty() {
        text.push_str("No run has a result table with compared metrics.\n\n");
    }
    text.push_str(
        "`-`: the run has no such row (or no relative difference is meaningful); `n/a`: the table holds no value \
         (see that run's report for why).\n\n",
    );
    text
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn discover_runs_names_plain_and_run_folders_and_refuses_duplicates() {
        let dir = tempfile::tempdir().unwrap();
        let seq = |p: &Path| {
            let d = p.join("odometry").join("sequence=s");
            std::fs::create_dir_all(&d).unwrap();
            std::fs::write(d.join("part-0.parquet"), b"x").unwrap();
        };
        let campaign = dir.path().join("campaign");
        seq(&campaign.join("run=cfear"));
        seq(&campaign.join("run=fast-cfear"));
        let plain = dir.path().join("baseline");
        seq(&plain);
        let runs = discover_runs(&[campaign.clone(), plain.clone()]).unwrap();
        let ids: Vec<&str> = runs.iter().map(|r| r.id.as_str()).collect();
        assert_eq!(ids, ["cfear", "fast-cfear", "baseline"]);
        assert_eq!(runs[2].tables, plain);

        let other = dir.path().join("other");
        seq(&other.join("run=cfear"));
        let err = discover_runs(&[campaign, other]).unwrap_err().to_string();
        assert!(err.contains("run id `cfear` twice"), "{err}");

        // A directory without tables or runs is a run that will say so when analyzed.
        let empty = dir.path().join("empty");
        std::fs::create_dir_all(&empty).unwrap();
        assert_eq!(discover_runs(std::slice::from_ref(&empty)).unwrap()[0].tables, empty);
    }

    /// Metrics of a run for the pooling tests (here and in `report`): only
    /// the counts and errors given vary.
    pub(crate) fn trajectory(
        poses: u64,
        segments: u64,
        kitti_pct: Option<f64>,
        ate_m: f64,
        rpe_m: f64,
    ) -> TrajectoryMetrics {
        TrajectoryMetrics {
            estimate_poses: poses,
            associated_poses: poses,
            interpolated_poses: 0,
            dropped_poses: 0,
            first_t_ns: 0,
            last_t_ns: 1,
            path_length_m: 100.0,
            estimate_path_length_m: 101.0,
            segment_lengths_m: vec![10.0],
            step_frames: Some(1),
            step_m: None,
            kitti_segments: segments,
            kitti_translational_pct: kitti_pct,
            kitti_rotational_deg_per_100m: kitti_pct,
            ate_rmse_m: ate_m,
            ate_max_m: 2.0 * ate_m,
            x_rmse_m: ate_m,
            y_rmse_m: ate_m,
            position_rmse_m: ate_m,
            yaw_rmse_rad: 0.01,
            final_position_error_m: 5.0,
            rpe_translation_rmse_m: rpe_m,
            rpe_yaw_rmse_rad: 0.001,
        }
    }

    #[test]
    fn compare_runs_reads_every_runs_partitions_and_pools_per_run() {
        use mmtrack_io::Overwrite;
        use mmtrack_io::table::write_table;
        let dir = tempfile::tempdir().unwrap();
        let write = |run: &str, sequence: &str, m: &TrajectoryMetrics| {
            let tables = dir.path().join(format!("run={run}")).join("tables");
            write_table(
                &tables,
                sequence,
                std::slice::from_ref(m),
                &mmtrack_io::table::RunInfo::new("{}", mmtrack_io::recording::TimeBase::UnixEpoch)
                    .with_frame(mmtrack_io::table::Frame::new("test_world", "a test's world frame")),
                Overwrite::Refuse,
            )
            .unwrap();
        };
        let (a1, a2) = (trajectory(11, 3, Some(1.0), 1.0, 0.1), trajectory(31, 1, Some(5.0), 2.0, 0.1));
        let b1 = trajectory(5, 0, None, 1.5, 0.1);
        write("a", "s1", &a1);
        write("a", "s2", &a2);
        write("b", "s1", &b1);
        // A run without the table adds no rows.
        std::fs::create_dir_all(dir.path().join("run=c/tables")).unwrap();

        let rows = compare_runs(dir.path()).unwrap();
        let value = |run: &str, sequence: &str, metric: &str| {
            let found: Vec<&RunComparisonRow> = rows
                .iter()
                .filter(|r| r.row.run == run && r.sequence == sequence && r.row.metric == metric)
                .map(|r| &r.row)
                .collect();
            assert_eq!(found.len(), 1, "{run} {sequence} {metric}: {found:?}");
            assert_eq!((found[0].source_table.as_str(), found[0].key.as_str()), ("trajectory_metrics", ""));
            found[0].value
        };
        // Pooled rows (`all`, `mean`) only for run a: b has one sequence, which they would repeat.
        assert_eq!(rows.len(), (3 + 1 + 1) * TRAJECTORY_COMPARED.len());
        assert!(rows.iter().all(|r| r.row.run == "a" || r.sequence == "s1"), "{rows:?}");
        assert!(rows.iter().all(|r| r.row.run != "c"));
        assert_eq!(value("a", "s1", "ate_rmse_m"), Some(1.0));
        assert_eq!(value("a", "s2", "kitti_translational_pct"), Some(5.0));
        assert_eq!(value("b", "s1", "ate_rmse_m"), Some(1.5));
        assert_eq!(value("b", "s1", "kitti_translational_pct"), None);
        // `all`: the same pooling as one run's report; `mean`: the plain mean.
        let pooled = pooled_trajectory_metrics(&[&a1, &a2]).unwrap().unwrap();
        assert_eq!(value("a", "all", "ate_rmse_m"), Some(pooled.ate_rmse_m));
        assert_eq!(value("a", "all", "kitti_translational_pct"), Some(2.0));
        assert_eq!(value("a", "mean", "ate_rmse_m"), Some(1.5));
        assert_eq!(value("a", "mean", "kitti_translational_pct"), Some(3.0));
        let unit = rows.iter().find(|r| r.row.metric == "ate_rmse_m").map(|r| r.row.unit.as_str());
        assert_eq!(unit, Some("m"));
        // Sequences first, then `all`, then `mean`; metrics in report order; runs last.
        let order: Vec<(&str, &str, &str)> =
            rows.iter().map(|r| (r.sequence.as_str(), r.row.metric.as_str(), r.row.run.as_str())).collect();
        assert_eq!(
            &order[..3],
            [
                ("s1", TRAJECTORY_COMPARED[0].column, "a"),
                ("s1", TRAJECTORY_COMPARED[0].column, "b"),
                ("s1", TRAJECTORY_COMPARED[1].column, "a")
            ]
        );
        let sequences: Vec<&str> = order.iter().map(|o| o.0).collect::<Vec<_>>();
        let mut deduped = sequences.clone();
        deduped.dedup();
        assert_eq!(deduped, ["s1", "s2", "all", "mean"]);
    }

    #[test]
    fn compare_runs_without_result_tables_is_empty() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("run=a/tables")).unwrap();
        assert!(compare_runs(dir.path()).unwrap().is_empty());
    }

    #[test]
    fn section_puts_runs_side_by_side_and_marks_missing_rows() {
        let row = |run: &str, sequence: &str, value: Option<f64>| ComparedRow {
            sequence: sequence.into(),
            row: RunComparisonRow {
                run: run.into(),
                source_table: "trajectory_metrics".into(),
                key: String::new(),
                metric: "ate_rmse_m".into(),
                unit: "m".into(),
                value,
            },
        };
        let rows = [row("a", "s1", Some(1.5)), row("b", "s1", None), row("a", "s2", Some(2.0))];
        let text = section(&rows, &["a".into(), "b".into()]);
        assert!(text.contains("| sequence | metric | a | b | b - a | b vs a |"), "{text}");
        assert!(text.contains("| s1 | ATE (m) | 1.500 | n/a | n/a | - |"), "{text}");
        // Run b has no row for s2: no value and no difference.
        assert!(text.contains("| s2 | ATE (m) | 2.000 | - | - | - |"), "{text}");
        // B - A and (B - A) / A by hand: 1.2 - 1.5 = -0.3, -20 %; none for dB.
        let rows = [
            row("a", "s1", Some(1.5)),
            row("b", "s1", Some(1.2)),
            row("a", "all", Some(1.5)),
            row("b", "all", Some(1.2)),
        ];
        let text = section(&rows, &["a".into(), "b".into()]);
        assert!(text.contains("| s1 | ATE (m) | 1.500 | 1.200 | -0.300 | -20.0 % |"), "{text}");
        // One sequence per run: the pooled row would repeat it and is left out.
        assert!(!text.contains("| all |"), "{text}");
        assert_eq!(relative(Some(-2.0), Some(-1.0), "dB"), "-");
        assert_eq!(relative(Some(0.0), Some(1.0), "m"), "-");
        assert_eq!(relative(Some(-2.0), Some(-1.0), "m"), "+50.0 %");
        assert_eq!(relative(Some(1.0), Some(1.0), ""), "0.0 %");
    }

    fn write_rows<R: mmtrack_io::table::TableRow>(dir: &Path, run: &str, rows: &[R]) {
        let tables = dir.join(format!("run={run}")).join("tables");
        mmtrack_io::table::write_table(
            &tables,
            "s",
            rows,
            &mmtrack_io::table::RunInfo::new("{}", mmtrack_io::recording::TimeBase::UnixEpoch),
            mmtrack_io::Overwrite::Refuse,
        )
        .unwrap();
    }

    /// SPEBT summaries store angles in radians: the comparison reads those
    /// columns and shows them in degrees, as the run's report does.
    #[test]
    fn spebt_summaries_compare_in_degrees() {
        use crate::beam::spebt_analysis::tests::summary;
        let dir = tempfile::tempdir().unwrap();
        write_rows(dir.path(), "a", &[summary("pose-error-model", 11, 2, [0.3, 0.312, 0.845], 1.0)]);
        write_rows(dir.path(), "b", &[summary("pose-error-model", 11, 2, [0.4, 0.5, 0.845], 2.0)]);
        let rows = compare_runs(dir.path()).unwrap();
        assert_eq!(rows.len(), 2 * 4, "{rows:?}");
        let text = section(&rows, &["a".into(), "b".into()]);
        assert!(text.contains("### spebt_summary"), "{text}");
        // 0.312 deg and 0.5 deg: B - A = 0.188 deg.
        assert!(text.contains("| s | pose-error-model / t | AoD RMSE (deg) | 0.312 | 0.500 | +0.188 |"), "{text}");
        // Re-initialisations 10 % and 20 % of the 10 tracked slots.
        assert!(text.contains("| re-initialisations (%) | 10.00 | 20.00 | +10.00 | +100.0 % |"), "{text}");
    }

    /// A table whose columns are not the compared ones is an error naming
    /// the table and column, never the engine's query plan.
    #[test]
    fn a_missing_column_is_named_in_user_terms() {
        let dir = tempfile::tempdir().unwrap();
        write_rows(dir.path(), "a", &[trajectory(3, 1, Some(1.0), 1.0, 0.1)]);
        let frame = read_runs(dir.path(), "trajectory_metrics").unwrap().unwrap();
        let wrong = ComparedTable {
            spec: &mmtrack_io::table::TRAJECTORY_METRICS,
            keys: &[],
            metrics: &[Metric {
                column: "no_such_m",
                label: "x (m)",
                scale: crate::compared::Scale::Same,
                decimals: 1,
            }],
            in_report: true,
        };
        let err = check_columns(&frame, &wrong).unwrap_err().to_string();
        assert!(err.contains("table `trajectory_metrics`") && err.contains("no column `no_such_m`"), "{err}");
        let err = query(frame.select([col("no_such_m")]), &wrong).unwrap_err().to_string();
        assert!(err.contains("comparing table `trajectory_metrics`") && !err.contains("plan"), "{err}");
        assert!(!err.contains('\n'), "{err}");
    }
}
