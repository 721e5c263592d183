//! Short-term MPC tracking within one set of snapshots (Mahler et al. 2017,
//! Sec. III-B, eqs. (11)-(32)).
//!
//! Each detection is the point `s = (a, tau)`: magnitude `a` in dB
//! ([`MpcDetection::power_db`], `20 log10 |alpha|`) and delay `tau` in seconds
//! (eq. (12)). With `N` snapshots in the set:
//!
//! 1. **Start** (eq. (28)): in snapshot `n = 0` take the strongest detection
//!    `s^` not yet part of a track.
//! 2. **Initial candidates** (eqs. (13)-(16)): the unassigned detections `s_c`
//!    of snapshot `n + 1` with `|a_c - a^| <= xi_a` and
//!    `|tau_c - tau^| <= xi_tau`, componentwise as eq. (15) lists the two
//!    gates (`xi_a` = [`ShortTermConfig::initial_magnitude_gate_db`],
//!    `xi_tau` = [`ShortTermConfig::initial_delay_gate_s`]). They are tried
//!    **nearest in delay first** (ties: nearest in magnitude, then detection
//!    order): the paper says "we start with the first initial direction
//!    candidate" without ordering them, and the delay is the quantity its
//!    tracker trusts most (eq. (25) also decides by delay).
//! 3. **Prediction** (eqs. (17)-(19)): from the last two points,
//!    `s~[m + 1] = s[m] + (s[m] - s[m - 1])`, in dB and seconds.
//! 4. **Search** (eqs. (20)-(23)): the unassigned detections of snapshot
//!    `m + 1` within `s~ +- epsilon`, componentwise (`epsilon_a` =
//!    [`ShortTermConfig::magnitude_tolerance_db`], `epsilon_tau` =
//!    [`ShortTermConfig::delay_tolerance_s`]); with several, the one nearest
//!    to the predicted delay (eq. (25); ties: nearest predicted magnitude, then
//!    detection order).
//! 5. **Identification** (eq. (26)): three adjacent detections make a track;
//!    without a third point the next initial candidate is tried; without any,
//!    `s^` starts no track (it stays free for later tracks).
//! 6. **Continuation**: steps 3-4 repeat until no detection lies in the search
//!    range or the set ends. A missed detection therefore ends the track: the
//!    paper's stated limitation (assumption 1, "the same MPC is detected in
//!    three consecutive snapshots"), kept as is.
//! 7. Then the next strongest unassigned detection of snapshot `n`, then
//!    snapshots `n = 1, 2, ...` (eq. (28)); every detection belongs to at most
//!    one track.
//! 8. **Doppler** (eqs. (30)-(31)): `nu = -m f_c`, `m` the least-squares slope
//!    of the track's delay over its detections' times.
//!
//! [`ShortTermConfig::min_track_length`] above 3 additionally drops tracks
//! shorter than it (the next initial candidate is then tried, as for a
//! failed identification); at 3, the paper's value, it changes nothing; below
//! 3 (refused by [`ShortTermConfig::validate`]) it acts as 3, since a track
//! is identified by three points in any case.
//!
//! Detections with non-finite magnitude or delay (zero amplitude gives
//! `-inf` dB) never pass a gate, so they can start no track and join none.
//!
//! The tracker is greedy and hand-written rather than an assignment solver
//! (e.g. `pathfinding`'s Kuhn-Munkres): the paper's method is this greedy,
//! order-dependent search, and reproducing it is the point.
//!
//! # References
//! T. Mahler, W. Keusgen, F. Tufvesson, T. Zemen, G. Caire, "Tracking of
//! wideband multipath components in a vehicular communication scenario",
//! IEEE TVT 66(1), 2017, Sec. III-B, eqs. (11)-(32).

use mmtrack_core::{MpcDetection, MpcTrack};

use crate::ShortTermConfig;

/// The tracking state of one detection: `s = (a, tau)` of eq. (12).
#[derive(Debug, Clone, Copy)]
struct Point {
    /// Magnitude, dB.
    a_db: f64,
    /// Delay, seconds.
    tau_s: f64,
}

/// Tracks the MPCs of one set (see the module docs).
///
/// `set` holds the detections of each snapshot of the set, in time order.
/// `carrier_hz` converts the delay slope to Doppler (eq. (31)). Tracks come in
/// the order they were found (start snapshot, then start strength) with ids
/// `first_track_id, first_track_id + 1, ...`; each track's detections are in
/// time order, one per snapshot, over consecutive snapshots.
#[must_use]
pub fn short_term_tracks(
    set: &[Vec<MpcDetection>],
    carrier_hz: f64,
    config: &ShortTermConfig,
    first_track_id: u64,
) -> Vec<MpcTrack> {
    let points: Vec<Vec<Point>> = set
        .iter()
        .map(|snapshot| snapshot.iter().map(|d| Point { a_db: d.power_db(), tau_s: d.delay_s }).collect())
        .collect();
    let mut used: Vec<Vec<bool>> = set.iter().map(|snapshot| vec![false; snapshot.len()]).collect();
    let mut tracks = Vec::new();
    let mut next_id = first_track_id;
    for n in 0..points.len() {
        for start in strongest_first(&points[n]) {
            if used[n][start] {
                continue;
            }
            let Some(path) = identify(&points, &used, n, start, config) else { continue };
            let detections: Vec<MpcDetection> = path
                .iter()
                .enumerate()
                .map(|(offset, &l)| {
                    used[n + offset][l] = true;
                    set[n + offset][l].clone()
                })
                .collect();
            tracks.push(MpcTrack { track_id: next_id, doppler_hz: doppler_hz(&detections, carrier_hz), detections });
            next_id += 1;
        }
    }
    tracks
}

