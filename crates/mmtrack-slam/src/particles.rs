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
//! normalised weights with the mean and covariance, the resampling's picks
//! and jitter. Maxima are reduced per chunk, then across chunks. A sum over
//! the particles (the effective sample size's, the normalisation's, the
//! circular mean's, the moments', the resampling's cumulative weights) is
//! taken per chunk, in particle order inside the chunk, by the pass that
//! computes its terms ([`ExpSums`], [`ChunkMoments`]); the leader adds the
//! chunks' partial sums in chunk order ([`in_chunk_order`]), at most one add
//! per chunk and quantity. Chunks have a fixed size and their own random
//! streams whatever the team, so every result is the same, bit for bit,
//! for any thread count (not the bits of one chain of adds over all
//! particles, which a sequential loop would give).
//!
//! The systematic resampling's cumulative weights are the chunks' prefix
//! over their totals plus each chunk's running sum; the picks (a search
//! and a walk) are found per output chunk in the resampling's pass
//! ([`Picks`]).
//!
//! Values a later step needs again are kept until the particles change:
//! the maximum of `logw + delta ll` and the effective sample size per
//! exponent `delta` (the tempering search asks for the same exponent more
//! than once), the exponentials of the last pass, and the normalised
//! weights, with the per-chunk sums of each. A phase that knows which
//! exponents come next takes their maxima in the same pass, and a phase that writes values a later step would
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
    /// Running sum of `weight` within the chunk, in particle order (the
    /// last is the chunk's total): the systematic resampling's walk.
    cumulative: Vec<f64>,
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
            cumulative: v(),
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

/// Sums over one chunk's exponentials `e` (its `exp`), each in particle
/// order: the chunk's share of the effective sample size, of the
/// normalisation and of the circular mean, written by the pass that wrote
/// the exponentials; the leader adds the chunks' sums in chunk order.
#[derive(Debug, Clone, Copy)]
struct ExpSums {
    /// `sum e`.
    sum: f64,
    /// `sum e^2`.
    sum_sq: f64,
    /// `(sum e cos h, sum e sin h)` over the headings `h`, taken when the
    /// chunk's trigonometry was current.
    heading: Option<[f64; 2]>,
}

impl ExpSums {
    /// The sums of `chunk`'s exponentials; the heading's with `trigonometry`
    /// (the chunk's cosines and sines are current).
    fn of(chunk: &Chunk, trigonometry: bool) -> Self {
        let (mut sum, mut sum_sq) = (0.0, 0.0);
        for e in &chunk.exp {
            sum += e;
            sum_sq += e * e;
        }
        let heading = trigonometry.then(|| {
            let (mut c, mut s) = (0.0, 0.0);
            for ((e, cos), sin) in chunk.exp.iter().zip(&chunk.cos_heading).zip(&chunk.sin_heading) {
                c += e * cos;
                s += e * sin;
            }
            [c, s]
        });
        Self { sum, sum_sq, heading }
    }
}

/// `sum_c f(p_c)` over per-chunk partials `p_c`, added in chunk order.
///
/// Chunks are fixed (their size and random streams do not depend on the
/// team), and each partial is a sum in particle order inside its chunk, so
/// the total is the same for any thread count.
fn in_chunk_order<T>(per_chunk: &[T], f: impl Fn(&T) -> f64) -> f64 {
    per_chunk.iter().fold(0.0, |total, p| total + f(p))
}

/// Effective sample size `(sum e)^2 / sum e^2` from per-chunk sums (0 when
/// `sum e^2` is not positive).
fn ess_of(sums: &[ExpSums]) -> f64 {
    let (s, s2) = (in_chunk_order(sums, |p| p.sum), in_chunk_order(sums, |p| p.sum_sq));
    if s2 > 0.0 { s * s / s2 } else { 0.0 }
}

/// One chunk's share of the weighted moments, each sum in particle order:
/// with deviations `d_i = s_i - r` from a reference state `r` (the heading's
/// wrapped),
/// `W = sum w_i`, `m = sum w_i d_i` and the upper triangle of
/// `C = sum w_i d_i d_i^T`.
#[derive(Debug, Clone, Copy)]
struct ChunkMoments {
    /// `sum w`.
    weight: f64,
    /// Every weight is non-negative (not NaN): the resampling may search.
    searchable: bool,
    /// `sum w d`.
    first: [f64; STATE_DIM],
    /// `sum w d_a d_b`, for `b >= a` (the other entries 0).
    second: [[f64; STATE_DIM]; STATE_DIM],
}

