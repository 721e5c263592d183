//! The non-line-of-sight part of the Zoechmann experiment: the proposed
//! geometric tracker on every path of an overtaking between two walls
//! (`mmtrack_sim::beam::overtaking_paths`: line of sight and both single
//! bounces), per-path position error over time against the simulator's
//! truth, and per path the table of `(t, x, y, vx, vy)` other sensors could
//! be labelled with (the paper's closing proposal).
//!
//! Each path is tracked by its own `GeometricTracker` fed a full scan's
//! azimuth every epoch (the paper's 3-beam window diverges on full
//! overtaking, README) and the path's Doppler. Runs are summed in fixed
//! chunks on rayon, so the numbers do not depend on the thread count.

use anyhow::Context;
use mmtrack_beam::geometric::{DopplerBearing, GeometricTracker, RangeEstimator};
use mmtrack_io::table::{ZoechmannNlosErrorRow, ZoechmannPathLabelRow};
use mmtrack_sim::beam::overtaking::OvertakingReceiver;
use mmtrack_sim::beam::overtaking_paths::{PathKind, realise_paths};
use rayon::prelude::*;

use super::config::{Config, NlosConfig};

/// Per path, sums over runs.
#[derive(Debug, Clone)]
pub struct PathErrors {
    /// The path (`PathKind::name`).
    pub name: &'static str,
    /// Per epoch: sum over runs of the squared position error, m^2 ...
    pub position_sq: Vec<f64>,
    /// ... of the squared velocity error, (m/s)^2 ...
    pub velocity_sq: Vec<f64>,
    /// ... and the runs counted.
    pub counted: Vec<u64>,
    /// Runs whose tracker failed on this path.
    pub failures: u64,
}

/// What the NLOS run measured.
#[derive(Debug, Clone)]
pub struct NlosResult {
    /// The manoeuvre's name.
    pub manoeuvre: String,
    /// Runs.
    pub runs: u64,
    /// One per path, in `PathKind::ALL` order.
    pub paths: Vec<PathErrors>,
    /// The first run's per-path labels.
    pub labels: Vec<ZoechmannPathLabelRow>,
}

const RUNS_PER_CHUNK: u64 = 100;

/// Runs the paths of `runs` realisations.
pub(super) fn run(
    experiment: &Config,
    nlos: &NlosConfig,
    receiver: &OvertakingReceiver,
    runs: u64,
) -> anyhow::Result<NlosResult> {
    let manoeuvre = experiment
        .manoeuvres
        .iter()
        .find(|m| m.name == nlos.manoeuvre)
        .with_context(|| format!("[nlos] manoeuvre `{}` is not among [[manoeuvres]]", nlos.manoeuvre))?;
    let epochs = manoeuvre.epochs(experiment.scenario.epoch_s);
    let chunks = runs.div_ceil(RUNS_PER_CHUNK);
    let partials: Vec<(Vec<PathErrors>, Vec<ZoechmannPathLabelRow>)> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut paths = empty(epochs);
            let mut labels = Vec::new();
            for run_index in c * RUNS_PER_CHUNK..((c + 1) * RUNS_PER_CHUNK).min(runs) {
                let path_runs = realise_paths(&experiment.scenario, manoeuvre, &nlos.walls, experiment.seed, run_index)
                    .context("[nlos]")?;
                for (p, path) in path_runs.iter().enumerate() {
                    let mut tracker = GeometricTracker::new(experiment.tracker_config())?;
                    for (k, e) in path.epochs.iter().enumerate() {
                        let t = &e.truth;
                        let beam = receiver.strongest_beam(t.azimuth_rad);
                        let observation = DopplerBearing {
                            t_s: t.t_s,
                            azimuth_rad: receiver.beam_azimuth_rad(beam),
                            doppler_hz: t.measured_doppler_hz(),
                        };
                        if tracker.update(&observation).is_err() {
                            paths[p].failures += 1;
                            break;
                        }
                        let Some(state) = tracker.state() else { continue };
                        let (position, velocity) = (state.position_m(t.t_s), state.velocity_mps());
                        let dp = (position[0] - t.position_m[0]).hypot(position[1] - t.position_m[1]);
                        let dv = (velocity[0] - e.velocity_mps[0]).hypot(velocity[1] - e.velocity_mps[1]);
                        if dp.is_finite() && dv.is_finite() {
                            paths[p].position_sq[k] += dp * dp;
                            paths[p].velocity_sq[k] += dv * dv;
                            paths[p].counted[k] += 1;
                        }
                        if run_index == 0 {
                            labels.push(ZoechmannPathLabelRow {
                                path: path.kind.name().to_string(),
                                t_ns: (t.t_s * 1e9).round() as i64,
                                x_m: position[0],
                                y_m: position[1],
                                vx_mps: velocity[0],
                                vy_mps: velocity[1],
                                true_x_m: t.position_m[0],
                                true_y_m: t.position_m[1],
                                true_vx_mps: e.velocity_mps[0],
                                true_vy_mps: e.velocity_mps[1],
                                reflection_x_m: e.reflection_point_m.map(|r| r[0]),
                                reflection_y_m: e.reflection_point_m.map(|r| r[1]),
                            });
                        }
                    }
                }
            }
            Ok((paths, labels))
        })
        .collect::<anyhow::Result<_>>()?;
    let mut paths = empty(epochs);
    let mut labels = Vec::new();
    for (part, part_labels) in partials {
        for (total, p) in paths.iter_mut().zip(part) {
            for k in 0..epochs {
                total.position_sq[k] += p.position_sq[k];
                total.velocity_sq[k] += p.velocity_sq[k];
                total.counted[k] += p.counted[k];
            }
            total.failures += p.failures;
        }
        labels.extend(part_labels);
    }
    Ok(NlosResult { manoeuvre: manoeuvre.name.clone(), runs, paths, labels })
}

