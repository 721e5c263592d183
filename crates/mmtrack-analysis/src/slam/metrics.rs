//! The paper's metrics of one 5G mmWave SLAM run against its ground truth
//! (Kim et al. 2018, Sec. V-B): per epoch the UE errors and the localisation
//! errors of the confirmed VAs and SPs, and the epochs at which all VAs and
//! all SPs are confirmed. One evaluation for `mmtrack reproduce kim` (the
//! filter's output in memory) and `mmtrack analyze` (the tables of `mmtrack
//! process slam`).

use mmtrack_core::slam::{UeState, norm3, sub3};
use mmtrack_core::wrap_angle_rad;

/// Errors and map size of one epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochErrors {
    /// Horizontal-and-vertical UE position error, metres.
    pub position_m: f64,
    /// The filter's horizontal position spread (root of the covariance trace).
    pub position_std_m: f64,
    /// Normalised estimation error squared of the horizontal position,
    /// `e^T P^-1 e` (2 degrees of freedom: 2 on average for a consistent
    /// filter); `None` without the covariance or when it is singular.
    pub position_nees: Option<f64>,
    /// Absolute wrapped heading error, radians.
    pub heading_rad: f64,
    /// Absolute clock-bias error, metres.
    pub clock_bias_m: f64,
    /// Absolute speed error, m/s.
    pub speed_mps: f64,
    /// Absolute turn-rate error, rad/s.
    pub turn_rate_radps: f64,
    /// Mean error of every confirmed VA (its distance to the nearest true
    /// VA, however far); `None` without a confirmed VA.
    pub va_m: Option<f64>,
    /// The same for the confirmed SPs against the true SPs.
    pub sp_m: Option<f64>,
    /// Confirmed VAs.
    pub confirmed_va: usize,
    /// Confirmed SPs.
    pub confirmed_sp: usize,
    /// Confirmed sources that match no true source of their type
    /// ([`match_sources`]: one confirmed source per true one, within the
    /// match radius; duplicates and far sources are false).
    pub false_sources: usize,
    /// Mean distance of the false sources to the nearest true source of
    /// their type, metres; `None` without a false source.
    pub false_source_error_m: Option<f64>,
}

/// What one run measured.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    /// Per epoch.
    pub epochs: Vec<EpochErrors>,
    /// First epoch (1-based) at which every true VA had a confirmed VA
    /// within the match radius.
    pub all_va_epoch: Option<usize>,
    /// The same for every true SP that counts ([`MapTruth::seen_sp_m`]).
    pub all_sp_epoch: Option<usize>,
    /// False sources ([`EpochErrors::false_sources`]) at the last epoch.
    pub false_sources: usize,
    /// Paths skipped as unusable (set by the caller).
    pub skipped_paths: usize,
    /// Final confirmed VAs and SPs (for the map figure).
    pub final_va_m: Vec<[f64; 3]>,
    /// Final confirmed SPs.
    pub final_sp_m: Vec<[f64; 3]>,
    /// Estimated track.
    pub track_m: Vec<[f64; 3]>,
}

/// The true map a run is measured against.
#[derive(Debug, Clone, PartialEq)]
pub struct MapTruth {
    /// True virtual anchors, metres.
    pub va_m: Vec<[f64; 3]>,
    /// True scattering points, metres.
    pub sp_m: Vec<[f64; 3]>,
    /// The SPs that count for "all SPs confirmed": seen in enough epochs.
    pub seen_sp_m: Vec<[f64; 3]>,
    /// A confirmed source matches a true one of its type within this
    /// distance, metres (for "all confirmed" and the false-source count;
    /// the localisation errors score every confirmed source).
    pub match_radius_m: f64,
}

impl MapTruth {
    /// The truth with the SPs detected in at least `sp_min_detections`
    /// epochs counting (`detections[i]` for `sp_m[i]`).
    #[must_use]
    pub fn new(
        va_m: Vec<[f64; 3]>,
        sp_m: Vec<[f64; 3]>,
        detections: &[usize],
        sp_min_detections: usize,
        match_radius_m: f64,
    ) -> Self {
        let seen_sp_m =
            sp_m.iter().zip(detections).filter(|(_, d)| **d >= sp_min_detections).map(|(p, _)| *p).collect();
        Self { va_m, sp_m, seen_sp_m, match_radius_m }
    }
}

/// One epoch of a run: the estimate, the truth and the confirmed map.
#[derive(Debug, Clone, PartialEq)]
pub struct EpochView {
    /// The UE estimate.
    pub estimate: UeState,
    /// Its horizontal position spread, metres.
    pub position_std_m: f64,
    /// Its horizontal position covariance `[xx, xy, yy]`, m^2, when known
    /// (the filter's output in memory; the tables carry only the spread).
    pub position_cov_m2: Option<[f64; 3]>,
    /// The true UE state.
    pub truth: UeState,
    /// Confirmed VAs after the epoch.
    pub va_m: Vec<[f64; 3]>,
    /// Confirmed SPs after the epoch.
    pub sp_m: Vec<[f64; 3]>,
}

