//! What the artificial-channel experiment reports: the CSV files, the
//! targets and verdicts, `reproduce.md`, the README block and the figures
//! (drawn by `mmtrack_analysis::mpc_artificial`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use mmtrack_analysis::mpc_artificial::{self as plots, ArtificialTracker, SeparationBin, SweepPoint};
use mmtrack_io::Overwrite;

use super::config::SEPARATION_PLOT_POWERS_DB;
use super::run::Sweep;
use crate::model::{Claim, METRICS_FILE, Metric, Rule, Verdict, write_metrics};

/// The README block the summary replaces.
pub const README_BLOCK: &str = "reproduce-mpc-artificial";
/// Target: mean delay error below this ...
pub const TARGET_ERROR_NS: f64 = 0.03;
/// ... at this MPC power (proposed tracker, Kaiser window).
pub const TARGET_ERROR_POWER_DB: f64 = -116.0;
/// Target: two tracks in every run from the highest power down to this one.
pub const TARGET_TWO_TRACKS_DOWN_TO_DB: f64 = -126.0;
/// Target: mean delay error below this at -126 dB, where the proposed
/// tracker's tracks start to split ("at these power values is below 0.07
/// ns", Sec. IV-A, Fig. 5).
pub const TARGET_SPLIT_ERROR_NS: f64 = 0.07;
/// The paper's Fig. 4: GM-PHD starts to split at -124 dB.
const PAPER_GMPHD_SPLITS_AT_DB: f64 = -124.0;

/// The figures written next to results.csv: file name and what it shows.
pub const FIGURES: [(&str, &str); 3] = [
    ("tracks_vs_power.svg", "mean number of tracks vs MPC power (Fig. 4)"),
    ("delay_error_vs_power.svg", "mean delay error of the true tracks vs MPC power, log scale (Fig. 5)"),
    ("delay_error_vs_separation.svg", "mean delay error vs the MPCs' separation, proposed tracker, Kaiser window"),
];

/// Where the README's links to the figures point.
pub enum FiguresAt {
    /// The output directory relative to the README's directory.
    Relative(PathBuf),
    /// An output directory outside the README's directory (named, not linked).
    Elsewhere(PathBuf),
}

/// One paragraph on what was run.
fn description(sweep: &Sweep) -> String {
    let c = &sweep.channel;
    format!(
        "Two equal-power MPCs approaching from {:.1} to {:.1} ns over {} snapshots ({:.3} ms apart), noise floor \
         {} dB, {:.1} GHz carrier, {:.1} GHz band, {} sounder pulse; {}; {} Monte Carlo runs per point. Tracks have \
         at least 3 detections; a track is true when most of its points lie within 1 ns of a true MPC; delay \
         errors are those of the true tracks' points against the nearer true MPC.",
        c.start_separation_s * 1e9,
        c.end_separation_s * 1e9,
        c.snapshots,
        c.snapshot_interval_s * 1e3,
        c.sounder.noise_floor_db,
        c.sounder.carrier_hz / 1e9,
        c.sounder.bandwidth_hz / 1e9,
        sweep.pulse_name,
        if sweep.zero_below_threshold {
            "taps below floor + 6 dB zeroed before the search (the paper's step 1)"
        } else {
            "taps below floor + 6 dB kept (variant: --keep-taps-below-threshold)"
        },
        sweep.runs,
    )
}

/// The numbers `reproduce --all` checks, Kaiser window: at the target power
/// (-116 dB) and at -126 dB, each tracker's mean number of tracks and the
/// proposed tracker's mean delay error and share of runs with two tracks.
#[must_use]
pub fn metrics(sweep: &Sweep) -> Vec<Metric> {
    let mut out = Vec::new();
    for power in [TARGET_ERROR_POWER_DB, TARGET_TWO_TRACKS_DOWN_TO_DB] {
        for tracker in [ArtificialTracker::Proposed, ArtificialTracker::ProposedRefit, ArtificialTracker::GmPhd] {
            let Some(p) = sweep.point(power, true, tracker) else { continue };
            let name = tracker.name();
            out.push(Metric::new(format!("{name} mean tracks, {power} dB"), p.mean_tracks, "tracks", Some(2.0)));
            if tracker != ArtificialTracker::GmPhd {
                let paper = Some(if power == TARGET_ERROR_POWER_DB { TARGET_ERROR_NS } else { TARGET_SPLIT_ERROR_NS });
                if p.mean_delay_error_ns.is_finite() {
                    out.push(Metric::new(
                        format!("{name} mean delay error, {power} dB"),
                        p.mean_delay_error_ns,
                        "ns",
                        paper,
                    ));
                }
                let share = p.runs_with_two_tracks as f64 / p.runs.max(1) as f64;
                out.push(Metric::new(format!("{name} runs with two tracks, {power} dB"), share, "share", Some(1.0)));
            }
        }
    }
    out
}

