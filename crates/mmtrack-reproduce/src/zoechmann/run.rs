//! The Monte Carlo of the Zoechmann experiment.
//!
//! On the simulated overtaking manoeuvres (`mmtrack_sim::beam::overtaking`),
//! four estimators run on the same Monte Carlo realisations:
//!
//! - `proposed`: the recursive tracker (`GeometricTracker`) on the azimuths
//!   of its own beam schedule (full scans for the first 10 epochs, then the
//!   3 beams nearest the azimuth it projects to the epoch);
//! - `ho-chan`: the running-reference batch baseline on full-scan azimuths
//!   (a full scan every epoch: the baseline has no beam schedule);
//! - `error-free-genie` and `nullspace-genie`: the bounds of Sec. V on the
//!   true azimuths.
//!
//! All see the same noisy Doppler shifts. Per epoch: the NMSE of the range
//! over the runs. Checked: the paper's ordering at the end of each run,
//! the full-overtaking hand-over time (about 0.5 s), the beam-measurement
//! saving (counted), and the time of the whole run.
//!
//! Runs are split into fixed chunks computed on rayon and merged in chunk
//! order, so the numbers do not depend on the thread count.

use std::time::Instant;

use anyhow::Context;
use mmtrack_analysis::beam::zoechmann_plots::PositionTrace;
use mmtrack_beam::geometric::{
    BeamCount, BeamSchedule, BeamSelection, DopplerBearing, ErrorFreeRegressors, GeometricTracker,
    GeometricTrackerConfig, HoChanBatch, NullspaceProjection, PolarState, RangeEstimator,
};
use mmtrack_core::progress::Progress;
use mmtrack_core::stats::quantile_nearest_rank;
use mmtrack_sim::beam::overtaking::{EpochTruth, Manoeuvre, OvertakingReceiver};
use rayon::prelude::*;

use super::config::Config;
use super::nlos::{self, NlosResult};
use crate::common::load_average;

/// The estimators, in table order: the paper's four, two variants of the
/// proposed tracker's beam schedule, and four diagnostics of the
/// full-overtaking miss (docs/results/zoechmann.md):
/// - `ho-chan-true-azimuth`: the baseline on the true azimuths (what its
///   quantisation bias costs);
/// - `*-doppler-mps`: the same estimators with the Doppler equation (5)
///   multiplied by `lambda` ([`DOPPLER_MPS`]); `proposed-doppler-mps` is the
///   proposed tracker so, with its own beam window.
pub const ESTIMATORS: [&str; 11] = [
    "proposed",
    "ho-chan",
    "error-free-genie",
    "nullspace-genie",
    "proposed-full-scan",
    "proposed-gated",
    "ho-chan-true-azimuth",
    "ho-chan-doppler-mps",
    "error-free-genie-doppler-mps",
    "proposed-full-scan-doppler-mps",
    "proposed-doppler-mps",
];
/// The estimators of the time-series table and the figures: the paper's
/// four and the two schedule variants.
pub const PLOTTED: usize = 6;
/// Index of a variant: the proposed tracker on full-scan azimuths every
/// epoch (no beam-selection feedback), a diagnostic beside the paper's four.
pub const FULL_SCAN_VARIANT: usize = 4;
/// Index of a variant: the proposed tracker whose 3-beam window starts only
/// once it has handed over to RLS (full scans before), a diagnostic.
pub const GATED_VARIANT: usize = 5;
/// Index of the first `*-doppler-mps` diagnostic.
pub const DOPPLER_MPS_FIRST: usize = 7;
/// Index of the proposed tracker with its own window and the Doppler
/// equation in m/s.
pub const WINDOWED_DOPPLER_MPS: usize = 10;
/// Trackers that measure through their own beam window (beam accounting
/// index): the proposed tracker (0), the gated variant (1) and the
/// proposed tracker with the Doppler equation in m/s (2).
pub const WINDOWED: usize = 3;
const N: usize = ESTIMATORS.len();

