//! Verdicts and the Markdown summary of `reproduce shaham` (also the
//! README block).

use super::reproduce_shaham::{Experiment, PointResult, TRACKERS};

/// The README block the summary replaces with `--readme`.
pub const README_BLOCK: &str = "reproduce-shaham";

/// One checked claim of the paper.
pub struct Verdict {
    pub claim: String,
    pub paper: String,
    pub measured: String,
    pub met: bool,
}

fn point(results: &[PointResult], snr_db: f64, speed_kmh: f64) -> Option<&PointResult> {
    results.iter().find(|p| p.snr_db == snr_db && p.speed_kmh == speed_kmh)
}

fn blocks_text(blocks: Option<usize>, simulated: usize) -> String {
    blocks.map_or(format!("> {simulated}"), |b| b.to_string())
}

/// The numbers `reproduce --all` checks: valid tracking of each tracker at
/// each point (blocks simulated + 1 where it never ended), the paper's
/// number beside the proposed EKF's, and its gain over the angle-state EKF.
pub fn metrics(experiment: &Experiment, results: &[PointResult]) -> Vec<crate::reproduce_all::Metric> {
    use crate::reproduce_all::Metric;
    let mut out = Vec::new();
    for p in results {
        for (t, tracker) in TRACKERS.iter().enumerate() {
            let paper = experiment
                .targets
                .iter()
                .find(|g| t == 0 && g.snr_db == p.snr_db && g.speed_kmh == p.speed_kmh)
                .map(|g| g.paper_blocks as f64);
            let blocks = p.valid_blocks[t].unwrap_or(experiment.blocks + 1) as f64;
            let key = format!("{tracker} valid tracking, {} dB, {} km/h", p.snr_db, p.speed_kmh);
            out.push(Metric::new(key, blocks, "blocks", paper));
        }
    }
    if let Some(p) = point(results, 0.0, 60.0)
        && let (Some(pv), Some(angle)) = (p.valid_blocks[0], p.valid_blocks[2])
        && angle > 0
    {
        let gain = 100.0 * (pv as f64 / angle as f64 - 1.0);
        out.push(Metric::new("pv-ekf gain over angle-ekf, 0 dB, 60 km/h", gain, "%", Some(experiment.paper_gain_pct)));
    }
    out
}

/// Each published number within the tolerance, the two orderings and the
/// gain over the angle-state EKF, for the proposed tracker (`pv-ekf`).
pub fn verdicts(experiment: &Experiment, results: &[PointResult]) -> Vec<Verdict> {
    let simulated = experiment.blocks;
    let mut out = Vec::new();
    for target in &experiment.targets {
        let measured = point(results, target.snr_db, target.speed_kmh).and_then(|p| p.valid_blocks[0]);
        let paper = target.paper_blocks as f64;
        let met = measured.is_some_and(|m| (m as f64 - paper).abs() <= experiment.tolerance * paper);
        out.push(Verdict {
            claim: format!(
                "valid tracking, SNR {} dB, {} km/h ({}), within {:.0} %",
                target.snr_db,
                target.speed_kmh,
                target.figure,
                100.0 * experiment.tolerance
            ),
            paper: format!("{} blocks", target.paper_blocks),
            measured: format!("{} blocks", blocks_text(measured, simulated)),
            met,
        });
    }
    // Orderings: longer with SNR (60 km/h), shorter with speed (0 dB).
    // Each series in increasing order of the swept quantity.
    let series = |filter: &dyn Fn(&PointResult) -> bool, key: &dyn Fn(&PointResult) -> f64| -> Vec<Option<usize>> {
        let mut points: Vec<&PointResult> = results.iter().filter(|p| filter(p)).collect();
        points.sort_by(|a, b| key(a).total_cmp(&key(b)));
        points.iter().map(|p| p.valid_blocks[0]).collect()
    };
    let by_snr = series(&|p| p.speed_kmh == 60.0, &|p| p.snr_db);
    let by_speed = series(&|p| p.snr_db == 0.0, &|p| p.speed_kmh);
    let as_len = |b: &Option<usize>| b.unwrap_or(usize::MAX);
    let text = |s: &[Option<usize>]| s.iter().map(|b| blocks_text(*b, simulated)).collect::<Vec<_>>().join(" / ");
    out.push(Verdict {
        claim: "valid tracking grows with SNR (0 / 5 / 10 dB)".into(),
        paper: "99 / 142 / 193".into(),
        measured: text(&by_snr),
        met: by_snr.windows(2).all(|w| as_len(&w[0]) < as_len(&w[1])),
    });
    out.push(Verdict {
        claim: "valid tracking shrinks with speed (50 / 60 / 70 / 80 km/h)".into(),
        paper: "109 / 100 / 91 / 83".into(),
        measured: text(&by_speed),
        met: by_speed.windows(2).all(|w| as_len(&w[0]) > as_len(&w[1])),
    });
    let gain = point(results, 0.0, 60.0).and_then(|p| match (p.valid_blocks[0], p.valid_blocks[2]) {
        (Some(pv), Some(angle)) if angle > 0 => Some(100.0 * (pv as f64 / angle as f64 - 1.0)),
        _ => None,
    });
    out.push(Verdict {
        claim: "longer valid tracking than the angle-state EKF (SNR 0 dB, 60 km/h)".into(),
        paper: format!("+{:.0} %", experiment.paper_gain_pct),
        measured: gain.map_or("-".into(), |g| format!("{g:+.0} %")),
        met: gain.is_some_and(|g| g >= experiment.paper_gain_pct),
    });
    out
}