/// The paper's claims on the proposed tracker, Kaiser window: the mean
/// delay error at the target power, two tracks in every run from the
/// highest power down to -126 dB (measured: the smallest share of such
/// runs), and the mean delay error below 0.07 ns at -126 dB, where the
/// tracks start to split. The same three for `proposed-refit` (ours),
/// beside them and not counted.
#[must_use]
pub fn verdicts(sweep: &Sweep) -> Vec<Verdict> {
    let mut out = tracker_verdicts(sweep, ArtificialTracker::Proposed, "proposed, Kaiser", false);
    let whose = "proposed, Kaiser, detections refitted without window or zeroing (ours)";
    out.extend(tracker_verdicts(sweep, ArtificialTracker::ProposedRefit, whose, true));
    out
}

/// The three claims of [`verdicts`] for `tracker`, labelled `whose`.
fn tracker_verdicts(sweep: &Sweep, tracker: ArtificialTracker, whose: &str, informational: bool) -> Vec<Verdict> {
    let counted = |claim: Claim| if informational { claim.informational() } else { claim };
    let error_ns = sweep.point(TARGET_ERROR_POWER_DB, true, tracker).map(|p| p.mean_delay_error_ns);
    let worst_band = sweep
        .bins
        .iter()
        .filter(|b| b.power_db == TARGET_ERROR_POWER_DB && b.kaiser_window && b.tracker == tracker)
        .filter(|b| b.mean_delay_error_ns.is_finite())
        .max_by(|a, b| a.mean_delay_error_ns.total_cmp(&b.mean_delay_error_ns))
        .map(|b| (format!("{}-{} ns", b.separation_ns.start, b.separation_ns.end), b.mean_delay_error_ns));
    let error = Claim::new(
        format!(
            "mean delay error below {TARGET_ERROR_NS} ns at {TARGET_ERROR_POWER_DB} dB, separations 20..2.5 ns ({whose})"
        ),
        "ns",
        Some(TARGET_ERROR_NS),
        format!("below {TARGET_ERROR_NS} ns"),
        Rule::Below { bound: TARGET_ERROR_NS },
    );
    let error_text = format!(
        "{}{}",
        error_ns.map_or("-".into(), |e| format!("{e:.4} ns")),
        worst_band.as_ref().map_or(String::new(), |(band, e)| format!("; largest in the {band} band: {e:.4} ns")),
    );
    // (power, runs with two tracks, runs) down to the target power.
    let two_tracks: Vec<(f64, u64, u64)> = sweep
        .powers_db()
        .into_iter()
        .filter(|&p| p >= TARGET_TWO_TRACKS_DOWN_TO_DB)
        .filter_map(|p| sweep.point(p, true, tracker))
        .map(|p| (p.power_db, p.runs_with_two_tracks, p.runs))
        .collect();
    let smallest_share = two_tracks.iter().map(|&(_, two, runs)| two as f64 / runs as f64).min_by(f64::total_cmp);
    let every_run_two = |p: &SweepPoint| p.runs_with_two_tracks == p.runs;
    let best = two_tracks.iter().max_by_key(|t| t.1);
    let at_target = two_tracks.iter().find(|t| t.0 == TARGET_TWO_TRACKS_DOWN_TO_DB);
    let runs = |t: Option<&(f64, u64, u64)>| t.map_or("-".into(), |t| format!("{}/{} runs at {} dB", t.1, t.2, t.0));
    let two = Claim::new(
        format!("two tracks in every run down to {TARGET_TWO_TRACKS_DOWN_TO_DB} dB ({whose})"),
        "share of runs",
        Some(1.0),
        "every run",
        Rule::AtLeast { bound: 1.0 },
    );
    let two_text = format!(
        "two tracks in every run {}; at best {}; {}; exactly two tracks on the true MPCs in every run {} (the other \
         tracks are made of noise detections)",
        down_to(sweep.down_to(true, tracker, every_run_two)),
        runs(best),
        runs(at_target),
        down_to(sweep.down_to(true, tracker, |p| p.runs_with_two_true_tracks == p.runs)),
    );
    let split_error_ns = sweep.point(TARGET_TWO_TRACKS_DOWN_TO_DB, true, tracker).map(|p| p.mean_delay_error_ns);
    let split_error = Claim::new(
        format!(
            "mean delay error below {TARGET_SPLIT_ERROR_NS} ns at {TARGET_TWO_TRACKS_DOWN_TO_DB} dB, where the \
             tracks start to split ({whose})"
        ),
        "ns",
        Some(TARGET_SPLIT_ERROR_NS),
        format!("below {TARGET_SPLIT_ERROR_NS} ns"),
        Rule::Below { bound: TARGET_SPLIT_ERROR_NS },
    );
    let split_text = split_error_ns.map_or("-".into(), |e| format!("{e:.4} ns"));
    vec![
        Verdict::judged(counted(error), error_ns, error_text),
        Verdict::judged(counted(two), smallest_share, two_text),
        Verdict::judged(counted(split_error), split_error_ns, split_text),
    ]
}