/// The Doppler equation (5) multiplied by `lambda`: `a_D = [0, sin b, cos
/// b]`, `y = lambda nu` (the range rate, m/s, noise 0.5 m/s). The same
/// equation, but in the unweighted least squares of (7) its weight against
/// the bearing rows (2) (metres; quantisation error ~0.5 m at 20 m) drops by
/// `lambda^2`: printed in Hz, a Doppler row counts `(1 / lambda)^2 = 4e4`
/// times a bearing row of the same size. The estimators take it as a
/// "wavelength" of 1 m and a "Doppler shift" of `lambda nu`.
const DOPPLER_MPS: f64 = 1.0;

/// Where an estimator's azimuths come from.
#[derive(Clone, Copy)]
enum Azimuths {
    /// The strongest beam of a full codebook scan.
    FullScan,
    /// The true (unquantised) azimuth: the genies.
    True,
}

/// Runs per rayon task: fixed, so partial sums merge in the same order on
/// any number of threads.
const RUNS_PER_CHUNK: u64 = 250;

/// What one manoeuvre measured.
#[derive(Debug, Clone)]
pub struct ManoeuvreResult {
    /// The manoeuvre.
    pub manoeuvre: Manoeuvre,
    /// Runs.
    pub runs: u64,
    /// NMSE per estimator and epoch.
    pub nmse: [Vec<f64>; N],
    /// RMSE per estimator and epoch, metres.
    pub rmse_m: [Vec<f64>; N],
    /// Runs with an estimate per estimator and epoch.
    pub counted: [Vec<u64>; N],
    /// Hand-over time of each converged run, sorted.
    pub handovers_s: Vec<f64>,
    /// The same for the full-scan variant.
    pub handovers_full_scan_s: Vec<f64>,
    /// Beam accounting of the proposed tracker (index 0) and of the gated
    /// variant (1).
    pub beams: [BeamCount; WINDOWED],
    /// Windowed epochs over all runs, per windowed tracker.
    pub window_epochs: [u64; WINDOWED],
    /// Windowed epochs whose window held the strongest beam, per windowed tracker.
    pub window_hits: [u64; WINDOWED],
    /// Per epoch: windowed runs and hits (proposed 0, gated 1).
    pub window_epochs_by_epoch: [Vec<u64>; WINDOWED],
    /// See `window_epochs_by_epoch`.
    pub window_hits_by_epoch: [Vec<u64>; WINDOWED],
    /// Runs whose first window points more than 90 deg from the truth.
    pub backwards_first_windows: u64,
    /// Estimator errors (the estimator stops for the rest of the run).
    pub failures: u64,
    /// The first run's true and estimated positions (proposed tracker).
    pub trace: PositionTrace,
}

impl ManoeuvreResult {
    /// NMSE of estimator `e` at the last epoch.
    pub fn final_nmse(&self, e: usize) -> Option<f64> {
        self.nmse[e].last().copied().filter(|v| v.is_finite())
    }

    /// Nearest-rank quantile `q` of the hand-over times.
    pub fn handover_quantile(&self, q: f64) -> Option<f64> {
        quantile_nearest_rank(&self.handovers_s, q)
    }

    /// Share of windowed epochs whose window held the strongest beam, of the
    /// proposed tracker (0) or the gated variant (1).
    pub fn window_hit_rate(&self, i: usize) -> f64 {
        self.window_hits[i] as f64 / self.window_epochs[i].max(1) as f64
    }

    /// Share of windowed runs whose window held the strongest beam over the
    /// epochs `epochs`, proposed (0) or gated (1); `None` without windows.
    pub fn window_hit_rate_over(&self, i: usize, epochs: std::ops::Range<usize>) -> Option<f64> {
        let n: u64 = self.window_epochs_by_epoch[i].get(epochs.clone())?.iter().sum();
        let hits: u64 = self.window_hits_by_epoch[i].get(epochs)?.iter().sum();
        (n > 0).then(|| hits as f64 / n as f64)
    }

    /// Mean hand-over time.
    pub fn handover_mean(&self) -> Option<f64> {
        let n = self.handovers_s.len();
        (n > 0).then(|| self.handovers_s.iter().sum::<f64>() / n as f64)
    }
}

