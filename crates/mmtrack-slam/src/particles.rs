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

    /// `f` of every chunk, in chunk order, computed in parallel.
    fn per_chunk<T: Send>(&self, f: impl Fn(&Chunk) -> T + Sync + Send) -> Vec<T> {
        self.chunks.par_iter().map(f).collect()
    }

    // Which passes run in parallel: only those with a transcendental
    // function per particle (the exponentials of the weights, the heading's
    // sine and cosine; the likelihood, the prediction and the jitter
    // elsewhere), one parallel region each. A pass of a few arithmetic
    // operations per particle (maxima, sums, `absorb`, deviations) takes a
    // microsecond or two on one core for 2000 particles, less than handing
    // work to another thread and waiting for it, so it stays on the calling
    // thread. Every sum runs over the particles in order, as one flat loop
    // would: the results are the same for any thread count.

    /// Effective sample size of `logw + delta * ll`: `(sum e)^2 / sum e^2`
    /// with `e = exp(logw + delta ll - max)`, the exponentials per chunk in
    /// parallel.
    pub(crate) fn ess_with(&self, delta: f64) -> f64 {
        let max = self.fold_max(delta);
        if !max.is_finite() {
            return 0.0;
        }
        let e = self.per_chunk(|c| c.logw.iter().zip(&c.ll).map(|(w, l)| (w + delta * l - max).exp()).collect());
        let (s, s2) = e.iter().flat_map(|v: &Vec<f64>| v.iter()).fold((0.0, 0.0), |a, &e| (a.0 + e, a.1 + e * e));
        if s2 > 0.0 { s * s / s2 } else { 0.0 }
    }

    /// The largest `logw + delta * ll` (`logw` for `delta = 0`). A maximum
    /// is exact in any order (up to the sign of a zero, which no later
    /// value depends on), so each chunk is scanned with four running maxima.
    fn fold_max(&self, delta: f64) -> f64 {
        self.chunks.iter().map(|c| chunk_max(c, delta)).fold(f64::NEG_INFINITY, f64::max)
    }

    /// `logw += delta * ll`, then normalised so the largest is 0.
    pub(crate) fn absorb(&mut self, delta: f64) {
        for c in &mut self.chunks {
            for (w, l) in c.logw.iter_mut().zip(&c.ll) {
                *w += delta * l;
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
    #[cfg(test)]
    pub(crate) fn weights(&self) -> Vec<f64> {
        self.weights_and(|_| ()).0
    }

    /// Normalised weights, flat, in particle order, and `per_particle(heading)`
    /// of every particle, both computed per chunk in one parallel region:
    /// `exp(logw - max)`, then the sum and the division in particle order.
    fn weights_and<T: Send>(&self, per_particle: impl Fn(f64) -> T + Sync + Send) -> (Vec<f64>, Vec<T>) {
        let max = self.fold_max(0.0);
        let parts = self.per_chunk(|c| {
            let e: Vec<f64> = c.logw.iter().map(|l| (l - max).exp()).collect();
            let t: Vec<T> = c.heading.iter().map(|&h| per_particle(h)).collect();
            (e, t)
        });
        let mut w = Vec::with_capacity(self.n);
        let mut t = Vec::with_capacity(self.n);
        for (e, v) in parts {
            w.extend(e);
            t.extend(v);
        }
        let s: f64 = w.iter().sum();
        if s > 0.0 && s.is_finite() {
            for v in &mut w {
                *v /= s;
            }
        }
        (w, t)
    }

    /// Iterates the particle states in order.
    pub(crate) fn states(&self) -> impl Iterator<Item = [f64; STATE_DIM]> + '_ {
        self.chunks.iter().flat_map(|c| (0..c.len()).map(move |i| c.get(i)))
    }

    /// Weighted mean and covariance.
    pub(crate) fn moments(&self) -> Moments {
        self.moments_and_weights().0
    }

    /// Weighted mean and covariance, and the normalised weights they used:
    /// the circular mean of the heading, the mean of the rest, and the
    /// covariance with heading deviations wrapped around the mean. The
    /// weights' exponentials and the headings' cosines and sines run in one
    /// parallel region, the sums on the calling thread in particle order.
    pub(crate) fn moments_and_weights(&self) -> (Moments, Vec<f64>) {
        let (w, trig) = self.weights_and(|h| (h.cos(), h.sin()));
        let (mut sx, mut sy) = (0.0, 0.0);
        for (&(cos, sin), wi) in trig.iter().zip(&w) {
            sx += wi * cos;
            sy += wi * sin;
        }
        let heading = sy.atan2(sx);
        let mut mean = [0.0; STATE_DIM];
        for (s, wi) in self.states().zip(&w) {
            for d in 0..STATE_DIM {
                mean[d] += wi * if d == 2 { wrap_angle_rad(s[2] - heading) } else { s[d] };
            }
        }
        mean[2] = wrap_angle_rad(mean[2] + heading);
        let mut cov = [[0.0; STATE_DIM]; STATE_DIM];
        for (s, wi) in self.states().zip(&w) {
            let d: [f64; STATE_DIM] =
                std::array::from_fn(|k| if k == 2 { wrap_angle_rad(s[2] - mean[2]) } else { s[k] - mean[k] });
            for a in 0..STATE_DIM {
                for b in a..STATE_DIM {
                    cov[a][b] += wi * d[a] * d[b];
                }
            }
        }
        let cov = Mat::from_fn(STATE_DIM, STATE_DIM, |a, b| cov[a.min(b)][a.max(b)]);
        (Moments { mean, cov }, w)
    }

    /// Systematic resampling (one uniform from `(seed, epoch, stage)`),
    /// then a Gaussian kernel jitter `h L n` (regularised particle filter,
    /// `L` the Cholesky factor of the weighted covariance), drawn per chunk.
    /// `weights` are [`Particles::weights`] of the current particles.
    ///
    /// Particle `i` takes the state of the first `j` whose cumulative weight
    /// `c_(j+1) = w_0 + ... + w_j` (summed in order) reaches
    /// `u_i = u_0 + i / n`, the last particle at most: the sequential
    /// sweep's choice, found by bisection of the cumulative weights so that
    /// each chunk picks and jitters its particles in parallel.
    pub(crate) fn resample(
        &mut self,
        weights: &[f64],
        jitter_chol: Option<&Mat<f64>>,
        h: f64,
        seed: u64,
        words: [u64; 2],
    ) {
        let n = self.n;
        let mut rng = keyed_stream(STREAM_KEY, seed, &[words[0], words[1], 0x7265_7361]);
        let u0: f64 = rng.random::<f64>() / n as f64;
        let mut cumulative = Vec::with_capacity(n);
        let mut sum = 0.0;
        for &w in weights {
            sum += w;
            cumulative.push(sum);
        }
        // The sweep never moves past the last particle.
        let cumulative = &cumulative[..n - 1];
        let old = std::mem::take(&mut self.chunks);
        let chunk_size = self.chunk_size;
        self.chunks = (0..old.len())
            .into_par_iter()
            .map(|c| {
                let mut chunk = Chunk::with_len(old[c].len());
                // The stage's log-likelihoods stay where they were, as an
                // in-place resampling leaves them.
                chunk.ll.copy_from_slice(&old[c].ll);
                let mut rng = keyed_stream(STREAM_KEY, seed, &[words[0], words[1], 0x6a69_7474, c as u64]);
                for i in 0..chunk.len() {
                    let u = u0 + (c * chunk_size + i) as f64 / n as f64;
                    let j = cumulative.partition_point(|&p| p < u);
                    let mut s = old[j / chunk_size].get(j % chunk_size);
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
                chunk
            })
            .collect();
    }
}

/// The largest `logw + delta * ll` of a chunk (`logw` for `delta = 0`),
/// with four running maxima so the comparisons do not wait on each other.
fn chunk_max(c: &Chunk, delta: f64) -> f64 {
    fn max4(values: impl Iterator<Item = f64>) -> f64 {
        let mut m = [f64::NEG_INFINITY; 4];
        for (i, v) in values.enumerate() {
            m[i % 4] = m[i % 4].max(v);
        }
        m[0].max(m[1]).max(m[2].max(m[3]))
    }
    if delta == 0.0 { max4(c.logw.iter().copied()) } else { max4(c.logw.iter().zip(&c.ll).map(|(w, l)| w + delta * l)) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1000 particles in uneven chunks of 96, with spread log-weights and
    /// log-likelihoods, one of them `-inf` (a degenerate geometry).
    fn particles() -> Particles {
        let mut p = Particles::draw(1000, 96, 1.5, 7, 1, |rng| {
            let s = std::array::from_fn(|k| standard_normal(rng) * if k == 2 { 2.5 } else { 3.0 });
            (s, -3.0 * rng.random::<f64>())
        });
        for (k, c) in p.chunks.iter_mut().enumerate() {
            for i in 0..c.len() {
                c.ll[i] = -50.0 * ((k * 31 + i * 7) % 101) as f64 / 101.0;
            }
        }
        p.chunks[3].ll[5] = f64::NEG_INFINITY;
        p
    }

    // The single flat loops the parallel passes replaced: every result must
    // be theirs, bit for bit.

    fn flat_max(p: &Particles, delta: f64) -> f64 {
        let values = p.chunks.iter().flat_map(|c| c.logw.iter().zip(&c.ll));
        values.map(|(w, l)| if delta == 0.0 { *w } else { w + delta * l }).fold(f64::NEG_INFINITY, f64::max)
    }

    fn flat_ess(p: &Particles, delta: f64) -> f64 {
        let max = flat_max(p, delta);
        if !max.is_finite() {
            return 0.0;
        }
        let (s, s2) = p
            .chunks
            .iter()
            .flat_map(|c| c.logw.iter().zip(&c.ll))
            .map(|(w, l)| {
                let e = (w + delta * l - max).exp();
                (e, e * e)
            })
            .fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
        if s2 > 0.0 { s * s / s2 } else { 0.0 }
    }

    fn flat_weights(p: &Particles) -> Vec<f64> {
        let max = flat_max(p, 0.0);
        let mut w: Vec<f64> = p.chunks.iter().flat_map(|c| c.logw.iter()).map(|l| (l - max).exp()).collect();
        let s: f64 = w.iter().sum();
        if s > 0.0 && s.is_finite() {
            for v in &mut w {
                *v /= s;
            }
        }
        w
    }

    fn flat_moments(p: &Particles) -> Moments {
        let w = flat_weights(p);
        let (mut sx, mut sy) = (0.0, 0.0);
        for (s, wi) in p.states().zip(&w) {
            sx += wi * s[2].cos();
            sy += wi * s[2].sin();
        }
        let heading = sy.atan2(sx);
        let mut mean = [0.0; STATE_DIM];
        for (s, wi) in p.states().zip(&w) {
            for d in 0..STATE_DIM {
                mean[d] += wi * if d == 2 { wrap_angle_rad(s[2] - heading) } else { s[d] };
            }
        }
        mean[2] = wrap_angle_rad(mean[2] + heading);
        let mut cov = Mat::zeros(STATE_DIM, STATE_DIM);
        for (s, wi) in p.states().zip(&w) {
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

    /// The sequential sweep of systematic resampling (no jitter).
    fn flat_resample(p: &Particles, seed: u64, words: [u64; 2]) -> Vec<[f64; STATE_DIM]> {
        let w = flat_weights(p);
        let mut rng = keyed_stream(STREAM_KEY, seed, &[words[0], words[1], 0x7265_7361]);
        let u0: f64 = rng.random::<f64>() / p.n as f64;
        let flat: Vec<[f64; STATE_DIM]> = p.states().collect();
        let (mut cum, mut j) = (0.0, 0);
        (0..p.n)
            .map(|i| {
                let u = u0 + i as f64 / p.n as f64;
                while j + 1 < p.n && cum + w[j] < u {
                    cum += w[j];
                    j += 1;
                }
                flat[j]
            })
            .collect()
    }

    fn bits(values: impl IntoIterator<Item = f64>) -> Vec<u64> {
        values.into_iter().map(f64::to_bits).collect()
    }

    #[test]
    fn the_parallel_passes_give_the_flat_loops_results_bit_for_bit_on_any_pool() {
        let reference = particles();
        let pool = |threads| rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        for threads in [1, 2, 3] {
            pool(threads).install(|| {
                let mut p = reference.clone();
                for delta in [0.0, 0.013, 0.5, 1.0] {
                    assert_eq!(p.ess_with(delta).to_bits(), flat_ess(&p, delta).to_bits(), "delta {delta}");
                }
                // ESS at 0 sees the -inf likelihood as NaN (0 * -inf) and is 0, as the flat loop.
                assert_eq!(p.ess_with(0.0), 0.0);
                assert!(p.ess_with(0.5) > 1.0);
                let mut flat = p.clone();
                p.absorb(0.3);
                for c in &mut flat.chunks {
                    for (w, l) in c.logw.iter_mut().zip(&c.ll) {
                        *w += 0.3 * l;
                    }
                }
                let max = flat_max(&flat, 0.0);
                for c in &mut flat.chunks {
                    c.logw.iter_mut().for_each(|w| *w -= max);
                }
                let logw = |p: &Particles| bits(p.chunks.iter().flat_map(|c| c.logw.clone()));
                assert_eq!(logw(&p), logw(&flat));
                assert_eq!(bits(p.weights()), bits(flat_weights(&p)));
                let (m, w) = p.moments_and_weights();
                let expected = flat_moments(&p);
                assert_eq!(bits(m.mean), bits(expected.mean));
                let entries = |c: &Mat<f64>| bits((0..STATE_DIM * STATE_DIM).map(|k| c[(k / 6, k % 6)]));
                assert_eq!(entries(&m.cov), entries(&expected.cov));
                let picked = flat_resample(&p, 5, [17, 2]);
                p.resample(&w, None, 0.0, 5, [17, 2]);
                let wrapped: Vec<[f64; STATE_DIM]> = picked
                    .iter()
                    .map(|s| {
                        let mut s = *s;
                        s[2] = wrap_angle_rad(s[2]);
                        s
                    })
                    .collect();
                assert_eq!(p.states().collect::<Vec<_>>(), wrapped, "threads {threads}");
                assert!(p.chunks.iter().all(|c| c.logw.iter().all(|&w| w == 0.0)));
                // Resampling picked many particles, not one.
                let distinct = wrapped.windows(2).filter(|w| w[0] != w[1]).count();
                assert!(distinct > 100, "{distinct}");
            });
        }
    }
}
