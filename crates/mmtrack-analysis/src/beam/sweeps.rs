//! Beam-sweep tracking on measured codebooks: the accounting of table
//! `beam_sweeps_tracked` (`mmtrack process beam`) per sequence and pooled
//! per site, its report section and the data of its plots.
//!
//! For each tracker: mean, median and 90th-percentile received-power loss
//! of the chosen beam against each full sweep's best beam (`10 log10(P_best
//! / P_chosen)`, as the table gives it), the share of sweeps whose chosen
//! beam is the best (top-1) or within one beam of it, the mean beams
//! measured per sweep (a full sweep counts every beam) and the
//! re-initialisations. The formulas are those of `mmtrack_beam`'s
//! `SweepSummary` (losses summed in ascending order), so the pooled numbers
//! equal what that crate reports on the same sweeps.

use std::collections::BTreeMap;
use std::fmt::Write;

use mmtrack_io::table::BeamSweepTracked;

use super::plots::{BeamIndexSeries, LossCurve};
use mmtrack_io::table::{BeamSweepPooledRow, BeamSweepSummaryRow};

/// Files of the plots of one sequence (under `plots/<sequence>/`) and of a
/// site (under `plots/site=<site>/`), with their captions.
pub const SEQUENCE_PLOTS: [(&str, &str); 2] =
    [("beam_index.svg", "beam index over time: best vs chosen"), ("loss_cdf.svg", "loss CDF")];
/// The plot of a site, pooled over its sequences.
pub const SITE_PLOT: (&str, &str) = ("loss_cdf.svg", "loss CDF, every pass pooled");

/// The summary of `rows` (one tracker, one site), `None` for none.
#[must_use]
pub fn summarise(tracker: &str, site: &str, passes: u64, rows: &[&BeamSweepTracked]) -> Option<BeamSweepSummaryRow> {
    if rows.is_empty() {
        return None;
    }
    let n = rows.len() as f64;
    let mut losses: Vec<f64> = rows.iter().map(|r| r.loss_db).collect();
    losses.sort_by(f64::total_cmp);
    let middle = losses.len() / 2;
    let median_loss_db =
        if losses.len() % 2 == 1 { losses[middle] } else { 0.5 * (losses[middle - 1] + losses[middle]) };
    // Nearest rank: the smallest loss with at least 90 % of the sweeps at or below it.
    let rank = ((0.9 * n).ceil() as usize).clamp(1, losses.len());
    let share = |ok: &dyn Fn(&BeamSweepTracked) -> bool| rows.iter().filter(|r| ok(r)).count() as f64 / n;
    Some(BeamSweepSummaryRow {
        tracker: tracker.to_string(),
        site: site.to_string(),
        passes,
        sweeps: rows.len() as u64,
        beam_count: rows.iter().map(|r| r.beam_count).max().unwrap_or(0),
        mean_loss_db: losses.iter().sum::<f64>() / n,
        median_loss_db,
        p90_loss_db: losses[rank - 1],
        top1: share(&|r| r.chosen_beam == r.best_beam),
        within_one: share(&|r| r.chosen_beam.abs_diff(r.best_beam) <= 1),
        mean_beams_per_sweep: rows.iter().map(|r| f64::from(r.beams_measured)).sum::<f64>() / n,
        reinitialisations: rows.iter().filter(|r| r.reinitialised).count() as u64,
    })
}

/// One sequence: its rows and one summary per tracker.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamSequenceResult {
    /// Sequence id.
    pub sequence: String,
    /// Its site.
    pub site: String,
    /// The table's rows.
    pub rows: Vec<BeamSweepTracked>,
    /// One row per tracker, in the table's order.
    pub summary: Vec<BeamSweepSummaryRow>,
}

/// Everything computed from `beam_sweeps_tracked`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BeamSweepResults {
    /// Per sequence, in sequence order.
    pub sequences: Vec<BeamSequenceResult>,
    /// Per site (sorted) and tracker (table order).
    pub pooled: Vec<BeamSweepPooledRow>,
}

