//! KITTI odometry drift, as the KITTI odometry devkit computes it.
//!
//! # References
//! A. Geiger, P. Lenz, R. Urtasun, "Are we ready for autonomous driving? The
//! KITTI vision benchmark suite", CVPR 2012, Sec. 3.2; the devkit's
//! `cpp/evaluate_odometry.cpp` (`trajectoryDistances`,
//! `lastFrameFromSegmentLength`, `rotationError`, `translationError`,
//! `calcSequenceErrors`, `saveStats`). The functions here follow it line by
//! line, with two differences: distances are `f64` where the devkit rounds
//! them to `f32` (so a segment end can differ when a distance lies within
//! `f32` rounding of a segment boundary), and segment lengths and the
//! first-frame step are parameters.

use mmtrack_core::Se2;

use super::TrajectoryError;

/// The devkit's segment lengths: 100, 200, ..., 800 m.
pub const KITTI_SEGMENT_LENGTHS_M: [f64; 8] = [100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0, 800.0];

/// The devkit's first-frame step (`step_size = 10`, "every second" at 10 Hz).
pub const KITTI_STEP_FRAMES: usize = 10;

/// How far apart the first frames of the segments are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FirstFrameStep {
    /// Every `n` frames, as the devkit (`step_size`); the default, with 10.
    Frames(usize),
    /// Every `step_m` metres of ground-truth path: the next first frame is the
    /// first frame whose distance is at least `step_m` beyond the previous
    /// one. Makes results independent of the frame rate (radar at 4 Hz vs
    /// KITTI's 10 Hz).
    Metres(f64),
}

/// Longest segment length accepted, metres (10 000 km): a bound far beyond
/// any recorded drive, so a mistyped value (1e300) is refused by name.
pub const MAX_SEGMENT_LENGTH_M: f64 = 1e7;

/// Options of [`kitti_drift`].
#[derive(Debug, Clone, PartialEq)]
pub struct DriftOptions {
    /// Segment lengths, metres, in report order. Default: the devkit's
    /// 100..800 m; short simulated drives use shorter ones (e.g. 10..80 m).
    pub segment_lengths_m: Vec<f64>,
    /// First-frame step; default `Frames(10)` like the devkit.
    pub step: FirstFrameStep,
}

impl Default for DriftOptions {
    fn default() -> Self {
        Self { segment_lengths_m: KITTI_SEGMENT_LENGTHS_M.to_vec(), step: FirstFrameStep::Frames(KITTI_STEP_FRAMES) }
    }
}

impl DriftOptions {
    /// The options as the provenance of result tables records them, fields
    /// of its JSON object: `"segment_lengths_m": [...]` and
    /// `"first_frame_step": {"frames": n}` (or `{"metres": x}`).
    #[must_use]
    pub fn config_fields(&self) -> serde_json::Map<String, serde_json::Value> {
        let step = match self.step {
            FirstFrameStep::Frames(n) => serde_json::json!({ "frames": n }),
            FirstFrameStep::Metres(m) => serde_json::json!({ "metres": m }),
        };
        let mut fields = serde_json::Map::new();
        fields.insert("segment_lengths_m".into(), serde_json::json!(self.segment_lengths_m));
        fields.insert("first_frame_step".into(), step);
        fields
    }

    fn check(&self) -> Result<(), TrajectoryError> {
        let bad = |detail: String| Err(TrajectoryError::InvalidOption(detail));
        if self.segment_lengths_m.is_empty() {
            return bad("no segment lengths".into());
        }
        if let Some(l) = self.segment_lengths_m.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
            return bad(format!("segment length {l} m is not a positive number"));
        }
        if let Some(l) = self.segment_lengths_m.iter().find(|l| **l > MAX_SEGMENT_LENGTH_M) {
            return bad(format!(
                "segment length {l} m is beyond {MAX_SEGMENT_LENGTH_M} m (longer than any drive); give lengths in metres"
            ));
        }
        // Each length is a row of the report and a share of the mean drift:
        // a repeated one would count its segments twice.
        for (i, l) in self.segment_lengths_m.iter().enumerate() {
            if self.segment_lengths_m[..i].contains(l) {
                return bad(format!("segment length {l} m is given twice; give each length once"));
            }
        }
        match self.step {
            FirstFrameStep::Frames(0) => bad("first-frame step of 0 frames".into()),
            FirstFrameStep::Metres(m) if !(m.is_finite() && m > 0.0) => {
                bad(format!("first-frame step {m} m is not a positive number"))
            }
            _ => Ok(()),
        }
    }
}

