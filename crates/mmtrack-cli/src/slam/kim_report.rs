//! Verdicts and the Markdown summary of `reproduce kim` (also the README
//! block).

use mmtrack_slam::SlamConfig;

use super::reproduce_kim::{Experiment, RowResult, Targets};

/// The README block the summary replaces with `--readme`.
pub const README_BLOCK: &str = "reproduce-kim";

/// One checked claim of the paper.
pub struct Verdict {
    pub claim: String,
    pub paper: String,
    pub measured: String,
    pub met: bool,
}

use crate::reproduce_all::Metric;

/// Every row's numbers, the paper's beside the paper row's.
pub fn metrics(targets: &Targets, results: &[RowResult]) -> Vec<Metric> {
    let mut out = Vec::new();
    for r in results {
        let s = &r.summary;
        let paper = |v: f64| r.row.checked.then_some(v);
        let mut push = |name: &str, value: Option<f64>, unit: &str, p: Option<f64>| {
            if let Some(value) = value.filter(|v| v.is_finite()) {
                out.push(Metric { key: format!("{} {name}", r.row.name), value, unit: unit.into(), paper: p });
            }
        };
        push("UE position error", Some(s.ue_position_error_m), "m", paper(targets.ue_position_m));
        push("UE heading error", Some(s.ue_heading_error_rad), "rad", paper(targets.ue_heading_rad));
        push("UE clock-bias error", Some(s.ue_clock_bias_error_m), "m", paper(targets.ue_clock_bias_m));
        push("VA error", s.va_error_m, "m", paper(targets.va_m));
        push("SP error", s.sp_error_m, "m", paper(targets.sp_m));
        push("all VAs confirmed, mean epoch", Some(s.all_va_epoch_mean), "epoch", paper(targets.all_va_epoch as f64));
        push("all SPs confirmed, mean epoch", Some(s.all_sp_epoch_mean), "epoch", paper(targets.all_sp_epoch as f64));
        push("false sources per run", Some(s.false_sources), "sources", None);
    }
    out
}

