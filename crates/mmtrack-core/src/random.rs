//! Seeded random draws: the one definition of the workspace's independent
//! random streams and of its standard-normal, exponential and gamma draws.
//!
//! Every simulator, filter and benchmark draws through these functions so
//! that a seed means the same thing everywhere and seeded outputs do not
//! depend on another crate's sampling algorithm (`rand_distr`'s normal is a
//! ziggurat, not Box-Muller, and would change every seeded value).
//!
//! # Streams
//!
//! A stream is a [`Pcg64`] seeded from a SplitMix64 fold of a list of words
//! ([`splitmix_fold`]), so any draw depends only on its inputs (seed, epoch,
//! run, chunk, ...) and parallel work can draw from independent streams in
//! any order:
//!
//! - [`hash_words`]: the SplitMix64 fold from the golden-ratio start (the
//!   simulators' stateless source, also used directly as random bits);
//! - [`stream`]: `Pcg64` seeded by `hash_words(&[seed, words...])`;
//! - [`keyed_stream`]: `Pcg64` seeded by the fold of `words` from
//!   `seed ^ key` (the particle filter's streams, key `"slam_mmt"`).
//!
//! # Draws
//!
//! The uniform draws are `rng.random_range(f64::MIN_POSITIVE..1.0)` when a
//! logarithm follows (never `ln(0)`) and `rng.random::<f64>()` otherwise; the
//! order of draws of each function is part of its contract, since seeded
//! outputs depend on it:
//!
//! - [`standard_normal`]: one Box-Muller value from two uniforms (the cosine
//!   branch);
//! - [`standard_normal_pair`]: both Box-Muller values from the same two
//!   uniforms (its first value equals [`standard_normal`]'s for the same
//!   state; the second is the sine branch, so two calls of
//!   [`standard_normal`] and one of the pair give different second values);
//! - [`box_muller`]: the transform itself, for callers with their own
//!   uniforms (hash bits, test generators);
//! - [`standard_exponential`]: `-ln(u)` from one uniform;
//! - [`gamma`]: Marsaglia-Tsang with unit scale.

use std::f64::consts::TAU;

use rand::{Rng, RngExt, SeedableRng};
pub use rand_pcg::Pcg64;

/// The SplitMix64 increment (`2^64 / phi`, odd) and the start of
/// [`hash_words`].
pub const SPLITMIX_GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// Folds `words` into `state` one at a time: `state ^ word`, plus
/// [`SPLITMIX_GAMMA`], then the SplitMix64 finaliser (Stafford's mix 13).
///
/// `splitmix_fold(splitmix_fold(s, a), b) == splitmix_fold(s, a ++ b)`.
#[must_use]
pub fn splitmix_fold(state: u64, words: &[u64]) -> u64 {
    let mut h = state;
    for w in words {
        h = (h ^ w).wrapping_add(SPLITMIX_GAMMA);
        h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        h ^= h >> 31;
    }
    h
}

/// SplitMix64 of a list of words (the fold from [`SPLITMIX_GAMMA`]): a
/// stateless random source, 64 bits that depend only on `words`.
#[must_use]
pub fn hash_words(words: &[u64]) -> u64 {
    splitmix_fold(SPLITMIX_GAMMA, words)
}

/// An independent stream for `(seed, words...)`: [`Pcg64`] seeded (by
/// `seed_from_u64`) with `hash_words(&[seed, words...])`.
#[must_use]
pub fn stream(seed: u64, words: &[u64]) -> Pcg64 {
    Pcg64::seed_from_u64(splitmix_fold(hash_words(&[seed]), words))
}

/// An independent stream for `(seed, words...)` in the family `key`:
/// [`Pcg64`] seeded (by `seed_from_u64`) with `splitmix_fold(seed ^ key,
/// words)`. Different keys give unrelated streams for the same seed and
/// words.
#[must_use]
pub fn keyed_stream(key: u64, seed: u64, words: &[u64]) -> Pcg64 {
    Pcg64::seed_from_u64(splitmix_fold(seed ^ key, words))
}