fn nearest(points: &[[f64; 3]], at: [f64; 3]) -> f64 {
    points.iter().map(|p| norm3(sub3(*p, at))).fold(f64::INFINITY, f64::min)
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Which confirmed sources match a true one: pairs (confirmed, true) within
/// `radius_m` taken greedily by increasing distance, each source at most
/// once (a duplicate of a matched source stays unmatched). Returns, per
/// confirmed source, whether it matched.
#[must_use]
pub fn match_sources(confirmed_m: &[[f64; 3]], true_m: &[[f64; 3]], radius_m: f64) -> Vec<bool> {
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for (i, c) in confirmed_m.iter().enumerate() {
        for (j, t) in true_m.iter().enumerate() {
            let d = norm3(sub3(*c, *t));
            if d <= radius_m {
                pairs.push((d, i, j));
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut matched = vec![false; confirmed_m.len()];
    let mut taken = vec![false; true_m.len()];
    for (_, i, j) in pairs {
        if !matched[i] && !taken[j] {
            matched[i] = true;
            taken[j] = true;
        }
    }
    matched
}

/// `e^T P^-1 e` of a horizontal error `e` and covariance `[xx, xy, yy]`;
/// `None` when the covariance is not positive definite.
fn nees_2d(e: [f64; 2], cov: [f64; 3]) -> Option<f64> {
    let [a, b, c] = cov;
    let det = a * c - b * b;
    (a > 0.0 && det > 0.0).then(|| (c * e[0] * e[0] - 2.0 * b * e[0] * e[1] + a * e[1] * e[1]) / det)
}

/// Measures a run, epoch by epoch (index 0 = epoch 1).
#[must_use]
pub fn evaluate(truth: &MapTruth, epochs: &[EpochView]) -> RunOutcome {
    let radius = truth.match_radius_m;
    let mut outcome = RunOutcome {
        epochs: Vec::with_capacity(epochs.len()),
        all_va_epoch: None,
        all_sp_epoch: None,
        false_sources: 0,
        skipped_paths: 0,
        final_va_m: Vec::new(),
        final_sp_m: Vec::new(),
        track_m: epochs.iter().map(|e| e.estimate.position_m).collect(),
    };
    let errors = |est: &[[f64; 3]], t: &[[f64; 3]]| -> Vec<f64> { est.iter().map(|p| nearest(t, *p)).collect() };
    let found = |est: &[[f64; 3]], t: &[[f64; 3]]| t.iter().all(|p| nearest(est, *p) <= radius);
    // The errors of the confirmed sources that match no true one.
    let unmatched = |est: &[[f64; 3]], t: &[[f64; 3]]| -> Vec<f64> {
        est.iter().zip(match_sources(est, t, radius)).filter(|(_, m)| !m).map(|(p, _)| nearest(t, *p)).collect()
    };
    for (k, view) in epochs.iter().enumerate() {
        let (e, t) = (&view.estimate, &view.truth);
        if outcome.all_va_epoch.is_none() && found(&view.va_m, &truth.va_m) {
            outcome.all_va_epoch = Some(k + 1);
        }
        if outcome.all_sp_epoch.is_none() && found(&view.sp_m, &truth.seen_sp_m) {
            outcome.all_sp_epoch = Some(k + 1);
        }
        let mut false_errors = unmatched(&view.va_m, &truth.va_m);
        false_errors.extend(unmatched(&view.sp_m, &truth.sp_m));
        let horizontal = [e.position_m[0] - t.position_m[0], e.position_m[1] - t.position_m[1]];
        outcome.epochs.push(EpochErrors {
            position_m: norm3(sub3(e.position_m, t.position_m)),
            position_std_m: view.position_std_m,
            position_nees: view.position_cov_m2.and_then(|cov| nees_2d(horizontal, cov)),
            heading_rad: wrap_angle_rad(e.heading_rad - t.heading_rad).abs(),
            clock_bias_m: (e.clock_bias_m - t.clock_bias_m).abs(),
            speed_mps: (e.speed_mps - t.speed_mps).abs(),
            turn_rate_radps: (e.turn_rate_radps - t.turn_rate_radps).abs(),
            va_m: mean(&errors(&view.va_m, &truth.va_m)),
            sp_m: mean(&errors(&view.sp_m, &truth.sp_m)),
            confirmed_va: view.va_m.len(),
            confirmed_sp: view.sp_m.len(),
            false_sources: false_errors.len(),
            false_source_error_m: mean(&false_errors),
        });
    }
    if let Some(last) = epochs.last() {
        outcome.false_sources = outcome.epochs.last().map_or(0, |e| e.false_sources);
        outcome.final_va_m = last.va_m.clone();
        outcome.final_sp_m = last.sp_m.clone();
    }
    outcome
}

impl RunOutcome {
    /// Time averages over the epochs: UE position, heading, clock-bias,
    /// speed and turn-rate errors, and the VA and SP errors over the epochs
    /// that had a confirmed source.
    #[must_use]
    pub fn time_averages(&self) -> [Option<f64>; 7] {
        let avg = |f: &dyn Fn(&EpochErrors) -> Option<f64>| {
            let v: Vec<f64> = self.epochs.iter().filter_map(f).collect();
            mean(&v)
        };
        [
            avg(&|e| Some(e.position_m)),
            avg(&|e| Some(e.heading_rad)),
            avg(&|e| Some(e.clock_bias_m)),
            avg(&|e| Some(e.speed_mps)),
            avg(&|e| Some(e.turn_rate_radps)),
            avg(&|e| e.va_m),
            avg(&|e| e.sp_m),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_duplicate_or_a_far_source_is_unmatched() {
        let truth = [[0.0, 0.0, 0.0], [100.0, 0.0, 0.0]];
        // Two sources near the first true one: the nearer matches, the other is a duplicate.
        let confirmed = [[1.0, 0.0, 0.0], [0.5, 0.0, 0.0], [100.0, 6.0, 0.0], [99.0, 0.0, 0.0]];
        assert_eq!(match_sources(&confirmed, &truth, 5.0), [false, true, false, true]);
        assert_eq!(match_sources(&confirmed, &truth, 10.0), [false, true, false, true]);
        assert_eq!(match_sources(&[], &truth, 5.0), Vec::<bool>::new());
        assert_eq!(match_sources(&confirmed[..1], &[], 5.0), [false]);
    }

    fn ue(x: f64, heading_rad: f64, bias: f64) -> UeState {
        UeState { position_m: [x, 0.0, 0.0], heading_rad, speed_mps: 1.0, turn_rate_radps: 0.0, clock_bias_m: bias }
    }

    #[test]
    fn errors_and_confirmation_epochs_by_hand() {
        let truth = MapTruth::new(vec![[200.0, 0.0, 40.0]], vec![[10.0, 0.0, 0.0], [50.0, 0.0, 0.0]], &[5, 1], 3, 5.0);
        // Only the first SP was seen often enough to count.
        assert_eq!(truth.seen_sp_m, vec![[10.0, 0.0, 0.0]]);
        let view = |va: Vec<[f64; 3]>, sp: Vec<[f64; 3]>| EpochView {
            estimate: ue(0.3, 3.1, 1.2),
            position_std_m: 0.2,
            position_cov_m2: Some([0.04, 0.0, 0.01]),
            truth: ue(0.0, -3.1, 1.0),
            va_m: va,
            sp_m: sp,
        };
        let epochs = [view(vec![], vec![]), view(vec![[201.0, 0.0, 40.0]], vec![[10.0, 2.0, 0.0], [90.0, 0.0, 0.0]])];
        let out = evaluate(&truth, &epochs);
        assert_eq!((out.all_va_epoch, out.all_sp_epoch), (Some(2), Some(2)));
        let e = out.epochs[1];
        assert!((e.position_m - 0.3).abs() < 1e-12);
        // 3.1 - (-3.1) = 6.2 wraps to 6.2 - 2 pi.
        assert!((e.heading_rad - (2.0 * std::f64::consts::PI - 6.2)).abs() < 1e-12);
        assert!((e.clock_bias_m - 0.2).abs() < 1e-12);
        // Every confirmed source is scored: the SP at x = 90 is 40 m from the nearest true SP.
        assert_eq!((e.va_m, e.sp_m), (Some(1.0), Some((2.0 + 40.0) / 2.0)));
        assert_eq!(out.false_sources, 1, "the SP at x = 90 matches nothing");
        assert_eq!((e.false_sources, e.false_source_error_m), (1, Some(40.0)));
        // e = (0.3, 0), P = diag(0.04, 0.01): 0.09 / 0.04.
        assert!((e.position_nees.unwrap() - 2.25).abs() < 1e-12);
        assert_eq!(out.epochs[0].va_m, None);
        assert_eq!((out.epochs[0].false_sources, out.epochs[0].false_source_error_m), (0, None));
        let avg = out.time_averages();
        assert_eq!(avg[5], Some(1.0));
        assert!((avg[0].unwrap() - 0.3).abs() < 1e-12);
    }
}