/// What the whole Monte Carlo measured, and how long it took.
#[derive(Debug, Clone)]
pub struct Measured {
    /// Runs per manoeuvre.
    pub runs: u64,
    /// One per manoeuvre, in the file's order.
    pub manoeuvres: Vec<ManoeuvreResult>,
    /// The non-line-of-sight run.
    pub nlos: NlosResult,
    /// Wall time of the manoeuvres' runs (not the NLOS run), seconds.
    pub elapsed_s: f64,
    /// Threads of the rayon pool.
    pub threads: usize,
    /// 1-minute load average before and after.
    pub load: (Option<f64>, Option<f64>),
}

/// Runs `runs` realisations of every manoeuvre of `experiment`, then
/// `nlos_runs` of the non-line-of-sight run.
///
/// # Errors
/// No manoeuvres, an invalid scenario or tracker configuration, a
/// simulator failure.
pub fn measure(experiment: &Config, runs: u64, nlos_runs: u64, progress: &dyn Progress) -> anyhow::Result<Measured> {
    let source = &experiment.source;
    anyhow::ensure!(!experiment.manoeuvres.is_empty(), "{source}: no [[manoeuvres]] (nothing was done)");
    for m in &experiment.manoeuvres {
        experiment.scenario.validate(m).with_context(|| format!("{source}: [scenario] / manoeuvre {}", m.name))?;
    }
    experiment.tracker_config().validate().with_context(|| source.clone())?;

    let load_before = load_average();
    let started = Instant::now();
    let receiver = experiment.scenario.receiver().with_context(|| format!("{source}: [scenario]"))?;
    let chunks = runs.div_ceil(RUNS_PER_CHUNK);
    progress.start("reproduce zoechmann", runs * experiment.manoeuvres.len() as u64, "runs");
    let mut results = Vec::new();
    for manoeuvre in &experiment.manoeuvres {
        let partials: Vec<Chunk> = (0..chunks)
            .into_par_iter()
            .map(|c| {
                let range = c * RUNS_PER_CHUNK..((c + 1) * RUNS_PER_CHUNK).min(runs);
                let n = range.end - range.start;
                progress.check_cancelled()?;
                let chunk = run_chunk(experiment, manoeuvre, &receiver, range);
                progress.advance(n);
                chunk
            })
            .collect::<anyhow::Result<_>>()
            .with_context(|| manoeuvre.name.clone())?;
        let epochs = manoeuvre.epochs(experiment.scenario.epoch_s);
        let mut total = Chunk::new(epochs);
        for part in partials {
            total.merge(part);
        }
        results.push(total.finish(manoeuvre.clone(), runs));
    }
    progress.finish();
    let elapsed_s = started.elapsed().as_secs_f64();
    let nlos = nlos::run(experiment, &experiment.nlos, &receiver, nlos_runs.max(1))
        .with_context(|| format!("{source}: [nlos]"))?;
    Ok(Measured {
        runs,
        manoeuvres: results,
        nlos,
        elapsed_s,
        threads: rayon::current_num_threads(),
        load: (load_before, load_average()),
    })
}

/// Partial sums of a chunk of runs.
struct Chunk {
    squared_error: [Vec<f64>; N],
    counted: [Vec<u64>; N],
    /// Sum of the squared true range per estimator (over the runs it counts).
    squared_range: [Vec<f64>; N],
    handovers_s: Vec<f64>,
    handovers_full_scan_s: Vec<f64>,
    beams: [BeamCount; WINDOWED],
    window_epochs: [u64; WINDOWED],
    window_hits: [u64; WINDOWED],
    /// Per epoch: windowed runs and hits, of the proposed tracker (0) and
    /// the gated variant (1).
    window_epochs_by_epoch: [Vec<u64>; WINDOWED],
    window_hits_by_epoch: [Vec<u64>; WINDOWED],
    /// Runs whose first window (the proposed tracker's) is centred more than
    /// 90 deg from the true azimuth.
    backwards_first_windows: u64,
    failures: u64,
    trace: Option<PositionTrace>,
}