/// The error of one segment `first_frame -> last_frame`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentError {
    /// First frame (index into the associated poses).
    pub first_frame: usize,
    /// Last frame: the first one more than `length_m` of ground-truth path
    /// beyond `first_frame`.
    pub last_frame: usize,
    /// Nominal segment length, metres (the normaliser, as in the devkit).
    pub length_m: f64,
    /// `|t(E)|` of the error pose `E`, metres.
    pub translation_error_m: f64,
    /// Devkit `rotationError(E)`, radians.
    pub rotation_error_rad: f64,
}

/// Mean drift over the segments of one length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LengthDrift {
    /// Segment length, metres.
    pub length_m: f64,
    /// Segments of this length.
    pub segments: usize,
    /// Mean of `translation_error_m / length_m`, percent.
    pub translational_pct: f64,
    /// Mean of `rotation_error_rad / length_m`, degrees per metre.
    pub rotational_deg_per_m: f64,
}

/// The devkit's overall average: the mean over all segments (`saveStats`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriftSummary {
    /// Segments averaged.
    pub segments: usize,
    /// Mean translational drift, percent.
    pub translational_pct: f64,
    /// Mean rotational drift, degrees per metre.
    pub rotational_deg_per_m: f64,
}

impl DriftSummary {
    /// Mean rotational drift, degrees per 100 m.
    #[must_use]
    pub fn rotational_deg_per_100m(&self) -> f64 {
        self.rotational_deg_per_m * 100.0
    }
}

/// KITTI drift of one trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct KittiDrift {
    /// Ground-truth path length, metres.
    pub path_length_m: f64,
    /// Every segment, in the devkit's order (first frame, then length).
    pub segments: Vec<SegmentError>,
    /// Means per length, in option order; lengths without segments omitted.
    pub per_length: Vec<LengthDrift>,
    /// Overall average; `None` when no segment fits (the path is shorter than
    /// the shortest segment length): an empty result, never NaN.
    pub summary: Option<DriftSummary>,
}

/// Devkit `trajectoryDistances`: cumulative ground-truth path length per frame.
#[must_use]
pub fn trajectory_distances_m(poses: &[Se2]) -> Vec<f64> {
    let mut dist = Vec::with_capacity(poses.len());
    let mut total = 0.0;
    for (i, p) in poses.iter().enumerate() {
        if i > 0 {
            let q = poses[i - 1];
            let (dx, dy) = (q.x_m - p.x_m, q.y_m - p.y_m);
            total += (dx * dx + dy * dy).sqrt();
        }
        dist.push(total);
    }
    dist
}

/// Devkit `lastFrameFromSegmentLength`: the first frame `i >= first` with
/// `dist[i] > dist[first] + length_m`, or `None`.
#[must_use]
pub fn last_frame_from_segment_length(dist: &[f64], first: usize, length_m: f64) -> Option<usize> {
    let start = *dist.get(first)?;
    (first..dist.len()).find(|&i| dist[i] > start + length_m)
}

/// Devkit `rotationError`: `acos(clamp(0.5 * (trace(R) - 1), -1, 1))` of the
/// 3x3 rotation of `pose_error` embedded in 3D, where `R = Rz(yaw)` has
/// `trace = cos + cos + 1`. Computed in that order so the rounding matches
/// the devkit's.
#[must_use]
pub fn devkit_rotation_error_rad(pose_error: &Se2) -> f64 {
    let c = pose_error.yaw_rad.cos();
    let trace = c + c + 1.0;
    (0.5 * (trace - 1.0)).clamp(-1.0, 1.0).acos()
}

fn first_frames(dist: &[f64], step: FirstFrameStep) -> Vec<usize> {
    match step {
        FirstFrameStep::Frames(n) => (0..dist.len()).step_by(n.max(1)).collect(),
        FirstFrameStep::Metres(step_m) => {
            let mut frames = Vec::new();
            let mut next = Some(0);
            while let Some(first) = next {
                frames.push(first);
                next = (first + 1..dist.len()).find(|&i| dist[i] >= dist[first] + step_m);
            }
            frames
        }
    }
}

