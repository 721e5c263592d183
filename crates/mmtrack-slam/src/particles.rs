//! UE particles in structure-of-arrays chunks of fixed size, processed in
//! parallel on rayon. Each chunk draws from its own random stream, seeded
//! from `(seed, epoch, stage, chunk index)`, so the particles do not depend
//! on the number of threads.

use faer::Mat;
use mmtrack_core::random::{keyed_stream, standard_normal, standard_normal_pair};
use mmtrack_core::slam::ctrv_displacement_m;
use mmtrack_core::wrap_angle_rad;
use rand::RngExt;
use rand_pcg::Pcg64;
use rayon::prelude::*;

use crate::model::FastPath;

/// Dimensions of a particle's varying state: `[x, y, heading, speed, turn
/// rate, clock bias]` (the height is fixed).
pub(crate) const STATE_DIM: usize = 6;

/// A fixed-size block of particles (structure of arrays).
#[derive(Debug, Clone, Default)]
pub(crate) struct Chunk {
    pub(crate) x: Vec<f64>,
    pub(crate) y: Vec<f64>,
    pub(crate) heading: Vec<f64>,
    pub(crate) speed: Vec<f64>,
    pub(crate) turn: Vec<f64>,
    pub(crate) bias: Vec<f64>,
    /// Log-weight (unnormalised).
    pub(crate) logw: Vec<f64>,
    /// Log-likelihood of the current stage.
    pub(crate) ll: Vec<f64>,
}

impl Chunk {
    fn with_len(n: usize) -> Self {
        let v = || vec![0.0; n];
        Self { x: v(), y: v(), heading: v(), speed: v(), turn: v(), bias: v(), logw: v(), ll: v() }
    }

    fn len(&self) -> usize {
        self.x.len()
    }

    fn get(&self, i: usize) -> [f64; STATE_DIM] {
        [self.x[i], self.y[i], self.heading[i], self.speed[i], self.turn[i], self.bias[i]]
    }

    fn set(&mut self, i: usize, s: [f64; STATE_DIM]) {
        self.x[i] = s[0];
        self.y[i] = s[1];
        self.heading[i] = wrap_angle_rad(s[2]);
        self.speed[i] = s[3];
        self.turn[i] = s[4];
        self.bias[i] = s[5];
    }
}

/// One path prepared for the per-particle likelihood: the source, the
/// measurement and the inverse of `Sigma + H_m P_m H_m^T`.
#[derive(Debug, Clone)]
pub(crate) struct PreparedPath {
    pub(crate) fast: FastPath,
    pub(crate) information: [[f64; 5]; 5],
}

/// `logw + delta * ll`, the tempered log-weight of one stage; `logw` alone
/// at `delta = 0`, also where `ll` is `-inf` (a particle no path can come
/// from), where `0 * -inf` would make it NaN.
fn tempered(logw: f64, ll: f64, delta: f64) -> f64 {
    if delta == 0.0 { logw } else { logw + delta * ll }
}

/// The particle set.
#[derive(Debug, Clone)]
pub(crate) struct Particles {
    pub(crate) chunks: Vec<Chunk>,
    pub(crate) z_m: f64,
    pub(crate) n: usize,
    chunk_size: usize,
}

/// The key of the filter's streams (`"slam_mmt"`): every draw comes from
/// `keyed_stream(STREAM_KEY, seed, &[epoch or tag, stage, chunk])`.
const STREAM_KEY: u64 = 0x736c_616d_5f6d_6d74;

/// Weighted moments of the particles.
#[derive(Debug, Clone)]
pub(crate) struct Moments {
    /// Mean of `[x, y, heading, speed, turn, bias]` (heading: circular mean).
    pub(crate) mean: [f64; STATE_DIM],
    /// Covariance (`6 x 6`), heading deviations wrapped around the mean.
    pub(crate) cov: Mat<f64>,
}

impl Particles {
    /// `n` particles drawn by `draw(rng) -> (state, logw)`, chunk by chunk.
    pub(crate) fn draw(
        n: usize,
        chunk_size: usize,
        z_m: f64,
        seed: u64,
        tag: u64,
        draw: impl Fn(&mut Pcg64) -> ([f64; STATE_DIM], f64) + Sync,
    ) -> Self {
        let mut chunks: Vec<Chunk> =
            (0..n.div_ceil(chunk_size)).map(|c| Chunk::with_len(chunk_size.min(n - c * chunk_size))).collect();
        chunks.par_iter_mut().enumerate().for_each(|(c, chunk)| {
            let mut rng = keyed_stream(STREAM_KEY, seed, &[tag, c as u64]);
            for i in 0..chunk.len() {
                let (s, logw) = draw(&mut rng);
                chunk.set(i, s);
                chunk.logw[i] = logw;
            }
        });
        Self { chunks, z_m, n, chunk_size }
    }

