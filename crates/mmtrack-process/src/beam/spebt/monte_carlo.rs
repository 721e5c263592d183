//! The SPEBT Monte Carlo of Liu et al. 2024 (Sec. IV, Algorithm 1): the
//! experiment file (`data/reproduce/spebt.toml`, the paper's Table I link,
//! the tracker's thresholds, Table III's numbers), the runs in fixed chunks
//! on rayon merged in chunk order (so the numbers do not depend on the
//! thread count), and the pose frames the estimates are moved into. Used by
//! `process beam --tracker spebt` and by the `reproduce spebt` experiment.

use std::time::Instant;

use anyhow::Context;
use mmtrack_beam::{Deviation, SpebtConfig, SpebtEkf, SpebtState};
use mmtrack_core::progress::Progress;
use mmtrack_core::{Se2, wrap_angle_rad};
use mmtrack_sim::beam::spebt_link::{SpebtLink, SpebtScenario, SpebtSlot};
use rayon::prelude::*;
use serde::Deserialize;

/// The experiment file, embedded so every caller runs from any directory.
pub const SPEBT_EXPERIMENT: &str = include_str!("../../../../../data/reproduce/spebt.toml");
/// Experiment (a), ground truth plus the pose-error model: the sequence
/// partition of its tables.
pub const POSE_ERROR_MODEL: &str = "pose-error-model";
/// Experiment (b), our radar odometry: the sequence partition of its tables.
pub const RADAR_ODOMETRY: &str = "radar-odometry";

/// The experiment file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpebtExperiment {
    /// Seed of the receiver noise and the pose errors.
    pub seed: u64,
    /// Monte Carlo runs, full tier.
    pub runs: u64,
    /// Monte Carlo runs, smoke tier (`--quick`).
    pub quick_runs: u64,
    /// Slots (poses of the trajectory) per run.
    pub slots: usize,
    #[serde(default)]
    /// The link (the paper's Table I).
    pub scenario: SpebtScenario,
    /// The filter's model and thresholds.
    pub tracker: TrackerParams,
    /// Experiment (b): radar odometry.
    pub odometry: OdometryParams,
    /// The paper's numbers (Table III).
    pub paper: Paper,
    /// The bounds the verdicts check.
    pub targets: Targets,
    /// Experiment (a) re-run at other pilot powers (none by default).
    #[serde(default)]
    pub sensitivity: Sensitivity,
}

/// Experiment (a) re-run at other pilot powers: the paper does not give the
/// pilot power, so the choice of `[scenario] pilot_power_dbm` is reported
/// beside its alternatives (variants, not targets).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sensitivity {
    /// Pilot powers of the variants, dBm (the scenario's own is the claims' run).
    pub pilot_power_dbm: Vec<f64>,
    /// Monte Carlo runs per variant, full tier.
    pub runs: u64,
    /// Monte Carlo runs per variant, smoke tier.
    pub quick_runs: u64,
}

/// The filter's model and thresholds.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackerParams {
    /// Pose-error sigma_r of the filter, metres per coordinate.
    pub position_sigma_m: f64,
    /// Pose-error sigma_theta of the filter, degrees.
    pub yaw_sigma_deg: f64,
    /// Re-initialisation threshold of the relative abs(alpha) change.
    pub gain_threshold: f64,
    /// Re-initialisation threshold of the AoD and AoA changes, degrees.
    pub angle_threshold_deg: f64,
}

/// Experiment (b): radar odometry on simulated scans.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OdometryParams {
    /// Odometry preset (`fast-cfear`, the paper's).
    pub preset: String,
    /// Monte Carlo runs, full tier.
    pub runs: u64,
    /// Monte Carlo runs, smoke tier.
    pub quick_runs: u64,
    /// Slots of the smoke tier.
    pub quick_slots: usize,
}

