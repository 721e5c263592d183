//! SPEBT beam tracking (Liu et al. 2024) in `mmtrack analyze`: the tables
//! `spebt_summary` and `spebt_per_slot` that `mmtrack process beam --tracker
//! spebt` (or `mmtrack reproduce spebt`) wrote, checked against each other,
//! pooled over sequences, with the paper's Fig. 5 figure per sequence.
//!
//! Pooling rule: each sequence's RMSE covers its `(slots - 1) x runs`
//! tracked estimates (slot 0 is the initial access), so the pooled RMSE is
//! `sqrt(sum_i n_i RMSE_i^2 / sum_i n_i)`, the RMS over every estimate of
//! every sequence; the re-initialisation share is every re-initialisation
//! over every tracked slot of every run. One row per experiment kind
//! (`pose-error-model`, `radar-odometry`): they are different inputs and are
//! never pooled together.

use std::fmt::Write;

use super::spebt_plots::SpebtTrackingSeries;
use mmtrack_io::table::{SpebtPooledRow, SpebtSlotRow, SpebtSummaryRow};

/// The figure of one sequence, with its caption.
pub const SEQUENCE_PLOT: (&str, &str) = ("spebt_tracking.svg", "run 0 against the truth (Liu et al. Fig. 5)");

/// Relative tolerance between `spebt_summary`'s RMSE and the one
/// recomputed from `spebt_per_slot` (both are f64 sums of the same squares
/// in a different order).
const CONSISTENCY_TOLERANCE: f64 = 1e-6;

/// One sequence: its summary row and slots.
#[derive(Debug, Clone, PartialEq)]
pub struct SpebtSequenceResult {
    /// Sequence id (the partition).
    pub sequence: String,
    /// The sequence's `spebt_summary` row.
    pub summary: SpebtSummaryRow,
    /// The sequence's `spebt_per_slot` rows, slot 0 first.
    pub per_slot: Vec<SpebtSlotRow>,
}

impl SpebtSequenceResult {
    /// Run 0 against the truth, for [`super::spebt_plots::spebt_tracking_svg`].
    #[must_use]
    pub fn tracking_series(&self) -> SpebtTrackingSeries {
        let mut s = SpebtTrackingSeries::default();
        for r in &self.per_slot {
            s.true_gain.push(r.true_gain);
            s.true_aod_deg.push(r.true_aod_rad.to_degrees());
            s.true_aoa_deg.push(r.true_aoa_rad.to_degrees());
            s.estimate_gain.push(r.run0_gain);
            s.estimate_aod_deg.push(r.run0_aod_rad.to_degrees());
            s.estimate_aoa_deg.push(r.run0_aoa_rad.to_degrees());
            s.reinitialised.push(r.run0_reinitialised);
        }
        s
    }
}

/// Everything computed from the SPEBT tables.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SpebtResults {
    /// Per sequence, in sequence order.
    pub sequences: Vec<SpebtSequenceResult>,
    /// Per experiment kind, in order of first appearance.
    pub pooled: Vec<SpebtPooledRow>,
}

impl SpebtResults {
    /// Whether there is nothing.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.sequences.is_empty()
    }
}