/// The Markdown summary: setup, per-point table, verdicts, speed.
pub fn summary(
    experiment: &Experiment,
    results: &[PointResult],
    verdicts: &[Verdict],
    runs: u64,
    threshold_rad: f64,
    (elapsed_s, threads, load): (f64, usize, (Option<f64>, Option<f64>)),
) -> String {
    let s = &experiment.scenario;
    let mut out = format!(
        "Written by `mmtrack reproduce shaham`. Overpass link (h = {} m, {}-element half-wavelength ULAs, {} ms blocks, \
         rho = {}, speed noise {} m/s per block, initial AoD {} deg), {runs} Monte Carlo runs per point, seed {}, \
         {} blocks per run. Valid tracking ends at the first block whose RMS transmit-beam pointing error over the runs \
         exceeds half the half-power beamwidth at the initial AoD ({:.2} deg).\n\n",
        s.height_m,
        s.elements,
        s.block_s * 1e3,
        s.rho,
        s.speed_sigma_mps,
        s.initial_aod_deg,
        experiment.seed,
        experiment.blocks,
        threshold_rad.to_degrees(),
    );
    out.push_str("| SNR dB | speed km/h | ");
    out.push_str(&TRACKERS.join(" | "));
    out.push_str(" | RMS error at block 50, pv-ekf / angle-ekf (deg) |\n|---|---|---|---|---|---|\n");
    for p in results {
        let cells: Vec<String> = p.valid_blocks.iter().map(|b| blocks_text(*b, experiment.blocks)).collect();
        let at = |t: usize| p.rms_rad[t].get(50).map_or("-".into(), |v| format!("{:.2}", v.to_degrees()));
        out.push_str(&format!("| {} | {} | {} | {} / {} |\n", p.snr_db, p.speed_kmh, cells.join(" | "), at(0), at(2)));
    }
    out.push_str("\n| claim (pv-ekf) | paper | measured | verdict |\n|---|---|---|---|\n");
    for v in verdicts {
        out.push_str(&format!(
            "| {} | {} | {} | {} |\n",
            v.claim,
            v.paper,
            v.measured,
            if v.met { "met" } else { "**missed**" }
        ));
    }
    let total_runs = runs as f64 * results.len() as f64;
    let speeds: Vec<String> = TRACKERS
        .iter()
        .enumerate()
        .map(|(t, name)| {
            let cpu: f64 = results.iter().map(|p| p.tracker_cpu_s[t]).sum();
            format!("{name} {:.0}", total_runs / cpu.max(1e-9))
        })
        .collect();
    out.push_str(&format!(
        "\n{} points x {runs} runs x 3 trackers in {elapsed_s:.1} s on {threads} threads; runs per thread-second of \
         {} blocks: {}.\n",
        results.len(),
        experiment.blocks,
        speeds.join(", ")
    ));
    let fmt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.1}"));
    out.push_str(&format!(
        "1-minute load average before / after the run: {} / {} (on {threads} threads; above that, other work shared \
         the cores and the times are longer).\n",
        fmt(load.0),
        fmt(load.1)
    ));
    out
}