/// "down to P dB", or that it fails already at the highest power.
fn down_to(power: Option<f64>) -> String {
    power.map_or_else(|| "at no power (not even the highest)".to_string(), |p| format!("down to {p} dB"))
}

/// The targets, measured values and verdicts, plus the paper's other
/// observations for comparison.
fn verdict_table(sweep: &Sweep) -> String {
    let (proposed, gmphd, matched) =
        (ArtificialTracker::Proposed, ArtificialTracker::GmPhd, ArtificialTracker::GmPhdMatched);
    let every_run_two = |p: &SweepPoint| p.runs_with_two_tracks == p.runs;
    let error_at = |tracker| {
        sweep
            .point(TARGET_ERROR_POWER_DB, true, tracker)
            .map_or("-".into(), |p| format!("{:.4} ns", p.mean_delay_error_ns))
    };
    let mut out = String::from("| target | measured | verdict |\n|---|---|---|\n");
    for v in verdicts(sweep) {
        let _ = writeln!(out, "| {} | {} | {} |", v.claim.what, v.note, v.word());
    }
    let _ = writeln!(
        out,
        "| for comparison: GM-PHD splits from {PAPER_GMPHD_SPLITS_AT_DB} dB (paper, Fig. 4) | two tracks in every run \
         (Kaiser): {} with Table I, {} with the matched measurement noise | - |",
        down_to(sweep.down_to(true, gmphd, every_run_two)),
        down_to(sweep.down_to(true, matched, every_run_two)),
    );
    let _ = writeln!(
        out,
        "| for comparison: the proposed tracker's delay error is lower than GM-PHD's (paper, Fig. 5) | at \
         {TARGET_ERROR_POWER_DB} dB (Kaiser): proposed {}, GM-PHD (Table I) {}, GM-PHD (matched) {} | - |",
        error_at(proposed),
        error_at(gmphd),
        error_at(matched),
    );
    out
}

fn cell(p: Option<&SweepPoint>) -> String {
    p.map_or("-".into(), |p| format!("{:.2} / {:.4}", p.mean_tracks, p.mean_delay_error_ns))
}

/// One row per power: tracks / mean delay error for each tracker and window.
fn compact_table(sweep: &Sweep) -> String {
    let mut out = String::from(
        "Each cell: mean number of tracks / mean delay error of the true tracks (ns). `gm-phd-matched` is the \
         sensitivity variant with sigma_epsilon set to the proposed tracker's rms delay error at the same point.\n\n\
         `proposed-refit` is the proposed tracker on the same detections refitted without window or zeroing (ours).\n\n\
         | MPC power dB | proposed, Kaiser | runs with 2 tracks (2 true tracks) | proposed, no window | proposed-refit, \
         Kaiser | runs with 2 tracks (2 true tracks) | gm-phd, Kaiser | gm-phd, no window | gm-phd-matched, Kaiser \
         | gm-phd-matched, no window | matched sigma_epsilon mm (Kaiser / none) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for power_db in sweep.powers_db() {
        let at = |window, tracker| sweep.point(power_db, window, tracker);
        let proposed = at(true, ArtificialTracker::Proposed);
        let refit = at(true, ArtificialTracker::ProposedRefit);
        let two_runs = |p: Option<&SweepPoint>| {
            p.map_or("-".into(), |p| {
                format!("{}/{} ({}/{})", p.runs_with_two_tracks, p.runs, p.runs_with_two_true_tracks, p.runs)
            })
        };
        let sigma = |window| {
            at(window, ArtificialTracker::GmPhdMatched)
                .and_then(|p| p.sigma_measurement_m)
                .map_or("-".into(), |s| format!("{:.1}", s * 1e3))
        };
        let _ = writeln!(
            out,
            "| {power_db} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} / {} |",
            cell(proposed),
            two_runs(proposed),
            cell(at(false, ArtificialTracker::Proposed)),
            cell(refit),
            two_runs(refit),
            cell(at(true, ArtificialTracker::GmPhd)),
            cell(at(false, ArtificialTracker::GmPhd)),
            cell(at(true, ArtificialTracker::GmPhdMatched)),
            cell(at(false, ArtificialTracker::GmPhdMatched)),
            sigma(true),
            sigma(false),
        );
    }
    out
}

