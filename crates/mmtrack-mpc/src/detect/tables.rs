//! Tables precomputed once per detector so that search and subtract works on
//! the tap-domain correlation with O(1) work per found path (CLEAN's "minor
//! cycle", Hogbom 1974; Clark 1980), instead of one inverse FFT and O(U)
//! exact correlation evaluations per path.
//!
//! Notation (see [`mmtrack_core::sounder`]): `U` taps, signed bins `s_k`.
//! For a spectrum `X`, its response at a fractional delay is
//! `x(t) = (1/U) sum_k X_k exp(j 2 pi s_k t / U)`.
//!
//! - [`KernelRows`]: the correlation of the template with one windowed unit
//!   path, `kappa(t)` (spectrum `z |P|^2`), at the integer taps `|m| <= 256`
//!   minus a fractional delay on a grid of 1/256 tap, linearly interpolated
//!   between grid rows (relative error below `|kappa''| / 524288`, about
//!   5e-6). A path whose response matters farther out (a path some 70 dB
//!   above the threshold with the Kaiser window; most paths without it) is
//!   subtracted exactly over all taps with one inverse FFT.
//! - [`PeakInterpolator`]: the band-limited interpolation
//!   `c(n0 + delta) = sum_n c[n] D(n0 + delta - n)` (exact with the Dirichlet
//!   kernel `D`, spectrum of ones, summed over all taps) truncated to the
//!   `2 M + 1` taps around the coarse peak, at 1/256-tap nodes, and a
//!   quadratic in between.

use std::sync::Arc;

use mmtrack_core::Complex64;
use mmtrack_core::sounder::SounderBand;
use rustfft::{Fft, FftPlanner};

/// Grid points per tap of both tables (rows of the subtraction table, nodes
/// of the refinement).
const PHASES: usize = 256;
/// Largest `|m|` the subtraction table holds.
const TABLE_REACH_TAPS: usize = 256;
/// Taps on each side of the coarse peak used by the refinement.
const PEAK_REACH_TAPS: usize = 32;
/// Truncation of a subtraction: residues are left only where the path's
/// response is below this fraction of the detection threshold's amplitude
/// (-40 dB), far below anything the search can pick up.
const SUBTRACTION_RESIDUE: f64 = 0.01;

/// `x(n - delta)` for `n = 0..U` (index `n`, i.e. signed tap `n mod U`).
fn shifted_response(
    band: &SounderBand,
    ifft: &dyn Fft<f64>,
    spectrum: &[Complex64],
    delta_taps: f64,
) -> Vec<Complex64> {
    let taps = band.taps();
    let turn = -2.0 * std::f64::consts::PI * delta_taps / taps as f64;
    let mut buffer: Vec<Complex64> = spectrum
        .iter()
        .enumerate()
        .map(|(k, x)| x * Complex64::from_polar(1.0 / taps as f64, turn * band.signed_bin(k) as f64))
        .collect();
    ifft.process(&mut buffer);
    buffer
}

/// `|m|` of the signed tap stored at index `n`.
fn signed_distance(n: usize, taps: usize) -> usize {
    n.min(taps - n)
}

/// `kappa(m - delta)` for `|m| <= W` and `delta` on a 1/256-tap grid in
/// `[0, 1]`, and how far a path's response matters.
pub(super) struct KernelRows {
    band: SounderBand,
    kernel: Vec<Complex64>,
    ifft: Arc<dyn Fft<f64>>,
    /// `W`: the table's reach, `min(U / 2, 256)` taps.
    reach: usize,
    /// Row `p` holds `kappa(m - p / 256)` for `m = -W..=W` at `p (2W + 1) + m + W`.
    rows: Vec<Complex64>,
    /// `tail[L]`: the largest `|kappa(m - delta)| / kappa(0)` over `|m| > L`
    /// and all rows.
    tail: Vec<f64>,
}

impl KernelRows {
    pub(super) fn new(band: &SounderBand, planner: &mut FftPlanner<f64>, kernel: &[Complex64]) -> Self {
        let taps = band.taps();
        let ifft = planner.plan_fft_inverse(taps);
        let reach = TABLE_REACH_TAPS.min(taps / 2);
        let width = 2 * reach + 1;
        let mut rows = Vec::with_capacity((PHASES + 1) * width);
        let mut largest = vec![0.0_f64; taps / 2 + 1];
        for p in 0..=PHASES {
            let row = shifted_response(band, ifft.as_ref(), kernel, p as f64 / PHASES as f64);
            for (n, value) in row.iter().enumerate() {
                let m = signed_distance(n, taps);
                largest[m] = largest[m].max(value.norm());
            }
            rows.extend((-(reach as i64)..=reach as i64).map(|m| row[m.rem_euclid(taps as i64) as usize]));
        }
        // Relative to the peak kappa(0): a residue r in c reads as an amplitude r / kappa(0).
        let peak = rows[reach].norm();
        let mut tail = vec![0.0_f64; largest.len()];
        for l in (0..largest.len() - 1).rev() {
            tail[l] = tail[l + 1].max(largest[l + 1] / peak);
        }
        Self { band: *band, kernel: kernel.to_vec(), ifft, reach, rows, tail }
    }