/// The paper's numbers.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Paper {
    /// RMSE of abs(alpha), %.
    pub rmse_gain_pct: f64,
    /// AoD RMSE, degrees.
    pub rmse_aod_deg: f64,
    /// AoA RMSE, degrees.
    pub rmse_aoa_deg: f64,
    /// Re-initialisations over the drive.
    pub reinitialisations: u64,
    /// Slots of the drive.
    pub slots: u64,
}

/// The bounds the verdicts check.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Targets {
    /// Largest AoD RMSE that meets the paper, degrees.
    pub max_rmse_aod_deg: f64,
    /// Largest AoA RMSE that meets the paper, degrees.
    pub max_rmse_aoa_deg: f64,
    /// Largest re-initialisation share that meets the paper, %.
    pub max_reinitialisation_share_pct: f64,
}

/// Runs per rayon task: fixed, so partial sums merge in the same order on
/// any number of threads.
const RUNS_PER_CHUNK: u64 = 4;
/// Chunks computed before their partial sums are merged (bounds the memory
/// of per-slot partial sums; the merge order stays the chunk order).
const CHUNKS_PER_BATCH: u64 = 32;

/// What the Monte Carlo runs of one experiment measured.
pub struct ExperimentResult {
    /// Runs merged.
    pub runs: u64,
    /// Per slot, per component (|alpha| relative, AoD, AoA): sum over runs
    /// of the squared error of the slot's final estimate (after a
    /// re-initialisation where one happened).
    pub sum_squared: [Vec<f64>; 3],
    /// The same for the estimate after the slot's update, before any
    /// re-initialisation: the error that made the deviation test fire
    /// counts here, where the re-initialised estimate replaces it above.
    pub sum_squared_before_reset: [Vec<f64>; 3],
    /// Per slot: runs re-initialised there.
    pub reinitialised_runs: Vec<u64>,
    /// Re-initialisations of each run, run order.
    pub reinitialisations: Vec<u64>,
    /// Re-initialisations where the |alpha|, AoD, AoA test fired.
    pub causes: [u64; 3],
    /// Run 0's estimates per slot and whether the slot re-initialised.
    pub run0: Vec<(SpebtState, bool)>,
    /// What the updates did to the AoA estimate.
    pub aoa_updates: UpdateSteps,
    /// CPU seconds in the tracker (summed over threads).
    pub tracker_cpu_s: f64,
}

impl ExperimentResult {
    /// No runs yet, for `slots` slots.
    #[must_use]
    pub fn new(slots: usize) -> Self {
        Self {
            runs: 0,
            sum_squared: std::array::from_fn(|_| vec![0.0; slots]),
            sum_squared_before_reset: std::array::from_fn(|_| vec![0.0; slots]),
            reinitialised_runs: vec![0; slots],
            reinitialisations: Vec::new(),
            causes: [0; 3],
            run0: Vec::new(),
            aoa_updates: UpdateSteps::default(),
            tracker_cpu_s: 0.0,
        }
    }

    /// Adds `other`'s runs (after this one's: run 0 stays the first).
    pub fn merge(&mut self, other: ExperimentResult) {
        for (mine, theirs) in self
            .sum_squared
            .iter_mut()
            .chain(self.sum_squared_before_reset.iter_mut())
            .zip(other.sum_squared.iter().chain(&other.sum_squared_before_reset))
        {
            for (a, b) in mine.iter_mut().zip(theirs) {
                *a += b;
            }
        }
        for (a, b) in self.reinitialised_runs.iter_mut().zip(&other.reinitialised_runs) {
            *a += b;
        }
        self.runs += other.runs;
        self.reinitialisations.extend(other.reinitialisations);
        for (a, b) in self.causes.iter_mut().zip(other.causes) {
            *a += b;
        }
        if self.run0.is_empty() {
            self.run0 = other.run0;
        }
        self.aoa_updates.merge(&other.aoa_updates);
        self.tracker_cpu_s += other.tracker_cpu_s;
    }

    /// Tracked slots per run (slot 0 is the initial access).
    #[must_use]
    pub fn tracked_slots(&self) -> usize {
        self.sum_squared[0].len().saturating_sub(1)
    }

