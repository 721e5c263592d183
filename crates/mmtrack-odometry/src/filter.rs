//! Stage 1: the k-strongest conservative filter, and placing the kept bins in
//! the vehicle frame with optional per-azimuth motion compensation.

use mmtrack_core::{PolarScan, PolarScanHeader, Se2};

/// A point kept by the filter, in the vehicle frame at the instant it is
/// placed at ([`place`]: the scan's stamp, or the middle of the sweep).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilteredPoint {
    /// Position, metres (x forward, y left).
    pub xy_m: [f64; 2],
    /// Power of the bin, counts.
    pub power: u8,
}

/// Constant body velocity of the vehicle: what motion compensation undoes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BodyVelocity {
    /// Forward speed, m/s.
    pub vx_mps: f64,
    /// Leftward speed, m/s.
    pub vy_mps: f64,
    /// Yaw rate, rad/s, counter-clockwise.
    pub yaw_rate_radps: f64,
}

impl BodyVelocity {
    /// The motion over `dt_s` at this constant body velocity: the SE(2)
    /// exponential of the twist times `dt_s` (exact arc, not a straight step).
    #[must_use]
    pub fn motion_over(&self, dt_s: f64) -> Se2 {
        let (vx, vy, w) = (self.vx_mps * dt_s, self.vy_mps * dt_s, self.yaw_rate_radps * dt_s);
        // V = [[sin w / w, -(1 - cos w) / w], [(1 - cos w) / w, sin w / w]] -> 1 and 0 as w -> 0.
        let (a, b) = if w.abs() < 1e-9 { (1.0 - w * w / 6.0, w / 2.0) } else { (w.sin() / w, (1.0 - w.cos()) / w) };
        Se2::new(a * vx - b * vy, b * vx + a * vy, w)
    }

    /// The velocity that moves by `motion` in `dt_s` (inverse of [`Self::motion_over`]).
    #[must_use]
    pub fn from_motion(motion: Se2, dt_s: f64) -> Self {
        let w = motion.yaw_rad;
        let (a, b) = if w.abs() < 1e-9 { (1.0 - w * w / 6.0, w / 2.0) } else { (w.sin() / w, (1.0 - w.cos()) / w) };
        // Invert V (a 2x2 rotation-scaling: det = a^2 + b^2).
        let det = a * a + b * b;
        let vx = (a * motion.x_m + b * motion.y_m) / det;
        let vy = (-b * motion.x_m + a * motion.y_m) / det;
        Self { vx_mps: vx / dt_s, vy_mps: vy / dt_s, yaw_rate_radps: w / dt_s }
    }
}

/// A bin kept by the filter, in polar form with its time offset, so it can be
/// placed for any assumed motion during the sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolarPoint {
    /// Range of the bin, metres.
    pub range_m: f64,
    /// Point direction in the vehicle frame at the azimuth's time, unit
    /// (`(cos a, -sin a)` for clockwise azimuth `a`).
    pub direction: [f64; 2],
    /// Azimuth time minus scan stamp, seconds.
    pub dt_s: f64,
    /// Power of the bin, counts.
    pub power: u8,
}

/// Bins per block that [`k_strongest`] skips whole when none of them can be kept.
const SKIP_BLOCK_BINS: usize = 64;