/// The Box-Muller transform of two uniforms, `u1` in `(0, 1]` and `u2` in
/// `[0, 1)`: `r = sqrt(-2 ln u1)`, `(r cos(2 pi u2), r sin(2 pi u2))`, two
/// independent standard normals.
#[must_use]
#[inline]
pub fn box_muller(u1: f64, u2: f64) -> (f64, f64) {
    let r = (-2.0 * u1.ln()).sqrt();
    let (s, c) = (TAU * u2).sin_cos();
    (r * c, r * s)
}

/// One standard normal by Box-Muller: `u1 = rng.random_range(f64::MIN_POSITIVE
/// ..1.0)`, then `u2 = rng.random::<f64>()`, `sqrt(-2 ln u1) cos(2 pi u2)`.
///
/// Two draws per value; the same value as `standard_normal_pair(rng).0`.
#[inline]
pub fn standard_normal<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    let u1: f64 = rng.random_range(f64::MIN_POSITIVE..1.0);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
}

/// Two independent standard normals from the two uniforms of one
/// [`standard_normal`] (same draws, same first value): [`box_muller`] of
/// `u1 = rng.random_range(f64::MIN_POSITIVE..1.0)`, `u2 = rng.random::<f64>()`.
#[inline]
pub fn standard_normal_pair<R: Rng + ?Sized>(rng: &mut R) -> (f64, f64) {
    let u1: f64 = rng.random_range(f64::MIN_POSITIVE..1.0);
    let u2: f64 = rng.random();
    box_muller(u1, u2)
}

/// One standard exponential (mean 1): `-ln(u)` with `u =
/// rng.random_range(f64::MIN_POSITIVE..1.0)`. Divide by a rate for an
/// exponential of that rate.
#[inline]
pub fn standard_exponential<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    -rng.random_range(f64::MIN_POSITIVE..1.0).ln()
}

