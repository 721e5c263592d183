//! Verdicts and the Markdown summary of `reproduce spebt` (also the README
//! block).

use std::path::Path;

use mmtrack_core::StampedPose;
use mmtrack_core::path_length_m;
use mmtrack_sim::beam::spebt_link::{SpebtLink, SpebtSlot};

use super::reproduce_spebt::{Experiment, ExperimentResult};

/// The README block the summary replaces with `--readme`.
pub const README_BLOCK: &str = "reproduce-spebt";

/// What the summary says about the run besides the results.
pub struct Context<'a> {
    pub experiment: &'a Experiment,
    pub trajectory: &'a Path,
    pub link: &'a SpebtLink,
    pub elapsed_s: f64,
    pub threads: usize,
}

/// One checked claim of the paper.
pub struct Verdict {
    pub claim: String,
    pub paper: String,
    pub measured: String,
    pub target: String,
    pub met: bool,
}

/// The three targets: AoD and AoA RMSE, re-initialisation share.
pub fn verdicts(experiment: &Experiment, result: &ExperimentResult) -> Vec<Verdict> {
    let [_, aod, aoa] = result.rmse();
    let (aod_deg, aoa_deg) = (aod.to_degrees(), aoa.to_degrees());
    let (paper, targets) = (&experiment.paper, &experiment.targets);
    let share_pct = 100.0 * result.mean_reinitialisations() / result.tracked_slots().max(1) as f64;
    vec![
        Verdict {
            claim: "RMSE AoD (deg)".into(),
            paper: format!("{:.3}", paper.rmse_aod_deg),
            measured: format!("{aod_deg:.3}"),
            target: format!("<= {}", targets.max_rmse_aod_deg),
            met: aod_deg <= targets.max_rmse_aod_deg,
        },
        Verdict {
            claim: "RMSE AoA (deg)".into(),
            paper: format!("{:.3}", paper.rmse_aoa_deg),
            measured: format!("{aoa_deg:.3}"),
            target: format!("<= {}", targets.max_rmse_aoa_deg),
            met: aoa_deg <= targets.max_rmse_aoa_deg,
        },
        Verdict {
            claim: "re-initialisations per run (share of tracked slots)".into(),
            paper: format!(
                "< {} of {} (< {:.2} %)",
                paper.reinitialisations,
                paper.slots,
                100.0 * paper.reinitialisations as f64 / paper.slots as f64
            ),
            measured: format!(
                "{:.1} of {} ({share_pct:.2} %)",
                result.mean_reinitialisations(),
                result.tracked_slots()
            ),
            target: format!("< {} %", targets.max_reinitialisation_share_pct),
            met: share_pct < targets.max_reinitialisation_share_pct,
        },
    ]
}

/// The Markdown summary: setup, results against the paper, verdicts, the
/// error floors of the model, speed.
pub fn summary(context: &Context<'_>, result: &ExperimentResult, verdicts: &[Verdict]) -> String {
    let (e, link) = (context.experiment, context.link);
    let s = &e.scenario;
    let slots = link.slots();
    let poses: Vec<StampedPose> =
        slots.iter().map(|slot| StampedPose { t_ns: slot.t_ns, parent_from_child: slot.pose }).collect();
    let duration_s = (slots[slots.len() - 1].t_ns - slots[0].t_ns) as f64 * 1e-9;
    let closest_m = slots.iter().map(|slot| slot.range_m).fold(f64::INFINITY, f64::min);
    let farthest_m = slots.iter().map(|slot| slot.range_m).fold(0.0, f64::max);
    let mut out = format!(
        "Written by `mmtrack reproduce spebt`. The vehicle drives the first {} poses of `{}` ({:.2} km in {:.0} s, one \
         slot per pose) past a base station at ({}, {}) m from its start ({closest_m:.0} to {farthest_m:.0} m away). \
         Link of Table I: {} GHz, {}x{} half-wavelength ULAs, path-loss exponent {}, |alpha_ref| = {} at {} m, noise \
         {} dBm under a {} dBm pilot. Pose estimates: ground truth plus the pose-error model (23), sigma_r = {} m, \
         sigma_theta = {} deg, independent per slot. {} Monte Carlo runs, seed {}. The paper's sequence \
         (2019-01-15-14-24-38, 6388 scans) is not available here: this is another drive of the same Oxford route.\n\n",
        link.len(),
        context.trajectory.display(),
        path_length_m(&poses) * 1e-3,
        duration_s,
        s.bs_x_m,
        s.bs_y_m,
        s.carrier_hz * 1e-9,
        s.bs_elements,
        s.vehicle_elements,
        s.path_loss_exponent,
        s.reference_gain_magnitude,
        s.reference_distance_m,
        s.noise_dbm,
        s.pilot_power_dbm,
        s.position_sigma_m,
        s.yaw_sigma_deg,
        result.runs,
        e.seed,
    );
    let [gain, _, _] = result.rmse();
    out.push_str("| claim | paper (Table III, 10^5 runs) | measured | target | verdict |\n|---|---|---|---|---|\n");
    out.push_str(&format!(
        "| RMSE abs(alpha) (%) | {:.3} | {:.3} | - | reported |\n",
        e.paper.rmse_gain_pct,
        100.0 * gain
    ));
    for v in verdicts {
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} |\n",
            v.claim,
            v.paper,
            v.measured,
            v.target,
            if v.met { "met" } else { "**missed**" }
        ));
    }
    let total: u64 = result.reinitialisations.iter().sum();
    let cause = |i: usize| 100.0 * result.causes[i] as f64 / total.max(1) as f64;
    out.push_str(&format!(
        "\nRe-initialisations per run: {} to {}; the |alpha| test fired in {:.0} % of them, the AoD test in {:.0} %, \
         the AoA test in {:.0} % (tests may fire together).\n",
        result.reinitialisations.iter().min().unwrap_or(&0),
        result.reinitialisations.iter().max().unwrap_or(&0),
        cause(0),
        cause(1),
        cause(2),
    ));
    out.push_str(&floors(context));
    out.push_str(&format!(
        "\n{} runs x {} slots in {:.1} s on {} threads ({:.0} runs per CPU-second).\n",
        result.runs,
        link.len(),
        context.elapsed_s,
        context.threads,
        result.runs as f64 / result.tracker_cpu_s.max(1e-9),
    ));
    out
}