impl Chunk {
    fn new(epochs: usize) -> Self {
        Self {
            squared_error: std::array::from_fn(|_| vec![0.0; epochs]),
            counted: std::array::from_fn(|_| vec![0; epochs]),
            squared_range: std::array::from_fn(|_| vec![0.0; epochs]),
            handovers_s: Vec::new(),
            handovers_full_scan_s: Vec::new(),
            beams: [BeamCount::default(); WINDOWED],
            window_epochs: [0; WINDOWED],
            window_hits: [0; WINDOWED],
            window_epochs_by_epoch: std::array::from_fn(|_| vec![0; epochs]),
            window_hits_by_epoch: std::array::from_fn(|_| vec![0; epochs]),
            backwards_first_windows: 0,
            failures: 0,
            trace: None,
        }
    }

    fn merge(&mut self, other: Chunk) {
        for e in 0..N {
            for (a, b) in self.squared_error[e].iter_mut().zip(&other.squared_error[e]) {
                *a += b;
            }
            for (a, b) in self.squared_range[e].iter_mut().zip(&other.squared_range[e]) {
                *a += b;
            }
            for (a, b) in self.counted[e].iter_mut().zip(&other.counted[e]) {
                *a += b;
            }
        }
        self.handovers_s.extend(other.handovers_s);
        self.handovers_full_scan_s.extend(other.handovers_full_scan_s);
        for i in 0..WINDOWED {
            self.beams[i].merge(&other.beams[i]);
            self.window_epochs[i] += other.window_epochs[i];
            self.window_hits[i] += other.window_hits[i];
            for (a, b) in self.window_epochs_by_epoch[i].iter_mut().zip(&other.window_epochs_by_epoch[i]) {
                *a += b;
            }
            for (a, b) in self.window_hits_by_epoch[i].iter_mut().zip(&other.window_hits_by_epoch[i]) {
                *a += b;
            }
        }
        self.backwards_first_windows += other.backwards_first_windows;
        self.failures += other.failures;
        if self.trace.is_none() {
            self.trace = other.trace;
        }
    }

    fn finish(mut self, manoeuvre: Manoeuvre, runs: u64) -> ManoeuvreResult {
        let nmse = std::array::from_fn(|e| {
            self.squared_error[e].iter().zip(&self.squared_range[e]).map(|(s, r)| s / r).collect()
        });
        let rmse_m = std::array::from_fn(|e| {
            self.squared_error[e].iter().zip(&self.counted[e]).map(|(s, &n)| (s / n as f64).sqrt()).collect()
        });
        self.handovers_s.sort_by(f64::total_cmp);
        self.handovers_full_scan_s.sort_by(f64::total_cmp);
        ManoeuvreResult {
            manoeuvre,
            runs,
            nmse,
            rmse_m,
            counted: self.counted,
            handovers_s: self.handovers_s,
            handovers_full_scan_s: self.handovers_full_scan_s,
            beams: self.beams,
            window_epochs: self.window_epochs,
            window_hits: self.window_hits,
            window_epochs_by_epoch: self.window_epochs_by_epoch,
            window_hits_by_epoch: self.window_hits_by_epoch,
            backwards_first_windows: self.backwards_first_windows,
            failures: self.failures,
            trace: self.trace.unwrap_or_default(),
        }
    }
}

