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
//!    `s~[m + 1] = s[m] + (s[m] - s[m - 1])`, in dB and seconds. Opt-in
//!    ([`ShortTermPrediction::LeastSquares`], not the paper's): from the
//!    least-squares line through all the track's points so far, of which
//!    eq. (17) is the two-point case; see [`extrapolate`].
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

use crate::{ShortTermConfig, ShortTermPrediction};

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
    // The track so far: detection indices and both components, reused from
    // one initial candidate to the next.
    let longest = points.len() - n;
    let (mut path, mut a_db, mut tau_s) =
        (Vec::with_capacity(longest), Vec::with_capacity(longest), Vec::with_capacity(longest));
    for candidate in initial_candidates(&points[n + 1], &used[n + 1], s_hat, config) {
        let second = points[n + 1][candidate];
        path.clear();
        path.extend([start, candidate]);
        a_db.clear();
        a_db.extend([s_hat.a_db, second.a_db]);
        tau_s.clear();
        tau_s.extend([s_hat.tau_s, second.tau_s]);
        loop {
            let m = n + path.len();
            if m >= points.len() {
                break;
            }
            let predicted =
                Point { a_db: extrapolate(config.prediction, &a_db), tau_s: extrapolate(config.prediction, &tau_s) };
            let Some(found) = nearest_in_search_range(&points[m], &used[m], predicted, config) else { break };
            path.push(found);
            a_db.push(points[m][found].a_db);
            tau_s.push(points[m][found].tau_s);
        }
        if path.len() >= min_len {
            return Some(path);
        }
    }
    None
}

