//! Writes the results of `mmtrack analyze` into one directory that appears
//! whole or not at all: everything is written into a hidden staging directory
//! beside the target, which then takes the target's place. A failure leaves
//! the previous results untouched and no staging directory behind.

use std::path::{Path, PathBuf};

use anyhow::Context;
use mmtrack_io::Overwrite;
use std::collections::BTreeMap;

use mmtrack_io::table::{RunComparisonRow, RunInfo, write_table};

use crate::sequence_run::SequenceRun;

use crate::beam::geometric_analysis::{self, GeometricResults};
use crate::beam::spebt_analysis::{self, SpebtResults};
use crate::beam::sweeps::{self, BeamSweepResults};
use crate::beam::{geometric_plots, plots as beam_plots, spebt_plots};
use crate::campaign::RunTables;
use crate::mpc::MpcResult;
use crate::pipeline::{RunResults, TrajectoryResult};
use crate::trajectory::DriftOptions;
use crate::{mpc_plots, mpc_report, plots, report, report_html};
use mmtrack_io::table::BeamSweepPooledRow;

/// Entries of a results directory (and `run=<id>` folders of several runs);
/// `--force` replaces only a directory that holds nothing else, so a
/// mistyped `-o` cannot delete unrelated files.
pub const OWN_ENTRIES: [&str; 4] = ["tables", "plots", "report.md", "report.html"];

/// What [`write_results`] wrote (final paths).
#[derive(Debug, Clone, PartialEq)]
pub struct WrittenResults {
    /// The results directory.
    pub out_dir: PathBuf,
    /// `<out>/tables`.
    pub tables_dir: PathBuf,
    /// `<out>/plots`.
    pub plots_dir: PathBuf,
    /// `<out>/report.md`.
    pub report: PathBuf,
    /// `<out>/report.html`: the same, one self-contained page.
    pub report_html: PathBuf,
    /// Number of table files and plots written.
    pub files: usize,
}

/// Checks, before any work, that `out` may be written: absent, or (with
/// [`Overwrite::Replace`]) a directory holding only [`OWN_ENTRIES`].
pub fn check_output(out: &Path, overwrite: Overwrite) -> anyhow::Result<()> {
    let owns = |relative: &Path, _is_dir: bool| {
        let top = relative.iter().next().map(|c| c.to_string_lossy()).unwrap_or_default();
        OWN_ENTRIES.contains(&top.as_ref()) || top.starts_with("run=")
    };
    Ok(mmtrack_io::check_replaceable_dir(out, "mmtrack analyze", &owns, overwrite)?)
}

fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Writes tables, plots and the report for trajectory `results` into `out`.
pub fn write_results(
    out: &Path,
    results: &[TrajectoryResult],
    skipped: &[(String, String)],
    options: &DriftOptions,
    run: &RunInfo,
    overwrite: Overwrite,
) -> anyhow::Result<WrittenResults> {
    let results = RunResults { trajectory: results.to_vec(), skipped: skipped.to_vec(), ..RunResults::default() };
    write_all_results(out, &results, options, run, overwrite)
}

/// Writes tables, plots and the report of one run's results (trajectory,
/// MPC, beam tracking, SLAM) into `out`.
pub fn write_all_results(
    out: &Path,
    results: &RunResults,
    options: &DriftOptions,
    run: &RunInfo,
    overwrite: Overwrite,
) -> anyhow::Result<WrittenResults> {
    check_output(out, overwrite)?;
    let staging = stage_beside(out)?;
    let files = write_run_into(staging.path(), results, options, run)?;
    publish(staging.keep(), out, overwrite)?;
    Ok(WrittenResults::at(out, files))
}