impl BeamSweepResults {
    /// Whether there is nothing.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.sequences.is_empty()
    }
}

/// Trackers in order of first appearance.
fn trackers<'a>(rows: impl Iterator<Item = &'a BeamSweepTracked>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for r in rows {
        if !out.contains(&r.tracker) {
            out.push(r.tracker.clone());
        }
    }
    out
}

/// Checks the rows of one sequence: finite, non-negative losses, beams
/// inside the codebook, one site.
fn check(sequence: &str, rows: &[BeamSweepTracked]) -> Result<String, String> {
    let site = rows.first().map(|r| r.site.clone()).ok_or_else(|| format!("sequence {sequence}: no rows"))?;
    for (index, r) in rows.iter().enumerate() {
        let bad =
            |what: String| Err(format!("sequence {sequence}: row {index} ({} at {} ns): {what}", r.tracker, r.t_ns));
        if !(r.loss_db.is_finite() && r.loss_db >= 0.0) {
            return bad(format!("loss_db {}, expected a finite loss >= 0 dB", r.loss_db));
        }
        if r.chosen_beam >= r.beam_count || r.best_beam >= r.beam_count {
            return bad(format!(
                "chosen_beam {} / best_beam {} outside a codebook of {} beams",
                r.chosen_beam, r.best_beam, r.beam_count
            ));
        }
        if r.site != site {
            return bad(format!("site {} differs from the sequence's first row ({site})", r.site));
        }
    }
    Ok(site)
}

/// Summaries of every sequence of `tables` (sequence -> rows) and pooled
/// per site.
///
/// # Errors
/// A message naming the sequence and row for an empty partition, a loss
/// that is not finite and non-negative, a beam outside the codebook, or two
/// sites in one sequence.
pub fn analyze_beam_sweeps(tables: BTreeMap<String, Vec<BeamSweepTracked>>) -> Result<BeamSweepResults, String> {
    let mut sequences = Vec::new();
    for (sequence, rows) in tables {
        let site = check(&sequence, &rows)?;
        let summary = trackers(rows.iter())
            .iter()
            .filter_map(|t| {
                let mine: Vec<&BeamSweepTracked> = rows.iter().filter(|r| &r.tracker == t).collect();
                summarise(t, &site, 1, &mine)
            })
            .collect();
        sequences.push(BeamSequenceResult { sequence, site, rows, summary });
    }
    let mut sites: BTreeMap<&str, Vec<&BeamSequenceResult>> = BTreeMap::new();
    for s in &sequences {
        sites.entry(&s.site).or_default().push(s);
    }
    let mut pooled = Vec::new();
    for (site, members) in &sites {
        for tracker in trackers(members.iter().flat_map(|s| s.rows.iter())) {
            let rows: Vec<&BeamSweepTracked> =
                members.iter().flat_map(|s| s.rows.iter()).filter(|r| r.tracker == tracker).collect();
            let passes = members.iter().filter(|s| s.rows.iter().any(|r| r.tracker == tracker)).count() as u64;
            pooled.extend(summarise(&tracker, site, passes, &rows).map(BeamSweepPooledRow));
        }
    }
    Ok(BeamSweepResults { sequences, pooled })
}

/// The best beam of each sweep of a sequence (from its first tracker's
/// rows) and each tracker's chosen beam, times from the first sweep.
#[must_use]
pub fn beam_index_series(result: &BeamSequenceResult) -> (BeamIndexSeries, Vec<BeamIndexSeries>) {
    let t0 = result.rows.iter().map(|r| r.t_ns).min().unwrap_or(0);
    let t_s = |r: &BeamSweepTracked| (r.t_ns - t0) as f64 * 1e-9;
    let names = trackers(result.rows.iter());
    let of = |name: &str| -> Vec<&BeamSweepTracked> { result.rows.iter().filter(|r| r.tracker == name).collect() };
    let first = names.first().map(String::as_str).unwrap_or_default();
    let best = BeamIndexSeries {
        label: "best beam".into(),
        t_s: of(first).into_iter().map(t_s).collect(),
        beam: of(first).into_iter().map(|r| f64::from(r.best_beam)).collect(),
    };
    let chosen = names
        .iter()
        .map(|name| BeamIndexSeries {
            label: name.clone(),
            t_s: of(name).into_iter().map(t_s).collect(),
            beam: of(name).into_iter().map(|r| f64::from(r.chosen_beam)).collect(),
        })
        .collect();
    (best, chosen)
}