/// The value the next snapshot is predicted to hold, from `values` of one
/// component (magnitude in dB or delay in seconds) over consecutive,
/// equally spaced snapshots `m = 0 .. k - 1` (eqs. (17)-(19)); `k >= 2`.
///
/// - [`ShortTermPrediction::LastDifference`] (the paper's eq. (17)):
///   `v~[k] = 2 v[k - 1] - v[k - 2]`.
/// - [`ShortTermPrediction::LeastSquares`] (ours): the least-squares line
///   `v(m) = vbar + b (m - mbar)` through all `k` points, at `m = k`:
///   `v~[k] = vbar + b (k - mbar)`, with `mbar = (k - 1) / 2`,
///   `b = sum (m - mbar)(v[m] - vbar) / S_mm` and
///   `S_mm = sum (m - mbar)^2`. Through two points it is eq. (17). Why: the
///   miss of eq. (17) is the second difference of the detections, `sqrt(6)`
///   times their delay noise at every step, so a noisy path leaves the fixed
///   `epsilon_tau` of eq. (23) although it moves on a line; the fitted
///   line's miss shrinks with the points behind it
///   ([`ShortTermPrediction`]).
///
/// With fewer than two values there is no line: the last value (or NaN for
/// none) is returned, which the tracker never asks for.
#[must_use]
pub fn extrapolate(prediction: ShortTermPrediction, values: &[f64]) -> f64 {
    let k = values.len();
    match (prediction, values) {
        (_, []) => f64::NAN,
        (_, [only]) => *only,
        (ShortTermPrediction::LastDifference, [.., previous, last]) => 2.0 * last - previous,
        (ShortTermPrediction::LeastSquares, [first, ..]) => {
            // Relative to the first value, so a large common delay keeps its
            // precision.
            let m_mean = (k as f64 - 1.0) / 2.0;
            let v_mean = values.iter().map(|v| v - first).sum::<f64>() / k as f64;
            let (mut s_mv, mut s_mm) = (0.0, 0.0);
            for (m, v) in values.iter().enumerate() {
                let dm = m as f64 - m_mean;
                s_mv += dm * (v - first - v_mean);
                s_mm += dm * dm;
            }
            first + v_mean + s_mv / s_mm * (k as f64 - m_mean)
        }
    }
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

#[cfg(test)]
mod tests {
    use mmtrack_core::Complex64;

    use super::*;

    /// The paper's snapshot period, 0.717 ms.
    const SNAPSHOT_NS: i64 = 717_000;

    /// One path of constant magnitude over six snapshots: a delay line of
    /// 0.1 ns per snapshot plus `noise_ns` (the detections' delay errors).
    fn noisy_path(noise_ns: [f64; 6]) -> Vec<Vec<MpcDetection>> {
        (0..6u32)
            .map(|n| {
                let delay_s = (40.0 + 0.1 * f64::from(n) + noise_ns[n as usize]) * 1e-9;
                vec![MpcDetection {
                    t_ns: i64::from(n) * SNAPSHOT_NS,
                    set_index: 0,
                    snapshot_index: n,
                    delay_s,
                    amplitude: Complex64::new(1e-6, 0.0),
                }]
            })
            .collect()
    }

    fn lengths(tracks: &[MpcTrack]) -> Vec<usize> {
        tracks.iter().map(|t| t.detections.len()).collect()
    }

    #[test]
    fn the_least_squares_line_is_eq_17_through_two_points_and_exact_on_a_line() {
        for prediction in [ShortTermPrediction::LastDifference, ShortTermPrediction::LeastSquares] {
            // Two points: both are eq. (17), 2 * 5 - 3 = 7 (to rounding).
            assert!((extrapolate(prediction, &[3.0, 5.0]) - 7.0).abs() < 1e-12, "{prediction:?}");
            // Points on a line: both continue it.
            let line: Vec<f64> = (0..5).map(|m| 40e-9 + 0.3e-9 * f64::from(m)).collect();
            let next = 40e-9 + 0.3e-9 * 5.0;
            assert!((extrapolate(prediction, &line) - next).abs() < 1e-21, "{prediction:?}");
        }
    }

    #[test]
    fn the_least_squares_line_averages_the_noise_eq_17_follows() {
        // Noise on the last point only: eq. (17) doubles it (2 * 0.3 - 0 =
        // 0.6); the line through 0, 0, 0, 0.3 (mean 0.075, slope 0.45 / 5 =
        // 0.09) gives 0.075 + 0.09 * 2.5 = 0.3 at m = 4.
        let values = [0.0, 0.0, 0.0, 0.3];
        assert!((extrapolate(ShortTermPrediction::LastDifference, &values) - 0.6).abs() < 1e-12);
        assert!((extrapolate(ShortTermPrediction::LeastSquares, &values) - 0.3).abs() < 1e-12);
    }

    #[test]
    fn a_noisy_linear_path_is_followed_over_the_set_by_the_least_squares_search_only() {
        // Delay errors 0, 0, 0, +0.3, -0.1, 0 ns. Eq. (17) misses the fifth
        // point by -0.1 - (2 * 0.3 - 0) = -0.7 ns, beyond epsilon_tau =
        // 0.5 ns: its track ends after four points and the last two make
        // none. The least-squares line through the first four points
        // predicts +0.3 ns (previous test): a miss of -0.4 ns; through five
        // it predicts 0.04 + 0.01 * 3 = 0.07 ns: a miss of -0.07 ns.
        let set = noisy_path([0.0, 0.0, 0.0, 0.3, -0.1, 0.0]);
        let paper = ShortTermConfig::default();
        assert_eq!(lengths(&short_term_tracks(&set, 28e9, &paper, 0)), vec![4]);
        let ours = ShortTermConfig { prediction: ShortTermPrediction::LeastSquares, ..paper };
        let tracks = short_term_tracks(&set, 28e9, &ours, 0);
        assert_eq!(lengths(&tracks), vec![6]);
        assert!(is_full_lifetime(&tracks[0], set.len()));
    }

    #[test]
    fn the_least_squares_search_keeps_the_tolerance_of_eq_23() {
        // A step of 0.8 ns at the fourth point leaves the line by more than
        // epsilon_tau whatever the prediction: both end the track there.
        let set = noisy_path([0.0, 0.0, 0.0, 0.8, 0.8, 0.8]);
        for prediction in [ShortTermPrediction::LastDifference, ShortTermPrediction::LeastSquares] {
            let config = ShortTermConfig { prediction, ..ShortTermConfig::default() };
            assert_eq!(lengths(&short_term_tracks(&set, 28e9, &config, 0)), vec![3, 3], "{prediction:?}");
        }
    }
}