/// Checks one sequence's tables and builds its result.
///
/// # Errors
/// A message naming the sequence (and slot and column) when the summary is
/// not exactly one row, a slot is missing or out of order, a value is not
/// finite, or the summary's RMSE differs from the one the slots give.
pub fn sequence_result(
    sequence: &str,
    summary: Vec<SpebtSummaryRow>,
    per_slot: Vec<SpebtSlotRow>,
) -> Result<SpebtSequenceResult, String> {
    let [summary]: [SpebtSummaryRow; 1] = summary.try_into().map_err(|rows: Vec<SpebtSummaryRow>| {
        format!("sequence {sequence}: table spebt_summary has {} rows, expected one per sequence", rows.len())
    })?;
    if summary.slots < 2 || summary.runs == 0 {
        return Err(format!(
            "sequence {sequence}: spebt_summary has slots {} and runs {}; expected at least 2 slots and 1 run",
            summary.slots, summary.runs
        ));
    }
    if per_slot.len() as u64 != summary.slots {
        return Err(format!(
            "sequence {sequence}: spebt_per_slot has {} rows but spebt_summary says {} slots",
            per_slot.len(),
            summary.slots
        ));
    }
    for (k, r) in per_slot.iter().enumerate() {
        if r.slot != k as u64 {
            return Err(format!("sequence {sequence}: spebt_per_slot row {k} is slot {}; expected slot {k}", r.slot));
        }
        let columns = [
            ("true_gain", r.true_gain),
            ("true_aod_rad", r.true_aod_rad),
            ("true_aoa_rad", r.true_aoa_rad),
            ("run0_gain", r.run0_gain),
            ("run0_aod_rad", r.run0_aod_rad),
            ("run0_aoa_rad", r.run0_aoa_rad),
            ("rmse_gain_pct", r.rmse_gain_pct),
            ("rmse_aod_rad", r.rmse_aod_rad),
            ("rmse_aoa_rad", r.rmse_aoa_rad),
            ("reinitialisation_rate", r.reinitialisation_rate),
        ];
        if let Some((name, value)) = columns.iter().find(|(_, v)| !v.is_finite()) {
            return Err(format!("sequence {sequence}: spebt_per_slot slot {k}: {name} is {value}, expected finite"));
        }
    }
    // The summary's RMSE over the tracked slots equals the RMS of the
    // per-slot RMSEs (every slot holds the same runs).
    let tracked = &per_slot[1..];
    let rms =
        |f: fn(&SpebtSlotRow) -> f64| (tracked.iter().map(|r| f(r) * f(r)).sum::<f64>() / tracked.len() as f64).sqrt();
    let checks = [
        ("rmse_gain_pct", summary.rmse_gain_pct, rms(|r| r.rmse_gain_pct)),
        ("rmse_aod_rad", summary.rmse_aod_rad, rms(|r| r.rmse_aod_rad)),
        ("rmse_aoa_rad", summary.rmse_aoa_rad, rms(|r| r.rmse_aoa_rad)),
    ];
    for (name, stated, from_slots) in checks {
        let scale = stated.abs().max(from_slots.abs()).max(1e-12);
        if !stated.is_finite() || (stated - from_slots).abs() > CONSISTENCY_TOLERANCE * scale {
            return Err(format!(
                "sequence {sequence}: spebt_summary.{name} is {stated} but spebt_per_slot gives {from_slots}: the two \
                 tables are not from the same run"
            ));
        }
    }
    Ok(SpebtSequenceResult { sequence: sequence.to_string(), summary, per_slot })
}

/// Pools `sequences` per experiment kind (module docs).
#[must_use]
pub fn pool(sequences: &[SpebtSequenceResult]) -> Vec<SpebtPooledRow> {
    let mut kinds: Vec<&str> = Vec::new();
    for s in sequences {
        if !kinds.contains(&s.summary.experiment.as_str()) {
            kinds.push(&s.summary.experiment);
        }
    }
    kinds
        .into_iter()
        .map(|kind| {
            let members: Vec<&SpebtSummaryRow> =
                sequences.iter().map(|s| &s.summary).filter(|s| s.experiment == kind).collect();
            let weight = |s: &SpebtSummaryRow| (s.slots - 1) * s.runs;
            let estimates: u64 = members.iter().map(|s| weight(s)).sum();
            let pooled = |f: fn(&SpebtSummaryRow) -> f64| {
                (members.iter().map(|s| weight(s) as f64 * f(s) * f(s)).sum::<f64>() / estimates as f64).sqrt()
            };
            let reinitialisations: f64 = members.iter().map(|s| s.reinitialisations_mean * s.runs as f64).sum();
            let first = members[0];
            SpebtPooledRow {
                experiment: kind.to_string(),
                sequences: members.len() as u64,
                tracked_estimates: estimates,
                rmse_gain_pct: pooled(|s| s.rmse_gain_pct),
                rmse_aod_rad: pooled(|s| s.rmse_aod_rad),
                rmse_aoa_rad: pooled(|s| s.rmse_aoa_rad),
                reinitialisation_share_pct: 100.0 * reinitialisations / estimates as f64,
                paper_rmse_gain_pct: first.paper_rmse_gain_pct,
                paper_rmse_aod_rad: first.paper_rmse_aod_rad,
                paper_rmse_aoa_rad: first.paper_rmse_aoa_rad,
                paper_reinitialisation_share_pct: first.paper_reinitialisation_share_pct,
            }
        })
        .collect()
}

/// A paper's number, stored in radians, back in the degrees the paper
/// prints (rounded to 9 decimals, so 0.22 deg reads 0.22 again).
fn paper_deg(rad: f64) -> f64 {
    (rad.to_degrees() * 1e9).round() / 1e9
}