    /// The constant turn-rate velocity prediction of eq. (1) with process
    /// noise on speed, turn rate and clock bias.
    pub(crate) fn predict(&mut self, dt_s: f64, noise: [f64; 3], seed: u64, epoch: u64) {
        self.chunks.par_iter_mut().enumerate().for_each(|(c, chunk)| {
            let mut rng = keyed_stream(STREAM_KEY, seed, &[epoch, 0x7072_6564, c as u64]);
            for i in 0..chunk.len() {
                let (dx, dy) = ctrv_displacement_m(chunk.heading[i], chunk.speed[i], chunk.turn[i], dt_s);
                chunk.x[i] += dx;
                chunk.y[i] += dy;
                chunk.heading[i] = wrap_angle_rad(chunk.heading[i] + chunk.turn[i] * dt_s);
                let (a, b) = standard_normal_pair(&mut rng);
                chunk.speed[i] += noise[0] * a;
                chunk.turn[i] += noise[1] * b;
                chunk.bias[i] += noise[2] * standard_normal(&mut rng);
            }
        });
    }

    /// Stores in `ll` the log-likelihood `sum_l -r^T W_l r / 2` of every
    /// particle (`-inf` for a degenerate geometry).
    pub(crate) fn log_likelihood(&mut self, paths: &[PreparedPath]) {
        let z_m = self.z_m;
        self.chunks.par_iter_mut().for_each(|chunk| {
            for i in 0..chunk.len() {
                let x = [chunk.x[i], chunk.y[i], z_m];
                let heading = chunk.heading[i].sin_cos();
                let bias = chunk.bias[i];
                let mut ll = 0.0;
                for p in paths {
                    let Some(r) = p.fast.residual(x, heading, bias) else {
                        ll = f64::NEG_INFINITY;
                        break;
                    };
                    let w = &p.information;
                    let mut q = 0.0;
                    for a in 0..5 {
                        let mut row = w[a][a] * r[a];
                        for b in (a + 1)..5 {
                            row += 2.0 * w[a][b] * r[b];
                        }
                        q += r[a] * row;
                    }
                    ll -= 0.5 * q;
                }
                chunk.ll[i] = ll;
            }
        });
    }

    /// Effective sample size of `logw + delta * ll`.
    pub(crate) fn ess_with(&self, delta: f64) -> f64 {
        let max = self.fold_max(delta);
        if !max.is_finite() {
            return 0.0;
        }
        let (s, s2) = self
            .chunks
            .iter()
            .flat_map(|c| c.logw.iter().zip(&c.ll))
            .map(|(w, l)| {
                let e = (tempered(*w, *l, delta) - max).exp();
                (e, e * e)
            })
            .fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
        if s2 > 0.0 { s * s / s2 } else { 0.0 }
    }

    fn fold_max(&self, delta: f64) -> f64 {
        self.chunks
            .iter()
            .flat_map(|c| c.logw.iter().zip(&c.ll))
            .map(|(w, l)| tempered(*w, *l, delta))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// `logw += delta * ll`, then normalised so the largest is 0.
    pub(crate) fn absorb(&mut self, delta: f64) {
        for c in &mut self.chunks {
            for (w, l) in c.logw.iter_mut().zip(&c.ll) {
                *w = tempered(*w, *l, delta);
            }
        }
        let max = self.fold_max(0.0);
        for c in &mut self.chunks {
            for w in &mut c.logw {
                *w -= max;
            }
        }
    }

    /// Normalised weights, flat, in particle order.
    pub(crate) fn weights(&self) -> Vec<f64> {
        let max = self.fold_max(0.0);
        let mut w: Vec<f64> = self.chunks.iter().flat_map(|c| c.logw.iter()).map(|l| (l - max).exp()).collect();
        let s: f64 = w.iter().sum();
        if s > 0.0 && s.is_finite() {
            for v in &mut w {
                *v /= s;
            }
        }
        w
    }

    /// Iterates `(state, normalised weight)`.
    pub(crate) fn states(&self) -> impl Iterator<Item = [f64; STATE_DIM]> + '_ {
        self.chunks.iter().flat_map(|c| (0..c.len()).map(move |i| c.get(i)))
    }