/// Whether `track` spans the whole set of `set_len` snapshots (a
/// full-lifetime track, `psi_k = n_snap` of Sec. V). Short-term tracks hold
/// one detection per snapshot over consecutive snapshots, so this is a count.
#[must_use]
pub fn is_full_lifetime(track: &MpcTrack, set_len: usize) -> bool {
    set_len > 0 && track.detections.len() == set_len
}

/// Detection indices of one snapshot, strongest first (ties: smaller delay,
/// then detection order; NaN magnitudes last).
fn strongest_first(points: &[Point]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&i, &j| {
        let (p, q) = (points[i], points[j]);
        q.a_db.total_cmp(&p.a_db).then(p.tau_s.total_cmp(&q.tau_s)).then(i.cmp(&j))
    });
    order
}

/// Tries to identify a track starting at detection `start` of snapshot `n`
/// (steps 2-6): the detection indices of the track in snapshots `n, n + 1,
/// ...`, or `None`.
fn identify(
    points: &[Vec<Point>],
    used: &[Vec<bool>],
    n: usize,
    start: usize,
    config: &ShortTermConfig,
) -> Option<Vec<usize>> {
    let min_len = config.min_track_length.max(3);
    if n + min_len > points.len() {
        return None;
    }
    let s_hat = points[n][start];
    for candidate in initial_candidates(&points[n + 1], &used[n + 1], s_hat, config) {
        let mut path = vec![start, candidate];
        let mut previous = s_hat;
        let mut last = points[n + 1][candidate];
        loop {
            let m = n + path.len();
            if m >= points.len() {
                break;
            }
            let predicted = Point { a_db: 2.0 * last.a_db - previous.a_db, tau_s: 2.0 * last.tau_s - previous.tau_s };
            let Some(found) = nearest_in_search_range(&points[m], &used[m], predicted, config) else { break };
            path.push(found);
            previous = last;
            last = points[m][found];
        }
        if path.len() >= min_len {
            return Some(path);
        }
    }
    None
}

/// The unassigned detections within the initial gates `xi` of `s_hat`
/// (eqs. (13)-(15)), nearest in delay first (ties: nearest in magnitude, then
/// detection order).
fn initial_candidates(points: &[Point], used: &[bool], s_hat: Point, config: &ShortTermConfig) -> Vec<usize> {
    let mut candidates: Vec<(usize, f64, f64)> = points
        .iter()
        .zip(used)
        .enumerate()
        .filter(|(_, (_, used))| !**used)
        .map(|(l, (p, _))| (l, (p.tau_s - s_hat.tau_s).abs(), (p.a_db - s_hat.a_db).abs()))
        .filter(|&(_, d_tau, d_a)| d_tau <= config.initial_delay_gate_s && d_a <= config.initial_magnitude_gate_db)
        .collect();
    candidates.sort_by(|x, y| x.1.total_cmp(&y.1).then(x.2.total_cmp(&y.2)).then(x.0.cmp(&y.0)));
    candidates.into_iter().map(|(l, _, _)| l).collect()
}

/// The unassigned detection within `predicted +- epsilon` (eqs. (20)-(23))
/// nearest to the predicted delay (eq. (25); ties: nearest predicted
/// magnitude, then detection order).
fn nearest_in_search_range(
    points: &[Point],
    used: &[bool],
    predicted: Point,
    config: &ShortTermConfig,
) -> Option<usize> {
    points
        .iter()
        .zip(used)
        .enumerate()
        .filter(|(_, (_, used))| !**used)
        .map(|(l, (p, _))| (l, (p.tau_s - predicted.tau_s).abs(), (p.a_db - predicted.a_db).abs()))
        .filter(|&(_, d_tau, d_a)| d_tau <= config.delay_tolerance_s && d_a <= config.magnitude_tolerance_db)
        .min_by(|x, y| x.1.total_cmp(&y.1).then(x.2.total_cmp(&y.2)).then(x.0.cmp(&y.0)))
        .map(|(l, _, _)| l)
}

/// `nu = -m f_c` (eqs. (30)-(31)), with `m` the least-squares slope of
/// `delay_s` over `t_ns`; `None` for fewer than two distinct times.
///
/// Times and delays are taken relative to the first detection, so the
/// nanosecond clock and a large common delay keep their precision.
#[must_use]
pub fn doppler_hz(detections: &[MpcDetection], carrier_hz: f64) -> Option<f64> {
    let first = detections.first()?;
    let n = detections.len() as f64;
    let ts: Vec<f64> = detections.iter().map(|d| (i128::from(d.t_ns) - i128::from(first.t_ns)) as f64 * 1e-9).collect();
    let taus: Vec<f64> = detections.iter().map(|d| d.delay_s - first.delay_s).collect();
    let t_mean = ts.iter().sum::<f64>() / n;
    let tau_mean = taus.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (t, tau) in ts.iter().zip(&taus) {
        sxy += (t - t_mean) * (tau - tau_mean);
        sxx += (t - t_mean) * (t - t_mean);
    }
    (sxx > 0.0).then(|| -carrier_hz * sxy / sxx)
}