/// Keeps, for every valid azimuth, the `k` strongest bins with power at least
/// `min_power` between `min_range_m` and `max_range_m` (ties: the nearer bin
/// first, as the authors' code does). Azimuths are clockwise from forward, so a
/// bin at range `r` and azimuth `a` lies at `r (cos a, -sin a)`.
///
/// # References
/// Liu et al., SPEBT, Sec. III-A.1 (k-strongest conservative filtering).
#[must_use]
pub fn k_strongest(scan: &PolarScan, k: usize, min_power: u8, min_range_m: f64, max_range_m: f64) -> Vec<PolarPoint> {
    let header = &scan.header;
    let resolution_m = header.range_resolution_m;
    let first_bin = ((min_range_m - header.range_offset_m) / resolution_m).ceil().max(0.0) as usize;
    let end_bin = (((max_range_m - header.range_offset_m) / resolution_m).floor() + 1.0).max(0.0) as usize;
    let end_bin = end_bin.min(header.bins_per_azimuth);
    // No more than the bins in range are kept, whatever `k` is.
    let kept_per_azimuth = k.min(end_bin.saturating_sub(first_bin));
    let mut points = Vec::with_capacity(header.azimuths.len() * kept_per_azimuth);
    let mut strongest: Vec<(u8, usize)> = Vec::with_capacity(kept_per_azimuth + 1);
    let mut candidates: Vec<(u8, usize)> = Vec::new();
    for (row_index, azimuth) in header.azimuths.iter().enumerate() {
        let Some(row) = scan.row(row_index) else { break };
        if !azimuth.valid || first_bin >= end_bin {
            continue;
        }
        let bins = &row[first_bin..end_bin];
        if k <= MAX_K_BY_INSERTION {
            strongest_by_insertion(bins, first_bin, k, min_power, &mut strongest);
        } else {
            strongest_by_counting(bins, first_bin, k, min_power, &mut candidates, &mut strongest);
        }
        let (sin_a, cos_a) = azimuth.azimuth_rad.sin_cos();
        let dt_s = (azimuth.t_ns - header.t_ns) as f64 * 1e-9;
        for &(power, bin) in &strongest {
            points.push(PolarPoint { range_m: header.range_m(bin), direction: [cos_a, -sin_a], dt_s, power });
        }
    }
    points
}

/// Largest `k` for which [`k_strongest`] keeps a row's strongest bins by
/// insertion into a sorted list (O(k) per entering bin, but a kept list
/// that fills early raises the bar and skips most blocks); above it, by
/// counting the candidates' powers (O(levels) per row, whatever `k`).
const MAX_K_BY_INSERTION: usize = 8;

/// The `k` strongest of `bins` with power at least `min_power`, as
/// `(power, bin)` in (power desc, bin asc) order: one sweep inserting into a
/// sorted list, skipping the blocks of [`SKIP_BLOCK_BINS`] none of whose
/// bins can enter.
fn strongest_by_insertion(bins: &[u8], first_bin: usize, k: usize, min_power: u8, strongest: &mut Vec<(u8, usize)>) {
    strongest.clear();
    let mut block_start = 0;
    while block_start < bins.len() {
        // The weakest power that can still enter: the threshold, or one
        // above the k-th strongest once k are kept. It only rises along
        // the row, so a block of bins all below it changes nothing and is
        // skipped whole (the test below compiles to a few vector
        // compares); the result is the bin-by-bin sweep's.
        let entry = if strongest.len() == k { u16::from(strongest[k - 1].0) + 1 } else { u16::from(min_power) };
        if entry > u16::from(u8::MAX) {
            break;
        }
        let block = &bins[block_start..bins.len().min(block_start + SKIP_BLOCK_BINS)];
        if u16::from(block.iter().fold(0u8, |m, &p| m.max(p))) < entry {
            block_start += block.len();
            continue;
        }
        for (offset, &power) in block.iter().enumerate() {
            if power < min_power || (strongest.len() == k && power <= strongest[k - 1].0) {
                continue;
            }
            // Insert keeping (power desc, bin asc); a later bin never displaces an equal earlier one.
            let at = strongest.iter().position(|&(p, _)| p < power).unwrap_or(strongest.len());
            strongest.insert(at, (power, first_bin + block_start + offset));
            strongest.truncate(k);
        }
        block_start += block.len();
    }
}

