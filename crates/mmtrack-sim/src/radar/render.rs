//! Rendering of one sweep: per-azimuth pose, ray casting with occlusion and
//! transmission, point targets through the beam pattern, multipath ghosts,
//! speckle, noise floor and the 8-bit compression. See the
//! [module docs](super) for the equations.

use std::f64::consts::TAU;

use mmtrack_core::random::{box_muller, hash_words};
use mmtrack_core::{AzimuthSample, PolarScan, PolarScanHeader, Se2};

use super::Sensor;
use super::sensor::Prepared;
use super::trajectory::Trajectory;
use super::world::{Hit, Scratch, World};

/// Reference range of the strengths, metres.
const REFERENCE_RANGE_M: f64 = 10.0;
/// Speckle patch along a surface, metres: the beam sees a new patch (fresh
/// speckle) every time its footprint moves this far along a wall.
const SPECKLE_PATCH_M: f64 = 0.5;
/// Returns nearer than this are not rendered (inside the sensor housing).
const MIN_RANGE_M: f64 = 0.5;

/// Everything a sweep render reads; shared by the worker threads.
pub(crate) struct RenderContext<'a> {
    pub world: &'a World,
    pub sensor: &'a Sensor,
    pub prepared: Prepared,
    pub trajectory: &'a Trajectory,
    pub seed: u64,
}

/// One return on a row before it is spread along range: centre range and
/// mean power (before speckle), with its speckle key.
#[derive(Debug, Clone, Copy)]
struct Return {
    range_m: f64,
    power: f64,
    key: u64,
    /// Volume tail behind the peak, bins (0: none).
    tail_bins: f64,
}

