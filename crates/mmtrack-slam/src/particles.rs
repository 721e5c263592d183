//! UE particles in structure-of-arrays chunks of fixed size, processed in
//! parallel by the epoch's [`Team`]. Each chunk draws from its own random
//! stream, seeded from `(seed, epoch, stage, chunk index)`, so the particles
//! do not depend on the number of threads.
//!
//! ## What runs in parallel, and why the results do not depend on it
//!
//! Every per-particle computation runs chunk by chunk on the team: the
//! prediction, the likelihood, the exponentials of the weights and of the
//! effective sample size, the sines and cosines of the headings, the
//! resampling's jitter, the covariance of the moments (a group of rows per
//! member, each entry summed over the particles in order). Maxima are
//! reduced per chunk, then across chunks. The sums that reach the output
//! (the effective sample size, the normalised weights, the means) are taken
//! by the leader, particle by particle in particle order, over the values
//! the parallel phase stored: a floating-point sum depends on its order,
//! and this is the order of a sequential loop, so every result is bit for
//! bit that of a sequential run for any thread count. They are one add per
//! particle and quantity; the exponentials and trigonometry they replace
//! are tens of cycles.
//!
//! The systematic resampling's running weight sums are such a chain too;
//! the picks they give (a division and a walk per particle) are found per
//! chunk in the resampling's pass ([`Picks`]).
//!
//! Values a later step needs again are kept until the particles change:
//! the maximum of `logw + delta ll` and the effective sample size per
//! exponent `delta` (the tempering search asks for the same exponent more
//! than once), the exponentials of the last pass, and the normalised
//! weights. A phase that knows which exponents come next takes their maxima
//! in the same pass, and a phase that writes values a later step would
//! compute in a pass of its own writes them too: the prediction the
//! headings' trigonometry (the log-weights, and so everything at `delta =
//! 0`, stay valid), the resampling the trigonometry, the exponentials
//! (all 1) and the maximum at 0 of the new particles.

use std::sync::{Arc, PoisonError, RwLock, RwLockReadGuard, RwLockWriteGuard};

use faer::Mat;
use mmtrack_core::random::{keyed_stream, standard_normal, standard_normal_pair};
use mmtrack_core::slam::ctrv_displacement_m;
use mmtrack_core::wrap_angle_rad;
use rand::RngExt;
use rand_pcg::Pcg64;

use crate::model::FastPath;
use crate::team::Team;

/// Dimensions of a particle's varying state: `[x, y, heading, speed, turn
/// rate, clock bias]` (the height is fixed).
pub(crate) const STATE_DIM: usize = 6;

/// A fixed-size block of particles (structure of arrays), with the working
/// space of the parallel phases.
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
    /// `exp(logw + delta ll - max)` of the last exponential pass.
    exp: Vec<f64>,
    /// Cosine and sine of the heading.
    cos_heading: Vec<f64>,
    sin_heading: Vec<f64>,
    /// Normalised weight.
    weight: Vec<f64>,
}