/// What [`strongest_by_insertion`] returns, by a counting sort: the bins of
/// at least `min_power` are collected in bin order (blocks without one are
/// skipped whole), their powers counted, and each is written to its place
/// in (power desc, bin asc) order when that place is among the first `k`.
/// The same list: within a power, bins keep their order, so the nearer bin
/// wins a tie at the k-th place as in the insertion.
fn strongest_by_counting(
    bins: &[u8],
    first_bin: usize,
    k: usize,
    min_power: u8,
    candidates: &mut Vec<(u8, usize)>,
    strongest: &mut Vec<(u8, usize)>,
) {
    // Each bin of a block with a candidate is written to the next free slot,
    // which only advances for a candidate: no branch on the bin's power, whose
    // outcome is as good as random along a row. There are never more
    // candidates than bins, so the slots before each write are enough.
    if candidates.len() < bins.len() {
        candidates.resize(bins.len(), (0, 0));
    }
    let mut found = 0;
    for (block_index, block) in bins.chunks(SKIP_BLOCK_BINS).enumerate() {
        if block.iter().fold(0u8, |m, &p| m.max(p)) < min_power {
            continue;
        }
        let block_start = block_index * SKIP_BLOCK_BINS;
        for (offset, &power) in block.iter().enumerate() {
            candidates[found] = (power, first_bin + block_start + offset);
            found += usize::from(power >= min_power);
        }
    }
    let candidates = &candidates[..found];
    strongest.clear();
    let kept = k.min(candidates.len());
    if kept == 0 {
        return;
    }
    // next[p]: the place of the next candidate of power p, counted from
    // the strongest (the candidates stronger than p come first).
    let mut next = [0usize; 256];
    for &(power, _) in candidates {
        next[usize::from(power)] += 1;
    }
    let mut stronger = 0;
    for level in (usize::from(min_power)..256).rev() {
        let count = next[level];
        next[level] = stronger;
        stronger += count;
    }
    strongest.resize(kept, (0, 0));
    for &(power, bin) in candidates {
        let place = &mut next[usize::from(power)];
        if *place < kept {
            strongest[*place] = (power, bin);
        }
        *place += 1;
    }
}

/// Motion compensation of one sweep: the constant body velocity assumed
/// during it and the instant the points are placed at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepMotion {
    /// The vehicle's velocity during the sweep.
    pub velocity: BodyVelocity,
    /// The instant the points are placed at, seconds after the scan stamp
    /// (the middle of the sweep: [`sweep_middle_ns`]).
    pub reference_dt_s: f64,
}

/// The middle of the sweep, nanoseconds after the scan stamp: halfway
/// between the first and the last valid azimuth's time (0 without one).
/// Oxford stamps a scan with its first azimuth's time, about 125 ms before
/// the middle of its 250 ms sweep.
#[must_use]
pub fn sweep_middle_ns(header: &PolarScanHeader) -> i64 {
    let mut times = header.azimuths.iter().filter(|a| a.valid).map(|a| a.t_ns - header.t_ns);
    let Some(first) = times.next() else { return 0 };
    let (earliest, latest) = times.fold((first, first), |(lo, hi), t| (lo.min(t), hi.max(t)));
    earliest + (latest - earliest) / 2
}