    /// RMSE over every tracked slot and run, per component (relative for
    /// |alpha|, radians for the angles).
    #[must_use]
    pub fn rmse(&self) -> [f64; 3] {
        self.rmse_of(&self.sum_squared)
    }

    /// [`ExperimentResult::rmse`] of the estimates before any
    /// re-initialisation (see [`ExperimentResult::sum_squared_before_reset`]).
    #[must_use]
    pub fn rmse_before_reset(&self) -> [f64; 3] {
        self.rmse_of(&self.sum_squared_before_reset)
    }

    fn rmse_of(&self, sum_squared: &[Vec<f64>; 3]) -> [f64; 3] {
        let n = (self.tracked_slots() as f64 * self.runs as f64).max(1.0);
        sum_squared.each_ref().map(|sums| (sums.iter().skip(1).sum::<f64>() / n).sqrt())
    }

    /// Mean re-initialisations per run.
    #[must_use]
    pub fn mean_reinitialisations(&self) -> f64 {
        self.reinitialisations.iter().sum::<u64>() as f64 / self.reinitialisations.len().max(1) as f64
    }
}

/// What the measurement updates did to one angle of the estimate, over
/// every update of every run: how far they moved it and whether towards the
/// truth. The pilot's power `h(s)` of eq. (20) through beams steered at the
/// previous estimate falls off alike on both sides of the beam, so its
/// gradient (26) takes its sign from where the *prediction* sits against
/// the beam, not from where the truth does; a stronger pilot shrinks the
/// noise variance (21) relative to `h` and makes the update trust that sign
/// more. These sums show it (`reproduce spebt`, the pilot-power table).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct UpdateSteps {
    /// Updates counted.
    pub updates: u64,
    /// Updates after which the angle's error was larger than before.
    pub away: u64,
    /// Sum of the squared step `angle_k|k - angle_k|k-1`, rad^2.
    pub sum_squared_step_rad2: f64,
}

impl UpdateSteps {
    /// Counts one update from `prior_error_rad` to `posterior_error_rad`
    /// (errors against the truth, wrapped).
    pub fn add(&mut self, prior_error_rad: f64, posterior_error_rad: f64) {
        self.updates += 1;
        self.away += u64::from(posterior_error_rad.abs() > prior_error_rad.abs());
        let step = wrap_angle_rad(posterior_error_rad - prior_error_rad);
        self.sum_squared_step_rad2 += step * step;
    }

    fn merge(&mut self, other: &UpdateSteps) {
        self.updates += other.updates;
        self.away += other.away;
        self.sum_squared_step_rad2 += other.sum_squared_step_rad2;
    }

    /// Share of the updates that moved the angle away from the truth.
    #[must_use]
    pub fn away_share(&self) -> f64 {
        self.away as f64 / self.updates.max(1) as f64
    }

    /// RMS of the update's step, radians.
    #[must_use]
    pub fn rms_step_rad(&self) -> f64 {
        (self.sum_squared_step_rad2 / self.updates.max(1) as f64).sqrt()
    }
}

/// Where the tracker's pose estimates come from.
#[derive(Clone, Copy)]
pub enum PoseSource<'a> {
    /// Each run's own draw of the pose-error model (eq. (23)).
    ErrorModel,
    /// The same estimates in every run (radar odometry), one per slot.
    Fixed(&'a [Se2]),
}