/// Normalises `chunk`'s exponentials into its `weight` (`e / scale`, or `e`
/// as is without `scale`) and their running sum into `cumulative`, and
/// returns the chunk's share of the moments about `reference` (one pass).
/// The bounds of the loops are constants so that they unroll (with a row
/// range known only at run time a covariance pass took 3.6 times the
/// instructions: callgrind, session 18). `w d_a d_b` is taken as `(w d_a)
/// d_b`.
// Indexed loops: `a` and `b` are the covariance's entries, and the bounds
// stay constants for the unrolling.
#[allow(clippy::needless_range_loop)]
fn chunk_moments(chunk: &mut Chunk, scale: Option<f64>, reference: &[f64; STATE_DIM]) -> ChunkMoments {
    let mut m =
        ChunkMoments { weight: 0.0, searchable: true, first: [0.0; STATE_DIM], second: [[0.0; STATE_DIM]; STATE_DIM] };
    let n = chunk.len();
    let Chunk { x, y, heading, speed, turn, bias, exp, weight, cumulative, .. } = chunk;
    // Slices of one length, so the loop below has no bounds checks (a call
    // of `Chunk::get` per particle, not inlined, took a fifth of this pass).
    let (x, y, heading, speed, turn, bias) = (&x[..n], &y[..n], &heading[..n], &speed[..n], &turn[..n], &bias[..n]);
    let (exp, weight, cumulative) = (&exp[..n], &mut weight[..n], &mut cumulative[..n]);
    let r = reference;
    let mut running = 0.0;
    for i in 0..n {
        let w = match scale {
            Some(s) => exp[i] / s,
            None => exp[i],
        };
        weight[i] = w;
        running += w;
        cumulative[i] = running;
        m.searchable &= w >= 0.0;
        let d = [
            x[i] - r[0],
            y[i] - r[1],
            wrap_angle_rad(heading[i] - r[2]),
            speed[i] - r[3],
            turn[i] - r[4],
            bias[i] - r[5],
        ];
        for a in 0..STATE_DIM {
            let wd = w * d[a];
            m.first[a] += wd;
            for b in a..STATE_DIM {
                m.second[a][b] += wd * d[b];
            }
        }
    }
    m.weight = running;
    m
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
    /// The chunks' `exp` holds `exp(logw + delta ll - max)` for this `delta`
    /// (bits), with each chunk's sums of them.
    exp_at: Option<(u64, Vec<ExpSums>)>,
    /// The chunks' `cos_heading` and `sin_heading` are current.
    trigonometry: bool,
    /// The chunks' `weight` and `cumulative` hold the normalised weights.
    weights: Option<WeightTotals>,
}

/// What the resampling needs to know of the normalised weights besides
/// the chunks' `cumulative`.
#[derive(Debug, Clone, Default)]
struct WeightTotals {
    /// Each chunk's sum of its weights (its last `cumulative`).
    per_chunk: Vec<f64>,
    /// Every weight is non-negative (not NaN).
    searchable: bool,
}

impl Known {
    fn max(&self, delta: f64) -> Option<f64> {
        self.max.iter().find(|(d, _)| *d == delta.to_bits()).map(|(_, m)| *m)
    }

    fn ess(&self, delta: f64) -> Option<f64> {
        self.ess.iter().find(|(d, _)| *d == delta.to_bits()).map(|(_, e)| *e)
    }