/// Places the kept bins in the vehicle frame. With `motion = Some(m)` each
/// point is moved from the pose at its azimuth's time to the pose at
/// `m.reference_dt_s`, assuming the constant body velocity `m.velocity`
/// during the sweep (motion compensation, CFEAR Sec. III-B):
/// `p = reference_from_azimuth * p_a` with `reference_from_azimuth =
/// exp(v (dt - reference_dt))`. With `None` the sweep is taken as
/// instantaneous, as Fast-CFEAR does.
///
/// # References
/// Adolfsson et al., CFEAR, T-RO 2023, Sec. III-B (motion compensation).
///
/// The points of one azimuth share its time offset (the filter emits them
/// together), so the transform and its sine and cosine are computed once per
/// run of equal `dt_s`, not once per point: the same arithmetic on the same
/// operands, hence the same coordinates, at about a k-th of the
/// trigonometry (k = 40 points per azimuth for CFEAR).
#[must_use]
pub fn place(points: &[PolarPoint], motion: Option<SweepMotion>) -> Vec<FilteredPoint> {
    let Some(SweepMotion { velocity: v, reference_dt_s }) = motion else {
        return points
            .iter()
            .map(|p| FilteredPoint { xy_m: [p.range_m * p.direction[0], p.range_m * p.direction[1]], power: p.power })
            .collect();
    };
    // (dt_s, sin yaw, cos yaw, x, y) of the last azimuth time seen.
    let mut cached: Option<(f64, f64, f64, f64, f64)> = None;
    points
        .iter()
        .map(|p| {
            let (s, c, x_m, y_m) = match cached {
                Some((dt_s, s, c, x_m, y_m)) if dt_s.to_bits() == p.dt_s.to_bits() => (s, c, x_m, y_m),
                _ => {
                    let motion = v.motion_over(p.dt_s - reference_dt_s);
                    let (s, c) = motion.yaw_rad.sin_cos();
                    cached = Some((p.dt_s, s, c, motion.x_m, motion.y_m));
                    (s, c, motion.x_m, motion.y_m)
                }
            };
            let a = [p.range_m * p.direction[0], p.range_m * p.direction[1]];
            // Se2::transform_point, term for term.
            FilteredPoint { xy_m: [c * a[0] - s * a[1] + x_m, s * a[0] + c * a[1] + y_m], power: p.power }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use mmtrack_core::{AzimuthSample, PolarScanHeader};

    use super::*;

    fn scan(rows: &[Vec<u8>]) -> PolarScan {
        let bins = rows[0].len();
        let azimuths = (0..rows.len())
            .map(|i| AzimuthSample {
                t_ns: i as i64 * 1_000_000,
                azimuth_rad: i as f64 * std::f64::consts::TAU / rows.len() as f64,
                valid: true,
            })
            .collect();
        let header =
            PolarScanHeader { t_ns: 0, range_resolution_m: 1.0, range_offset_m: 0.0, bins_per_azimuth: bins, azimuths };
        PolarScan::new(header, rows.concat()).unwrap()
    }

    #[test]
    fn keeps_the_k_strongest_above_threshold_nearer_first_on_ties() {
        let row = vec![0, 90, 50, 80, 90, 70, 90, 10];
        let s = scan(&[row, vec![0; 8], vec![0; 8], vec![0; 8]]);
        let points = place(&k_strongest(&s, 2, 60, 0.0, 100.0), None);
        let ranges: Vec<f64> = points.iter().map(|p| p.xy_m[0]).collect();
        assert_eq!(ranges, vec![1.0, 4.0]);
        assert!(points.iter().all(|p| p.power == 90));
    }

    #[test]
    fn counting_keeps_what_insertion_keeps_in_the_same_order() {
        // Rows of few distinct powers (many ties at the k-th place), of
        // bright and of empty stretches, for k below, at and above the
        // candidates in a row, and thresholds from 0 to 255.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let (mut strongest, mut candidates, mut by_insertion) = (Vec::new(), Vec::new(), Vec::new());
        let mut compared = 0;
        for row_index in 0..600 {
            let len = 1 + (next() % 400) as usize;
            let levels = [2, 5, 256][row_index % 3];
            let row: Vec<u8> = (0..len)
                .map(|i| {
                    let dark = (i / 64 + row_index) % 4 == 0;
                    if dark { 0 } else { (next() % levels) as u8 * (255 / (levels - 1).max(1)) as u8 }
                })
                .collect();
            for k in [1, 3, 9, 40, 500] {
                for min_power in [0u8, 1, 60, 128, 255] {
                    strongest_by_insertion(&row, 7, k, min_power, &mut by_insertion);
                    strongest_by_counting(&row, 7, k, min_power, &mut candidates, &mut strongest);
                    assert_eq!(strongest, by_insertion, "row {row_index}, k {k}, min power {min_power}");
                    compared += strongest.len();
                }
            }
        }
        assert!(compared > 100_000, "{compared}");
    }

    #[test]
    fn on_real_scans_counting_keeps_what_insertion_keeps() {
        let Some(scans) = crate::real_scans::oxford() else { return };
        let (mut by_insertion, mut candidates, mut by_counting) = (Vec::new(), Vec::new(), Vec::new());
        let mut kept = 0;
        for scan in &scans {
            for row_index in 0..scan.header.azimuths.len() {
                let row = scan.row(row_index).unwrap();
                // cfear's and CFEAR-1's k, Fast-CFEAR's K, over whole rows.
                for (k, min_power) in [(40, 60), (12, 60), (3, 55)] {
                    strongest_by_insertion(row, 0, k, min_power, &mut by_insertion);
                    strongest_by_counting(row, 0, k, min_power, &mut candidates, &mut by_counting);
                    assert_eq!(by_counting, by_insertion, "t {} row {row_index} k {k}", scan.header.t_ns);
                    kept += by_counting.len();
                }
            }
        }
        assert!(kept > 100_000, "{kept}");
    }

    #[test]
    fn range_limits_are_inclusive_bin_centres() {
        let s = scan(&[vec![100; 10], vec![0; 10], vec![0; 10], vec![0; 10]]);
        let points = place(&k_strongest(&s, 10, 1, 2.0, 5.0), None);
        let ranges: Vec<f64> = points.iter().map(|p| p.xy_m[0]).collect();
        assert_eq!(ranges, vec![2.0, 3.0, 4.0, 5.0]);
    }

    #[test]
    fn azimuths_turn_clockwise() {
        // Row 1 of 4 is azimuth 90 deg clockwise: the vehicle's right, y < 0.
        let mut rows = vec![vec![0; 10]; 4];
        rows[1][5] = 200;
        let points = place(&k_strongest(&scan(&rows), 1, 10, 0.0, 100.0), None);
        assert_eq!(points.len(), 1);
        assert!(points[0].xy_m[0].abs() < 1e-12 && (points[0].xy_m[1] + 5.0).abs() < 1e-12);
    }

    #[test]
    fn velocity_round_trips_through_the_exponential() {
        let v = BodyVelocity { vx_mps: 8.0, vy_mps: -0.3, yaw_rate_radps: 0.4 };
        let back = BodyVelocity::from_motion(v.motion_over(0.25), 0.25);
        assert!((back.vx_mps - 8.0).abs() < 1e-12 && (back.vy_mps + 0.3).abs() < 1e-12);
        assert!((back.yaw_rate_radps - 0.4).abs() < 1e-12);
    }

    #[test]
    fn the_middle_of_the_sweep_is_halfway_between_the_first_and_last_valid_azimuth() {
        let mut s = scan(&vec![vec![0u8; 4]; 5]);
        s.header.t_ns = 100;
        for (a, azimuth) in s.header.azimuths.iter_mut().enumerate() {
            azimuth.t_ns = 100 + 1000 * a as i64;
        }
        assert_eq!(sweep_middle_ns(&s.header), 2000);
        // Invalid rows at either end do not count; an odd span rounds down
        // (1000 + 2001 / 2).
        s.header.azimuths[0].valid = false;
        s.header.azimuths[4].valid = false;
        s.header.azimuths[3].t_ns = 3101;
        assert_eq!(sweep_middle_ns(&s.header), 2000);
        s.header.azimuths[3].t_ns = 3300;
        assert_eq!(sweep_middle_ns(&s.header), 2100);
        s.header.azimuths.iter_mut().for_each(|a| a.valid = false);
        assert_eq!(sweep_middle_ns(&s.header), 0);
    }

    #[test]
    fn placing_at_the_reference_instant_leaves_its_azimuth_where_it_was_seen() {
        let mut s = scan(&[vec![0, 0, 90, 0], vec![0, 0, 0, 80]]);
        s.header.azimuths[1].t_ns = 250_000_000;
        let kept = k_strongest(&s, 1, 60, 0.0, 100.0);
        let velocity = BodyVelocity { vx_mps: 8.0, vy_mps: 0.0, yaw_rate_radps: 0.2 };
        let at_second = place(&kept, Some(SweepMotion { velocity, reference_dt_s: 0.25 }));
        let instantaneous = place(&kept, None);
        assert_eq!(at_second[1], instantaneous[1]);
        // The first azimuth, 0.25 s earlier, is moved back by the motion over 0.25 s.
        let back = velocity.motion_over(-0.25).transform_point(instantaneous[0].xy_m);
        assert!((at_second[0].xy_m[0] - back[0]).abs() < 1e-12 && (at_second[0].xy_m[1] - back[1]).abs() < 1e-12);
    }
}