/// One loss curve per tracker of `rows`.
#[must_use]
pub fn loss_curves<'a>(rows: impl Iterator<Item = &'a BeamSweepTracked> + Clone) -> Vec<LossCurve> {
    trackers(rows.clone())
        .into_iter()
        .map(|name| LossCurve {
            loss_db: rows.clone().filter(|r| r.tracker == name).map(|r| r.loss_db).collect(),
            label: name,
        })
        .collect()
}

/// The plot directory of a site, relative to `plots/`.
#[must_use]
pub fn site_plot_dir(site: &str) -> String {
    format!("site={site}")
}

fn summary_cells(s: &BeamSweepSummaryRow) -> String {
    format!(
        "{:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.2} | {}",
        s.mean_loss_db,
        s.median_loss_db,
        s.p90_loss_db,
        s.top1,
        s.within_one,
        s.mean_beams_per_sweep,
        s.reinitialisations
    )
}

/// The report section.
pub fn section(out: &mut String, results: &BeamSweepResults) {
    out.push_str(
        "## Beam sweeps (table `beam_sweeps_tracked`)\n\n\
         Each sweep's loss is 10 log10(P_best / P_chosen) of the tracker's chosen beam against the best beam of the \
         full measured sweep; beams are those the tracker measured in the sweep (a full sweep counts every beam, a \
         re-acquisition its beams); re-initialisations count pass starts. Pooled rows weight every sweep once.\n\n\
         ### Pooled per site\n\n\
         | site | tracker | passes | sweeps | mean loss (dB) | median loss (dB) | p90 loss (dB) | top-1 | within one \
         | beams per sweep | re-initialisations |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for BeamSweepPooledRow(s) in &results.pooled {
        let _ = writeln!(out, "| {} | {} | {} | {} | {} |", s.site, s.tracker, s.passes, s.sweeps, summary_cells(s));
    }
    out.push('\n');
    let mut sites: Vec<&str> = results.pooled.iter().map(|p| p.0.site.as_str()).collect();
    sites.dedup();
    for site in sites {
        let _ = writeln!(out, "![{site}: {}](plots/{}/{})", SITE_PLOT.1, site_plot_dir(site), SITE_PLOT.0);
    }
    out.push_str(
        "\n### Per sequence\n\n| sequence | tracker | sweeps | mean loss (dB) | median loss (dB) | p90 loss (dB) | top-1 \
         | within one | beams per sweep | re-initialisations |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &results.sequences {
        for s in &r.summary {
            let _ = writeln!(out, "| {} | {} | {} | {} |", r.sequence, s.tracker, s.sweeps, summary_cells(s));
        }
    }
    out.push('\n');
    for r in &results.sequences {
        let _ = writeln!(out, "### `{}` (beam sweeps)\n", r.sequence);
        for (file, caption) in SEQUENCE_PLOTS {
            let _ = writeln!(out, "![{caption}](plots/{}/{file})", r.sequence);
        }
        out.push('\n');
    }
}