/// The report section (angles in degrees, as the paper reports them).
pub fn section(out: &mut String, results: &SpebtResults) {
    out.push_str(
        "## SPEBT beam tracking (tables `spebt_summary`, `spebt_per_slot`)\n\n\
         RMSE over every tracked slot (slot 0, the initial access, excluded) of every run, against the simulated \
         link's true channel (Liu et al. 2024, Table III); re-initialisations per tracked slot (Algorithm 1). Pooled \
         rows weight each sequence by its (slots - 1) x runs estimates; the paper's numbers in brackets.\n\n\
         ### Pooled\n\n\
         | experiment | sequences | estimates | abs(alpha) RMSE (%) | AoD RMSE (deg) | AoA RMSE (deg) | \
         re-initialisations (%) |\n|---|---|---|---|---|---|---|\n",
    );
    for p in &results.pooled {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.2} [{}] | {:.3} [{}] | {:.2} [{}] | {:.2} [{:.1}] |",
            p.experiment,
            p.sequences,
            p.tracked_estimates,
            p.rmse_gain_pct,
            p.paper_rmse_gain_pct,
            p.rmse_aod_rad.to_degrees(),
            paper_deg(p.paper_rmse_aod_rad),
            p.rmse_aoa_rad.to_degrees(),
            paper_deg(p.paper_rmse_aoa_rad),
            p.reinitialisation_share_pct,
            p.paper_reinitialisation_share_pct
        );
    }
    out.push_str(
        "\n### Per sequence\n\n| sequence | experiment | slots | runs | abs(alpha) RMSE (%) | AoD RMSE (deg) | \
         AoA RMSE (deg) | re-initialisations (%) |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in &results.sequences {
        let s = &r.summary;
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {:.2} | {:.3} | {:.2} | {:.2} |",
            r.sequence,
            s.experiment,
            s.slots,
            s.runs,
            s.rmse_gain_pct,
            s.rmse_aod_rad.to_degrees(),
            s.rmse_aoa_rad.to_degrees(),
            s.reinitialisation_share_pct,
        );
    }
    out.push('\n');
    for r in &results.sequences {
        let _ = writeln!(
            out,
            "### `{}` (SPEBT)\n\n![{}](plots/{}/{})\n",
            r.sequence, SEQUENCE_PLOT.1, r.sequence, SEQUENCE_PLOT.0
        );
    }
}