/// `runs` Monte Carlo runs on `link` in fixed chunks on rayon, merged in
/// chunk order.
///
/// # Errors
/// A run whose filter fails (naming the run), or pose estimates of the
/// wrong length.
pub fn monte_carlo(
    link: &SpebtLink,
    config: &SpebtConfig,
    seed: u64,
    runs: u64,
    source: PoseSource<'_>,
    progress: &dyn Progress,
) -> anyhow::Result<ExperimentResult> {
    let chunks = runs.div_ceil(RUNS_PER_CHUNK);
    let label = match source {
        PoseSource::ErrorModel => "spebt: tracking, pose-error model",
        PoseSource::Fixed(_) => "spebt: tracking on radar odometry",
    };
    progress.start(label, runs, "runs");
    let mut total = ExperimentResult::new(link.len());
    for batch in (0..chunks).step_by(CHUNKS_PER_BATCH as usize) {
        let partials: Vec<ExperimentResult> = (batch..(batch + CHUNKS_PER_BATCH).min(chunks))
            .into_par_iter()
            .map(|c| {
                let range = c * RUNS_PER_CHUNK..((c + 1) * RUNS_PER_CHUNK).min(runs);
                let count = range.end - range.start;
                progress.check_cancelled()?;
                let chunk = run_chunk(link, config, seed, range, source);
                progress.advance(count);
                chunk
            })
            .collect::<anyhow::Result<_>>()?;
        for part in partials {
            total.merge(part);
        }
    }
    progress.finish();
    Ok(total)
}

/// The filter's parameters: the link's Table I values and the [tracker] table.
#[must_use]
pub fn tracker_config(experiment: &SpebtExperiment) -> SpebtConfig {
    let (s, t) = (&experiment.scenario, &experiment.tracker);
    SpebtConfig {
        bs_elements: s.bs_elements,
        vehicle_elements: s.vehicle_elements,
        spacing_wavelengths: s.spacing_wavelengths,
        path_loss_exponent: s.path_loss_exponent,
        bs_x_m: s.bs_x_m,
        bs_y_m: s.bs_y_m,
        pilot_power_w: s.pilot_power_w(),
        noise_variance_w: s.noise_variance_w(),
        position_sigma_m: t.position_sigma_m,
        yaw_sigma_rad: t.yaw_sigma_deg.to_radians(),
        gain_threshold: t.gain_threshold,
        aod_threshold_rad: t.angle_threshold_deg.to_radians(),
        aoa_threshold_rad: t.angle_threshold_deg.to_radians(),
    }
}

/// Initial access: the true channel of a slot.
#[must_use]
pub fn initial_access(slot: &SpebtSlot) -> SpebtState {
    SpebtState { gain_magnitude: slot.gain.norm(), aod_rad: slot.aod_rad, aoa_rad: slot.aoa_rad }
}

fn run_chunk(
    link: &SpebtLink,
    config: &SpebtConfig,
    seed: u64,
    runs: std::ops::Range<u64>,
    source: PoseSource<'_>,
) -> anyhow::Result<ExperimentResult> {
    let mut chunk = ExperimentResult::new(link.len());
    for run_index in runs {
        let realisation = link.realise(seed, run_index);
        let poses = match source {
            PoseSource::ErrorModel => &realisation.pose_estimates[..],
            PoseSource::Fixed(poses) => poses,
        };
        anyhow::ensure!(poses.len() == link.len(), "{} pose estimates for {} slots", poses.len(), link.len());
        let started = Instant::now();
        let truth = link.slots();
        let mut ekf =
            SpebtEkf::new(config, initial_access(&truth[0]), &poses[0]).with_context(|| format!("run {run_index}"))?;
        let keep = run_index == 0;
        if keep {
            chunk.run0.push((ekf.estimate(), false));
        }
        let mut reinitialisations = 0;
        for (k, slot) in truth.iter().enumerate().skip(1) {
            let beams = ekf.predict(&poses[k]).with_context(|| format!("run {run_index}"))?;
            let prior_errors = estimate_errors(&ekf.estimate(), slot);
            let pilot = link.pilot(k, beams.rx_steer_u, beams.tx_steer_u, realisation.noise[k]);
            let deviation = ekf.update(pilot).with_context(|| format!("run {run_index}"))?;
            let errors_before_reset = estimate_errors(&ekf.estimate(), slot);
            chunk.aoa_updates.add(prior_errors[2], errors_before_reset[2]);
            for (sums, e) in chunk.sum_squared_before_reset.iter_mut().zip(errors_before_reset) {
                sums[k] += e * e;
            }
            let reinitialised = if let Deviation::Exceeded { gain, aod, aoa } = deviation {
                ekf.reinitialise(initial_access(slot))?;
                for (count, fired) in chunk.causes.iter_mut().zip([gain, aod, aoa]) {
                    *count += u64::from(fired);
                }
                chunk.reinitialised_runs[k] += 1;
                reinitialisations += 1;
                true
            } else {
                false
            };
            let estimate = ekf.estimate();
            let errors = if reinitialised { estimate_errors(&estimate, slot) } else { errors_before_reset };
            for (sums, e) in chunk.sum_squared.iter_mut().zip(errors) {
                sums[k] += e * e;
            }
            if keep {
                chunk.run0.push((estimate, reinitialised));
            }
        }
        chunk.tracker_cpu_s += started.elapsed().as_secs_f64();
        chunk.reinitialisations.push(reinitialisations);
        chunk.runs += 1;
    }
    Ok(chunk)
}