    /// Weighted mean and covariance.
    pub(crate) fn moments(&self) -> Moments {
        let w = self.weights();
        let (mut sx, mut sy) = (0.0, 0.0);
        for (s, wi) in self.states().zip(&w) {
            sx += wi * s[2].cos();
            sy += wi * s[2].sin();
        }
        let heading = sy.atan2(sx);
        let mut mean = [0.0; STATE_DIM];
        for (s, wi) in self.states().zip(&w) {
            for d in 0..STATE_DIM {
                mean[d] += wi * if d == 2 { wrap_angle_rad(s[2] - heading) } else { s[d] };
            }
        }
        mean[2] = wrap_angle_rad(mean[2] + heading);
        let mut cov = Mat::zeros(STATE_DIM, STATE_DIM);
        for (s, wi) in self.states().zip(&w) {
            let d: [f64; STATE_DIM] =
                std::array::from_fn(|k| if k == 2 { wrap_angle_rad(s[2] - mean[2]) } else { s[k] - mean[k] });
            for a in 0..STATE_DIM {
                for b in a..STATE_DIM {
                    cov[(a, b)] += wi * d[a] * d[b];
                }
            }
        }
        for a in 0..STATE_DIM {
            for b in 0..a {
                cov[(a, b)] = cov[(b, a)];
            }
        }
        Moments { mean, cov }
    }

    /// Systematic resampling (one uniform from `(seed, epoch, stage)`),
    /// then a Gaussian kernel jitter `h L n` (regularised particle filter,
    /// `L` the Cholesky factor of the weighted covariance), drawn per chunk.
    pub(crate) fn resample(&mut self, jitter_chol: Option<&Mat<f64>>, h: f64, seed: u64, words: [u64; 2]) {
        let w = self.weights();
        let mut rng = keyed_stream(STREAM_KEY, seed, &[words[0], words[1], 0x7265_7361]);
        let u0: f64 = rng.random::<f64>() / self.n as f64;
        let flat: Vec<[f64; STATE_DIM]> = self.states().collect();
        let mut picked = Vec::with_capacity(self.n);
        let mut cum = 0.0;
        let mut j = 0;
        for i in 0..self.n {
            let u = u0 + i as f64 / self.n as f64;
            while j + 1 < self.n && cum + w[j] < u {
                cum += w[j];
                j += 1;
            }
            picked.push(flat[j]);
        }
        let chunk_size = self.chunk_size;
        self.chunks.par_iter_mut().enumerate().for_each(|(c, chunk)| {
            let mut rng = keyed_stream(STREAM_KEY, seed, &[words[0], words[1], 0x6a69_7474, c as u64]);
            for i in 0..chunk.len() {
                let mut s = picked[c * chunk_size + i];
                if let Some(l) = jitter_chol {
                    let pairs = [
                        standard_normal_pair(&mut rng),
                        standard_normal_pair(&mut rng),
                        standard_normal_pair(&mut rng),
                    ];
                    let n: [f64; STATE_DIM] =
                        std::array::from_fn(|k| if k % 2 == 0 { pairs[k / 2].0 } else { pairs[k / 2].1 });
                    for a in 0..STATE_DIM {
                        let mut v = 0.0;
                        for b in 0..=a {
                            v += l[(a, b)] * n[b];
                        }
                        s[a] += h * v;
                    }
                }
                chunk.set(i, s);
                chunk.logw[i] = 0.0;
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three equal weights; one particle no path can come from (`ll = -inf`).
    fn three() -> Particles {
        let mut chunk = Chunk::with_len(3);
        chunk.ll = vec![f64::NEG_INFINITY, -1.0, -1.0];
        Particles { chunks: vec![chunk], z_m: 0.0, n: 3, chunk_size: 3 }
    }

    #[test]
    fn a_particle_with_minus_infinite_likelihood_keeps_the_untempered_ess() {
        let particles = three();
        // Untempered: three equal weights, ESS 3 (it was NaN: 0 * -inf).
        assert_eq!(particles.ess_with(0.0), 3.0);
        // Tempered: the -inf particle drops out, two equal weights remain.
        assert_eq!(particles.ess_with(0.5), 2.0);
        let mut absorbed = particles.clone();
        absorbed.absorb(0.0);
        assert_eq!(absorbed.chunks[0].logw, [0.0, 0.0, 0.0]);
    }
}