/// Writes several runs into `out`: each run's results as [`write_all_results`]
/// would, into `<out>/run=<id>/`, then the runs side by side (polars over
/// the runs' result tables, [`crate::campaign`]): table
/// `<out>/tables/run_comparison/sequence=<id>/part-0.parquet` (one partition
/// per sequence, `all` and `mean` for the pooled rows) and
/// `<out>/report.md` / `report.html` linking each run's own report.
pub fn write_campaign(
    out: &Path,
    runs: &[(RunTables, RunResults)],
    options: &DriftOptions,
    run: &RunInfo,
    overwrite: Overwrite,
) -> anyhow::Result<WrittenResults> {
    check_output(out, overwrite)?;
    let staging = stage_beside(out)?;
    let mut files = 0;
    for (RunTables { id, .. }, results) in runs {
        files += write_run_into(&staging.path().join(format!("run={id}")), results, options, run)
            .with_context(|| format!("run {id}"))?;
    }
    let rows = crate::campaign::compare_runs(staging.path())?;
    let tables = staging.path().join("tables");
    // One partition per sequence, so the Hive column `sequence` filters the table.
    let mut by_sequence: BTreeMap<&str, Vec<RunComparisonRow>> = BTreeMap::new();
    for compared in &rows {
        by_sequence.entry(compared.sequence.as_str()).or_default().push(compared.row.clone());
    }
    for (sequence, partition) in &by_sequence {
        write_table(&tables, sequence, partition, run, Overwrite::Refuse)?;
    }
    let ids: Vec<String> = runs.iter().map(|(r, _)| r.id.clone()).collect();
    let mut text = String::from("# mmtrack campaign report\n\n");
    text.push_str("| run | tables | report |\n|---|---|---|\n");
    for (RunTables { id, tables }, _) in runs {
        text.push_str(&format!(
            "| `{id}` | `{}` | [report.md](run={id}/report.md), [report.html](run={id}/report.html) |\n",
            tables.display()
        ));
    }
    text.push('\n');
    text.push_str(&crate::campaign::section(&rows, &ids));
    let (plots, overlays) = crate::compare_plots::compare_plots(runs)?;
    text.push_str(&overlays);
    files += crate::compare_plots::write_compare_plots(staging.path(), &plots)?;
    let report_path = staging.path().join("report.md");
    std::fs::write(&report_path, text).with_context(|| report_path.display().to_string())?;
    files += 1 + write_html(staging.path(), run)?;
    publish(staging.keep(), out, overwrite)?;
    Ok(WrittenResults::at(out, files))
}

fn stage_beside(out: &Path) -> anyhow::Result<tempfile::TempDir> {
    let parent = parent_dir(out);
    std::fs::create_dir_all(&parent).with_context(|| parent.display().to_string())?;
    let name = out.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "results".into());
    mmtrack_io::staging_dir(&parent, &format!(".{name}."))
        .with_context(|| format!("{}: cannot create a staging directory", parent.display()))
}

impl WrittenResults {
    fn at(out: &Path, files: usize) -> Self {
        WrittenResults {
            out_dir: out.to_path_buf(),
            tables_dir: out.join("tables"),
            plots_dir: out.join("plots"),
            report: out.join("report.md"),
            report_html: out.join("report.html"),
            files,
        }
    }
}

/// One run's tables, plots, `report.md` and `report.html` into `dir`.
fn write_run_into(dir: &Path, results: &RunResults, options: &DriftOptions, run: &RunInfo) -> anyhow::Result<usize> {
    let RunResults { trajectory, mpc, beam, slam, skipped, time_bases } = results;
    mmtrack_io::create_output_dirs(dir).with_context(|| dir.display().to_string())?;
    let tables_run = SequenceRun::new(run, time_bases);
    let mut files = write_into(dir, trajectory, skipped, options, &tables_run)?;
    files += write_mpc_into(dir, mpc, &tables_run)?;
    files += write_beam_into(dir, &beam.sweeps, &tables_run)?;
    files += write_spebt_into(dir, &beam.spebt, &tables_run)?;
    files += write_geometric_into(dir, &beam.geometric, &tables_run)?;
    files += crate::slam::analysis::write_slam_into(dir, slam, &tables_run)?;
    if !mpc.is_empty() || !beam.is_empty() || !slam.is_empty() {
        let report_path = dir.join("report.md");
        let mut text = report::markdown(trajectory, &[], options)?;
        if !mpc.is_empty() {
            mpc_report::section(&mut text, mpc);
        }
        if !beam.sweeps.is_empty() {
            sweeps::section(&mut text, &beam.sweeps);
        }
        if !beam.spebt.is_empty() {
            spebt_analysis::section(&mut text, &beam.spebt);
        }
        if !beam.geometric.is_empty() {
            geometric_analysis::section(&mut text, &beam.geometric);
        }
        if !slam.is_empty() {
            crate::slam::analysis::section(&mut text, slam);
        }
        text.push_str(&report::not_analyzed(skipped));
        std::fs::write(&report_path, text).with_context(|| report_path.display().to_string())?;
    }
    files += write_html(dir, run)?;
    Ok(files)
}