/// One line per experiment kind, as the CLI prints it.
#[must_use]
pub fn one_lines(results: &SpebtResults) -> Vec<String> {
    results
        .pooled
        .iter()
        .map(|p| {
            format!(
                "spebt {} ({} sequences, {} estimates): RMSE abs(alpha) {:.2} %, AoD {:.3} deg, AoA {:.2} deg, \
                 re-initialisations {:.2} % of slots (paper {} %, {} deg, {} deg, {:.1} %)",
                p.experiment,
                p.sequences,
                p.tracked_estimates,
                p.rmse_gain_pct,
                p.rmse_aod_rad.to_degrees(),
                p.rmse_aoa_rad.to_degrees(),
                p.reinitialisation_share_pct,
                p.paper_rmse_gain_pct,
                paper_deg(p.paper_rmse_aod_rad),
                paper_deg(p.paper_rmse_aoa_rad),
                p.paper_reinitialisation_share_pct
            )
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn summary(
        experiment: &str,
        slots: u64,
        runs: u64,
        rmse: [f64; 3],
        reinit_mean: f64,
    ) -> SpebtSummaryRow {
        SpebtSummaryRow {
            experiment: experiment.into(),
            trajectory: "t".into(),
            slots,
            runs,
            seed: 1,
            rmse_gain_pct: rmse[0],
            rmse_aod_rad: rmse[1].to_radians(),
            rmse_aoa_rad: rmse[2].to_radians(),
            rmse_gain_before_reset_pct: rmse[0],
            rmse_aod_before_reset_rad: rmse[1].to_radians(),
            rmse_aoa_before_reset_rad: rmse[2].to_radians(),
            reinitialisations_mean: reinit_mean,
            reinitialisations_min: 0,
            reinitialisations_max: 1,
            reinitialisation_share_pct: 100.0 * reinit_mean / (slots - 1) as f64,
            reinit_gain_pct: 0.0,
            reinit_aod_pct: 100.0,
            reinit_aoa_pct: 0.0,
            paper_rmse_gain_pct: 0.3,
            paper_rmse_aod_rad: 0.22f64.to_radians(),
            paper_rmse_aoa_rad: 4.6f64.to_radians(),
            paper_reinitialisation_share_pct: 4.7,
        }
    }

    fn slot(k: u64, rmse: [f64; 3]) -> SpebtSlotRow {
        SpebtSlotRow {
            slot: k,
            t_ns: 250_000_000 * k as i64,
            x_m: 0.0,
            y_m: 0.0,
            yaw_rad: 0.0,
            range_m: 100.0,
            true_gain: 1e-6,
            true_aod_rad: 10f64.to_radians(),
            true_aoa_rad: -20f64.to_radians(),
            run0_gain: 1.1e-6,
            run0_aod_rad: 10.1f64.to_radians(),
            run0_aoa_rad: -21f64.to_radians(),
            run0_reinitialised: false,
            rmse_gain_pct: rmse[0],
            rmse_aod_rad: rmse[1].to_radians(),
            rmse_aoa_rad: rmse[2].to_radians(),
            reinitialisation_rate: 0.0,
        }
    }

    #[test]
    fn pooled_rmse_weights_each_estimate_once_by_hand() {
        // Sequence a: 3 slots, 2 runs (4 estimates), slot RMSEs 1 and 3 deg
        // -> RMSE sqrt(5). Sequence b: 2 slots, 4 runs (4 estimates), 2 deg.
        let a = sequence_result(
            "a",
            vec![summary("radar-odometry", 3, 2, [1.0, 5f64.sqrt(), 2.0], 1.0)],
            vec![slot(0, [9.0; 3]), slot(1, [1.0, 1.0, 2.0]), slot(2, [1.0, 3.0, 2.0])],
        )
        .unwrap();
        let b = sequence_result(
            "b",
            vec![summary("radar-odometry", 2, 4, [1.0, 2.0, 2.0], 0.5)],
            vec![slot(0, [0.0; 3]), slot(1, [1.0, 2.0, 2.0])],
        )
        .unwrap();
        let other = sequence_result(
            "c",
            vec![summary("pose-error-model", 2, 1, [7.0; 3], 0.0)],
            vec![slot(0, [0.0; 3]), slot(1, [7.0; 3])],
        )
        .unwrap();
        let pooled = pool(&[a, b, other]);
        assert_eq!(pooled.len(), 2, "experiment kinds are never pooled together");
        let p = &pooled[0];
        assert_eq!((p.experiment.as_str(), p.sequences, p.tracked_estimates), ("radar-odometry", 2, 8));
        // (4 x 5 + 4 x 4) / 8 = 4.5.
        assert!((p.rmse_aod_rad.to_degrees() - 4.5f64.sqrt()).abs() < 1e-12, "{}", p.rmse_aod_rad);
        // Re-initialisations: 1 x 2 runs + 0.5 x 4 runs = 4 over 8 tracked slots.
        assert!((p.reinitialisation_share_pct - 50.0).abs() < 1e-12);
        assert_eq!(pooled[1].rmse_aod_rad, 7f64.to_radians());
        let mut text = String::new();
        section(&mut text, &SpebtResults { sequences: Vec::new(), pooled });
        assert!(text.contains("| radar-odometry | 2 | 8 | 1.00 [0.3] | 2.121 [0.22] |"), "{text}");
    }

    #[test]
    fn inconsistent_or_bad_tables_are_named() {
        let good = || vec![slot(0, [0.0; 3]), slot(1, [1.0, 2.0, 3.0])];
        let err = sequence_result("p", vec![summary("x", 2, 1, [1.0, 2.5, 3.0], 0.0)], good()).unwrap_err();
        let (stated, slots) = (2.5f64.to_radians(), 2f64.to_radians());
        let expected = format!("sequence p: spebt_summary.rmse_aod_rad is {stated} but spebt_per_slot gives {slots}");
        assert!(err.contains(&expected), "{err}");
        let err = sequence_result("p", Vec::new(), good()).unwrap_err();
        assert!(err.contains("has 0 rows, expected one"), "{err}");
        let mut slots = good();
        slots[1].run0_aoa_rad = f64::NAN;
        let err = sequence_result("p", vec![summary("x", 2, 1, [1.0, 2.0, 3.0], 0.0)], slots).unwrap_err();
        assert!(err.contains("slot 1: run0_aoa_rad is NaN"), "{err}");
        let mut slots = good();
        slots[1].slot = 5;
        let err = sequence_result("p", vec![summary("x", 2, 1, [1.0, 2.0, 3.0], 0.0)], slots).unwrap_err();
        assert!(err.contains("row 1 is slot 5"), "{err}");
        let err = sequence_result("p", vec![summary("x", 3, 1, [1.0, 2.0, 3.0], 0.0)], good()).unwrap_err();
        assert!(err.contains("2 rows but spebt_summary says 3 slots"), "{err}");
    }
}