/// One line per site and tracker, as the CLI prints it.
#[must_use]
pub fn one_lines(results: &BeamSweepResults) -> Vec<String> {
    results
        .pooled
        .iter()
        .map(|BeamSweepPooledRow(s)| {
            format!(
                "{} ({} passes, {} sweeps) {}: mean loss {:.3} dB, median {:.3} dB, top-1 {:.3}, within one {:.3}, \
                 {:.2} beams per sweep, {} re-initialisations",
                s.site,
                s.passes,
                s.sweeps,
                s.tracker,
                s.mean_loss_db,
                s.median_loss_db,
                s.top1,
                s.within_one,
                s.mean_beams_per_sweep,
                s.reinitialisations
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(tracker: &str, sweep: u64, chosen: u32, best: u32, beams: u32, loss_db: f64) -> BeamSweepTracked {
        BeamSweepTracked {
            tracker: tracker.into(),
            site: "s".into(),
            t_ns: sweep as i64 * 100_000_000,
            sweep,
            beam_count: 64,
            chosen_beam: chosen,
            best_beam: best,
            beams_measured: beams,
            reinitialised: sweep == 0,
            loss_db,
            gnss_beam: None,
        }
    }

    #[test]
    fn summaries_per_sequence_and_pooled_by_hand() {
        let a = vec![
            row("w", 0, 10, 10, 17, 0.0),
            row("w", 1, 11, 12, 3, 1.0),
            row("w", 2, 15, 12, 5, 4.0),
            row("l", 0, 10, 10, 64, 0.0),
        ];
        let b = vec![row("w", 0, 20, 20, 17, 0.0), row("w", 1, 20, 21, 3, 0.5)];
        let results = analyze_beam_sweeps(BTreeMap::from([("a".into(), a), ("b".into(), b)])).unwrap();
        let w = &results.sequences[0].summary[0];
        assert_eq!((w.tracker.as_str(), w.sweeps, w.reinitialisations), ("w", 3, 1));
        // Losses 0, 1, 4: mean 5/3, median 1, p90 the 3rd of 3; top-1 1 of 3,
        // within one 2 of 3; beams (17 + 3 + 5) / 3.
        assert_eq!((w.mean_loss_db, w.median_loss_db, w.p90_loss_db), (5.0 / 3.0, 1.0, 4.0));
        assert_eq!((w.top1, w.within_one, w.mean_beams_per_sweep), (1.0 / 3.0, 2.0 / 3.0, 25.0 / 3.0));
        assert_eq!(results.sequences[0].summary[1].tracker, "l");
        let pooled_w = &results.pooled[0].0;
        // Pooled: losses 0, 0, 0.5, 1, 4 -> median 0.5, p90 rank ceil(4.5) = 5.
        assert_eq!((pooled_w.passes, pooled_w.sweeps, pooled_w.median_loss_db, pooled_w.p90_loss_db), (2, 5, 0.5, 4.0));
        assert_eq!(pooled_w.mean_loss_db, (0.0 + 0.0 + 0.5 + 1.0 + 4.0) / 5.0);
        assert_eq!(results.pooled[1].0.passes, 1, "tracker l ran on one sequence");
        let mut text = String::new();
        section(&mut text, &results);
        assert!(text.contains("| s | w | 2 | 5 | 1.100 | 0.500 | 4.000 |"), "{text}");
        assert!(text.contains("plots/site=s/loss_cdf.svg") && text.contains("plots/a/beam_index.svg"), "{text}");
    }

    #[test]
    fn bad_rows_are_errors_naming_sequence_and_row() {
        let mut rows = vec![row("w", 0, 1, 1, 3, 0.0), row("w", 1, 1, 2, 3, f64::NAN)];
        let err = analyze_beam_sweeps(BTreeMap::from([("p1".into(), rows.clone())])).unwrap_err();
        assert!(err.contains("sequence p1: row 1 (w at 100000000 ns): loss_db NaN"), "{err}");
        rows[1].loss_db = 0.1;
        rows[1].best_beam = 64;
        let err = analyze_beam_sweeps(BTreeMap::from([("p1".into(), rows.clone())])).unwrap_err();
        assert!(err.contains("outside a codebook of 64 beams"), "{err}");
        rows[1].best_beam = 2;
        rows[1].site = "other".into();
        let err = analyze_beam_sweeps(BTreeMap::from([("p1".into(), rows)])).unwrap_err();
        assert!(err.contains("site other differs"), "{err}");
    }
}