/// `report.html` beside the staged `report.md`, its plots embedded, with
/// the provenance: version, build commit, time (`SOURCE_DATE_EPOCH` when
/// set, [`report_html::report_time`]) and this process's command line. The
/// time and command line are in `report.html` only: tables and `report.md`
/// stay byte-identical for the same input, configuration and seed.
fn write_html(dir: &Path, run: &RunInfo) -> anyhow::Result<usize> {
    let markdown_path = dir.join("report.md");
    let markdown = std::fs::read_to_string(&markdown_path).with_context(|| markdown_path.display().to_string())?;
    let now_s = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_secs()).unwrap_or(i64::MAX));
    let generated = report_html::report_time(std::env::var("SOURCE_DATE_EPOCH").ok().as_deref(), now_s);
    // The program by its file name (`mmtrack`, or `python3` for the Python
    // package), as typed; its directory says nothing about the run.
    let command_line = shell_words(std::env::args_os().enumerate().map(|(k, a)| {
        let word = if k == 0 { Path::new(&a).file_name().map_or_else(|| a.clone(), ToOwned::to_owned) } else { a };
        word.to_string_lossy().into_owned()
    }));
    let provenance = report_html::Provenance {
        config_json: &run.config_json,
        version: env!("CARGO_PKG_VERSION"),
        commit: report_html::BUILD_COMMIT,
        generated: &generated,
        command_line: &command_line,
    };
    let path = dir.join("report.html");
    std::fs::write(&path, report_html::html(&markdown, dir, &provenance))
        .with_context(|| path.display().to_string())?;
    Ok(1)
}

/// Words as a shell would need them typed: plain words as they are, others
/// in single quotes.
fn shell_words(words: impl Iterator<Item = String>) -> String {
    let plain = |w: &str| !w.is_empty() && w.chars().all(|c| c.is_ascii_alphanumeric() || "-_./=,:@+%".contains(c));
    words.map(|w| if plain(&w) { w } else { format!("'{}'", w.replace('\'', "'\\''")) }).collect::<Vec<_>>().join(" ")
}

fn write_into(
    dir: &Path,
    results: &[TrajectoryResult],
    skipped: &[(String, String)],
    options: &DriftOptions,
    run: &SequenceRun<'_>,
) -> anyhow::Result<usize> {
    let tables = dir.join("tables");
    let mut files = 0;
    for r in results {
        let seq = &r.sequence;
        write_table(&tables, seq, std::slice::from_ref(&r.metrics), &run.at(seq), Overwrite::Refuse)?;
        write_table(&tables, seq, &r.drift_rows(), &run.at(seq), Overwrite::Refuse)?;
        write_table(&tables, seq, &r.rpe_rows(), &run.at(seq), Overwrite::Refuse)?;
        let plot_dir = dir.join("plots").join(seq);
        mmtrack_io::create_output_dirs(&plot_dir).with_context(|| plot_dir.display().to_string())?;
        let mut plots = vec![
            ("trajectory.svg", plots::trajectory_svg(r)),
            ("trajectory_relative.svg", plots::trajectory_relative_svg(r)),
            ("errors_vs_distance.svg", plots::errors_vs_distance_svg(r)),
        ];
        // Without a KITTI segment there is nothing to draw; the report says why.
        if !r.drift.per_length.is_empty() {
            plots.push(("drift_per_length.svg", plots::drift_per_length_svg(r)));
        }
        files += 3 + plots.len();
        for (file, svg) in plots {
            let path = plot_dir.join(file);
            let svg = svg.with_context(|| format!("sequence {seq}: {file}"))?;
            std::fs::write(&path, svg).with_context(|| path.display().to_string())?;
        }
    }
    let report_path = dir.join("report.md");
    std::fs::write(&report_path, report::markdown(results, skipped, options)?)
        .with_context(|| report_path.display().to_string())?;
    Ok(files + 1)
}