fn empty(epochs: usize) -> Vec<PathErrors> {
    PathKind::ALL
        .iter()
        .map(|k| PathErrors {
            name: k.name(),
            position_sq: vec![0.0; epochs],
            velocity_sq: vec![0.0; epochs],
            counted: vec![0; epochs],
            failures: 0,
        })
        .collect()
}

fn rms(sum_sq: f64, n: u64) -> f64 {
    (sum_sq / n as f64).sqrt()
}

/// The `zoechmann_nlos_error` rows.
pub(super) fn error_rows(result: &NlosResult, epoch_s: f64) -> Vec<ZoechmannNlosErrorRow> {
    let mut rows = Vec::new();
    for p in &result.paths {
        for k in 0..p.counted.len() {
            rows.push(ZoechmannNlosErrorRow {
                path: p.name.to_string(),
                epoch: k as u64,
                t_ns: (k as f64 * epoch_s * 1e9).round() as i64,
                runs: p.counted[k],
                position_rmse_m: rms(p.position_sq[k], p.counted[k]),
                velocity_rmse_mps: rms(p.velocity_sq[k], p.counted[k]),
            });
        }
    }
    rows
}

/// The Markdown section: position and velocity RMSE per path at a few times.
pub(super) fn summary(result: &NlosResult, nlos: &NlosConfig, epoch_s: f64) -> String {
    let mut out = format!(
        "\nNon-line-of-sight paths ({}, walls at y = {} m and {} m, {} runs; each path tracked on its own with a full \
         scan's azimuth every epoch): RMS error of the apparent source's position (transmitter or wall image), m, and \
         of its relative velocity, m/s.\n\n| path |",
        result.manoeuvre, nlos.walls.left_wall_m, nlos.walls.right_wall_m, result.runs
    );
    let epochs = result.paths.first().map_or(0, |p| p.counted.len());
    let picks: Vec<usize> =
        [0.5, 1.0, 2.0, 3.0, 4.0].iter().map(|t| (t / epoch_s).round() as usize).filter(|&k| k < epochs).collect();
    for &k in &picks {
        out.push_str(&format!(" {:.1} s |", k as f64 * epoch_s));
    }
    out.push_str(" failures |\n|---|");
    out.push_str(&"---|".repeat(picks.len() + 1));
    out.push('\n');
    for p in &result.paths {
        out.push_str(&format!("| {} |", p.name));
        for &k in &picks {
            out.push_str(&format!(
                " {:.2} m, {:.2} m/s |",
                rms(p.position_sq[k], p.counted[k]),
                rms(p.velocity_sq[k], p.counted[k])
            ));
        }
        out.push_str(&format!(" {} |\n", p.failures));
    }
    out
}