/// The errors of an estimate against the slot's true channel: relative for
/// |alpha|, wrapped radians for AoD and AoA.
fn estimate_errors(estimate: &SpebtState, slot: &SpebtSlot) -> [f64; 3] {
    let true_gain = slot.gain.norm();
    [
        (estimate.gain_magnitude - true_gain) / true_gain,
        wrap_angle_rad(estimate.aod_rad - slot.aod_rad),
        wrap_angle_rad(estimate.aoa_rad - slot.aoa_rad),
    ]
}

/// Odometry estimates (their world frame is the first scan's pose) moved
/// into the ground truth's frame at the first pose:
/// `world_from_first_truth * first_estimate^-1 * estimate`. Empty for no
/// estimates.
#[must_use]
pub fn into_truth_frame(first_truth: Se2, raw: &[Se2]) -> Vec<Se2> {
    let Some(first) = raw.first() else { return Vec::new() };
    let truth_from_estimate = first_truth * first.inverse();
    raw.iter().map(|e| truth_from_estimate * *e).collect()
}

/// Estimates in the ground truth's frame moved into the link's frame, whose
/// positions are relative to the first true position (headings kept;
/// `mmtrack_sim::beam::spebt_link` module docs).
#[must_use]
pub fn into_link_frame(first_truth: Se2, estimates: &[Se2]) -> Vec<Se2> {
    estimates.iter().map(|e| Se2::new(e.x_m - first_truth.x_m, e.y_m - first_truth.y_m, e.yaw_rad)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn update_steps_count_the_moves_away_from_the_truth_and_their_size() {
        let mut steps = UpdateSteps::default();
        steps.add(0.10, 0.05); // towards the truth
        steps.add(0.10, -0.20); // past it, further away
        steps.add(-0.10, -0.13); // away
        let mut other = UpdateSteps::default();
        other.add(0.0, 0.0); // no move: not away
        steps.merge(&other);
        assert_eq!((steps.updates, steps.away), (4, 2));
        assert!((steps.away_share() - 0.5).abs() < 1e-15);
        let expected = ((0.05f64.powi(2) + 0.30f64.powi(2) + 0.03f64.powi(2)) / 4.0).sqrt();
        assert!((steps.rms_step_rad() - expected).abs() < 1e-12, "{}", steps.rms_step_rad());
        assert_eq!(UpdateSteps::default().away_share(), 0.0, "no update: no share, not NaN");
    }

    #[test]
    fn the_embedded_experiment_parses_with_table_i() {
        let experiment: SpebtExperiment = toml::from_str(SPEBT_EXPERIMENT).unwrap();
        assert_eq!(experiment.scenario, SpebtScenario::default(), "[scenario] spells out Table I");
        assert_eq!((experiment.slots, experiment.paper.slots), (6388, 6388));
        let config = tracker_config(&experiment);
        assert!((config.noise_variance_w - 1e-12).abs() < 1e-24);
        assert!((config.aoa_threshold_rad.to_degrees() - 7.5).abs() < 1e-12);
    }
}