    /// The per-chunk sums of the exponentials, when the chunks' `exp` holds
    /// those at `delta`.
    fn exp_sums(&self, delta: f64) -> Option<&[ExpSums]> {
        self.exp_at.as_ref().filter(|(d, _)| *d == delta.to_bits()).map(|(_, sums)| &sums[..])
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
    /// size, exponentials, normalised weights) stays. `sums_at_zero`: the
    /// exponentials' sums the same pass took, when they were those at 0
    /// (the heading's sums changed with the headings).
    fn states_moved(&mut self, sums_at_zero: Option<Vec<ExpSums>>) {
        let zero = 0f64.to_bits();
        self.max.retain(|(d, _)| *d == zero);
        self.ess.retain(|(d, _)| *d == zero);
        let at_zero = self.exp_at.take().is_some_and(|(d, _)| d == zero);
        self.exp_at = sums_at_zero.filter(|_| at_zero).map(|sums| (zero, sums));
        self.trigonometry = true;
    }
}

/// The picks of the systematic resampling: output particle `i` takes the
/// first `j` whose cumulative weight `cum_j` reaches `u_i = u0 + i / n`
/// (the last particle when none does).
///
/// `cum_j = P_c + L_j` for particle `j` of chunk `c`: `L_j` the running sum
/// of the chunk's weights up to and including `w_j`, in particle order
/// (the chunks' `cumulative`, written by the moments' pass), `P_c` the
/// chunks' totals before `c` added in chunk order. So the picks are the
/// same for any thread count. With non-negative weights `cum` does not
/// decrease (also across chunks: the last `cum` of chunk `c` is `P_c + T_c`,
/// the very add that gives `P_{c + 1}`), so each chunk of outputs finds its
/// first pick by a binary search (over the chunks' `P`, then in one chunk)
/// and walks to the rest, on the team; the leader adds only the chunks'
/// totals. With a negative or NaN weight the leader walks all outputs
/// ([`walk`]); either way the picks are the walk's over the same `cum`.
#[derive(Debug)]
enum Picks {
    /// `prefix[c]` is `P_c`, `prefix[chunks]` the sum of all weights.
    Search { prefix: Vec<f64>, n: usize, u0: f64, chunk_size: usize },
    /// A weight is negative or NaN: every pick, by the sequential walk.
    Walked(Vec<usize>),
}

/// `P_c` for each chunk `c` and the total: the chunks' weight totals added
/// in chunk order.
fn chunk_prefix(totals: &[f64]) -> Vec<f64> {
    let mut prefix = Vec::with_capacity(totals.len() + 1);
    let mut sum = 0.0;
    prefix.push(sum);
    for t in totals {
        sum += t;
        prefix.push(sum);
    }
    prefix
}

/// `cum_j = P_c + L_j` of every particle, in particle order.
fn cumulative_weights(chunks: &[RwLock<Chunk>], prefix: &[f64]) -> Vec<f64> {
    let mut cum = Vec::new();
    for (c, p) in chunks.iter().zip(prefix) {
        cum.extend(read(c).cumulative.iter().map(|l| p + l));
    }
    cum
}

impl Picks {
    fn new(chunks: &[RwLock<Chunk>], totals: &WeightTotals, n: usize, u0: f64, chunk_size: usize) -> Self {
        let prefix = chunk_prefix(&totals.per_chunk);
        if totals.searchable && totals.per_chunk.len() == chunks.len() {
            Self::Search { prefix, n, u0, chunk_size }
        } else {
            Self::Walked(walk(cumulative_weights(chunks, &prefix).into_iter(), n, u0))
        }
    }