/// KITTI drift of `estimate` against `ground_truth`, frame-aligned (see
/// [`super::associate`]).
///
/// For each first frame (every [`DriftOptions::step`]) and each segment
/// length `L`, the last frame is [`last_frame_from_segment_length`] on the
/// ground-truth distances; the error pose is
/// `E = (est[f]^-1 est[l])^-1 (gt[f]^-1 gt[l])`; the segment's translational
/// error is `|t(E)| / L` and its rotational error
/// [`devkit_rotation_error_rad`]`(E) / L`. Note the normaliser is the nominal
/// `L`, not the path actually travelled (which exceeds `L` by up to a step).
pub fn kitti_drift(
    estimate: &[Se2],
    ground_truth: &[Se2],
    options: &DriftOptions,
) -> Result<KittiDrift, TrajectoryError> {
    options.check()?;
    if estimate.len() != ground_truth.len() {
        return Err(TrajectoryError::LengthMismatch { estimate: estimate.len(), ground_truth: ground_truth.len() });
    }
    let dist = trajectory_distances_m(ground_truth);
    let mut segments = Vec::new();
    for first in first_frames(&dist, options.step) {
        for &length_m in &options.segment_lengths_m {
            let Some(last) = last_frame_from_segment_length(&dist, first, length_m) else { continue };
            let delta_gt = ground_truth[first].inverse() * ground_truth[last];
            let delta_est = estimate[first].inverse() * estimate[last];
            let error = delta_est.inverse() * delta_gt;
            segments.push(SegmentError {
                first_frame: first,
                last_frame: last,
                length_m,
                translation_error_m: (error.x_m * error.x_m + error.y_m * error.y_m).sqrt(),
                rotation_error_rad: devkit_rotation_error_rad(&error),
            });
        }
    }
    let per_length = options
        .segment_lengths_m
        .iter()
        .filter_map(|&length_m| {
            let of_length: Vec<&SegmentError> = segments.iter().filter(|s| s.length_m == length_m).collect();
            let (t, r, n) = mean_ratios(&of_length)?;
            Some(LengthDrift { length_m, segments: n, translational_pct: t, rotational_deg_per_m: r })
        })
        .collect();
    let all: Vec<&SegmentError> = segments.iter().collect();
    let summary =
        mean_ratios(&all).map(|(t, r, n)| DriftSummary { segments: n, translational_pct: t, rotational_deg_per_m: r });
    Ok(KittiDrift { path_length_m: dist.last().copied().unwrap_or(0.0), segments, per_length, summary })
}