    /// `kappa(0)`, the correlation of a unit path at its own delay.
    pub(super) fn peak(&self) -> Complex64 {
        self.rows[self.reach]
    }

    /// `kappa(m - p / 256)` for `p` in `-256..=256` (a node of the
    /// refinement) and `|m| < W`.
    fn at_node(&self, m: i64, p: i64) -> Complex64 {
        // kappa(m - p/256) = kappa((m + 1) - (p + 256)/256) for negative p.
        let (m, p) = if p < 0 { (m + 1, p + PHASES as i64) } else { (m, p) };
        let width = 2 * self.reach + 1;
        self.rows[p as usize * width + (m + self.reach as i64) as usize]
    }

    /// Half-width in taps of the subtraction of a path `amplitude_ratio`
    /// times the threshold's amplitude: beyond it its response stays below
    /// [`SUBTRACTION_RESIDUE`] of the threshold.
    pub(super) fn reach_taps(&self, amplitude_ratio: f64) -> usize {
        self.tail.partition_point(|t| t * amplitude_ratio >= SUBTRACTION_RESIDUE)
    }

    /// `c[n] -= amplitude kappa(n - x)` for `|n - x| <= reach` (circularly);
    /// returns the first tap changed and how many were.
    pub(super) fn subtract(
        &self,
        correlation: &mut [Complex64],
        x_taps: f64,
        amplitude: Complex64,
        reach: usize,
    ) -> (usize, usize) {
        let taps = self.band.taps();
        if reach > self.reach && 2 * self.reach + 1 < taps {
            // Beyond the table: exactly, over every tap.
            let response = shifted_response(&self.band, self.ifft.as_ref(), &self.kernel, x_taps);
            correlation.iter_mut().zip(&response).for_each(|(c, k)| *c -= amplitude * k);
            return (0, taps);
        }
        let width = 2 * self.reach + 1;
        let whole = x_taps.floor();
        let position = (x_taps - whole) * PHASES as f64;
        let p = (position.floor() as usize).min(PHASES - 1);
        let weight = position - p as f64;
        let (low, high) = (&self.rows[p * width..(p + 1) * width], &self.rows[(p + 1) * width..(p + 2) * width]);
        // Signed taps -reach..=reach, or every tap once when that covers the CIR.
        let (first_m, count) =
            if 2 * reach + 1 >= taps { (-((taps / 2) as i64), taps) } else { (-(reach as i64), 2 * reach + 1) };
        let first_n = (whole as i64 + first_m).rem_euclid(taps as i64) as usize;
        let mut n = first_n;
        let (a_low, a_high) = (amplitude * (1.0 - weight), amplitude * weight);
        for i in 0..count {
            let m = (first_m + i as i64 + self.reach as i64) as usize;
            correlation[n] -= a_low * low[m] + a_high * high[m];
            n += 1;
            if n == taps {
                n = 0;
            }
        }
        (first_n, count)
    }
}

/// The refined correlation peak: fractional delay from the coarse tap and
/// the correlation there.
pub(super) struct Peak {
    pub(super) delta_taps: f64,
    pub(super) value: Complex64,
}

/// Sub-tap refinement of a correlation peak from the `2 M + 1` taps around
/// it, with the truncation's bias on a lone path measured at construction
/// and removed.
pub(super) struct PeakInterpolator {
    reach: usize,
    /// Row length: `2 M + 1` padded with zeros to a multiple of [`LANES`].
    width: usize,
    /// Row `q` (node `delta = q / 256 - 1`) holds `D(delta - m)` at `m + M`,
    /// real and imaginary parts apart (the dot products vectorise).
    rows_re: Vec<f64>,
    rows_im: Vec<f64>,
    /// Per node: refined minus true delay of a lone unit path, taps.
    bias_taps: Vec<f64>,
    /// Per node: refined correlation of a lone unit path over `kappa(0)`.
    gain: Vec<Complex64>,
}

/// Independent accumulators of the refinement's dot products.
const LANES: usize = 4;

/// The taps around a coarse peak, `c[n0 - M ..= n0 + M]`, real and
/// imaginary parts apart, zero-padded like the interpolator's rows.
#[derive(Default)]
pub(super) struct Neighbourhood {
    re: Vec<f64>,
    im: Vec<f64>,
}

