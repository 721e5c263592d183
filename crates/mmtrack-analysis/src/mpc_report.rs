//! The MPC section of the `mmtrack analyze` report.

use std::fmt::Write;

use crate::mpc::MpcResult;

/// Plot files of one sequence, under `plots/<sequence>/`, with their titles.
pub const PLOTS: [(&str, &str); 5] = [
    ("mpc_delay_tracks.svg", "delay vs time: detections by power, short-term tracks"),
    ("mpc_count.svg", "number of MPCs per set (Fig. 12)"),
    ("mpc_birth_death.svg", "birth and death rates (Fig. 13)"),
    ("mpc_power_loss.svg", "channel, detected and tracked gain; power loss (Figs. 8-9)"),
    ("mpc_power_std.svg", "per-track power standard deviation (Fig. 7)"),
];

fn opt(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "n/a".to_string(), |v| format!("{v:.decimals$}"))
}

fn pct(v: Option<f64>) -> String {
    v.map_or_else(|| "n/a".to_string(), |v| format!("{:.1} %", 100.0 * v))
}

/// Births/deaths per metre when a distance is known, else per second.
fn rates(r: &MpcResult) -> (String, String, &'static str) {
    let s = &r.summary;
    match (s.birth_rate_per_m, s.death_rate_per_m) {
        (Some(b), Some(d)) => (format!("{b:.3}"), format!("{d:.3}"), "1/m"),
        _ => (opt(s.birth_rate_per_s, 2), opt(s.death_rate_per_s, 2), "1/s"),
    }
}

/// The one-line summary of a sequence, as the CLI prints it.
#[must_use]
pub fn one_line(r: &MpcResult) -> String {
    let s = &r.summary;
    let (b, d, unit) = rates(r);
    format!(
        "{}: {} sets, {} MPCs per set, births {b} / deaths {d} {unit} (distance: {}), detection loss {} dB, tracking loss {} dB{}{}",
        r.sequence,
        s.sets,
        opt(s.mean_mpcs_per_set, 1),
        s.distance_source,
        opt(s.mean_detection_loss_db, 2),
        opt(s.mean_tracking_loss_db, 2),
        match (s.precision, s.recall) {
            (Some(p), Some(rc)) => format!(", precision {:.3} recall {:.3}", p, rc),
            _ => String::new(),
        },
        match (s.first_path_hint_abs_median_s, s.first_path_hint_abs_p90_s) {
            (Some(median), Some(p90)) => format!(
                ", first path vs the receiver's estimate: median |difference| {:.3} ns, 90th percentile {:.3} ns",
                median * 1e9,
                p90 * 1e9
            ),
            _ => String::new(),
        }
    )
}

fn ns(v: Option<f64>) -> String {
    v.map_or_else(|| "n/a".to_string(), |v| format!("{:+.3}", v * 1e9))
}

/// The first-path table: every sequence, its rule and, where the recording
/// carries the receiver's own first-path estimate, the differences.
fn first_path_section(out: &mut String, results: &[MpcResult]) {
    let _ = write!(
        out,
        "First path (table `mpc_first_path`): per snapshot, the earliest detection at most the dynamic range below the \
         snapshot's strongest detection. Where the recording carries the receiver's own first-path estimate (e.g. the \
         DW1000's leading edge HLP, `mpc_snapshots.first_path_hint_s`), first path minus that estimate, in ns. \
         Detections before the first path are more than the dynamic range below the strongest: noise peaks, or a \
         weak first path the range leaves out (`--first-path-range-db` reaches further).\n\n\
         | sequence | dynamic range (dB) | snapshots with a first path | with detections before it | with the \
         receiver's estimate | median difference | median absolute difference | 90th percentile of the absolute \
         difference |\n|---|---|---|---|---|---|---|---|\n"
    );
    for r in results {
        let s = &r.summary;
        let _ = writeln!(
            out,
            "| {} | {:.1} | {} | {} | {} | {} | {} | {} |",
            r.sequence,
            s.first_path_dynamic_range_db,
            s.first_path_snapshots,
            s.first_path_earlier_snapshots,
            s.first_path_hint_snapshots,
            ns(s.first_path_minus_hint_median_s),
            ns(s.first_path_hint_abs_median_s).trim_start_matches('+'),
            ns(s.first_path_hint_abs_p90_s).trim_start_matches('+'),
        );
    }
    out.push('\n');
}

