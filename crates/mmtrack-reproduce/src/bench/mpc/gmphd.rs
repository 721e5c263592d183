//! The GM-PHD baseline alone on sparse and dense detections: how its time
//! per snapshot scales with the detections, apart from any detector.
//!
//! The detections are drawn directly (not detected from CIRs, so they do not
//! move when detection changes): [`SPARSE_PATHS`] or [`DENSE_PATHS`] paths
//! with delays spread over the 2048 ns window and drifting linearly (Doppler
//! up to +-400 Hz, as the channel of `bench mpc`), each detected with
//! probability 0.95 at a delay error of 0.01 ns (Table I's 3 mm), plus on
//! average [`CLUTTER_PER_SNAPSHOT`] false detections uniform over the window,
//! in sets of 6 snapshots 0.717 ms apart, a set every 10 ms. About 13
//! detections per snapshot as on the simulated convoy, and about 140 as the
//! dense case the GM-PHD was first timed on. One filter per set, one thread;
//! generation is not timed.

use std::time::Instant;

use mmtrack_core::random::standard_normal;
use mmtrack_core::{Complex64, MpcDetection};
use mmtrack_mpc::{GmPhdConfig, GmPhdSnapshot, track_gmphd};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;

/// Paths of the sparse row: 13 x 0.95 + 0.5 clutter, about 12.9 detections per snapshot.
pub const SPARSE_PATHS: usize = 13;
/// Paths of the dense row: 147 x 0.95 + 0.5 clutter, about 140 detections per snapshot.
pub const DENSE_PATHS: usize = 147;
/// Mean false detections per snapshot.
pub const CLUTTER_PER_SNAPSHOT: f64 = 0.5;
/// Sets of the sparse and the dense row (6 snapshots each), at most.
const SPARSE_SETS: usize = 400;
const DENSE_SETS: usize = 100;
/// Runs per row; the fastest is reported.
const REPEATS: usize = 3;
const WINDOW_S: f64 = 2048e-9;
const MARGIN_S: f64 = 16e-9;
const DETECTION_PROBABILITY: f64 = 0.95;
const DELAY_ERROR_S: f64 = 0.01e-9;
const SEED: u64 = 29;

/// The GM-PHD baseline on one kind of detections.
#[derive(Debug, Clone, PartialEq)]
pub struct GmPhdRow {
    /// `sparse` or `dense`.
    pub label: &'static str,
    /// Paths drawn.
    pub paths: usize,
    /// Snapshots tracked.
    pub snapshots: usize,
    /// Detections per snapshot.
    pub detections_per_snapshot: f64,
    /// Filter time per snapshot, microseconds (fastest of the runs).
    pub us_per_snapshot: f64,
    /// Tracks it returned over all sets.
    pub tracks: usize,
}

/// The sets of `paths` paths (see the module docs).
fn draw_sets(paths: usize, sets: usize) -> Vec<Vec<GmPhdSnapshot>> {
    let mut rng = Pcg64::seed_from_u64(SEED ^ paths as u64);
    let slot_s = (WINDOW_S - 2.0 * MARGIN_S) / paths.max(1) as f64;
    let drawn: Vec<(f64, f64, f64)> = (0..paths)
        .map(|i| {
            let delay_s = MARGIN_S + slot_s * (i as f64 + 0.25 + 0.5 * rng.random::<f64>());
            let delay_rate = -400.0 * (2.0 * rng.random::<f64>() - 1.0) / 5.7e9;
            let magnitude = 10f64.powf((-125.0 + 35.0 * rng.random::<f64>()) / 20.0);
            (delay_s, delay_rate, magnitude)
        })
        .collect();
    (0..sets as u64)
        .map(|set| {
            let mut rng = Pcg64::seed_from_u64((SEED << 32) ^ (set + 1));
            (0..6u32)
                .map(|k| {
                    let t_ns = set as i64 * 10_000_000 + i64::from(k) * 717_000;
                    let t_s = t_ns as f64 * 1e-9;
                    let at = |delay_s: f64, magnitude: f64, phase_rad: f64| MpcDetection {
                        t_ns,
                        set_index: set,
                        snapshot_index: k,
                        delay_s,
                        amplitude: Complex64::from_polar(magnitude, phase_rad),
                    };
                    let mut detections = Vec::with_capacity(paths + 2);
                    for &(delay_s, rate, magnitude) in &drawn {
                        if rng.random::<f64>() < DETECTION_PROBABILITY {
                            let d = delay_s + rate * t_s + DELAY_ERROR_S * standard_normal(&mut rng);
                            detections.push(at(d, magnitude, std::f64::consts::TAU * rng.random::<f64>()));
                        }
                    }
                    // At most two false detections, 0.5 on average.
                    for _ in 0..2 {
                        if rng.random::<f64>() < 0.5 * CLUTTER_PER_SNAPSHOT {
                            let d = MARGIN_S + (WINDOW_S - 2.0 * MARGIN_S) * rng.random::<f64>();
                            detections.push(at(d, 10f64.powf(-128.0 / 20.0), 0.0));
                        }
                    }
                    GmPhdSnapshot { t_ns, set_index: set, snapshot_index: k, detections }
                })
                .collect()
        })
        .collect()
}

/// Times one row.
fn row(label: &'static str, paths: usize, sets: usize, config: &GmPhdConfig) -> anyhow::Result<GmPhdRow> {
    let input = draw_sets(paths, sets);
    let snapshots = input.iter().map(Vec::len).sum::<usize>();
    let detections: usize = input.iter().flatten().map(|s| s.detections.len()).sum();
    let (mut best_s, mut tracks) = (f64::INFINITY, 0);
    for _ in 0..REPEATS {
        let started = Instant::now();
        tracks = 0;
        for set in &input {
            tracks += std::hint::black_box(track_gmphd(set, config)?).len();
        }
        best_s = best_s.min(started.elapsed().as_secs_f64());
    }
    Ok(GmPhdRow {
        label,
        paths,
        snapshots,
        detections_per_snapshot: detections as f64 / snapshots as f64,
        us_per_snapshot: best_s / snapshots as f64 * 1e6,
        tracks,
    })
}

/// The sparse and the dense row, over at most `snapshots` snapshots each
/// (2400 sparse, 600 dense at most).
///
/// # Errors
/// The filter fails (not expected for the drawn detections).
pub fn rows(config: &GmPhdConfig, snapshots: usize) -> anyhow::Result<Vec<GmPhdRow>> {
    let sets = snapshots.div_ceil(6).max(1);
    Ok(vec![
        row("sparse", SPARSE_PATHS, sets.min(SPARSE_SETS), config)?,
        row("dense", DENSE_PATHS, sets.min(DENSE_SETS), config)?,
    ])
}

/// The Markdown table of the rows.
#[must_use]
pub fn markdown(rows: &[GmPhdRow]) -> String {
    let mut out = String::from(
        "\nGM-PHD alone (Table I, one filter per set of 6 snapshots, one thread, fastest of 3 runs) on drawn \
         detections (paths detected with probability 0.95 at 0.01 ns delay error, 0.5 false detections per \
         snapshot; not from the detector above):\n\n\
         | detections | paths | snapshots | detections per snapshot | us per snapshot | tracks |\n\
         |---|---|---|---|---|---|\n",
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {} | {} | {:.1} | {:.1} | {} |\n",
            r.label, r.paths, r.snapshots, r.detections_per_snapshot, r.us_per_snapshot, r.tracks
        ));
    }
    out
}