impl RenderContext<'_> {
    /// Renders sweep `scan` whose first azimuth is at `t_ns`.
    pub(crate) fn render(&self, scan: u64, t_ns: i64) -> PolarScan {
        let sensor = self.sensor;
        let n = sensor.azimuths;
        let sweep_ns = sensor.sweep_ns();
        let azimuths: Vec<AzimuthSample> = (0..n)
            .map(|a| AzimuthSample {
                t_ns: t_ns + (a as i64 * sweep_ns) / n as i64,
                azimuth_rad: a as f64 * TAU / n as f64,
                valid: true,
            })
            .collect();
        let poses: Vec<Se2> = azimuths.iter().map(|a| self.trajectory.pose_at(a.t_ns)).collect();
        let mut point_returns = self.point_returns(&poses);
        let mut power = vec![0u8; n * sensor.bins];
        let mut row = vec![0f32; sensor.bins];
        let mut scratch = Scratch::default();
        for (a, (out, pose)) in power.chunks_exact_mut(sensor.bins).zip(&poses).enumerate() {
            let points = point_returns.get_mut(a).map(std::mem::take).unwrap_or_default();
            let returns = self.row_returns(*pose, a, points, &mut scratch);
            self.fill_noise(scan, a as u64, &mut row);
            for r in &returns {
                let speckle = speckle_intensity(self.seed, scan, r.key, sensor.speckle_static_fraction);
                add_profile(&mut row, r.range_m / sensor.range_resolution_m, r.power * speckle, r.tail_bins, sensor);
            }
            for (o, p) in out.iter_mut().zip(&row) {
                *o = self.prepared.quantize(*p);
            }
        }
        let header = PolarScanHeader {
            t_ns,
            range_resolution_m: sensor.range_resolution_m,
            range_offset_m: 0.0,
            bins_per_azimuth: sensor.bins,
            azimuths,
        };
        PolarScan { header, power }
    }

    /// Receiver noise and clutter floor: a seeded slice of the noise buffer
    /// times the per-bin floor.
    fn fill_noise(&self, scan: u64, a: u64, row: &mut [f32]) {
        let noise = &self.prepared.noise;
        let span = noise.len().saturating_sub(row.len()).max(1);
        let offset = (hash_words(&[self.seed, 0x006e_6f69_7365, scan, a]) % span as u64) as usize;
        let slice = noise.get(offset..offset + row.len()).unwrap_or(&[]);
        for ((r, n), f) in row.iter_mut().zip(slice).zip(&self.prepared.floor) {
            *r = n * f;
        }
    }

    /// Returns of surfaces along row `a`'s beam and of the point targets seen
    /// on it, attenuated by what the beam crossed before (two-way).
    fn row_returns(&self, pose: Se2, a: usize, points: Vec<(u32, f64, f64)>, scratch: &mut Scratch) -> Vec<Return> {
        let sensor = self.sensor;
        let theta = a as f64 * TAU / sensor.azimuths as f64;
        let heading = pose.yaw_rad - theta;
        let dir = [heading.cos(), heading.sin()];
        let origin = [pose.x_m, pose.y_m];
        let max_range_m = sensor.max_range_m();
        let hits = self.world.cast(origin, dir, max_range_m, scratch);
        let mut out = Vec::with_capacity(hits.len() + points.len() + 1);
        let mut transmission = 1.0;
        for hit in &hits {
            if hit.range_m >= MIN_RANGE_M {
                out.push(self.surface_return(hit, hit.range_m, transmission, 0));
            }
            transmission *= self.world.segments.get(hit.segment as usize).map_or(0.0, |s| s.transmission);
        }
        for (id, range_m, power) in points {
            // Two-way transmission through every surface crossed before the point.
            let t: f64 = hits
                .iter()
                .take_while(|h| h.range_m < range_m)
                .map(|h| self.world.segments.get(h.segment as usize).map_or(0.0, |s| s.transmission))
                .product();
            if t > 0.0 {
                out.push(Return { range_m, power: power * t * t, key: (2 << 60) | u64::from(id), tail_bins: 0.0 });
            }
        }
        if sensor.multipath_ghosts
            && let Some(first) = hits.first()
            && let Some(ghost) = self.ghost(origin, dir, first, max_range_m, scratch)
        {
            out.push(Return { power: ghost.power * Sensor::db_to_power(-sensor.multipath_loss_db), ..ghost });
        }
        out
    }

    /// Mean power of a surface hit seen at path range `range_m` through `transmission` (one-way).
    fn surface_return(&self, hit: &Hit, range_m: f64, transmission: f64, bounce: u64) -> Return {
        let Some(s) = self.world.segments.get(hit.segment as usize) else {
            return Return { range_m, power: 0.0, key: 0, tail_bins: 0.0 };
        };
        let incidence = s.diffuse_fraction + (1.0 - s.diffuse_fraction) * hit.cos_incidence.powi(2);
        let power = s.power_10m * incidence * (REFERENCE_RANGE_M / range_m).powi(3) * transmission * transmission;
        let patch = (hit.along_m / SPECKLE_PATCH_M).floor().max(0.0) as u64 & 0xff_ffff;
        let key = (bounce << 60) | (u64::from(hit.segment) << 24) | patch;
        Return { range_m, power, key, tail_bins: s.depth_m / self.sensor.range_resolution_m }
    }

    /// The ghost of the first surface when it mirrors: the beam reflected
    /// specularly, its first hit seen at the summed path length.
    fn ghost(
        &self,
        origin: [f64; 2],
        dir: [f64; 2],
        first: &Hit,
        max_range_m: f64,
        scratch: &mut Scratch,
    ) -> Option<Return> {
        let mirror = self.world.segments.get(first.segment as usize)?;
        if !mirror.mirror || mirror.transmission > 0.0 {
            return None;
        }
        let edge = [mirror.b[0] - mirror.a[0], mirror.b[1] - mirror.a[1]];
        let length = edge[0].hypot(edge[1]);
        let normal = [-edge[1] / length, edge[0] / length];
        let dot = dir[0] * normal[0] + dir[1] * normal[1];
        let reflected = [dir[0] - 2.0 * dot * normal[0], dir[1] - 2.0 * dot * normal[1]];
        let at = [origin[0] + first.range_m * dir[0], origin[1] + first.range_m * dir[1]];
        let start = [at[0] + 1e-6 * reflected[0], at[1] + 1e-6 * reflected[1]];
        let remaining = max_range_m - first.range_m;
        let second = *self.world.cast(start, reflected, remaining, scratch).first()?;
        let path_m = first.range_m + second.range_m;
        Some(self.surface_return(&second, path_m, 1.0, 1))
    }

    /// Point targets per row: `(point id, range, mean power)` with the
    /// two-way Gaussian beam pattern, each row at its own pose.
    fn point_returns(&self, poses: &[Se2]) -> Vec<Vec<(u32, f64, f64)>> {
        let sensor = self.sensor;
        let n = poses.len();
        let mut rows: Vec<Vec<(u32, f64, f64)>> = vec![Vec::new(); n];
        let (Some(first), Some(last)) = (poses.first(), poses.last()) else { return rows };
        let centre = [0.5 * (first.x_m + last.x_m), 0.5 * (first.y_m + last.y_m)];
        let travel = (last.x_m - first.x_m).hypot(last.y_m - first.y_m);
        let step_rad = TAU / n as f64;
        let beam_rad = sensor.beam_width_deg.to_radians();
        // Two-way power pattern exp(-8 ln2 (d / beam)^2): -6 dB at d = beam / 2.
        let pattern = |d: f64| (-8.0 * std::f64::consts::LN_2 * (d / beam_rad).powi(2)).exp();
        let reach = (1.5 * beam_rad / step_rad).ceil() as i64 + 1;
        let geometry = |id: u32, a: usize| -> Option<(f64, f64)> {
            let point = self.world.points.get(id as usize)?;
            let p = poses.get(a)?.inverse().transform_point(point.p);
            let bearing_cw = (-p[1]).atan2(p[0]).rem_euclid(TAU);
            Some((p[0].hypot(p[1]), bearing_cw))
        };
        for id in self.world.points_near(centre, sensor.max_range_m() + travel) {
            // Find the row facing the point: guess from the first pose, refine with the guessed row's pose.
            let mut a_guess = 0usize;
            for _ in 0..3 {
                let Some((_, bearing)) = geometry(id, a_guess) else { break };
                a_guess = ((bearing / step_rad).round() as usize) % n;
            }
            for k in -reach..=reach {
                let a = (a_guess as i64 + k).rem_euclid(n as i64) as usize;
                let Some((range_m, bearing)) = geometry(id, a) else { continue };
                let off = mmtrack_core::wrap_angle_rad(bearing - a as f64 * step_rad);
                let gain = pattern(off);
                if gain < 1e-3 || !(MIN_RANGE_M..=sensor.max_range_m()).contains(&range_m) {
                    continue;
                }
                let power_10m = self.world.points.get(id as usize).map_or(0.0, |p| p.power_10m);
                let power = power_10m * gain * (REFERENCE_RANGE_M / range_m).powi(4);
                if let Some(row) = rows.get_mut(a) {
                    row.push((id, range_m, power));
                }
            }
        }
        rows
    }
}