/// One Gamma(`shape`, scale 1) draw (mean `shape`) by Marsaglia and Tsang
/// (2000), with their boost `u^(1/shape)` for `shape < 1`. Divide by `shape`
/// for unit mean.
///
/// Draws, in order: for `shape < 1` one uniform for the boost; then per trial
/// one [`standard_normal`] and, unless the trial is refused before it, one
/// uniform `u` in `(0, 1)`. `NaN` (and no draw) for a `shape` that is not
/// positive and finite.
pub fn gamma<R: Rng + ?Sized>(rng: &mut R, shape: f64) -> f64 {
    if !(shape > 0.0 && shape.is_finite()) {
        return f64::NAN;
    }
    let boost = if shape < 1.0 { rng.random_range(f64::MIN_POSITIVE..1.0).powf(1.0 / shape) } else { 1.0 };
    let d = if shape < 1.0 { shape + 1.0 } else { shape } - 1.0 / 3.0;
    let c = 1.0 / (9.0 * d).sqrt();
    loop {
        let x = standard_normal(rng);
        let v = (1.0 + c * x).powi(3);
        if v <= 0.0 {
            continue;
        }
        let u: f64 = rng.random_range(f64::MIN_POSITIVE..1.0);
        if u.ln() < 0.5 * x * x + d - d * v + d * v.ln() {
            return d * v * boost;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mean, variance, skewness and excess kurtosis of `xs`.
    fn moments(xs: &[f64]) -> [f64; 4] {
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let central = |p: i32| xs.iter().map(|x| (x - mean).powi(p)).sum::<f64>() / n;
        let var = central(2);
        [mean, var, central(3) / var.powf(1.5), central(4) / (var * var) - 3.0]
    }

    #[test]
    fn standard_normal_has_the_moments_of_a_standard_normal() {
        let n = 200_000;
        let mut rng = stream(1, &[]);
        let xs: Vec<f64> = (0..n).map(|_| standard_normal(&mut rng)).collect();
        let [mean, var, skew, kurt] = moments(&xs);
        // Standard errors: mean 1/sqrt(n) = 0.0022, variance sqrt(2/n) =
        // 0.0032, skewness sqrt(6/n) = 0.0055, kurtosis sqrt(24/n) = 0.011;
        // about 5 sigma each.
        assert!(mean.abs() < 0.012, "{mean}");
        assert!((var - 1.0).abs() < 0.016, "{var}");
        assert!(skew.abs() < 0.03, "{skew}");
        assert!(kurt.abs() < 0.06, "{kurt}");
        let within_one = xs.iter().filter(|x| x.abs() < 1.0).count() as f64 / n as f64;
        assert!((within_one - 0.682_689).abs() < 0.006, "{within_one}");
    }

    #[test]
    fn both_values_of_the_pair_are_standard_normal_and_uncorrelated() {
        let n = 200_000;
        let mut rng = stream(2, &[]);
        let (a, b): (Vec<f64>, Vec<f64>) = (0..n).map(|_| standard_normal_pair(&mut rng)).unzip();
        for xs in [&a, &b] {
            let [mean, var, skew, kurt] = moments(xs);
            assert!(mean.abs() < 0.012, "{mean}");
            assert!((var - 1.0).abs() < 0.016, "{var}");
            assert!(skew.abs() < 0.03, "{skew}");
            assert!(kurt.abs() < 0.06, "{kurt}");
        }
        let corr = a.iter().zip(&b).map(|(x, y)| x * y).sum::<f64>() / n as f64;
        assert!(corr.abs() < 0.012, "{corr}");
    }

    #[test]
    fn the_single_value_is_the_first_of_the_pair_bit_for_bit() {
        let (mut one, mut two) = (stream(3, &[4]), stream(3, &[4]));
        for _ in 0..100_000 {
            assert_eq!(standard_normal(&mut one).to_bits(), standard_normal_pair(&mut two).0.to_bits());
        }
    }

    /// Seeded values pinned: the simulators' and filters' seeded outputs
    /// (and their tests) depend on these exact draws. The values are those
    /// of the copies this module replaced (radar `hash`, the links' `normal`,
    /// the particle filter's `stream` and `normal_pair`, the radar sensor's
    /// `gamma`), computed before they were removed.
    #[test]
    fn seeded_values_are_pinned() {
        assert_eq!(hash_words(&[]), SPLITMIX_GAMMA);
        assert_eq!(hash_words(&[1, 2, 3]), HASH_1_2_3);
        let mut rng = stream(7, &[0x6f76_6572, 1]);
        let got: Vec<u64> = (0..3).map(|_| standard_normal(&mut rng).to_bits()).collect();
        assert_eq!(got, NORMALS_7);
        let mut rng = keyed_stream(0x736c_616d_5f6d_6d74, 7, &[1, 2]);
        let (a, b) = standard_normal_pair(&mut rng);
        assert_eq!([a.to_bits(), b.to_bits()], PAIR_SLAM_7);
        let mut rng = Pcg64::seed_from_u64(5);
        // Unit mean, as the radar simulator's noise texture draws it.
        assert_eq!((gamma(&mut rng, 0.4) / 0.4).to_bits(), GAMMA_5);
        assert_eq!(standard_exponential(&mut rng).to_bits(), EXPONENTIAL_5);
    }

    const HASH_1_2_3: u64 = 0x48cf_5028_b6df_10db;
    const NORMALS_7: [u64; 3] = [0x3feb_baf1_c238_1a8d, 0x3fba_3e95_4d92_8a1a, 0x3ff1_58e3_a026_19ef];
    /// (-1.1949852364074587, -0.31782336748508044).
    const PAIR_SLAM_7: [u64; 2] = [0xbff3_1ea8_d6d9_2a73, 0xbfd4_5737_d250_3152];
    /// 0.21338938597287174.
    const GAMMA_5: u64 = 0x3fcb_5057_e908_93a1;
    /// 0.3284815097533682.
    const EXPONENTIAL_5: u64 = 0x3fd5_05d7_4f6e_cf9c;

    #[test]
    fn stream_is_hash_words_of_the_seed_and_words() {
        for (seed, words) in [(0, vec![]), (7, vec![1]), (u64::MAX, vec![3, 4, 5])] {
            let mut all = vec![seed];
            all.extend(&words);
            let mut a = stream(seed, &words);
            let mut b = Pcg64::seed_from_u64(hash_words(&all));
            assert_eq!(a.random::<u64>(), b.random::<u64>());
        }
        assert_eq!(splitmix_fold(splitmix_fold(9, &[1, 2]), &[3]), splitmix_fold(9, &[1, 2, 3]));
    }

    #[test]
    fn streams_are_reproducible_and_independent() {
        let draw = |mut rng: Pcg64| -> Vec<f64> { (0..4096).map(|_| standard_normal(&mut rng)).collect() };
        assert_eq!(draw(stream(11, &[1, 2])), draw(stream(11, &[1, 2])));
        assert_eq!(draw(keyed_stream(5, 11, &[1, 2])), draw(keyed_stream(5, 11, &[1, 2])));
        // Neighbouring seeds and words, word order, and keys: pairwise
        // sample correlation of 4096 normals within 5 standard errors (0.078).
        let streams = [
            draw(stream(11, &[1, 2])),
            draw(stream(12, &[1, 2])),
            draw(stream(11, &[1, 3])),
            draw(stream(11, &[2, 1])),
            draw(stream(11, &[1, 2, 0])),
            draw(keyed_stream(5, 11, &[1, 2])),
            draw(keyed_stream(6, 11, &[1, 2])),
        ];
        for (i, a) in streams.iter().enumerate() {
            for b in &streams[i + 1..] {
                assert_ne!(a, b);
                let corr = a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>() / a.len() as f64;
                assert!(corr.abs() < 0.078, "streams {i}: {corr}");
            }
        }
    }

    #[test]
    fn exponential_has_unit_mean_and_variance() {
        let n = 200_000;
        let mut rng = stream(13, &[]);
        let xs: Vec<f64> = (0..n).map(|_| standard_exponential(&mut rng)).collect();
        let [mean, var, _, _] = moments(&xs);
        assert!(xs.iter().all(|x| x.is_finite() && *x >= 0.0));
        // Standard errors 1/sqrt(n) = 0.0022 and sqrt(8/n) = 0.0063.
        assert!((mean - 1.0).abs() < 0.012, "{mean}");
        assert!((var - 1.0).abs() < 0.032, "{var}");
    }

    #[test]
    fn gamma_has_its_mean_and_variance() {
        let n = 100_000;
        let mut rng = stream(17, &[]);
        for shape in [0.3, 1.0, 2.5, 20.0] {
            let xs: Vec<f64> = (0..n).map(|_| gamma(&mut rng, shape)).collect();
            assert!(xs.iter().all(|x| x.is_finite() && *x >= 0.0));
            let [mean, var, _, _] = moments(&xs);
            // Mean standard error sqrt(shape / n); variance (shape) within 5 %.
            assert!((mean - shape).abs() < 5.0 * (shape / n as f64).sqrt(), "shape {shape}: mean {mean}");
            assert!((var / shape - 1.0).abs() < 0.05, "shape {shape}: variance {var}");
        }
        for shape in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(gamma(&mut rng, shape).is_nan());
        }
    }

    #[test]
    fn box_muller_of_known_uniforms() {
        let (a, b) = box_muller(1.0, 0.3);
        assert_eq!((a, b), (0.0, 0.0));
        let (a, b) = box_muller((-0.5f64).exp(), 0.25);
        assert!(a.abs() < 1e-15 && (b - 1.0).abs() < 1e-15, "{a} {b}");
    }
}