impl Chunk {
    fn with_len(n: usize) -> Self {
        let v = || vec![0.0; n];
        Self {
            x: v(),
            y: v(),
            heading: v(),
            speed: v(),
            turn: v(),
            bias: v(),
            logw: v(),
            ll: v(),
            exp: v(),
            cos_heading: v(),
            sin_heading: v(),
            weight: v(),
        }
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

    /// `max_i (logw_i + delta ll_i)` for each `delta`.
    fn max_at(&self, deltas: &[f64]) -> Vec<f64> {
        deltas
            .iter()
            .map(|d| {
                self.logw.iter().zip(&self.ll).map(|(w, l)| tempered(*w, *l, *d)).fold(f64::NEG_INFINITY, f64::max)
            })
            .collect()
    }

    /// Cosine and sine of every heading.
    fn trigonometry(&mut self) {
        for i in 0..self.len() {
            self.cos_heading[i] = self.heading[i].cos();
            self.sin_heading[i] = self.heading[i].sin();
        }
    }
}

/// `sum_l -r^T W_l r / 2` of one particle, `-inf` when a path cannot come
/// from it.
fn particle_log_likelihood(paths: &[PreparedPath], x: [f64; 3], heading_rad: f64, bias_m: f64) -> f64 {
    let heading = heading_rad.sin_cos();
    let mut ll = 0.0;
    for p in paths {
        let Some(r) = p.fast.residual(x, heading, bias_m) else {
            return f64::NEG_INFINITY;
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
    ll
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

/// Rows `FIRST..END` of the weighted covariance `sum_i w_i d_i d_i^T`, `d_i`
/// the deviation of particle `i` from `mean` (heading wrapped), summed in
/// particle order; entry `b` of a row `a` is kept for `b >= a`, the other
/// entries and rows are 0. The rows are constants so that the loops unroll
/// (with a row range known only at run time the same pass took 3.6 times
/// the instructions: callgrind, `bench slam`'s 100 epochs at 2000
/// particles on one thread, 276 M against 76 M).
fn covariance_rows<const FIRST: usize, const END: usize>(
    chunks: &[RwLock<Chunk>],
    mean: &[f64; STATE_DIM],
) -> [[f64; STATE_DIM]; STATE_DIM] {
    let mut acc = [[0.0; STATE_DIM]; STATE_DIM];
    for c in chunks {
        let c = read(c);
        for i in 0..c.len() {
            let (s, wi) = (c.get(i), c.weight[i]);
            // The deviations these rows need (`b >= FIRST`), as a plain
            // loop: an `array::from_fn` here was left un-inlined in one
            // build and took a fifth of the one-thread time.
            let mut d = [0.0; STATE_DIM];
            for k in FIRST..STATE_DIM {
                d[k] = if k == 2 { wrap_angle_rad(s[2] - mean[2]) } else { s[k] - mean[k] };
            }
            for a in FIRST..END {
                for b in a..STATE_DIM {
                    acc[a][b] += wi * d[a] * d[b];
                }
            }
        }
    }
    acc
}

/// Element-wise maximum of per-chunk maxima, in chunk order.
fn max_over(per_chunk: &[Vec<f64>], k: usize) -> Vec<f64> {
    (0..k).map(|j| per_chunk.iter().map(|m| m[j]).fold(f64::NEG_INFINITY, f64::max)).collect()
}

fn read(chunk: &RwLock<Chunk>) -> RwLockReadGuard<'_, Chunk> {
    chunk.read().unwrap_or_else(PoisonError::into_inner)
}

fn write(chunk: &RwLock<Chunk>) -> RwLockWriteGuard<'_, Chunk> {
    chunk.write().unwrap_or_else(PoisonError::into_inner)
}

/// The chunks of one generation, shared with the team's tasks.
type Generation = Arc<Vec<RwLock<Chunk>>>;

fn generation(chunks: Vec<Chunk>) -> Generation {
    Arc::new(chunks.into_iter().map(RwLock::new).collect())
}

fn deep_copy(g: &Generation) -> Generation {
    generation(g.iter().map(|c| read(c).clone()).collect())
}

/// What is known about the current particles (cleared when they change).
#[derive(Debug, Clone, Default)]
struct Known {
    /// `max (logw + delta ll)` per `delta` (bits).
    max: Vec<(u64, f64)>,
    /// Effective sample size per `delta` (bits).
    ess: Vec<(u64, f64)>,
    /// The chunks' `exp` holds `exp(logw + delta ll - max)` for this `delta` (bits).
    exp_at: Option<u64>,
    /// The chunks' `cos_heading` and `sin_heading` are current.
    trigonometry: bool,
    /// The chunks' `weight` holds the normalised weights.
    weights: bool,
}

impl Known {
    fn max(&self, delta: f64) -> Option<f64> {
        self.max.iter().find(|(d, _)| *d == delta.to_bits()).map(|(_, m)| *m)
    }

    fn ess(&self, delta: f64) -> Option<f64> {
        self.ess.iter().find(|(d, _)| *d == delta.to_bits()).map(|(_, e)| *e)
    }

    fn set_max(&mut self, deltas: &[f64], max: &[f64]) {
        for (d, m) in deltas.iter().zip(max) {
            if self.max(*d).is_none() {
                self.max.push((d.to_bits(), *m));
            }
        }
    }

    /// The weights or the likelihoods changed (the states did not).
    fn weights_changed(&mut self) {
        let trigonometry = self.trigonometry;
        *self = Self { trigonometry, ..Self::default() };
    }

    /// The states moved (the prediction) and their trigonometry was taken
    /// in the same pass; the log-weights did not change, so what depends on
    /// them alone (the values at `delta = 0`: maximum, effective sample
    /// size, exponentials, normalised weights) stays.
    fn states_moved(&mut self) {
        let zero = 0f64.to_bits();
        self.max.retain(|(d, _)| *d == zero);
        self.ess.retain(|(d, _)| *d == zero);
        self.exp_at = self.exp_at.filter(|d| *d == zero);
        self.trigonometry = true;
    }
}

/// The picks of the systematic resampling: output particle `i` takes the
/// first `j` whose running weight sum reaches `u0 + i / n` (the last
/// particle when none does).
///
/// The running sums are taken in particle order (a chain of adds, the
/// only serial part); each chunk of outputs then finds its picks by a
/// binary search for its first output and a walk for the rest, on the
/// team. The sums of non-negative weights do not decrease, which the
/// search needs; with a negative or NaN weight the picks are made by the
/// sequential walk over all outputs instead. Either way they equal the
/// walk's: `j` advances past `j` while `j + 1 < n` and the sum up to and
/// including `w_j` is below `u`, the same adds in the same order.
#[derive(Debug)]
enum Picks {
    /// `cum[k]` is the sum of the first `k` weights (`cum[0] = 0`).
    Search { cum: Vec<f64>, n: usize, u0: f64 },
    /// A weight is negative or NaN: every pick, by the sequential walk.
    Walked(Vec<usize>),
}

impl Picks {
    fn new(weights: impl Iterator<Item = f64> + Clone, n: usize, u0: f64) -> Self {
        let mut cum = Vec::with_capacity(n + 1);
        let mut sum = 0.0;
        cum.push(sum);
        for w in weights.clone().take(n) {
            if w.is_nan() || w < 0.0 {
                return Self::Walked(walk(weights, n, u0));
            }
            sum += w;
            cum.push(sum);
        }
        cum.resize(n + 1, sum);
        Self::Search { cum, n, u0 }
    }

    /// The picks of outputs `first..first + len`.
    fn chunk(&self, first: usize, len: usize) -> Vec<usize> {
        match self {
            Self::Walked(picked) => picked[first..first + len].to_vec(),
            Self::Search { cum, n, u0 } => {
                let n = *n;
                let u = |i: usize| u0 + i as f64 / n as f64;
                // First `j` in `0..n - 1` with `cum[j + 1] >= u`, else `n - 1`.
                let advances = |j: usize, u: f64| j + 1 < n && cum[j + 1] < u;
                let mut j = cum[1..n].partition_point(|c| *c < u(first));
                let mut out = Vec::with_capacity(len);
                for i in first..first + len {
                    let u = u(i);
                    while advances(j, u) {
                        j += 1;
                    }
                    out.push(j);
                }
                out
            }
        }
    }
}

/// The systematic resampling's sequential walk over the weights in
/// particle order: for each output `i`, `u = u0 + i / n`, `j` advances
/// while `j + 1 < n` and `cum + w_j < u` (then `cum += w_j`).
fn walk(weights: impl Iterator<Item = f64>, n: usize, u0: f64) -> Vec<usize> {
    let mut w = weights;
    let mut picked = Vec::with_capacity(n);
    let mut cum = 0.0;
    let mut j = 0;
    let mut wj = w.next().unwrap_or(0.0);
    for i in 0..n {
        let u = u0 + i as f64 / n as f64;
        while j + 1 < n && cum + wj < u {
            cum += wj;
            j += 1;
            wj = w.next().unwrap_or(0.0);
        }
        picked.push(j);
    }
    picked
}

/// The particle set.
#[derive(Debug)]
pub(crate) struct Particles {
    chunks: Generation,
    /// The next generation, written by the resampling.
    spare: Generation,
    pub(crate) z_m: f64,
    pub(crate) n: usize,
    chunk_size: usize,
    known: Known,
}

impl Clone for Particles {
    fn clone(&self) -> Self {
        Self {
            chunks: deep_copy(&self.chunks),
            spare: deep_copy(&self.spare),
            z_m: self.z_m,
            n: self.n,
            chunk_size: self.chunk_size,
            known: self.known.clone(),
        }
    }
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

/// The next stage's likelihood, computed in the resampling's pass: the
/// paths and the exponents whose maxima the tempering search asks first.
pub(crate) struct NextStage {
    pub(crate) paths: Arc<[PreparedPath]>,
    pub(crate) prefetch: Vec<f64>,
}

impl Particles {
    /// `n` particles drawn by `draw(rng) -> (state, logw)`, chunk by chunk.
    pub(crate) fn draw(
        team: &Team,
        n: usize,
        chunk_size: usize,
        z_m: f64,
        seed: u64,
        tag: u64,
        draw: impl Fn(&mut Pcg64) -> ([f64; STATE_DIM], f64) + Send + Sync + 'static,
    ) -> Self {
        let chunks = team.map(n.div_ceil(chunk_size), move |c| {
            let mut chunk = Chunk::with_len(chunk_size.min(n - c * chunk_size));
            let mut rng = keyed_stream(STREAM_KEY, seed, &[tag, c as u64]);
            for i in 0..chunk.len() {
                let (s, logw) = draw(&mut rng);
                chunk.set(i, s);
                chunk.logw[i] = logw;
            }
            chunk
        });
        let spare = generation(chunks.clone());
        Self { chunks: generation(chunks), spare, z_m, n, chunk_size, known: Known::default() }
    }

    /// Number of chunks.
    pub(crate) fn chunk_count(&self) -> usize {
        self.chunks.len()
    }

    /// The states, flat, in particle order.
    pub(crate) fn states(&self) -> Vec<[f64; STATE_DIM]> {
        let mut out = Vec::with_capacity(self.n);
        for c in self.chunks.iter() {
            let c = read(c);
            out.extend((0..c.len()).map(|i| c.get(i)));
        }
        out
    }

    /// The constant turn-rate velocity prediction of eq. (1) with process
    /// noise on speed, turn rate and clock bias.
    pub(crate) fn predict(&mut self, team: &Team, dt_s: f64, noise: [f64; 3], seed: u64, epoch: u64) {
        let chunks = self.chunks.clone();
        team.map(chunks.len(), move |c| {
            let mut chunk = write(&chunks[c]);
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
            // The moments after the prediction need them; taking them here
            // saves the normalisation a pass of its own.
            chunk.trigonometry();
        });
        self.known.states_moved();
    }

    /// Stores in `ll` the log-likelihood `sum_l -r^T W_l r / 2` of every
    /// particle (`-inf` for a degenerate geometry), and takes the maxima of
    /// `logw + delta ll` at the exponents `prefetch`.
    pub(crate) fn log_likelihood(&mut self, team: &Team, paths: &Arc<[PreparedPath]>, prefetch: &[f64]) {
        let (chunks, paths, z_m) = (self.chunks.clone(), paths.clone(), self.z_m);
        let deltas = prefetch.to_vec();
        let maxima = team.map(chunks.len(), move |c| {
            let mut chunk = write(&chunks[c]);
            for i in 0..chunk.len() {
                chunk.ll[i] =
                    particle_log_likelihood(&paths, [chunk.x[i], chunk.y[i], z_m], chunk.heading[i], chunk.bias[i]);
            }
            chunk.max_at(&deltas)
        });
        self.known.weights_changed();
        self.known.set_max(prefetch, &max_over(&maxima, prefetch.len()));
    }

    /// The maximum of `logw + delta ll`.
    fn max_at(&mut self, team: &Team, delta: f64) -> f64 {
        if let Some(m) = self.known.max(delta) {
            return m;
        }
        let chunks = self.chunks.clone();
        let maxima = team.map(chunks.len(), move |c| read(&chunks[c]).max_at(&[delta]));
        let m = max_over(&maxima, 1)[0];
        self.known.set_max(&[delta], &[m]);
        m
    }

    /// Effective sample size `(sum e)^2 / sum e^2` of `e = exp(logw + delta
    /// ll - max)`, `max` the maximum of the exponent (0 when it is not
    /// finite), summed in particle order; the same pass takes the maxima at
    /// the exponents `prefetch`.
    pub(crate) fn ess_with(&mut self, team: &Team, delta: f64, prefetch: &[f64]) -> f64 {
        if let Some(ess) = self.known.ess(delta) {
            return ess;
        }
        let max = self.max_at(team, delta);
        if !max.is_finite() {
            self.known.ess.push((delta.to_bits(), 0.0));
            return 0.0;
        }
        self.exponentials(team, delta, max, prefetch);
        let (mut s, mut s2) = (0.0, 0.0);
        for c in self.chunks.iter() {
            for e in &read(c).exp {
                s += e;
                s2 += e * e;
            }
        }
        let ess = if s2 > 0.0 { s * s / s2 } else { 0.0 };
        self.known.ess.push((delta.to_bits(), ess));
        ess
    }

    /// `exp(logw + delta ll - max)` of every particle into the chunks'
    /// `exp` (unless already there), and the maxima at `prefetch`.
    fn exponentials(&mut self, team: &Team, delta: f64, max: f64, prefetch: &[f64]) {
        let prefetch: Vec<f64> = prefetch.iter().copied().filter(|d| self.known.max(*d).is_none()).collect();
        if self.known.exp_at == Some(delta.to_bits()) && prefetch.is_empty() {
            return;
        }
        let (chunks, deltas) = (self.chunks.clone(), prefetch.clone());
        let maxima = team.map(chunks.len(), move |c| {
            let mut chunk = write(&chunks[c]);
            let chunk = &mut *chunk;
            for ((e, w), l) in chunk.exp.iter_mut().zip(&chunk.logw).zip(&chunk.ll) {
                *e = (tempered(*w, *l, delta) - max).exp();
            }
            chunk.max_at(&deltas)
        });
        self.known.exp_at = Some(delta.to_bits());
        self.known.set_max(&prefetch, &max_over(&maxima, prefetch.len()));
    }

    /// `logw += delta * ll`, then normalised so the largest is 0.
    ///
    /// The largest `logw + delta ll` is the maximum the effective sample
    /// size at `delta` took (the same values, folded in the same order), so
    /// the sum and the normalisation are one pass.
    pub(crate) fn absorb(&mut self, team: &Team, delta: f64) {
        let max = self.max_at(team, delta);
        // The largest is now 0 (or all are -inf): the weights' exponentials
        // `exp(logw - 0)` and the headings' trigonometry come in the same pass.
        let (chunks, trigonometry) = (self.chunks.clone(), !self.known.trigonometry);
        let maxima = team.map(chunks.len(), move |c| {
            let mut chunk = write(&chunks[c]);
            let chunk = &mut *chunk;
            for ((w, e), l) in chunk.logw.iter_mut().zip(chunk.exp.iter_mut()).zip(&chunk.ll) {
                *w = tempered(*w, *l, delta) - max;
                *e = (*w - 0.0).exp();
            }
            if trigonometry {
                chunk.trigonometry();
            }
            chunk.max_at(&[0.0])
        });
        let new_max = max_over(&maxima, 1)[0];
        self.known.weights_changed();
        self.known.trigonometry = true;
        self.known.set_max(&[0.0], &[new_max]);
        // `exp(logw - new_max)` equals `exp(logw - 0)` when `new_max` is
        // +0 or -0 (the difference is `logw` or a zero of either sign).
        if new_max == 0.0 {
            self.known.exp_at = Some(0f64.to_bits());
        }
    }

    /// The normalised weights into the chunks' `weight` (the
    /// exponentials at `delta = 0` over their sum in particle order, as
    /// is when that sum is 0 or not finite), and the headings' cosine and
    /// sine; returns the normalised weights' `(sum w cos, sum w sin)` in
    /// particle order.
    fn normalise(&mut self, team: &Team) -> (f64, f64) {
        let max = self.max_at(team, 0.0);
        let trigonometry = !self.known.trigonometry;
        if self.known.exp_at != Some(0f64.to_bits()) || trigonometry {
            let chunks = self.chunks.clone();
            team.map(chunks.len(), move |c| {
                let mut chunk = write(&chunks[c]);
                let chunk = &mut *chunk;
                for (e, w) in chunk.exp.iter_mut().zip(&chunk.logw) {
                    *e = (w - max).exp();
                }
                if trigonometry {
                    chunk.trigonometry();
                }
            });
            self.known.exp_at = Some(0f64.to_bits());
            self.known.trigonometry = true;
        }
        let s: f64 = {
            let guards: Vec<_> = self.chunks.iter().map(|c| read(c)).collect();
            guards.iter().flat_map(|c| c.exp.iter()).sum()
        };
        let scale = s > 0.0 && s.is_finite();
        let (mut sx, mut sy) = (0.0, 0.0);
        for c in self.chunks.iter() {
            let mut c = write(c);
            let c = &mut *c;
            for i in 0..c.exp.len() {
                let w = if scale { c.exp[i] / s } else { c.exp[i] };
                c.weight[i] = w;
                sx += w * c.cos_heading[i];
                sy += w * c.sin_heading[i];
            }
        }
        self.known.weights = true;
        (sx, sy)
    }

    /// Every `stride`-th particle (`stride = max(1, n / at_most)`, from the
    /// first) with its normalised weight, in particle order: at most about
    /// `at_most` of them, copied instead of all.
    pub(crate) fn weighted_sample(&mut self, team: &Team, at_most: usize) -> Vec<([f64; STATE_DIM], f64)> {
        if !self.known.weights {
            self.normalise(team);
        }
        let stride = (self.n / at_most.max(1)).max(1);
        let mut out = Vec::with_capacity(self.n / stride + 1);
        let mut first = 0;
        for c in self.chunks.iter() {
            let c = read(c);
            // Indices `i` of this chunk with `first + i` a multiple of `stride`.
            let start = (stride - first % stride) % stride;
            out.extend((start..c.len()).step_by(stride).map(|i| (c.get(i), c.weight[i])));
            first += c.len();
        }
        out
    }

    /// Weighted mean and covariance.
    pub(crate) fn moments(&mut self, team: &Team) -> Moments {
        let (sx, sy) = self.normalise(team);
        let heading = sy.atan2(sx);
        // Each sum over the particles in order, as zipped slices (no bounds
        // checks in the chain of adds the leader runs alone).
        let mut mean = [0.0; STATE_DIM];
        for c in self.chunks.iter() {
            let c = read(c);
            let [mx, my, mh, mv, mt, mb] = &mut mean;
            let states = c.x.iter().zip(&c.y).zip(&c.heading).zip(&c.speed).zip(&c.turn).zip(&c.bias);
            for ((((((x, y), h), v), t), b), w) in states.zip(&c.weight) {
                *mx += w * x;
                *my += w * y;
                *mh += w * wrap_angle_rad(h - heading);
                *mv += w * v;
                *mt += w * t;
                *mb += w * b;
            }
        }
        mean[2] = wrap_angle_rad(mean[2] + heading);
        // The covariance's rows in one pass over the particles per member:
        // all six for a lone leader, else rows 0-1 (11 entries) and 2-5
        // (10); each entry summed over the particles in order.
        let chunks = self.chunks.clone();
        let groups = team.map_per_member(2, move |g, groups| match (groups, g) {
            (1, _) => covariance_rows::<0, STATE_DIM>(&chunks, &mean),
            (_, 0) => covariance_rows::<0, 2>(&chunks, &mean),
            _ => covariance_rows::<2, STATE_DIM>(&chunks, &mean),
        });
        let mut upper = groups[0];
        if let Some(rest) = groups.get(1) {
            upper[2..].copy_from_slice(&rest[2..]);
        }
        let cov = Mat::from_fn(STATE_DIM, STATE_DIM, |a, b| if a <= b { upper[a][b] } else { upper[b][a] });
        Moments { mean, cov }
    }

    /// Systematic resampling (one uniform from `(seed, epoch, stage)`) with
    /// the last normalised weights, then a Gaussian kernel jitter `h L n`
    /// (regularised particle filter, `L` the Cholesky factor of the
    /// weighted covariance), drawn per chunk; with `next`, the new
    /// particles' likelihoods in the same pass.
    pub(crate) fn resample(
        &mut self,
        team: &Team,
        jitter_chol: Option<&Mat<f64>>,
        h: f64,
        seed: u64,
        words: [u64; 2],
        next: Option<NextStage>,
    ) {
        if !self.known.weights {
            self.normalise(team);
        }
        let n = self.n;
        let mut rng = keyed_stream(STREAM_KEY, seed, &[words[0], words[1], 0x7265_7361]);
        let u0: f64 = rng.random::<f64>() / n as f64;
        let picks = {
            let guards: Vec<_> = self.chunks.iter().map(|c| read(c)).collect();
            Picks::new(guards.iter().flat_map(|c| c.weight.iter().copied()), n, u0)
        };
        let l: Option<[[f64; STATE_DIM]; STATE_DIM]> =
            jitter_chol.map(|l| std::array::from_fn(|a| std::array::from_fn(|b| l[(a, b)])));
        let (old, new, chunk_size, z_m) = (self.chunks.clone(), self.spare.clone(), self.chunk_size, self.z_m);
        let (paths, deltas) = next.map_or((None, Vec::new()), |s| (Some(s.paths), s.prefetch));
        let paths_given = paths.is_some();
        // The new particles' log-weights are 0, so the maximum at `delta =
        // 0` (taken with the others) is 0 and their exponentials are 1.
        let maxima_at: Vec<f64> = std::iter::once(0.0).chain(deltas.iter().copied()).collect();
        let prefetch = maxima_at.clone();
        let picks = Arc::new(picks);
        let maxima = team.map(new.len(), move |c| {
            let mut chunk = write(&new[c]);
            let mut rng = keyed_stream(STREAM_KEY, seed, &[words[0], words[1], 0x6a69_7474, c as u64]);
            let mut from: Option<(usize, RwLockReadGuard<'_, Chunk>)> = None;
            let picked = picks.chunk(c * chunk_size, chunk.len());
            for (i, j) in picked.into_iter().enumerate() {
                if from.as_ref().is_none_or(|(k, _)| *k != j / chunk_size) {
                    from = Some((j / chunk_size, read(&old[j / chunk_size])));
                }
                let mut s = from.as_ref().map_or([0.0; STATE_DIM], |(_, g)| g.get(j % chunk_size));
                if let Some(l) = &l {
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
                            v += l[a][b] * n[b];
                        }
                        s[a] += h * v;
                    }
                }
                chunk.set(i, s);
                chunk.logw[i] = 0.0;
                chunk.exp[i] = 1.0;
                if let Some(paths) = &paths {
                    chunk.ll[i] = particle_log_likelihood(paths, [s[0], s[1], z_m], chunk.heading[i], s[5]);
                }
            }
            // Needed before the states move again (by the next stage's
            // weights or the moments): taken here, not in a pass of their own.
            chunk.trigonometry();
            if paths.is_some() { chunk.max_at(&maxima_at) } else { chunk.max_at(&maxima_at[..1]) }
        });
        std::mem::swap(&mut self.chunks, &mut self.spare);
        self.known = Known::default();
        let prefetch = if paths_given { &prefetch[..] } else { &prefetch[..1] };
        let max = max_over(&maxima, prefetch.len());
        self.known.set_max(prefetch, &max);
        // `exp(0 - max) = exp(0) = 1` when the maximum is a zero of either sign.
        if max[0] == 0.0 {
            self.known.exp_at = Some(0f64.to_bits());
        }
        self.known.trigonometry = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three equal weights; one particle no path can come from (`ll = -inf`).
    fn three() -> Particles {
        let mut chunk = Chunk::with_len(3);
        chunk.ll = vec![f64::NEG_INFINITY, -1.0, -1.0];
        let chunks = generation(vec![chunk]);
        Particles { spare: deep_copy(&chunks), chunks, z_m: 0.0, n: 3, chunk_size: 3, known: Known::default() }
    }

    #[test]
    fn a_particle_with_minus_infinite_likelihood_keeps_the_untempered_ess() {
        let team = Team::solo();
        let mut particles = three();
        // Untempered: three equal weights, ESS 3 (it was NaN: 0 * -inf).
        assert_eq!(particles.ess_with(&team, 0.0, &[]), 3.0);
        // Tempered: the -inf particle drops out, two equal weights remain.
        assert_eq!(particles.ess_with(&team, 0.5, &[]), 2.0);
        let mut absorbed = three();
        absorbed.absorb(&team, 0.0);
        assert_eq!(read(&absorbed.chunks[0]).logw, [0.0, 0.0, 0.0]);
    }

    #[test]
    fn the_resampling_picks_by_chunk_equal_the_sequential_walk() {
        let mut rng = keyed_stream(STREAM_KEY, 1, &[2]);
        for (n, chunk) in [(1, 1), (7, 3), (100, 16), (1000, 256)] {
            for case in 0..6 {
                // Weights with zeros, ties, a dominant one; case 5 has a NaN
                // and case 4 a negative one (the walk's fallback).
                let mut w: Vec<f64> = (0..n)
                    .map(|i| match case {
                        0 => 1.0 / n as f64,
                        1 if i % 3 == 1 => 0.0,
                        2 if i == n / 2 => 1e3,
                        _ => rng.random::<f64>(),
                    })
                    .collect();
                let sum: f64 = w.iter().sum();
                w.iter_mut().for_each(|v| *v /= sum);
                if case == 4 {
                    w[n - 1] = -0.1;
                }
                if case == 5 {
                    w[n / 2] = f64::NAN;
                }
                let u0 = rng.random::<f64>() / n as f64;
                let picks = Picks::new(w.iter().copied(), n, u0);
                let by_chunk: Vec<usize> =
                    (0..n.div_ceil(chunk)).flat_map(|c| picks.chunk(c * chunk, chunk.min(n - c * chunk))).collect();
                assert_eq!(by_chunk, walk(w.iter().copied(), n, u0), "n {n} case {case}");
                assert_eq!(matches!(picks, Picks::Walked(_)), case >= 4, "n {n} case {case}");
            }
        }
    }
}