fn write_mpc_into(dir: &Path, results: &[MpcResult], run: &SequenceRun<'_>) -> anyhow::Result<usize> {
    let tables = dir.join("tables");
    let mut files = 0;
    for r in results {
        let seq = &r.sequence;
        write_table(&tables, seq, std::slice::from_ref(&r.summary), &run.at(seq), Overwrite::Refuse)?;
        write_table(&tables, seq, &r.per_set, &run.at(seq), Overwrite::Refuse)?;
        write_table(&tables, seq, &r.counts, &run.at(seq), Overwrite::Refuse)?;
        write_table(&tables, seq, &r.power_std, &run.at(seq), Overwrite::Refuse)?;
        write_table(&tables, seq, &r.chi, &run.at(seq), Overwrite::Refuse)?;
        write_table(&tables, seq, &r.first_path, &run.at(seq), Overwrite::Refuse)?;
        let plot_dir = dir.join("plots").join(seq);
        mmtrack_io::create_output_dirs(&plot_dir).with_context(|| plot_dir.display().to_string())?;
        let svgs = [
            mpc_plots::delay_tracks_svg(r),
            mpc_plots::count_svg(r),
            mpc_plots::birth_death_svg(r),
            mpc_plots::power_loss_svg(r),
            mpc_plots::power_std_svg(r),
        ];
        for ((file, _), svg) in mpc_report::PLOTS.iter().zip(svgs) {
            if mpc_plots::empty_because(r, file).is_some() {
                continue;
            }
            let path = plot_dir.join(file);
            let svg = svg.with_context(|| format!("sequence {seq}: {file}"))?;
            std::fs::write(&path, svg).with_context(|| path.display().to_string())?;
            files += 1;
        }
        files += 6;
    }
    Ok(files)
}

fn write_svg(path: &Path, svg: anyhow::Result<String>, what: &str) -> anyhow::Result<()> {
    if let Some(dir) = path.parent() {
        mmtrack_io::create_output_dirs(dir).with_context(|| dir.display().to_string())?;
    }
    let svg = svg.with_context(|| what.to_string())?;
    std::fs::write(path, svg).with_context(|| path.display().to_string())
}

fn write_beam_into(dir: &Path, results: &BeamSweepResults, run: &SequenceRun<'_>) -> anyhow::Result<usize> {
    if results.is_empty() {
        return Ok(0);
    }
    let tables = dir.join("tables");
    let plots = dir.join("plots");
    let mut files = 0;
    for r in &results.sequences {
        let seq = &r.sequence;
        write_table(&tables, seq, &r.summary, &run.at(seq), Overwrite::Refuse)?;
        let (best, chosen) = sweeps::beam_index_series(r);
        let beam_count = r.rows.iter().map(|row| row.beam_count).max().unwrap_or(1);
        let [(index_file, _), (cdf_file, _)] = sweeps::SEQUENCE_PLOTS;
        write_svg(
            &plots.join(seq).join(index_file),
            beam_plots::beam_index_svg(&format!("{seq}: beam index"), &best, &chosen, beam_count),
            &format!("sequence {seq}: {index_file}"),
        )?;
        write_svg(
            &plots.join(seq).join(cdf_file),
            beam_plots::loss_cdf_svg(&format!("{seq}: received-power loss"), &sweeps::loss_curves(r.rows.iter())),
            &format!("sequence {seq}: {cdf_file}"),
        )?;
        files += 1 + sweeps::SEQUENCE_PLOTS.len();
    }
    write_pooled(&tables, &results.pooled, run, results.sequences.iter().map(|r| r.sequence.as_str()))?;
    let mut sites: Vec<&str> = results.pooled.iter().map(|BeamSweepPooledRow(p)| p.site.as_str()).collect();
    sites.dedup();
    for site in sites {
        let rows = results.sequences.iter().filter(|s| s.site == site).flat_map(|s| s.rows.iter());
        let (file, _) = sweeps::SITE_PLOT;
        write_svg(
            &plots.join(sweeps::site_plot_dir(site)).join(file),
            beam_plots::loss_cdf_svg(&format!("{site}: received-power loss, every pass"), &sweeps::loss_curves(rows)),
            &format!("site {site}: {file}"),
        )?;
        files += 1;
    }
    Ok(files + 1)
}