fn run_chunk(
    experiment: &Config,
    manoeuvre: &Manoeuvre,
    receiver: &OvertakingReceiver,
    runs: std::ops::Range<u64>,
) -> anyhow::Result<Chunk> {
    let scenario = &experiment.scenario;
    let lambda = scenario.wavelength_m();
    let schedule = BeamSchedule {
        beams: scenario.beams,
        full_scan_epochs: experiment.full_scan_epochs,
        window_beams: experiment.window_beams,
    };
    let mut chunk = Chunk::new(manoeuvre.epochs(scenario.epoch_s));
    for run_index in runs {
        let run = scenario.realise(manoeuvre, experiment.seed, run_index)?;
        let proposed = GeometricTracker::new(experiment.tracker_config())?;
        let mps_tracker = GeometricTrackerConfig { wavelength_m: DOPPLER_MPS, ..experiment.tracker_config() };
        let mut estimators = [
            Fed::new(1, HoChanBatch::new(lambda)?, Azimuths::FullScan, false),
            Fed::new(2, ErrorFreeRegressors::new(lambda)?, Azimuths::True, false),
            Fed::new(3, NullspaceProjection::new(lambda)?, Azimuths::True, false),
            Fed::new(6, HoChanBatch::new(lambda)?, Azimuths::True, false),
            Fed::new(DOPPLER_MPS_FIRST, HoChanBatch::new(DOPPLER_MPS)?, Azimuths::FullScan, true),
            Fed::new(DOPPLER_MPS_FIRST + 1, ErrorFreeRegressors::new(DOPPLER_MPS)?, Azimuths::True, true),
            Fed::new(DOPPLER_MPS_FIRST + 2, GeometricTracker::new(mps_tracker)?, Azimuths::FullScan, true),
        ];
        let mut full_scan = Some(GeometricTracker::new(experiment.tracker_config())?);
        let mut windowed = [
            Windowed { tracker: Some(proposed), gated: false, doppler_factor: 1.0, estimator: 0, counter: 0 },
            Windowed {
                tracker: Some(GeometricTracker::new(experiment.tracker_config())?),
                gated: true,
                doppler_factor: 1.0,
                estimator: GATED_VARIANT,
                counter: 1,
            },
            Windowed {
                tracker: Some(GeometricTracker::new(mps_tracker)?),
                gated: false,
                doppler_factor: lambda,
                estimator: WINDOWED_DOPPLER_MPS,
                counter: 2,
            },
        ];
        let mut trace = (run_index == 0).then(PositionTrace::default);
        for (k, truth) in run.epochs.iter().enumerate() {
            let doppler_hz = truth.measured_doppler_hz();
            let full_scan_beam = receiver.strongest_beam(truth.azimuth_rad);
            for w in &mut windowed {
                let Some(state) = w.step(&mut chunk, &schedule, receiver, k, truth, full_scan_beam) else { continue };
                if w.estimator == 0
                    && let Some(trace) = &mut trace
                {
                    trace.truth_m.push(truth.position_m);
                    trace.estimate_m.push(state.position_m(truth.t_s));
                }
            }
            let full_scan_azimuth_rad = receiver.beam_azimuth_rad(full_scan_beam);
            if let Some(tracker) = &mut full_scan {
                let observation = DopplerBearing { t_s: truth.t_s, azimuth_rad: full_scan_azimuth_rad, doppler_hz };
                match tracker.update(&observation) {
                    Ok(()) => {
                        if let Some(r) = tracker.range_now_m() {
                            add(&mut chunk, FULL_SCAN_VARIANT, k, r, truth.range_m);
                        }
                    }
                    Err(_) => {
                        chunk.failures += 1;
                        full_scan = None;
                    }
                }
            }
            for fed in &mut estimators {
                let Some(estimator) = &mut fed.estimator else { continue };
                let azimuth_rad = match fed.azimuths {
                    Azimuths::FullScan => full_scan_azimuth_rad,
                    Azimuths::True => truth.azimuth_rad,
                };
                let doppler_hz = if fed.doppler_mps { lambda * doppler_hz } else { doppler_hz };
                let observation = DopplerBearing { t_s: truth.t_s, azimuth_rad, doppler_hz };
                match estimator.update(&observation) {
                    Ok(()) => {
                        if let Some(r) = estimator.range_now_m() {
                            add(&mut chunk, fed.column, k, r, truth.range_m);
                        }
                    }
                    Err(_) => {
                        chunk.failures += 1;
                        fed.estimator = None;
                    }
                }
            }
        }
        if let Some(t) = windowed[0].tracker.as_ref().and_then(GeometricTracker::handover_t_s) {
            chunk.handovers_s.push(t);
        }
        if let Some(t) = full_scan.and_then(|f| f.handover_t_s()) {
            chunk.handovers_full_scan_s.push(t);
        }
        if let Some(trace) = trace {
            chunk.trace = Some(trace);
        }
    }
    Ok(chunk)
}