/// Appends the section for `results` (nothing when empty).
pub fn section(out: &mut String, results: &[MpcResult]) {
    if results.is_empty() {
        return;
    }
    out.push_str(
        "## Multipath components (tables `mpc_*` of `mmtrack process mpc`)\n\n\
         After Mahler et al. 2017, Secs. IV-VI. MPCs per set: full-lifetime tracks entered in long-term tracks. \
         Births: long-term tracks starting in a set (not the first); deaths: ending in a set (not the last); rates \
         per metre use the cumulative distance of both vehicles (`ground_truth_tx` + `ground_truth_rx`) when present, \
         else the one trajectory named under distance, else they are per second. Losses: channel gain after \
         thresholding and windowing minus the captured gain, mean over sets in dB; a negative loss means the MPCs' own \
         energies sum to more than the channel gain, as when resolved paths closer than the windowed pulse interfere \
         destructively (their cross term is in the channel gain only). Power std: sample standard \
         deviation of a track's detection powers over its set. chi <= 0.1 ns: share of the linked long-term power in \
         the tightest confidence class (paper: 72 %); unrelated: share of long-term power in entries related to no \
         adjacent set (paper: 5 %).\n\n",
    );
    out.push_str(
        "| sequence | sets | MPCs/set mean (median) | births | deaths | rate unit | distance | detection loss (dB) | \
         tracking loss (dB) | full-lifetime loss (dB) | GM-PHD loss (dB) | full-lifetime std < 1 dB | all std < 1.5 dB | \
         chi <= 0.1 ns | unrelated |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in results {
        let s = &r.summary;
        let (b, d, unit) = rates(r);
        let distance =
            s.distance_m.map_or_else(|| s.distance_source.clone(), |m| format!("{m:.1} m ({})", s.distance_source));
        let _ = writeln!(
            out,
            "| {} | {} | {} ({}) | {b} | {d} | {unit} | {distance} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.sequence,
            s.sets,
            opt(s.mean_mpcs_per_set, 2),
            opt(s.median_mpcs_per_set, 1),
            opt(s.mean_detection_loss_db, 2),
            opt(s.mean_tracking_loss_db, 2),
            opt(s.mean_full_lifetime_loss_db, 2),
            opt(s.mean_gmphd_tracking_loss_db, 2),
            pct(s.full_lifetime_std_below_1db),
            pct(s.all_tracks_std_below_1_5db),
            pct(s.chi_0_1ns_power_share),
            pct(s.unrelated_power_share),
        );
    }
    out.push('\n');
    for r in results {
        for note in &r.notes {
            let _ = writeln!(out, "`{}`: {note}.\n", r.sequence);
        }
    }
    let with_truth: Vec<&MpcResult> = results.iter().filter(|r| r.summary.truth_mpcs.is_some()).collect();
    if !with_truth.is_empty() {
        out.push_str(
            "Against the simulator's truth (`mpc_truth`), made resolvable first (true MPCs of a snapshot within 0.5 \
             ns of each other count as one, with the complex sum of their amplitudes): a detection matches a true MPC \
             of the same snapshot within 0.5 ns, one to one, strongest true MPC first; recall above floor counts the \
             detectable true MPCs, at least 6 dB above the set's noise floor; purity is the share of a track's \
             detections on its majority path, over tracks with a matched detection; false tracks have none. \
             Long-term tracks follow the majority path of their detections; births/deaths on true paths count \
             those that follow one, tracks per path is how many long-term tracks each followed path was split \
             into. True births and deaths count paths above the floor appearing or vanishing between consecutive \
             sets.\n\n\
             | sequence | true MPCs | precision | recall | recall above floor | track purity | false tracks | \
             false long-term tracks | long-term tracks per path | births est / on true paths / true | \
             deaths est / on true paths / true | birth rate est / true (1/m) | death rate est / true (1/m) |\n\
             |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        for r in with_truth {
            let s = &r.summary;
            let n = |v: Option<u64>| v.map_or_else(|| "n/a".into(), |v| v.to_string());
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} / {} / {} | {} / {} / {} | {} / {} | {} / {} |",
                r.sequence,
                s.truth_mpcs.unwrap_or(0),
                opt(s.precision, 3),
                opt(s.recall, 3),
                opt(s.recall_above_floor, 3),
                opt(s.track_purity, 3),
                pct(s.false_track_share),
                pct(s.false_long_term_share),
                opt(s.long_term_tracks_per_path, 1),
                n(s.births),
                n(s.births_on_true_paths),
                n(s.true_births),
                n(s.deaths),
                n(s.deaths_on_true_paths),
                n(s.true_deaths),
                opt(s.birth_rate_per_m, 3),
                opt(s.true_birth_rate_per_m, 3),
                opt(s.death_rate_per_m, 3),
                opt(s.true_death_rate_per_m, 3),
            );
        }
        out.push('\n');
    }
    first_path_section(out, results);
    for r in results {
        let _ = writeln!(out, "### `{}` (MPC)\n", r.sequence);
        for (file, title) in PLOTS {
            if let Some(reason) = crate::mpc_plots::empty_because(r, file) {
                let _ = writeln!(out, "\n*No plot ({title}): {reason}.*\n");
                continue;
            }
            let subset = match crate::mpc_plots::delay_plot_subset(r) {
                Some(note) if file == PLOTS[0].0 => format!(" ({note})"),
                _ => String::new(),
            };
            let _ = writeln!(out, "![{title}{subset}](plots/{}/{file})", r.sequence);
        }
        out.push('\n');
    }
}
