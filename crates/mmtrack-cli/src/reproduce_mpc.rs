//! `mmtrack reproduce mpc-artificial`: the artificial-channel experiment of
//! Mahler et al. 2017, Sec. IV-A, Figs. 4-5 (issue #5).
//!
//! Two MPCs of equal power approach in delay over a -140 dB noise floor; the
//! MPC power is swept. For each power, with and without the Kaiser window,
//! the proposed tracker (short-term tracking over the whole approach, one
//! set) and the GM-PHD baseline (Table I) run on the same detections. The
//! paper compares with ground truth "up to a distance of 2.5 ns", so the
//! channel approaches from 20 ns to 2.5 ns. Reported per point: the mean
//! number of tracks (>= 3 detections), how many of them follow a true MPC,
//! and the mean delay error of those tracks' points against the nearer true
//! MPC of the same snapshot, overall and per 2.5 ns band of the separation.
//! Tracks made of noise detections count in the number of tracks (the
//! paper's splitting criterion) but not in the error.
//!
//! A third tracker, `gm-phd-matched`, is a sensitivity variant of the
//! baseline: Table I's measurement noise (3 mm, 0.01 ns of delay) is below
//! our detector's delay noise at most powers, so each point also runs GM-PHD
//! with `sigma_measurement_m` set to the rms delay error of the proposed
//! tracker's true tracks at the same point, times c. The paper says its
//! parameters were "matched to our measurement data"; Table I stays the
//! reported baseline.
//!
//! Targets (PAPERS.md section 2): mean delay error below 0.03 ns at -116 dB
//! (proposed, Kaiser window); exactly two tracks in every run down to
//! -126 dB (proposed, Kaiser window).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::Args;
use mmtrack_analysis::mpc_artificial::{self as plots, ArtificialTracker, SeparationBin, SweepPoint};
use mmtrack_core::{MpcDetection, MpcTrack, MpcTruth};
use mmtrack_io::{AtomicFile, Durability, Overwrite};
use mmtrack_mpc::{
    DetectionConfig, Detector, GmPhdConfig, GmPhdSnapshot, SPEED_OF_LIGHT_M_PER_S, ShortTermConfig, SounderPulse,
};
use mmtrack_sim::sounder::{ArtificialChannelConfig, PulseModel, SounderConfig, artificial_channel};

use crate::reproduce_mpc_report::{self as report, README_BLOCK, Sweep};

