//! The compare report's plots: the runs' curves of one sequence overlaid
//! (estimated trajectories over the ground truth in the tables' frame, the
//! relative pose errors against the distance travelled, the beam-sweep loss
//! CDFs), and the report section that shows them. The numbers side by side
//! are [`crate::campaign::section`].

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::Path;

use crate::beam::plots::{LossCurve, loss_cdf_svg};
use crate::campaign::RunTables;
use crate::pipeline::{RunResults, TrajectoryResult};
use crate::plots::{errors_overlay_svg, trajectory_overlay_svg};

/// One plot to write: path under the results directory, caption, SVG.
pub struct ComparePlot {
    /// Path relative to the results directory (`plots/<sequence>/...`).
    pub path: String,
    /// Caption in the report.
    pub caption: String,
    /// The SVG document.
    pub svg: String,
}

/// The overlays of every sequence that at least one run analyzed, and the
/// report section showing them (empty when there is nothing to overlay).
///
/// # Errors
/// When a plot cannot be drawn (names the sequence and file).
pub fn compare_plots(runs: &[(RunTables, RunResults)]) -> anyhow::Result<(Vec<ComparePlot>, String)> {
    let mut plots = Vec::new();
    let mut text = String::new();
    let trajectory_sequences: BTreeSet<&str> =
        runs.iter().flat_map(|(_, r)| r.trajectory.iter().map(|t| t.sequence.as_str())).collect();
    let beam_sequences: BTreeSet<&str> =
        runs.iter().flat_map(|(_, r)| r.beam.sweeps.sequences.iter().map(|s| s.sequence.as_str())).collect();
    if trajectory_sequences.is_empty() && beam_sequences.is_empty() {
        return Ok((plots, text));
    }
    text.push_str(
        "## Runs overlaid\n\nPer sequence, every run's curve in one plot (run colours as in the legends; the \
         ground truth in black, in the tables' frame, as each run's estimate (`odometry` or `poses`) and \
         `ground_truth` tables hold them).\n\n",
    );
    for sequence in trajectory_sequences {
        let of_runs: Vec<(&str, &TrajectoryResult)> = runs
            .iter()
            .filter_map(|(run, r)| r.trajectory.iter().find(|t| t.sequence == sequence).map(|t| (run.id.as_str(), t)))
            .collect();
        let _ = writeln!(text, "### `{sequence}` (trajectory)\n");
        for (file, caption, svg) in [
            (
                "trajectory_overlay.svg",
                "estimated trajectories of every run over the ground truth, tables' frame",
                trajectory_overlay_svg(&of_runs),
            ),
            (
                "errors_overlay.svg",
                "relative pose errors of every run against the distance travelled",
                errors_overlay_svg(&of_runs),
            ),
        ] {
            let svg = svg.map_err(|e| anyhow::anyhow!("sequence {sequence}: {file}: {e}"))?;
            push(&mut plots, &mut text, sequence, file, caption, svg);
        }
        text.push('\n');
    }
    for sequence in beam_sequences {
        let curves: Vec<LossCurve> = runs
            .iter()
            .filter_map(|(run, r)| {
                r.beam.sweeps.sequences.iter().find(|s| s.sequence == sequence).map(|s| (run.id.as_str(), s))
            })
            .flat_map(|(run, s)| {
                crate::beam::sweeps::loss_curves(s.rows.iter())
                    .into_iter()
                    .map(move |c| LossCurve { label: format!("{run} / {}", c.label), loss_db: c.loss_db })
            })
            .collect();
        let file = "loss_cdf_overlay.svg";
        let svg = loss_cdf_svg(&format!("{sequence}: received-power loss, every run"), &curves)
            .map_err(|e| anyhow::anyhow!("sequence {sequence}: {file}: {e}"))?;
        let _ = writeln!(text, "### `{sequence}` (beam sweeps)\n");
        push(&mut plots, &mut text, sequence, file, "loss CDF of every run and tracker", svg);
        text.push('\n');
    }
    Ok((plots, text))
}

fn push(plots: &mut Vec<ComparePlot>, text: &mut String, sequence: &str, file: &str, caption: &str, svg: String) {
    let path = format!("plots/{sequence}/{file}");
    let _ = writeln!(text, "![{caption}]({path})");
    plots.push(ComparePlot { path, caption: caption.to_string(), svg });
}

/// Writes `plots` under `dir` (the staging directory); returns how many.
///
/// # Errors
/// A directory or file that cannot be written, named.
pub fn write_compare_plots(dir: &Path, plots: &[ComparePlot]) -> anyhow::Result<usize> {
    use anyhow::Context;
    for plot in plots {
        let path = dir.join(&plot.path);
        if let Some(parent) = path.parent() {
            mmtrack_io::create_output_dirs(parent).with_context(|| parent.display().to_string())?;
        }
        std::fs::write(&path, &plot.svg).with_context(|| path.display().to_string())?;
    }
    Ok(plots.len())
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;
    use std::path::PathBuf;

    use mmtrack_io::table::BeamSweepTracked;

    use super::*;
    use crate::beam::sweeps::analyze_beam_sweeps;

    fn row(tracker: &str, sweep: u64, loss_db: f64) -> BeamSweepTracked {
        BeamSweepTracked {
            tracker: tracker.into(),
            site: "s".into(),
            t_ns: sweep as i64 * 100_000_000,
            sweep,
            beam_count: 64,
            chosen_beam: 1,
            best_beam: 1,
            beams_measured: 3,
            reinitialised: sweep == 0,
            loss_db,
            gnss_beam: None,
        }
    }

    fn run(id: &str, loss_db: f64) -> (RunTables, RunResults) {
        let rows = vec![row("w", 0, 0.0), row("w", 1, loss_db), row("l", 0, 0.0), row("l", 1, 2.0 * loss_db)];
        let sweeps = analyze_beam_sweeps(BTreeMap::from([("pass".to_string(), rows)])).unwrap();
        let mut results = RunResults::default();
        results.beam.sweeps = sweeps;
        (RunTables { id: id.into(), tables: PathBuf::from(id) }, results)
    }

    #[test]
    fn beam_sweep_loss_cdfs_of_every_run_and_tracker_in_one_plot() {
        let (plots, text) = compare_plots(&[run("a", 1.0), run("b", 3.0)]).unwrap();
        assert_eq!(plots.len(), 1, "one sequence, one overlay");
        assert_eq!(plots[0].path, "plots/pass/loss_cdf_overlay.svg");
        for label in ["a / w", "a / l", "b / w", "b / l"] {
            assert!(plots[0].svg.contains(&format!(">\n{label}\n<")), "{label}");
        }
        assert!(text.contains("## Runs overlaid") && text.contains("### `pass` (beam sweeps)"), "{text}");
        assert!(text.contains("![loss CDF of every run and tracker](plots/pass/loss_cdf_overlay.svg)"), "{text}");
        // Nothing to overlay: no section.
        let empty = (RunTables { id: "c".into(), tables: PathBuf::from("c") }, RunResults::default());
        assert_eq!(compare_plots(&[empty]).unwrap().1, "");
    }
}