/// Mean delay error per separation band (columns) and power (rows) of one
/// tracker and window setting.
fn separation_table(sweep: &Sweep, tracker: ArtificialTracker, window: bool) -> String {
    let mine = |b: &&SeparationBin| b.tracker == tracker && b.kaiser_window == window;
    let mut bands: Vec<(f64, f64)> =
        sweep.bins.iter().filter(mine).map(|b| (b.separation_ns.start, b.separation_ns.end)).collect();
    bands.sort_by(|a, b| b.0.total_cmp(&a.0));
    bands.dedup();
    let mut out = String::from("| MPC power dB |");
    for (lo, hi) in &bands {
        let _ = write!(out, " {lo}-{hi} ns |");
    }
    let _ = write!(out, "\n|---|{}\n", "---|".repeat(bands.len()));
    for power_db in sweep.powers_db() {
        let _ = write!(out, "| {power_db} |");
        for band in &bands {
            let bin = sweep
                .bins
                .iter()
                .filter(mine)
                .find(|b| b.power_db == power_db && (b.separation_ns.start, b.separation_ns.end) == *band);
            let _ = write!(out, " {} |", bin.map_or("-".into(), |b| format!("{:.4}", b.mean_delay_error_ns)));
        }
        out.push('\n');
    }
    out
}

/// `reproduce.md`: everything, including the full per-point table.
#[must_use]
pub fn markdown(sweep: &Sweep) -> String {
    let mut out = format!("# reproduce mpc-artificial\n\n{}\n\n{}\n", description(sweep), verdict_table(sweep));
    out.push_str(&compact_table(sweep));
    out.push_str(
        "\n## All points\n\n| MPC power dB | window | tracker | mean tracks | on a true MPC | runs with 2 tracks | \
         runs with 2 true tracks | mean delay error ns | rms delay error ns | GM-PHD sigma_epsilon m |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for p in &sweep.points {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.2} | {:.2} | {}/{} | {}/{} | {:.4} | {:.4} | {} |",
            p.power_db,
            if p.kaiser_window { "Kaiser" } else { "none" },
            p.tracker.name(),
            p.mean_tracks,
            p.mean_true_tracks,
            p.runs_with_two_tracks,
            p.runs,
            p.runs_with_two_true_tracks,
            p.runs,
            p.mean_delay_error_ns,
            p.rms_delay_error_ns,
            p.sigma_measurement_m.map_or("-".into(), |s| format!("{s:.2e}")),
        );
    }
    out.push_str("\n## Mean delay error (ns) per separation band: proposed, Kaiser window\n\n");
    out.push_str(&separation_table(sweep, ArtificialTracker::Proposed, true));
    out.push_str("\n## Figures\n\n");
    for (name, what) in FIGURES {
        let _ = writeln!(out, "- [{name}]({name}): {what}");
    }
    out
}

/// The README block: description, verdicts, compact table and where the
/// figures are.
#[must_use]
pub fn readme_summary(sweep: &Sweep, figures: &FiguresAt) -> String {
    let mut out = format!(
        "Written by `mmtrack reproduce mpc-artificial --readme docs/results/multipath.md`. {}\n\n{}\n",
        description(sweep),
        verdict_table(sweep)
    );
    out.push_str(&compact_table(sweep));
    out.push('\n');
    match figures {
        FiguresAt::Relative(dir) => {
            let dir = dir.to_string_lossy().replace('\\', "/");
            out.push_str("Figures, written by the run next to its CSV files and reproduce.md (not committed):\n\n");
            for (name, what) in FIGURES {
                let _ = writeln!(out, "- [{name}]({dir}/{name}): {what}");
            }
        }
        FiguresAt::Elsewhere(dir) => {
            let names: Vec<&str> = FIGURES.iter().map(|f| f.0).collect();
            let _ = writeln!(out, "Figures: {} in `{}` (written by the run).", names.join(", "), dir.display());
        }
    }
    out
}