fn write_spebt_into(dir: &Path, results: &SpebtResults, run: &SequenceRun<'_>) -> anyhow::Result<usize> {
    if results.is_empty() {
        return Ok(0);
    }
    let tables = dir.join("tables");
    let mut files = 0;
    for r in &results.sequences {
        let seq = &r.sequence;
        write_table(&tables, seq, std::slice::from_ref(&r.summary), &run.at(seq), Overwrite::Refuse)?;
        let (file, _) = spebt_analysis::SEQUENCE_PLOT;
        let title = format!("{seq}: SPEBT {} run 0 against the truth", r.summary.experiment);
        write_svg(
            &dir.join("plots").join(seq).join(file),
            spebt_plots::spebt_tracking_svg(&title, &r.tracking_series()),
            &format!("sequence {seq}: {file}"),
        )?;
        files += 2;
    }
    write_pooled(&tables, &results.pooled, run, results.sequences.iter().map(|r| r.sequence.as_str()))?;
    Ok(files + 1)
}

/// The rows pooled over `sequences`, as the `sequence=all` partition of
/// their table.
fn write_pooled<'a, T: mmtrack_io::table::TableRow>(
    tables: &Path,
    rows: &[T],
    run: &SequenceRun<'_>,
    sequences: impl Iterator<Item = &'a str>,
) -> anyhow::Result<()> {
    write_table(tables, "all", rows, &run.pooled(sequences), Overwrite::Refuse)?;
    Ok(())
}

fn write_geometric_into(dir: &Path, results: &GeometricResults, run: &SequenceRun<'_>) -> anyhow::Result<usize> {
    let tables = dir.join("tables");
    for r in &results.sequences {
        let seq = &r.sequence;
        write_table(&tables, seq, std::slice::from_ref(&r.summary), &run.at(seq), Overwrite::Refuse)?;
        let (file, _) = geometric_analysis::SEQUENCE_PLOT;
        let title = format!("{seq}: geometric Doppler-bearing tracker against the truth");
        write_svg(
            &dir.join("plots").join(seq).join(file),
            geometric_plots::geometric_tracking_svg(&title, &r.tracking_series()),
            &format!("sequence {seq}: {file}"),
        )?;
    }
    Ok(2 * results.sequences.len())
}

/// Moves the complete `staged` directory to `out` ([`mmtrack_io::publish_dir`]:
/// an existing `out` is moved aside and deleted only after the new one is in
/// place, with no window in which an interruption leaves `out` missing).
fn publish(staged: PathBuf, out: &Path, overwrite: Overwrite) -> anyhow::Result<()> {
    let result = publish_inner(&staged, out, overwrite);
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&staged);
    }
    result
}

fn publish_inner(staged: &Path, out: &Path, overwrite: Overwrite) -> anyhow::Result<()> {
    // Re-check: another process may have written here while we worked.
    check_output(out, overwrite)?;
    mmtrack_io::publish_dir(staged, out).with_context(|| format!("{}: cannot move results into place", out.display()))
}