    /// The picks of outputs `first..first + len`; `chunks` are the ones
    /// whose `cumulative` the picks were made for.
    fn chunk(&self, chunks: &[RwLock<Chunk>], first: usize, len: usize) -> Vec<usize> {
        match self {
            Self::Walked(picked) => picked[first..first + len].to_vec(),
            Self::Search { prefix, n, u0, chunk_size } => {
                let (n, chunk_size) = (*n, *chunk_size);
                let u = |i: usize| u0 + i as f64 / n as f64;
                let u_first = u(first);
                // The chunk of the first pick: the first whose last `cum`
                // (`P_{c + 1}`) reaches `u`; none: every pick is the last.
                let mut c = prefix[1..].partition_point(|p| *p < u_first);
                if c >= chunks.len() {
                    return vec![n - 1; len];
                }
                let mut guard = read(&chunks[c]);
                let mut k = guard.cumulative.partition_point(|l| prefix[c] + l < u_first).min(guard.len() - 1);
                let mut out = Vec::with_capacity(len);
                // Particle `j = c * chunk_size + k` advances while `j + 1 < n`
                // and `cum_j = P_c + L_k < u`.
                let (mut j, mut before) = (c * chunk_size + k, prefix[c]);
                for i in first..first + len {
                    let u = u(i);
                    while j + 1 < n && before + guard.cumulative[k] < u {
                        j += 1;
                        k += 1;
                        if k == guard.len() {
                            c += 1;
                            k = 0;
                            guard = read(&chunks[c]);
                            before = prefix[c];
                        }
                    }
                    out.push(j);
                }
                out
            }
        }
    }
}

/// The systematic resampling's sequential walk: for each output `i`, `u =
/// u0 + i / n`, `j` advances while `j + 1 < n` and `cum_j < u` (`cum` the
/// cumulative weights in particle order).
fn walk(mut cum: impl Iterator<Item = f64>, n: usize, u0: f64) -> Vec<usize> {
    let mut picked = Vec::with_capacity(n);
    let mut j = 0;
    let mut cum_j = cum.next().unwrap_or(0.0);
    for i in 0..n {
        let u = u0 + i as f64 / n as f64;
        while j + 1 < n && cum_j < u {
            j += 1;
            cum_j = cum.next().unwrap_or(0.0);
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
        let chunks = team.map_blocks(n.div_ceil(chunk_size), move |c| {
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
        let exp_at_zero = self.known.exp_sums(0.0).is_some();
        let sums = team.map_blocks(chunks.len(), move |c| {
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
            // The moments after the prediction need them (and the sums of
            // the weights' exponentials with them); taking them here saves
            // the normalisation a pass of its own.
            chunk.trigonometry();
            exp_at_zero.then(|| ExpSums::of(&chunk, true))
        });
        self.known.states_moved(sums.into_iter().collect());
    }

    /// Stores in `ll` the log-likelihood `sum_l -r^T W_l r / 2` of every
    /// particle (`-inf` for a degenerate geometry), and takes the maxima of
    /// `logw + delta ll` at the exponents `prefetch`.
    pub(crate) fn log_likelihood(&mut self, team: &Team, paths: &Arc<[PreparedPath]>, prefetch: &[f64]) {
        let (chunks, paths, z_m) = (self.chunks.clone(), paths.clone(), self.z_m);
        let deltas = prefetch.to_vec();
        let maxima = team.map_blocks(chunks.len(), move |c| {
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
        let maxima = team.map_blocks(chunks.len(), move |c| read(&chunks[c]).max_at(&[delta]));
        let m = max_over(&maxima, 1)[0];
        self.known.set_max(&[delta], &[m]);
        m
    }

    /// Effective sample size `(sum e)^2 / sum e^2` of `e = exp(logw + delta
    /// ll - max)`, `max` the maximum of the exponent (0 when it is not
    /// finite), each sum per chunk in the pass of the exponentials, then in
    /// chunk order ([`in_chunk_order`]); the same pass takes the maxima at
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
        let ess = self.known.exp_sums(delta).map_or(0.0, ess_of);
        self.known.ess.push((delta.to_bits(), ess));
        ess
    }

    /// `exp(logw + delta ll - max)` of every particle into the chunks'
    /// `exp` with their per-chunk sums (unless already there), and the
    /// maxima at `prefetch`.
    fn exponentials(&mut self, team: &Team, delta: f64, max: f64, prefetch: &[f64]) {
        let prefetch: Vec<f64> = prefetch.iter().copied().filter(|d| self.known.max(*d).is_none()).collect();
        if self.known.exp_sums(delta).is_some() && prefetch.is_empty() {
            return;
        }
        let (chunks, deltas, trigonometry) = (self.chunks.clone(), prefetch.clone(), self.known.trigonometry);
        let (maxima, sums): (Vec<_>, Vec<_>) = team
            .map_blocks(chunks.len(), move |c| {
                let mut chunk = write(&chunks[c]);
                let chunk = &mut *chunk;
                for ((e, w), l) in chunk.exp.iter_mut().zip(&chunk.logw).zip(&chunk.ll) {
                    *e = (tempered(*w, *l, delta) - max).exp();
                }
                // The heading's sums serve the moments, at `delta = 0` only.
                (chunk.max_at(&deltas), ExpSums::of(chunk, trigonometry && delta == 0.0))
            })
            .into_iter()
            .unzip();
        self.known.exp_at = Some((delta.to_bits(), sums));
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
        let (maxima, sums): (Vec<_>, Vec<_>) = team
            .map_blocks(chunks.len(), move |c| {
                let mut chunk = write(&chunks[c]);
                let chunk = &mut *chunk;
                if trigonometry {
                    chunk.trigonometry();
                }
                for ((w, e), l) in chunk.logw.iter_mut().zip(chunk.exp.iter_mut()).zip(&chunk.ll) {
                    *w = tempered(*w, *l, delta) - max;
                    *e = (*w - 0.0).exp();
                }
                (chunk.max_at(&[0.0]), ExpSums::of(chunk, true))
            })
            .into_iter()
            .unzip();
        let new_max = max_over(&maxima, 1)[0];
        self.known.weights_changed();
        self.known.trigonometry = true;
        self.known.set_max(&[0.0], &[new_max]);
        // `exp(logw - new_max)` equals `exp(logw - 0)` when `new_max` is
        // +0 or -0 (the difference is `logw` or a zero of either sign).
        if new_max == 0.0 {
            self.known.exp_at = Some((0f64.to_bits(), sums));
        }
    }

    /// The exponentials at `delta = 0` in the chunks' `exp` and their
    /// per-chunk sums with the heading's (one pass for what is not there
    /// yet: the exponentials, the headings' trigonometry, the sums).
    fn exponentials_at_zero(&mut self, team: &Team) -> Vec<ExpSums> {
        if let Some(sums) = self.known.exp_sums(0.0)
            && sums.iter().all(|s| s.heading.is_some())
        {
            return sums.to_vec();
        }
        let max = self.max_at(team, 0.0);
        let (exponentials, trigonometry) = (self.known.exp_sums(0.0).is_none(), !self.known.trigonometry);
        let chunks = self.chunks.clone();
        let sums = team.map_blocks(chunks.len(), move |c| {
            let mut chunk = write(&chunks[c]);
            let chunk = &mut *chunk;
            if exponentials {
                for (e, w) in chunk.exp.iter_mut().zip(&chunk.logw) {
                    *e = (w - max).exp();
                }
            }
            if trigonometry {
                chunk.trigonometry();
            }
            ExpSums::of(chunk, true)
        });
        self.known.exp_at = Some((0f64.to_bits(), sums.clone()));
        self.known.trigonometry = true;
        sums
    }

    /// Every `stride`-th particle (`stride = max(1, n / at_most)`, from the
    /// first) with its normalised weight, in particle order: at most about
    /// `at_most` of them, copied instead of all.
    pub(crate) fn weighted_sample(&mut self, team: &Team, at_most: usize) -> Vec<([f64; STATE_DIM], f64)> {
        if self.known.weights.is_none() {
            self.moments(team);
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

    /// Weighted mean and covariance; writes the normalised weights `w_i =
    /// e_i / sum e` (`e_i = exp(logw_i - max)`; `e_i` as is when the sum is
    /// 0 or not finite) into the chunks.
    ///
    /// The heading's mean is circular: `atan2(sum e sin h, sum e cos h)`
    /// (the sums of the pass that wrote `e`), refined by the weighted mean
    /// of the wrapped deviations from it. The rest in one pass over the
    /// particles, per chunk (the weights and [`chunk_moments`] about a
    /// reference `r`: the first particle's state, the circular mean as its
    /// heading), the chunks' sums `W`, `m`, `C` added in chunk order:
    /// `mean = r + m` and `cov = sum w (d - m)(d - m)^T = C - (2 - W) m m^T`
    /// (the shifted-data form of the weighted covariance, `d = s - r`; with
    /// `r` a particle the deviations stay of the spread's size, so the
    /// cancellation costs a few ulps of the covariance).
    pub(crate) fn moments(&mut self, team: &Team) -> Moments {
        let sums = self.exponentials_at_zero(team);
        let s = in_chunk_order(&sums, |p| p.sum);
        let [sum_cos, sum_sin] = [0, 1].map(|k| in_chunk_order(&sums, |p| p.heading.map_or(0.0, |h| h[k])));
        let heading = sum_sin.atan2(sum_cos);
        let scale = (s > 0.0 && s.is_finite()).then_some(s);
        let mut reference = self.chunks.first().map_or([0.0; STATE_DIM], |c| {
            let c = read(c);
            if c.len() > 0 { c.get(0) } else { [0.0; STATE_DIM] }
        });
        reference[2] = heading;
        let chunks = self.chunks.clone();
        let per_chunk =
            team.map_blocks(chunks.len(), move |c| chunk_moments(&mut write(&chunks[c]), scale, &reference));
        let w = in_chunk_order(&per_chunk, |p| p.weight);
        let m: [f64; STATE_DIM] = std::array::from_fn(|a| in_chunk_order(&per_chunk, |p| p.first[a]));
        let mut mean = reference;
        for (r, d) in mean.iter_mut().zip(&m) {
            *r += d;
        }
        mean[2] = wrap_angle_rad(mean[2]);
        let cov = Mat::from_fn(STATE_DIM, STATE_DIM, |a, b| {
            let (a, b) = (a.min(b), a.max(b));
            in_chunk_order(&per_chunk, |p| p.second[a][b]) - (2.0 - w) * m[a] * m[b]
        });
        self.known.weights = Some(WeightTotals {
            per_chunk: per_chunk.iter().map(|p| p.weight).collect(),
            searchable: per_chunk.iter().all(|p| p.searchable),
        });
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
        if self.known.weights.is_none() {
            self.moments(team);
        }
        let totals = self.known.weights.clone().unwrap_or_default();
        let n = self.n;
        let mut rng = keyed_stream(STREAM_KEY, seed, &[words[0], words[1], 0x7265_7361]);
        let u0: f64 = rng.random::<f64>() / n as f64;
        let picks = Picks::new(&self.chunks, &totals, n, u0, self.chunk_size);
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
        let per_chunk = team.map_blocks(new.len(), move |c| {
            let mut chunk = write(&new[c]);
            let mut rng = keyed_stream(STREAM_KEY, seed, &[words[0], words[1], 0x6a69_7474, c as u64]);
            let mut from: Option<(usize, RwLockReadGuard<'_, Chunk>)> = None;
            let picked = picks.chunk(&old, c * chunk_size, chunk.len());
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
            let maxima = if paths.is_some() { chunk.max_at(&maxima_at) } else { chunk.max_at(&maxima_at[..1]) };
            (maxima, ExpSums::of(&chunk, true))
        });
        let (maxima, sums): (Vec<_>, Vec<_>) = per_chunk.into_iter().unzip();
        std::mem::swap(&mut self.chunks, &mut self.spare);
        self.known = Known::default();
        let prefetch = if paths_given { &prefetch[..] } else { &prefetch[..1] };
        let max = max_over(&maxima, prefetch.len());
        self.known.set_max(prefetch, &max);
        // `exp(0 - max) = exp(0) = 1` when the maximum is a zero of either sign.
        if max[0] == 0.0 {
            self.known.exp_at = Some((0f64.to_bits(), sums));
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

    /// Chunks of `chunk` particles holding the weights `w` as the moments'
    /// pass leaves them (`weight`, `cumulative`), and their totals.
    fn weighted(w: &[f64], chunk: usize) -> (Generation, WeightTotals) {
        let chunks: Vec<Chunk> = w
            .chunks(chunk)
            .map(|w| {
                let mut c = Chunk::with_len(w.len());
                c.weight = w.to_vec();
                let mut running = 0.0;
                for (l, w) in c.cumulative.iter_mut().zip(w) {
                    running += w;
                    *l = running;
                }
                c
            })
            .collect();
        let totals = WeightTotals {
            per_chunk: chunks.iter().map(|c| c.cumulative.last().copied().unwrap_or(0.0)).collect(),
            searchable: w.iter().all(|w| *w >= 0.0),
        };
        (generation(chunks), totals)
    }

    #[test]
    fn the_resampling_picks_by_chunk_equal_the_walk_over_the_chunk_ordered_sums() {
        let mut rng = keyed_stream(STREAM_KEY, 1, &[2]);
        for (n, chunk) in [(1, 1), (7, 3), (100, 16), (1000, 256), (2000, 256)] {
            for case in 0..7 {
                // Weights with zeros, ties, a dominant one, all in the last
                // chunk; case 5 has a NaN and case 4 a negative one (the
                // walk's fallback).
                let mut w: Vec<f64> = (0..n)
                    .map(|i| match case {
                        0 => 1.0 / n as f64,
                        1 if i % 3 == 1 => 0.0,
                        2 if i == n / 2 => 1e3,
                        6 if i < n - n.min(chunk) => 0.0,
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
                let (chunks, totals) = weighted(&w, chunk);
                let picks = Picks::new(&chunks, &totals, n, u0, chunk);
                let by_chunk: Vec<usize> = (0..n.div_ceil(chunk))
                    .flat_map(|c| picks.chunk(&chunks, c * chunk, chunk.min(n - c * chunk)))
                    .collect();
                // The walk, written out here over `cum_j = P_c + L_j`: the
                // chunk totals added in chunk order, then each chunk's
                // running sum.
                let mut expected = Vec::with_capacity(n);
                let mut cum = Vec::with_capacity(n);
                let mut before = 0.0;
                for part in w.chunks(chunk) {
                    let mut running = 0.0;
                    for v in part {
                        running += v;
                        cum.push(before + running);
                    }
                    before += running;
                }
                let mut j = 0;
                for i in 0..n {
                    let u = u0 + i as f64 / n as f64;
                    while j + 1 < n && cum[j] < u {
                        j += 1;
                    }
                    expected.push(j);
                }
                assert_eq!(by_chunk, expected, "n {n} case {case}");
                assert_eq!(matches!(picks, Picks::Walked(_)), (4..=5).contains(&case), "n {n} case {case}");
                // Systematic: each particle is picked about `n w` times
                // (within one), so a wrong walk shows.
                if case < 4 || case == 6 {
                    for (k, wk) in w.iter().enumerate() {
                        let count = by_chunk.iter().filter(|j| **j == k).count() as f64;
                        assert!((count - n as f64 * wk).abs() <= 1.0 + 1e-6, "n {n} case {case} particle {k}");
                    }
                }
            }
        }
    }

    #[test]
    fn the_moments_equal_the_direct_weighted_sums() {
        // 1000 particles in chunks of 64, spread around a far point with
        // headings across +-pi; compared with the textbook two-pass sums.
        let team = Team::solo();
        let mut particles = Particles::draw(&team, 1000, 64, 0.0, 5, 6, |rng| {
            let s = [
                300.0 + 2.0 * standard_normal(rng),
                -40.0 + standard_normal(rng),
                std::f64::consts::PI + 0.2 * standard_normal(rng),
                10.0 + standard_normal(rng),
                0.1 * standard_normal(rng),
                5.0 + standard_normal(rng),
            ];
            (s, -rng.random::<f64>() * 3.0)
        });
        let m = particles.moments(&team);
        let states = particles.states();
        let logw: Vec<f64> = particles.chunks.iter().flat_map(|c| read(c).logw.clone()).collect();
        let top = logw.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let e: Vec<f64> = logw.iter().map(|l| (l - top).exp()).collect();
        let total: f64 = e.iter().sum();
        let w: Vec<f64> = e.iter().map(|e| e / total).collect();
        let (c, s) = states.iter().zip(&w).fold((0.0, 0.0), |(c, s), (x, w)| (c + w * x[2].cos(), s + w * x[2].sin()));
        let circular = s.atan2(c);
        let mut mean = [0.0; STATE_DIM];
        for (x, w) in states.iter().zip(&w) {
            for k in 0..STATE_DIM {
                mean[k] += w * if k == 2 { wrap_angle_rad(x[2] - circular) } else { x[k] };
            }
        }
        mean[2] = wrap_angle_rad(mean[2] + circular);
        // Tolerance: sums of 1000 terms of size 300 in another order and
        // with another reference, a few hundred ulps of 300 (6e-14 m).
        for (k, (got, want)) in m.mean.iter().zip(&mean).enumerate() {
            assert!((got - want).abs() < 1e-11, "mean {k}: {got} against {want}");
        }
        for a in 0..STATE_DIM {
            for b in 0..STATE_DIM {
                let d = |x: &[f64; STATE_DIM], k: usize| {
                    if k == 2 { wrap_angle_rad(x[2] - mean[2]) } else { x[k] - mean[k] }
                };
                let direct: f64 = states.iter().zip(&w).map(|(x, w)| w * d(x, a) * d(x, b)).sum();
                // Relative to the variances' scale (the shifted form's
                // cancellation and the order of the adds: ~1e-15 of
                // `|d|^2`, `d` a few metres from the first particle).
                let scale = (m.cov[(a, a)] * m.cov[(b, b)]).sqrt();
                assert!((m.cov[(a, b)] - direct).abs() < 1e-12 * scale.max(1e-300), "cov {a} {b}");
            }
        }
        // The weights are written normalised, summing to 1 within rounding.
        let written: f64 = particles.chunks.iter().flat_map(|c| read(c).weight.clone()).sum();
        assert!((written - 1.0).abs() < 1e-12, "{written}");
    }
}