/// `results.csv`: one row per point.
fn csv(points: &[SweepPoint]) -> String {
    let mut out = String::from(
        "mpc_power_db,kaiser_window,tracker,mean_tracks,mean_true_tracks,runs_with_two_tracks,\
         runs_with_two_true_tracks,runs,mean_delay_error_ns,rms_delay_error_ns,gmphd_sigma_measurement_m\n",
    );
    for p in points {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{}",
            p.power_db,
            p.kaiser_window,
            p.tracker.name(),
            p.mean_tracks,
            p.mean_true_tracks,
            p.runs_with_two_tracks,
            p.runs_with_two_true_tracks,
            p.runs,
            p.mean_delay_error_ns,
            p.rms_delay_error_ns,
            p.sigma_measurement_m.map_or(String::new(), |s| s.to_string()),
        );
    }
    out
}

/// `results_by_separation.csv`: one row per point and separation band.
fn separation_csv(bins: &[SeparationBin]) -> String {
    let mut out = String::from(
        "mpc_power_db,kaiser_window,tracker,separation_min_ns,separation_max_ns,points,truth_points,mean_delay_error_ns\n",
    );
    for b in bins {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{}",
            b.power_db,
            b.kaiser_window,
            b.tracker.name(),
            b.separation_ns.start,
            b.separation_ns.end,
            b.points,
            b.truth_points,
            b.mean_delay_error_ns,
        );
    }
    out
}

/// Writes `results.csv`, `results_by_separation.csv`, `reproduce.md`
/// (`markdown`), `metrics.json` and the figures into `output` (created if
/// needed; files of an earlier run are replaced one by one); returns the
/// files written.
///
/// # Errors
/// A file or figure cannot be written.
pub fn write_outputs(output: &Path, sweep: &Sweep, markdown: &str, metrics: &[Metric]) -> anyhow::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(output).with_context(|| output.display().to_string())?;
    write_atomically(&output.join("results.csv"), &csv(&sweep.points))?;
    write_atomically(&output.join("results_by_separation.csv"), &separation_csv(&sweep.bins))?;
    write_atomically(&output.join("reproduce.md"), markdown)?;
    write_metrics(output, metrics)?;
    write_figures(sweep, output)?;
    let mut files: Vec<PathBuf> = ["results.csv", "results_by_separation.csv", "reproduce.md", METRICS_FILE]
        .into_iter()
        .chain(FIGURES.iter().map(|f| f.0))
        .map(|name| output.join(name))
        .collect();
    files.sort();
    Ok(files)
}

fn write_atomically(path: &Path, text: &str) -> anyhow::Result<()> {
    mmtrack_io::atomic::write_file(path, text.as_bytes(), Overwrite::Replace)?;
    Ok(())
}

/// The figures, next to results.csv (names in [`FIGURES`]).
fn write_figures(sweep: &Sweep, dir: &Path) -> anyhow::Result<()> {
    let [tracks, error, separation] = FIGURES;
    let svgs = [
        (tracks.0, plots::tracks_vs_power_svg(&sweep.points, TARGET_TWO_TRACKS_DOWN_TO_DB)?),
        (error.0, plots::delay_error_vs_power_svg(&sweep.points, TARGET_ERROR_NS, TARGET_ERROR_POWER_DB)?),
        (
            separation.0,
            plots::delay_error_vs_separation_svg(
                &sweep.bins,
                ArtificialTracker::Proposed,
                true,
                &SEPARATION_PLOT_POWERS_DB,
                TARGET_ERROR_NS,
            )?,
        ),
    ];
    for (name, svg) in svgs {
        write_atomically(&dir.join(name), &svg)?;
    }
    Ok(())
}

/// Where a README at `readme` finds the figures in `output`: the output
/// directory relative to the README's directory when it lies below it,
/// else the path as given.
#[must_use]
pub fn figures_location(readme: &Path, output: &Path) -> FiguresAt {
    let readme_dir = match readme.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    match (readme_dir.canonicalize(), output.canonicalize()) {
        (Ok(base), Ok(out)) => match out.strip_prefix(&base) {
            Ok(relative) => FiguresAt::Relative(relative.to_path_buf()),
            Err(_) => FiguresAt::Elsewhere(output.to_path_buf()),
        },
        _ => FiguresAt::Elsewhere(output.to_path_buf()),
    }
}