/// Level of a volume tail just behind the peak, relative to the peak.
const TAIL_LEVEL: f64 = 0.03;

/// Adds a return of peak power `peak` centred on `centre_bin`: a Gaussian
/// range profile, and behind it (when `tail_bins > 0`) a volume tail
/// `TAIL_LEVEL * exp(-(bin - centre) / tail_bins)`, whichever is larger.
fn add_profile(row: &mut [f32], centre_bin: f64, peak: f64, tail_bins: f64, sensor: &Sensor) {
    let sigma = sensor.range_profile_sigma_bins;
    let reach = (4.0 * sigma).ceil() as i64;
    let tail_reach = if tail_bins > 0.0 { (7.0 * tail_bins).ceil() as i64 } else { 0 };
    let centre = centre_bin.round() as i64;
    let first = (centre - reach).max(0);
    let last = (centre + reach.max(tail_reach)).min(row.len() as i64 - 1);
    for bin in first..=last {
        let offset = bin as f64 - centre_bin;
        let z = offset / sigma;
        let mut gain = (-0.5 * z * z).exp();
        if tail_bins > 0.0 && offset > 0.0 {
            gain = gain.max(TAIL_LEVEL * (-offset / tail_bins).exp());
        }
        if let Some(v) = row.get_mut(bin as usize) {
            *v += (peak * gain) as f32;
        }
    }
}

/// Speckle intensity (mean 1, exponential marginal) of the scatterer `key`
/// in sweep `scan`: `|sqrt(f) z_static + sqrt(1 - f) z_scan|^2 / 2` with unit
/// complex Gaussians, so consecutive sweeps of a static scene correlate by
/// `f^2` in intensity.
fn speckle_intensity(seed: u64, scan: u64, key: u64, static_fraction: f64) -> f64 {
    let fixed = complex_gaussian(hash_words(&[seed, 0x7370_6563, key]));
    let fresh = complex_gaussian(hash_words(&[seed, 0x7370_6563, key, scan]));
    let (a, b) = (static_fraction.sqrt(), (1.0 - static_fraction).sqrt());
    let re = a * fixed[0] + b * fresh[0];
    let im = a * fixed[1] + b * fresh[1];
    0.5 * (re * re + im * im)
}

/// Two independent standard Gaussians from 64 random bits (Box-Muller).
fn complex_gaussian(bits: u64) -> [f64; 2] {
    let u1 = ((bits >> 32) as f64 + 1.0) / 4_294_967_297.0;
    let u2 = (bits & 0xffff_ffff) as f64 / 4_294_967_296.0;
    let (re, im) = box_muller(u1, u2);
    [re, im]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speckle_has_unit_mean_and_the_asked_correlation() {
        let n = 20_000u64;
        let a: Vec<f64> = (0..n).map(|k| speckle_intensity(1, 0, k, 0.7)).collect();
        let b: Vec<f64> = (0..n).map(|k| speckle_intensity(1, 1, k, 0.7)).collect();
        let mean = a.iter().sum::<f64>() / n as f64;
        // Exponential: standard error of the mean 1/sqrt(n) = 0.007; 5 sigma.
        assert!((mean - 1.0).abs() < 0.035, "{mean}");
        let cov = a.iter().zip(&b).map(|(x, y)| (x - 1.0) * (y - 1.0)).sum::<f64>() / n as f64;
        // Intensity correlation f^2 = 0.49 (unit variance); standard error about 0.01.
        assert!((cov - 0.49).abs() < 0.06, "{cov}");
    }
}