impl Neighbourhood {
    /// Fills from `c` around tap `n0` (circularly) for `interpolator`.
    pub(super) fn fill(&mut self, interpolator: &PeakInterpolator, correlation: &[Complex64], n0: usize) {
        let taps = correlation.len() as i64;
        let reach = interpolator.reach as i64;
        self.re.clear();
        self.im.clear();
        for m in -reach..=reach {
            let c = correlation[(n0 as i64 + m).rem_euclid(taps) as usize];
            self.re.push(c.re);
            self.im.push(c.im);
        }
        self.re.resize(interpolator.width, 0.0);
        self.im.resize(interpolator.width, 0.0);
    }

    fn centre(&self, reach: usize, offset: i64) -> f64 {
        let i = (reach as i64 + offset) as usize;
        self.re[i].hypot(self.im[i])
    }
}

impl PeakInterpolator {
    /// The refinement for `band`, calibrated on the kernel of `rows`.
    pub(super) fn new(band: &SounderBand, rows: &KernelRows) -> Self {
        let taps = band.taps();
        // The calibration reads kappa at |m| <= M + 1 from the table.
        let reach = PEAK_REACH_TAPS.min((taps - 1) / 2).min(rows.reach.saturating_sub(1)).max(1);
        let width = (2 * reach + 1).next_multiple_of(LANES);
        let nodes = 2 * PHASES + 1;
        let (mut rows_re, mut rows_im) = (vec![0.0; nodes * width], vec![0.0; nodes * width]);
        for q in 0..nodes {
            for i in 0..=2 * reach {
                let value = dirichlet(band, node_delta(q) - (i as f64 - reach as f64));
                (rows_re[q * width + i], rows_im[q * width + i]) = (value.re, value.im);
            }
        }
        let mut interpolator = Self {
            reach,
            width,
            rows_re,
            rows_im,
            bias_taps: vec![0.0; nodes],
            gain: vec![Complex64::new(1.0, 0.0); nodes],
        };
        let peak = rows.peak();
        let mut bias_taps = Vec::with_capacity(nodes);
        let mut gain = Vec::with_capacity(nodes);
        let mut lone = Neighbourhood::default();
        for q in 0..nodes {
            // The lone unit path at delta: c[m] = kappa(m - delta) around tap 0.
            let p = q as i64 - PHASES as i64;
            lone.re.clear();
            lone.im.clear();
            for m in -(reach as i64)..=reach as i64 {
                let value = rows.at_node(m, p);
                lone.re.push(value.re);
                lone.im.push(value.im);
            }
            lone.re.resize(width, 0.0);
            lone.im.resize(width, 0.0);
            let found = interpolator.search(&lone);
            bias_taps.push(found.delta_taps - node_delta(q));
            gain.push(found.value / peak);
        }
        interpolator.bias_taps = bias_taps;
        interpolator.gain = gain;
        interpolator
    }

    /// The peak of `|c(n0 + delta)|` for `delta` in `[-1, 1]` from the taps
    /// around `n0`, with the lone-path bias removed.
    pub(super) fn refine(&self, local: &Neighbourhood) -> Peak {
        let found = self.search(local);
        let position = (found.delta_taps + 1.0) * PHASES as f64;
        let q = (position.floor().max(0.0) as usize).min(self.bias_taps.len() - 2);
        let w = (position - q as f64).clamp(0.0, 1.0);
        let bias = self.bias_taps[q] * (1.0 - w) + self.bias_taps[q + 1] * w;
        let gain = self.gain[q] * (1.0 - w) + self.gain[q + 1] * w;
        Peak { delta_taps: found.delta_taps - bias, value: found.value / gain }
    }

    /// `c` at node `q`.
    fn at(&self, local: &Neighbourhood, q: usize) -> Complex64 {
        let row = q * self.width..(q + 1) * self.width;
        let (mut re, mut im) = ([0.0; LANES], [0.0; LANES]);
        let rows = self.rows_re[row.clone()].chunks_exact(LANES).zip(self.rows_im[row].chunks_exact(LANES));
        let values = local.re.chunks_exact(LANES).zip(local.im.chunks_exact(LANES));
        for ((d_re, d_im), (c_re, c_im)) in rows.zip(values) {
            for lane in 0..LANES {
                re[lane] += d_re[lane] * c_re[lane] - d_im[lane] * c_im[lane];
                im[lane] += d_re[lane] * c_im[lane] + d_im[lane] * c_re[lane];
            }
        }
        Complex64::new(re.iter().sum(), im.iter().sum())
    }