/// `(mean t/L in %, mean r/L in deg/m, count)`, or `None` for no segments.
/// Sums ratios in segment order, then divides, as `saveStats` does.
fn mean_ratios(segments: &[&SegmentError]) -> Option<(f64, f64, usize)> {
    if segments.is_empty() {
        return None;
    }
    let n = segments.len() as f64;
    let t: f64 = segments.iter().map(|s| s.translation_error_m / s.length_m).sum();
    let r: f64 = segments.iter().map(|s| s.rotation_error_rad / s.length_m).sum();
    Some((t / n * 100.0, (r / n).to_degrees(), segments.len()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight drive along x in 1 m steps: `dist[i] = i` exactly.
    fn straight(frames: usize) -> Vec<Se2> {
        (0..frames).map(|i| Se2::new(i as f64, 0.0, 0.0)).collect()
    }

    /// Composes per-step motions `inv(gt[k-1]) gt[k]`, each changed by `f`.
    fn perturbed(gt: &[Se2], f: impl Fn(Se2) -> Se2) -> Vec<Se2> {
        let mut out = vec![gt[0]];
        for k in 1..gt.len() {
            let step = gt[k - 1].inverse() * gt[k];
            let prev = out[k - 1];
            out.push(prev * f(step));
        }
        out
    }

    fn short_lengths() -> DriftOptions {
        DriftOptions { segment_lengths_m: (1..=8).map(|k| 10.0 * f64::from(k)).collect(), ..Default::default() }
    }

    /// A curvy drive: 1 m steps turning 0.02 rad each (a loop of radius ~50 m).
    fn curvy(frames: usize) -> Vec<Se2> {
        perturbed(&straight(frames), |s| Se2::new(s.x_m, 0.0, 0.02))
    }

    #[test]
    fn perfect_estimate_has_zero_drift() {
        let gt = curvy(300);
        let drift = kitti_drift(&gt, &gt, &short_lengths()).unwrap();
        let s = drift.summary.unwrap();
        assert!(s.segments > 100);
        assert_eq!((s.translational_pct, s.rotational_deg_per_m), (0.0, 0.0));
    }

    #[test]
    fn translation_scaled_by_1_01_gives_one_percent_of_the_displacement() {
        // Straight drive: a segment of nominal length L ends at the first
        // frame more than L beyond its start, L + 1 m, so the devkit reports
        // 1 % x (L + 1) / L: it normalises by L, not by the distance driven.
        let gt = straight(200);
        let est = perturbed(&gt, |s| Se2::new(1.01 * s.x_m, 1.01 * s.y_m, s.yaw_rad));
        let options = short_lengths();
        let drift = kitti_drift(&est, &gt, &options).unwrap();
        for seg in &drift.segments {
            let expected = 0.01 * (seg.length_m + 1.0);
            // 1e-12 relative: rounding of ~100 additions of O(100) values.
            assert!((seg.translation_error_m - expected).abs() < 1e-12 * expected, "{seg:?}");
            assert_eq!(seg.rotation_error_rad, 0.0);
        }
        // On a finely sampled drive (1 mm steps) the overshoot vanishes:
        // 1.000 % to the step's share of the length.
        let fine: Vec<Se2> = (0..12_001).map(|i| Se2::new(i as f64 * 1e-3, 0.0, 0.0)).collect();
        let est = perturbed(&fine, |s| Se2::new(1.01 * s.x_m, s.y_m, s.yaw_rad));
        let options = DriftOptions { segment_lengths_m: vec![10.0], step: FirstFrameStep::Frames(100) };
        let s = kitti_drift(&est, &fine, &options).unwrap().summary.unwrap();
        // Overshoot <= 1 mm of 10 m = 1e-4 relative, plus rounding.
        assert!((s.translational_pct - 1.0).abs() < 1.2e-4, "{s:?}");
    }

    #[test]
    fn constant_yaw_bias_gives_expected_deg_per_m() {
        let gt = straight(200);
        let bias_rad = 1e-3;
        let est = perturbed(&gt, |s| Se2::new(s.x_m, s.y_m, s.yaw_rad + bias_rad));
        let options = short_lengths();
        let drift = kitti_drift(&est, &gt, &options).unwrap();
        // Each segment spans L + 1 steps of 1 m, so its rotation error is
        // (L + 1) * bias, divided by L.
        let expected: Vec<f64> = drift.segments.iter().map(|s| (s.length_m + 1.0) * bias_rad / s.length_m).collect();
        let mean_deg_per_m = (expected.iter().sum::<f64>() / expected.len() as f64).to_degrees();
        let s = drift.summary.unwrap();
        // 1e-9 relative: acos near 1 loses ~half the digits of cos (angles ~1e-2).
        assert!((s.rotational_deg_per_m - mean_deg_per_m).abs() < 1e-9 * mean_deg_per_m, "{s:?} vs {mean_deg_per_m}");
        assert!((s.rotational_deg_per_100m() - 100.0 * s.rotational_deg_per_m).abs() < 1e-12);
        for l in &drift.per_length {
            let want = ((l.length_m + 1.0) * bias_rad / l.length_m).to_degrees();
            assert!((l.rotational_deg_per_m - want).abs() < 1e-9 * want, "{l:?}");
        }
    }

    #[test]
    fn short_trajectory_gives_an_empty_result_not_nan() {
        let gt = straight(50);
        let drift = kitti_drift(&gt, &gt, &DriftOptions::default()).unwrap();
        assert!(drift.segments.is_empty() && drift.per_length.is_empty() && drift.summary.is_none());
        assert_eq!(drift.path_length_m, 49.0);
    }

    #[test]
    fn first_frames_follow_the_step() {
        let dist: Vec<f64> = (0..25).map(|i| 0.5 * f64::from(i)).collect();
        assert_eq!(first_frames(&dist, FirstFrameStep::Frames(10)), vec![0, 10, 20]);
        assert_eq!(first_frames(&dist, FirstFrameStep::Metres(5.0)), vec![0, 10, 20]);
        assert_eq!(last_frame_from_segment_length(&dist, 0, 5.0), Some(11));
        assert_eq!(last_frame_from_segment_length(&dist, 20, 5.0), None);
        let bad = DriftOptions { segment_lengths_m: vec![f64::NAN], ..Default::default() };
        assert!(kitti_drift(&[], &[], &bad).is_err());
        // Before: 8,2,2 counted the 2 m segments twice; 1e300 was accepted.
        for (lengths, said) in [(vec![8.0, 2.0, 2.0], "2 m is given twice"), (vec![1e300], "beyond 10000000 m")] {
            let bad = DriftOptions { segment_lengths_m: lengths, ..Default::default() };
            let error = kitti_drift(&[], &[], &bad).unwrap_err().to_string();
            assert!(error.contains(said), "{error}");
        }
    }
}