/// What the pose-error model leaves on this trajectory to a filter that
/// follows the poses: the bearing error of one pose estimate (and how much
/// of it the slots near the BS make), and the AoA deviation that trips the
/// threshold with no motion at all.
fn floors(context: &Context<'_>) -> String {
    let (e, link) = (context.experiment, context.link);
    let slots = link.slots();
    let sigma_r = e.scenario.position_sigma_m;
    let inverse_square = |s: &&SpebtSlot| 1.0 / (s.range_m * s.range_m);
    let total = slots.iter().map(|s| inverse_square(&s)).sum::<f64>();
    let near: Vec<&SpebtSlot> = slots.iter().filter(|s| s.range_m < NEAR_M).collect();
    let near_share = near.iter().map(inverse_square).sum::<f64>() / total;
    // One pose estimate's bearing error sigma_r / |r| (its across-range
    // component), RMS over the slots; the evolution from the last initial
    // access at slot j to slot k carries the errors of both poses.
    let aod_floor_deg = (sigma_r * (total / slots.len() as f64).sqrt()).to_degrees();
    let yaw_sigma = e.scenario.yaw_sigma_deg;
    // AoA error from the yaw errors of two slots: N(0, 2 sigma_theta^2); the
    // share of slots where it alone exceeds the threshold.
    let threshold = e.tracker.angle_threshold_deg;
    let noise_trip = erfc(threshold / (2.0 * yaw_sigma));
    format!(
        "\nWhat the pose-error model leaves to a filter that follows the poses (one power measurement per slot through \
         {}-element arrays, {:.0} deg beams, carries little angle information): the bearing error of one pose \
         estimate, sigma_r / |r_k|, has an RMS of {aod_floor_deg:.3} deg over these slots, and {:.0} % of its mean \
         square comes from the {} slots within {NEAR_M} m of the base station; the evolution since the last initial \
         access carries two such errors ({:.3} deg). Its AoA error holds the yaw errors of two slots, a standard \
         deviation of sqrt(2) x {yaw_sigma} = {:.2} deg, which alone exceeds the {threshold} deg threshold in {:.1} % \
         of the slots.\n",
        e.scenario.bs_elements.max(e.scenario.vehicle_elements),
        half_power_beamwidth_deg(e.scenario.bs_elements, e.scenario.spacing_wavelengths),
        100.0 * near_share,
        near.len(),
        aod_floor_deg * std::f64::consts::SQRT_2,
        yaw_sigma * std::f64::consts::SQRT_2,
        100.0 * noise_trip,
    )
}

/// Slots nearer to the BS than this dominate the AoD error floor, metres.
const NEAR_M: f64 = 50.0;

/// Broadside half-power beamwidth of an `n`-element ULA, degrees.
fn half_power_beamwidth_deg(n: usize, spacing_wavelengths: f64) -> f64 {
    mmtrack_core::array::UniformLinearArray::new(n, spacing_wavelengths)
        .map_or(f64::NAN, |a| a.half_power_beamwidth_rad(std::f64::consts::FRAC_PI_2).to_degrees())
}

/// Complementary error function (Abramowitz and Stegun 7.1.26, absolute
/// error below 1.5e-7), for `x >= 0`.
fn erfc(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x);
    let poly =
        t * (0.254_829_592 + t * (-0.284_496_736 + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    poly * (-x * x).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erfc_matches_tabulated_values() {
        // erfc(0) = 1, erfc(1.25) = 0.077100, erfc(2) = 0.004678 (tables).
        assert!((erfc(0.0) - 1.0).abs() < 2e-7);
        assert!((erfc(1.25) - 0.077_100_3).abs() < 2e-7);
        assert!((erfc(2.0) - 0.004_677_7).abs() < 2e-7);
        assert!((half_power_beamwidth_deg(4, 0.5) - 26.3).abs() < 0.2);
    }
}