/// An estimator fed without beam-selection feedback: its NMSE column, the
/// estimator (`None` after an error), where its azimuths come from and
/// whether its Doppler equation is in m/s ([`DOPPLER_MPS`]).
struct Fed {
    column: usize,
    estimator: Option<Box<dyn RangeEstimator>>,
    azimuths: Azimuths,
    doppler_mps: bool,
}

impl Fed {
    fn new(column: usize, estimator: impl RangeEstimator + 'static, azimuths: Azimuths, doppler_mps: bool) -> Self {
        Self { column, estimator: Some(Box::new(estimator)), azimuths, doppler_mps }
    }
}

/// A proposed tracker that measures through its own beam window.
struct Windowed {
    /// `None` after an estimator error.
    tracker: Option<GeometricTracker>,
    /// Window only after the hand-over to RLS (the gated variant).
    gated: bool,
    /// Multiplies the measured Doppler shift: 1, or `lambda` for the Doppler
    /// equation in m/s ([`DOPPLER_MPS`]).
    doppler_factor: f64,
    /// Column of the NMSE sums.
    estimator: usize,
    /// Index of the beam accounting.
    counter: usize,
}

impl Windowed {
    /// Selects the beams, measures the strongest of them, updates the
    /// tracker and adds its range error; the new state on success.
    fn step(
        &mut self,
        chunk: &mut Chunk,
        schedule: &BeamSchedule,
        receiver: &OvertakingReceiver,
        k: usize,
        truth: &EpochTruth,
        full_scan_beam: usize,
    ) -> Option<PolarState> {
        let tracker = self.tracker.as_mut()?;
        let may_window = k > 0 && (!self.gated || tracker.converged());
        let projected = if may_window { tracker.state().map(|s| s.azimuth_rad(truth.t_s)) } else { None };
        let selection = schedule.select(k, projected);
        chunk.beams[self.counter].add(&selection, schedule.beams);
        let beam = match &selection {
            BeamSelection::FullScan => full_scan_beam,
            BeamSelection::Window(window) => {
                chunk.window_epochs[self.counter] += 1;
                chunk.window_epochs_by_epoch[self.counter][k] += 1;
                if window.contains(&full_scan_beam) {
                    chunk.window_hits[self.counter] += 1;
                    chunk.window_hits_by_epoch[self.counter][k] += 1;
                }
                // The proposed tracker's first window (the gated one opens later).
                if self.counter == 0
                    && k == schedule.full_scan_epochs
                    && let Some(projected) = projected
                    && mmtrack_core::wrap_angle_rad(projected - truth.azimuth_rad).abs() > std::f64::consts::FRAC_PI_2
                {
                    chunk.backwards_first_windows += 1;
                }
                receiver.strongest_of(window, truth.azimuth_rad).unwrap_or(full_scan_beam)
            }
        };
        let doppler_hz = truth.measured_doppler_hz();
        let observation = DopplerBearing {
            t_s: truth.t_s,
            azimuth_rad: receiver.beam_azimuth_rad(beam),
            doppler_hz: self.doppler_factor * doppler_hz,
        };
        if tracker.update(&observation).is_err() {
            chunk.failures += 1;
            self.tracker = None;
            return None;
        }
        let (range_m, state) = (tracker.range_now_m()?, tracker.state()?);
        add(chunk, self.estimator, k, range_m, truth.range_m);
        Some(state)
    }
}

fn add(chunk: &mut Chunk, estimator: usize, epoch: usize, range_m: f64, true_range_m: f64) {
    if range_m.is_finite() {
        chunk.squared_error[estimator][epoch] += (range_m - true_range_m).powi(2);
        chunk.squared_range[estimator][epoch] += true_range_m * true_range_m;
        chunk.counted[estimator][epoch] += 1;
    }
}