#[derive(Args)]
pub struct MpcArtificialArgs {
    /// Output directory (results.csv, results_by_separation.csv, reproduce.md, SVG figures).
    #[arg(short, long, default_value = "out/reproduce/mpc-artificial")]
    output: PathBuf,
    /// Replace a previous run's output directory.
    #[arg(long)]
    force: bool,
    /// Monte Carlo runs per point (different noise and phases).
    #[arg(long, default_value_t = 20)]
    runs: u64,
    /// Sounder pulse of the artificial channel: `measured-like` (band edges
    /// rolled off and a small ripple, as a pulse measured through an RF
    /// cable, which is what the paper used) or `flat` (an ideal band whose
    /// off-grid paths spread over the whole CIR as a sinc).
    #[arg(long, value_enum, default_value_t = PulseChoice::MeasuredLike)]
    pulse: PulseChoice,
    /// Detection variant: keep the CIR taps below floor + 6 dB instead of
    /// zeroing them (the paper's step 1 zeroes them). Zeroing cuts the weak
    /// skirts of each pulse, which costs delay accuracy; this shows how much.
    #[arg(long)]
    keep_taps_below_threshold: bool,
    /// The CI version: 3 runs, powers -100..-130 dB in 6 dB steps plus -116 and -126 dB.
    #[arg(long)]
    quick: bool,
    /// Replace the block `<!-- reproduce-mpc-artificial:begin -->` ... `end`
    /// in this file with the summary (checked before the run).
    #[arg(long, value_name = "README.md")]
    readme: Option<PathBuf>,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum PulseChoice {
    MeasuredLike,
    Flat,
}

impl PulseChoice {
    fn model(self) -> PulseModel {
        match self {
            Self::MeasuredLike => PulseModel::measured_like(),
            Self::Flat => PulseModel::Flat,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::MeasuredLike => "measured-like",
            Self::Flat => "flat",
        }
    }
}

/// The approach: from this separation, ns ...
const START_SEPARATION_NS: f64 = 20.0;
/// ... down to this one (the paper compares "up to a distance of 2.5 ns").
const END_SEPARATION_NS: f64 = 2.5;
/// Width of the separation bands of `results_by_separation.csv`, ns.
const SEPARATION_BAND_NS: f64 = 2.5;
/// Number of bands between the end and the start separation.
const SEPARATION_BANDS: usize = 7;
const _: () = assert!(END_SEPARATION_NS + SEPARATION_BAND_NS * SEPARATION_BANDS as f64 == START_SEPARATION_NS);
/// Powers in the separation figure (present in both the quick and the full sweep).
const SEPARATION_PLOT_POWERS_DB: [f64; 5] = [-100.0, -112.0, -116.0, -124.0, -126.0];

pub fn run(args: &MpcArtificialArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    if args.output.exists() && !args.force {
        bail!("{}: exists; use --force to replace it (nothing was done)", args.output.display());
    }
    anyhow::ensure!(args.runs >= 1, "--runs must be at least 1 (nothing was done)");
    if let Some(readme) = &args.readme {
        crate::readme_block::check_block(readme, README_BLOCK)?;
    }
    let powers_db: Vec<f64> = if args.quick {
        vec![-100.0, -106.0, -112.0, -116.0, -118.0, -124.0, -126.0, -130.0]
    } else {
        (0..=16).map(|i| -100.0 - 2.0 * f64::from(i)).collect()
    };
    let runs = if args.quick { 3 } else { args.runs };
    let pulse = args.pulse.model();
    let mut sweep = Sweep {
        channel: channel_config(powers_db.first().copied().unwrap_or(-116.0), &pulse),
        pulse_name: args.pulse.name(),
        zero_below_threshold: !args.keep_taps_below_threshold,
        runs,
        points: Vec::new(),
        bins: Vec::new(),
    };
    for &power_db in &powers_db {
        for window in [true, false] {
            let detection = DetectionConfig {
                kaiser_beta: window.then_some(6.0),
                zero_below_threshold: !args.keep_taps_below_threshold,
                ..DetectionConfig::default()
            };
            let (points, bins) = sweep_point(&channel_config(power_db, &pulse), detection, runs)?;
            sweep.points.extend(points);
            sweep.bins.extend(bins);
        }
        if !quiet {
            eprintln!("reproduce mpc-artificial: {power_db} dB done");
        }
    }
    let markdown = report::markdown(&sweep);
    std::fs::create_dir_all(&args.output).with_context(|| args.output.display().to_string())?;
    write_atomically(&args.output.join("results.csv"), &report::csv(&sweep.points))?;
    write_atomically(&args.output.join("results_by_separation.csv"), &report::separation_csv(&sweep.bins))?;
    write_atomically(&args.output.join("reproduce.md"), &markdown)?;
    crate::reproduce_all::write_metrics(&args.output, &report::metrics(&sweep))?;
    write_figures(&sweep, &args.output)?;
    if let Some(readme) = &args.readme {
        let summary = report::readme_summary(&sweep, &figures_location(readme, &args.output));
        crate::readme_block::replace_block(readme, README_BLOCK, &summary)?;
    }
    if !quiet {
        println!("{markdown}");
        println!("outputs: {}", args.output.display());
    }
    Ok(if report::verdicts(&sweep).all_met() { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// The artificial channel at one MPC power.
fn channel_config(power_db: f64, pulse: &PulseModel) -> ArtificialChannelConfig {
    ArtificialChannelConfig {
        mpc_power_db: power_db,
        start_separation_s: START_SEPARATION_NS * 1e-9,
        end_separation_s: END_SEPARATION_NS * 1e-9,
        sounder: SounderConfig { pulse: pulse.clone(), ..Default::default() },
        ..ArtificialChannelConfig::default()
    }
}

fn write_atomically(path: &Path, text: &str) -> anyhow::Result<()> {
    use std::io::Write as _;
    let file = AtomicFile::create(path, Overwrite::Replace)?;
    let mut writer = file.writer()?;
    writer.write_all(text.as_bytes()).with_context(|| path.display().to_string())?;
    writer.flush().with_context(|| path.display().to_string())?;
    drop(writer);
    file.commit(Overwrite::Replace, Durability::Fsync)?;
    Ok(())
}

/// The figures, next to results.csv (names in [`report::FIGURES`]).
fn write_figures(sweep: &Sweep, dir: &Path) -> anyhow::Result<()> {
    let [tracks, error, separation] = report::FIGURES;
    let power = report::TARGET_ERROR_POWER_DB;
    let svgs = [
        (tracks.0, plots::tracks_vs_power_svg(&sweep.points, report::TARGET_TWO_TRACKS_DOWN_TO_DB)?),
        (error.0, plots::delay_error_vs_power_svg(&sweep.points, report::TARGET_ERROR_NS, power)?),
        (
            separation.0,
            plots::delay_error_vs_separation_svg(
                &sweep.bins,
                ArtificialTracker::Proposed,
                true,
                &SEPARATION_PLOT_POWERS_DB,
                report::TARGET_ERROR_NS,
            )?,
        ),
    ];
    for (name, svg) in svgs {
        write_atomically(&dir.join(name), &svg)?;
    }
    Ok(())
}

/// Where the README finds the figures: the output directory relative to the
/// README's directory when it lies below it, else the path as given.
fn figures_location(readme: &Path, output: &Path) -> report::FiguresAt {
    let readme_dir = match readme.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    match (readme_dir.canonicalize(), output.canonicalize()) {
        (Ok(base), Ok(out)) => match out.strip_prefix(&base) {
            Ok(relative) => report::FiguresAt::Relative(relative.to_path_buf()),
            Err(_) => report::FiguresAt::Elsewhere(output.to_path_buf()),
        },
        _ => report::FiguresAt::Elsewhere(output.to_path_buf()),
    }
}

/// One Monte Carlo run's detections (as GM-PHD input) and truth, kept for
/// the matched GM-PHD pass.
struct RunData {
    phd_input: Vec<GmPhdSnapshot>,
    truth: Vec<MpcTruth>,
}

/// The three trackers at one power and window setting: their sweep points
/// and separation bands.
fn sweep_point(
    config: &ArtificialChannelConfig,
    detection: DetectionConfig,
    runs: u64,
) -> anyhow::Result<(Vec<SweepPoint>, Vec<SeparationBin>)> {
    let window = detection.kaiser_beta.is_some();
    let band = config.sounder.band()?;
    let pulse = SounderPulse::from_spectrum(config.sounder.pulse.spectrum(&band))?;
    let detector = Detector::new(detection, band.tap_spacing_s(), &pulse)?;
    let carrier_hz = config.sounder.carrier_hz;
    let table_i = GmPhdConfig { carrier_hz, ..GmPhdConfig::default() };
    let mut proposed = Tally::default();
    let mut gmphd = Tally::default();
    let mut data = Vec::new();
    for run in 0..runs {
        let (snapshots, truth) = artificial_channel(config, 0x5eed_0000 + run)?;
        let mut per_snapshot: Vec<Vec<MpcDetection>> = Vec::with_capacity(snapshots.len());
        for (index, snapshot) in snapshots.iter().enumerate() {
            per_snapshot.push(detector.detect(snapshot, index)?.detections);
        }
        let phd_input: Vec<GmPhdSnapshot> =
            snapshots.iter().zip(&per_snapshot).map(|(s, d)| GmPhdSnapshot::of(s, d.clone())).collect();
        let tracks =
            mmtrack_mpc::short_term::short_term_tracks(&per_snapshot, carrier_hz, &ShortTermConfig::default(), 0);
        proposed.add(&tracks, &truth, 3);
        gmphd.add(&mmtrack_mpc::track_gmphd(&phd_input, &table_i)?, &truth, table_i.min_track_detections);
        data.push(RunData { phd_input, truth });
    }
    // The sensitivity variant: GM-PHD's measurement noise set to the delay
    // noise the proposed tracker's true tracks show at this point (Table I's
    // value when they have no points).
    let rms_s = proposed.rms_error_s();
    let matched = GmPhdConfig {
        sigma_measurement_m: if rms_s > 0.0 { rms_s * SPEED_OF_LIGHT_M_PER_S } else { table_i.sigma_measurement_m },
        ..table_i.clone()
    };
    let mut gmphd_matched = Tally::default();
    for run in &data {
        let tracks = mmtrack_mpc::track_gmphd(&run.phd_input, &matched)?;
        gmphd_matched.add(&tracks, &run.truth, matched.min_track_detections);
    }
    let power_db = config.mpc_power_db;
    let mut points = Vec::new();
    let mut bins = Vec::new();
    for (tracker, tally, sigma_m) in [
        (ArtificialTracker::Proposed, proposed, None),
        (ArtificialTracker::GmPhd, gmphd, Some(table_i.sigma_measurement_m)),
        (ArtificialTracker::GmPhdMatched, gmphd_matched, Some(matched.sigma_measurement_m)),
    ] {
        bins.extend(tally.bins(power_db, window, tracker));
        points.push(tally.point(power_db, window, tracker, sigma_m));
    }
    Ok((points, bins))
}

/// A track point is "on" a true MPC when within 1 ns of it (the blocked
/// range is 2.5 ns wide); a track is true when most of its points are.
const ON_TRUTH_S: f64 = 1e-9;

/// Sums over the runs of one tracker at one point.
#[derive(Default)]
struct Tally {
    runs: u64,
    tracks: u64,
    true_tracks: u64,
    runs_with_two: u64,
    runs_with_two_true: u64,
    error_sum_s: f64,
    error_square_sum_s2: f64,
    points: u64,
    /// Per separation band: true-track points, their error sum (s) and the
    /// true MPC positions (2 per snapshot).
    band_points: [u64; SEPARATION_BANDS],
    band_error_sum_s: [f64; SEPARATION_BANDS],
    band_truth_points: [u64; SEPARATION_BANDS],
}

/// The band of a separation; the start separation (20 ns) belongs to the
/// last band, which is closed on both sides. `None` outside the approach
/// (beyond a rounding tolerance of 1e-6 of a band).
fn band_of(separation_s: f64) -> Option<usize> {
    let x = (separation_s * 1e9 - END_SEPARATION_NS) / SEPARATION_BAND_NS;
    let bands = SEPARATION_BANDS as f64;
    (x.is_finite() && x > -1e-6 && x < bands + 1e-6).then(|| (x.max(0.0).floor() as usize).min(SEPARATION_BANDS - 1))
}

impl Tally {
    fn add(&mut self, tracks: &[MpcTrack], truth: &[MpcTruth], min_len: usize) {
        // The two MPCs' separation per snapshot.
        let mut span: BTreeMap<i64, (f64, f64)> = BTreeMap::new();
        for m in truth {
            let e = span.entry(m.t_ns).or_insert((f64::INFINITY, f64::NEG_INFINITY));
            *e = (e.0.min(m.delay_s), e.1.max(m.delay_s));
        }
        let band: BTreeMap<i64, Option<usize>> = span.iter().map(|(&t, &(lo, hi))| (t, band_of(hi - lo))).collect();
        for b in band.values().flatten() {
            self.band_truth_points[*b] += 2;
        }
        let kept: Vec<&MpcTrack> = tracks.iter().filter(|t| t.detections.len() >= min_len).collect();
        self.runs += 1;
        self.tracks += kept.len() as u64;
        self.runs_with_two += u64::from(kept.len() == 2);
        let mut true_tracks = 0;
        for track in kept {
            let errors: Vec<(i64, f64)> = track
                .detections
                .iter()
                .map(|d| {
                    let error = truth
                        .iter()
                        .filter(|m| m.t_ns == d.t_ns)
                        .map(|m| (m.delay_s - d.delay_s).abs())
                        .fold(f64::INFINITY, f64::min);
                    (d.t_ns, error)
                })
                .collect();
            if 2 * errors.iter().filter(|e| e.1 <= ON_TRUTH_S).count() <= errors.len() {
                continue;
            }
            true_tracks += 1;
            for (t_ns, error) in errors {
                self.error_sum_s += error;
                self.error_square_sum_s2 += error * error;
                self.points += 1;
                if let Some(&Some(b)) = band.get(&t_ns) {
                    self.band_points[b] += 1;
                    self.band_error_sum_s[b] += error;
                }
            }
        }
        self.true_tracks += true_tracks;
        self.runs_with_two_true += u64::from(true_tracks == 2);
    }

    /// Root mean square of the true tracks' delay errors, s (0 without points).
    fn rms_error_s(&self) -> f64 {
        if self.points == 0 { 0.0 } else { (self.error_square_sum_s2 / self.points as f64).sqrt() }
    }

    fn bins(&self, power_db: f64, window: bool, tracker: ArtificialTracker) -> Vec<SeparationBin> {
        (0..SEPARATION_BANDS)
            .map(|b| {
                let lo_ns = END_SEPARATION_NS + SEPARATION_BAND_NS * b as f64;
                SeparationBin {
                    power_db,
                    kaiser_window: window,
                    tracker,
                    separation_ns: lo_ns..lo_ns + SEPARATION_BAND_NS,
                    points: self.band_points[b],
                    truth_points: self.band_truth_points[b],
                    mean_delay_error_ns: mean_ns(self.band_error_sum_s[b], self.band_points[b]),
                }
            })
            .collect()
    }

    fn point(&self, power_db: f64, window: bool, tracker: ArtificialTracker, sigma_m: Option<f64>) -> SweepPoint {
        let runs = self.runs.max(1);
        SweepPoint {
            power_db,
            kaiser_window: window,
            tracker,
            mean_tracks: self.tracks as f64 / runs as f64,
            mean_true_tracks: self.true_tracks as f64 / runs as f64,
            runs_with_two_tracks: self.runs_with_two,
            runs_with_two_true_tracks: self.runs_with_two_true,
            runs: self.runs,
            mean_delay_error_ns: mean_ns(self.error_sum_s, self.points),
            rms_delay_error_ns: if self.points == 0 { f64::NAN } else { self.rms_error_s() * 1e9 },
            sigma_measurement_m: sigma_m,
        }
    }
}

/// `sum_s / n` in ns; NaN when `n` is 0.
fn mean_ns(sum_s: f64, n: u64) -> f64 {
    if n == 0 { f64::NAN } else { sum_s / n as f64 * 1e9 }
}