/// The paper row's numbers against the targets: at most `paper * (1 +
/// tolerance)`.
pub fn verdicts(targets: &Targets, tolerance: f64, results: &[RowResult]) -> Vec<Verdict> {
    let mut out = Vec::new();
    for r in results.iter().filter(|r| r.row.checked) {
        let s = &r.summary;
        let bound = |paper: f64| paper * (1.0 + tolerance);
        let mut check = |claim: &str, paper: f64, measured: Option<f64>, unit: &str, digits: usize| {
            out.push(Verdict {
                claim: format!("{claim} ({})", r.row.name),
                paper: format!("{paper} {unit}"),
                measured: measured.map_or("none confirmed".into(), |m| format!("{m:.digits$} {unit}")),
                met: measured.is_some_and(|m| m <= bound(paper)),
            });
        };
        check("mean UE position error", targets.ue_position_m, Some(s.ue_position_error_m), "m", 3);
        check("mean UE heading error", targets.ue_heading_rad, Some(s.ue_heading_error_rad), "rad", 4);
        check("mean UE clock-bias error", targets.ue_clock_bias_m, Some(s.ue_clock_bias_error_m), "m", 3);
        check("mean VA localisation error", targets.va_m, s.va_error_m, "m", 3);
        check("mean SP localisation error", targets.sp_m, s.sp_error_m, "m", 3);
        let epochs = |claim: &str, paper: u64, mean: f64, max: u64| Verdict {
            claim: format!("{claim} ({}), mean over runs", r.row.name),
            paper: format!("epoch {paper}"),
            measured: format!("epoch {mean:.1} (worst run {max})"),
            met: mean <= bound(paper as f64),
        };
        out.push(epochs("all VAs confirmed by", targets.all_va_epoch, s.all_va_epoch_mean, s.all_va_epoch_max));
        out.push(epochs("all SPs confirmed by", targets.all_sp_epoch, s.all_sp_epoch_mean, s.all_sp_epoch_max));
    }
    out
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

/// The Markdown summary: setup, per-row table, verdicts, speed.
pub fn summary(
    experiment: &Experiment,
    filter: &SlamConfig,
    results: &[RowResult],
    verdicts: &[Verdict],
    runs: u64,
    tolerance: f64,
    (elapsed_s, threads, load): (f64, usize, (Option<f64>, Option<f64>)),
) -> String {
    let s = &experiment.scenario;
    let mut out = format!(
        "Written by `mmtrack reproduce kim`. Circular road (start ({}, {}, {}) m, {} m/s, {:.4} rad/s, clock bias {} m), \
         BS at ({}, {}, {}) m, {} walls (VAs), {} random SPs seen within {} m, {} epochs of {} s, sigma {} m (TOA) and \
         {} rad (angles). {runs} Monte Carlo runs per row (seed {}), {} particles, {} iterations, prior centred on the \
         true first state. Errors are time averages over the epochs, then means over the runs; a confirmed source \
         counts when a true source of its type is within {} m (the others are false sources).\n\n",
        s.initial.position_m[0],
        s.initial.position_m[1],
        s.initial.position_m[2],
        s.initial.speed_mps,
        s.initial.turn_rate_radps,
        s.initial.clock_bias_m,
        s.bs_m[0],
        s.bs_m[1],
        s.bs_m[2],
        s.walls.len(),
        s.random_scattering_points + s.scattering_points_m.len(),
        s.sp_visibility_m,
        s.epochs,
        s.epoch_s,
        s.toa_std_m,
        s.angle_std_rad,
        experiment.seed,
        filter.particles,
        filter.iterations,
        experiment.match_radius_m,
    );
    out.push_str(
        "| row | P_D | clutter/epoch | UE position (m) | error / spread | heading (rad) | clock bias (m) | speed (m/s) | turn rate (rad/s) \
         | VA (m) | SP (m) | all VAs by epoch (mean / worst) | all SPs by epoch (mean / worst) | false sources/run |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let t = &experiment.targets;
    out.push_str(&format!(
        "| Kim et al. (one run) | 1 | 0 | {} | - | {} | {} | < 1.5 | < 0.6 | {} | {} | {} | {} | 0 |\n",
        t.ue_position_m, t.ue_heading_rad, t.ue_clock_bias_m, t.va_m, t.sp_m, t.all_va_epoch, t.all_sp_epoch
    ));
    for r in results {
        let s = &r.summary;
        out.push_str(&format!(
            "| {} | {} | {} | {:.3} | {:.1} | {:.4} | {:.3} | {:.3} | {:.4} | {} | {} | {:.1} / {} | {:.1} / {} | {:.2} |\n",
            s.row,
            s.detection_probability,
            s.clutter_per_epoch,
            s.ue_position_error_m,
            s.ue_error_over_spread,
            s.ue_heading_error_rad,
            s.ue_clock_bias_error_m,
            s.ue_speed_error_mps,
            s.ue_turn_rate_error_radps,
            opt(s.va_error_m, 3),
            opt(s.sp_error_m, 3),
            s.all_va_epoch_mean,
            s.all_va_epoch_max,
            s.all_sp_epoch_mean,
            s.all_sp_epoch_max,
            s.false_sources,
        ));
    }
    out.push_str(&format!(
        "\n| claim (at most the paper's number{}) | paper | measured | verdict |\n|---|---|---|---|\n",
        if tolerance > 0.0 { format!(" times {}", 1.0 + tolerance) } else { String::new() }
    ));
    for v in verdicts {
        out.push_str(&format!(
            "| {} | {} | {} | {} |\n",
            v.claim,
            v.paper,
            v.measured,
            if v.met { "met" } else { "**missed**" }
        ));
    }
    let load_text = |l: Option<f64>| l.map_or("-".into(), |v| format!("{v:.2}"));
    out.push_str(&format!(
        "\n{:.1} s on {threads} threads (load average {} before, {} after).\n",
        elapsed_s,
        load_text(load.0),
        load_text(load.1)
    ));
    out
}