    /// The maximum of `|c|^2` from the three-tap parabola's estimate by
    /// successive quadratic fits of `c` through three nodes: 1/16 tap apart,
    /// then neighbouring nodes (1/256 tap) around the best, moved until the
    /// maximum lies within half a node of the middle one. About six
    /// evaluations of `c` per peak, each node once.
    fn search(&self, local: &Neighbourhood) -> Peak {
        let mut evaluated = Evaluated::default();
        let reach = self.reach;
        let (left, middle, right) = (local.centre(reach, -1), local.centre(reach, 0), local.centre(reach, 1));
        let curvature = left - 2.0 * middle + right;
        let start = if curvature < 0.0 { (0.5 * (left - right) / curvature).clamp(-0.5, 0.5) } else { 0.0 };
        let last = 2 * PHASES;
        let coarse = PHASES / 16;
        let mut q = ((start + 1.0) * PHASES as f64).round() as usize;
        for _ in 0..8 {
            q = q.clamp(coarse, last - coarse);
            let (t, _) = self.fit(local, &mut evaluated, q, coarse);
            q = (q as f64 + t * coarse as f64).round() as usize;
            if t.abs() < 1.0 {
                break;
            }
        }
        let mut best = (q, 0.0, Complex64::default());
        for _ in 0..8 {
            let q_fit = q.clamp(1, last - 1);
            let (t, value) = self.fit(local, &mut evaluated, q_fit, 1);
            best = (q_fit, t, value);
            q = (q_fit as f64 + t).round() as usize;
            if t.abs() <= 0.5 || q == q_fit {
                break;
            }
        }
        let (q, t, value) = best;
        Peak { delta_taps: (q as f64 + t) / PHASES as f64 - 1.0, value }
    }

    /// Fits `c(t) = c_q + b t + a t^2` through nodes `q - step`, `q`,
    /// `q + step` (`t` in steps) and returns the `t` in `[-1, 1]` where
    /// `|c(t)|^2` peaks (Newton steps; the larger end when the fit is not
    /// concave) and `c` there.
    fn fit(&self, local: &Neighbourhood, evaluated: &mut Evaluated, q: usize, step: usize) -> (f64, Complex64) {
        let mut at_node = |node: usize| match evaluated.get(node) {
            Some(value) => value,
            None => evaluated.insert(node, self.at(local, node)),
        };
        let (before, here, after) = (at_node(q - step), at_node(q), at_node(q + step));
        let b = (after - before) * 0.5;
        let a = (after + before) * 0.5 - here;
        let at = |t: f64| here + b * t + a * t * t;
        let mut t = 0.0_f64;
        for _ in 0..8 {
            let (value, slope) = (at(t), b + a * (2.0 * t));
            let j1 = 2.0 * (value.conj() * slope).re;
            let j2 = 2.0 * (slope.norm_sqr() + (value.conj() * a * 2.0).re);
            let next = if j2 < 0.0 { (t - j1 / j2).clamp(-1.0, 1.0) } else { j1.signum() };
            let moved = (next - t).abs();
            t = next;
            if moved < 1e-12 {
                break;
            }
        }
        (t, at(t))
    }
}

/// The nodes one peak search has evaluated and `c` there: successive fits
/// share nodes, and each is evaluated once (at most 48 per search: 8 fits
/// of three nodes in each of its two loops; kept on the stack).
struct Evaluated {
    count: usize,
    nodes: [usize; 48],
    values: [Complex64; 48],
}

impl Default for Evaluated {
    fn default() -> Self {
        Self { count: 0, nodes: [0; 48], values: [Complex64::default(); 48] }
    }
}

impl Evaluated {
    fn get(&self, node: usize) -> Option<Complex64> {
        self.nodes[..self.count].iter().position(|&n| n == node).map(|i| self.values[i])
    }

    fn insert(&mut self, node: usize, value: Complex64) -> Complex64 {
        self.nodes[self.count] = node;
        self.values[self.count] = value;
        self.count += 1;
        value
    }
}

/// Delay of node `q`, taps: `q / 256 - 1`.
fn node_delta(q: usize) -> f64 {
    q as f64 / PHASES as f64 - 1.0
}

/// The Dirichlet kernel `D(t) = (1/U) sum_k exp(j 2 pi s_k t / U)` in closed
/// form: `exp(j 2 pi c t / U) sin(pi t) / (U sin(pi t / U))` with `c` the
/// centre of the signed bins (`-1/2` for even `U`, `0` for odd), for
/// `|t| < U` (1 at `t = 0`).
fn dirichlet(band: &SounderBand, t: f64) -> Complex64 {
    let taps = band.taps() as f64;
    if t == 0.0 {
        return Complex64::new(1.0, 0.0);
    }
    let centre = if band.taps().is_multiple_of(2) { -0.5 } else { 0.0 };
    let pi = std::f64::consts::PI;
    let magnitude = (pi * t).sin() / (taps * (pi * t / taps).sin());
    Complex64::from_polar(magnitude, 2.0 * pi * centre * t / taps)
}
