//! The map `M_k` of Sec. III-A: the BS (known), confirmed virtual anchors
//! and scattering points with Gaussian spatial beliefs, and unconfirmed
//! sources that carry both hypotheses (VA and SP) until footnote 3's
//! fixed-point test decides between them (Sec. III-D, IV-A).

use faer::Mat;

use crate::small::{from3, spd_inverse, to3};

/// A Gaussian belief over a 3-D position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gauss3 {
    /// Mean, metres.
    pub mean_m: [f64; 3],
    /// Covariance, square metres.
    pub cov_m2: [[f64; 3]; 3],
}

impl Gauss3 {
    /// A point belief with isotropic covariance `var`.
    #[must_use]
    pub fn isotropic(mean_m: [f64; 3], var_m2: f64) -> Self {
        Self { mean_m, cov_m2: std::array::from_fn(|i| std::array::from_fn(|j| if i == j { var_m2 } else { 0.0 })) }
    }

    /// Root of the trace of the covariance, metres.
    #[must_use]
    pub fn spread_m(&self) -> f64 {
        (self.cov_m2[0][0] + self.cov_m2[1][1] + self.cov_m2[2][2]).max(0.0).sqrt()
    }
}

/// The status (type `T_m`) of a map source.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SourceStatus {
    /// The known base station.
    BaseStation,
    /// A confirmed virtual anchor.
    VirtualAnchor,
    /// A confirmed scattering point.
    ScatteringPoint,
    /// Not yet classified (`P(T = VA) = P(T = SP) = 1/2`).
    Unconfirmed,
}

impl SourceStatus {
    /// A short lowercase name for tables: `bs`, `va`, `sp`, `unconfirmed`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::BaseStation => "bs",
            Self::VirtualAnchor => "va",
            Self::ScatteringPoint => "sp",
            Self::Unconfirmed => "unconfirmed",
        }
    }
}

/// Information-form accumulator of one hypothesis over its sightings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Fused {
    info: [[f64; 3]; 3],
    info_mean: [f64; 3],
}

impl Fused {
    pub(crate) fn new() -> Self {
        Self { info: [[0.0; 3]; 3], info_mean: [0.0; 3] }
    }

    pub(crate) fn add(&mut self, g: &Gauss3) {
        if let Some((inv, _)) = spd_inverse(&from3(&g.cov_m2)) {
            for i in 0..3 {
                for j in 0..3 {
                    self.info[i][j] += inv[(i, j)];
                    self.info_mean[i] += inv[(i, j)] * g.mean_m[j];
                }
            }
        }
    }

    pub(crate) fn mean(&self) -> Option<[f64; 3]> {
        let (cov, _) = spd_inverse(&from3(&self.info))?;
        Some(std::array::from_fn(|i| (0..3).map(|j| cov[(i, j)] * self.info_mean[j]).sum()))
    }
}

/// The two hypotheses of an unconfirmed source.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Hypotheses {
    pub(crate) va_first: Gauss3,
    pub(crate) va_last: Gauss3,
    pub(crate) va_fused: Fused,
    pub(crate) sp_first: Option<Gauss3>,
    pub(crate) sp_last: Option<Gauss3>,
    pub(crate) sp_fused: Fused,
}

impl Hypotheses {
    pub(crate) fn new(va: Gauss3, sp: Option<Gauss3>) -> Self {
        let mut va_fused = Fused::new();
        va_fused.add(&va);
        let mut sp_fused = Fused::new();
        if let Some(s) = &sp {
            sp_fused.add(s);
        }
        Self { va_first: va, va_last: va, va_fused, sp_first: sp, sp_last: sp, sp_fused }
    }

    pub(crate) fn observe(&mut self, va: Gauss3, sp: Option<Gauss3>) {
        self.va_last = va;
        self.va_fused.add(&va);
        if let Some(s) = sp {
            if self.sp_first.is_none() {
                self.sp_first = Some(s);
            }
            self.sp_fused.add(&s);
        }
        self.sp_last = sp;
    }

    /// Footnote 3's drift statistics `(d_VA, d_SP)`: the squared distance
    /// between the hypothesis' mean at the first and the latest sighting,
    /// weighed by the sum of their covariances (`inf` for a hypothesis that
    /// no longer exists).
    pub(crate) fn drifts(&self) -> (f64, f64) {
        let d_va = drift(&self.va_first, &self.va_last);
        let d_sp = match (&self.sp_first, &self.sp_last) {
            (Some(a), Some(b)) => drift(a, b),
            _ => f64::INFINITY,
        };
        (d_va, d_sp)
    }
}

fn drift(a: &Gauss3, b: &Gauss3) -> f64 {
    let sum = Mat::from_fn(3, 3, |i, j| a.cov_m2[i][j] + b.cov_m2[i][j]);
    let Some((inv, _)) = spd_inverse(&sum) else { return f64::INFINITY };
    let d: [f64; 3] = std::array::from_fn(|i| b.mean_m[i] - a.mean_m[i]);
    (0..3).map(|i| (0..3).map(|j| d[i] * inv[(i, j)] * d[j]).sum::<f64>()).sum()
}

/// One entry of the map.
#[derive(Debug, Clone, PartialEq)]
pub struct MapSource {
    /// Stable identifier (never reused).
    pub id: u64,
    /// BS, VA, SP or unconfirmed.
    pub status: SourceStatus,
    /// Spatial belief `p_k(x_m | T_m)`: for an unconfirmed source, the latest
    /// SP hypothesis (the VA one when the path cannot come from an SP).
    pub belief: Gauss3,
    /// Epoch of the first sighting.
    pub first_seen_epoch: usize,
    /// Epoch of the latest sighting.
    pub last_seen_epoch: usize,
    /// Number of epochs with an associated path.
    pub sightings: usize,
    /// Epoch at which it was confirmed (BS: 0).
    pub confirmed_epoch: Option<usize>,
    pub(crate) hypotheses: Option<Hypotheses>,
}

impl MapSource {
    /// The latest VA hypothesis of an unconfirmed source.
    #[must_use]
    pub fn va_hypothesis(&self) -> Option<Gauss3> {
        self.hypotheses.as_ref().map(|h| h.va_last)
    }

    /// The latest SP hypothesis of an unconfirmed source.
    #[must_use]
    pub fn sp_hypothesis(&self) -> Option<Gauss3> {
        self.hypotheses.as_ref().and_then(|h| h.sp_last)
    }
}

/// Information-form fusion of two Gaussians (merging two sources); `a` when
/// a covariance is singular.
pub(crate) fn fuse(a: &Gauss3, b: &Gauss3) -> Gauss3 {
    let (Some((ia, _)), Some((ib, _))) = (spd_inverse(&from3(&a.cov_m2)), spd_inverse(&from3(&b.cov_m2))) else {
        return *a;
    };
    let info = &ia + &ib;
    let Some((cov, _)) = spd_inverse(&info) else { return *a };
    let v: [f64; 3] =
        std::array::from_fn(|i| (0..3).map(|j| ia[(i, j)] * a.mean_m[j] + ib[(i, j)] * b.mean_m[j]).sum());
    Gauss3 { mean_m: std::array::from_fn(|i| (0..3).map(|j| cov[(i, j)] * v[j]).sum()), cov_m2: to3(&cov) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fixed_point_has_no_drift_and_a_moving_one_has() {
        let still = Gauss3::isotropic([200.0, 0.0, 40.0], 0.25);
        let mut h = Hypotheses::new(still, Some(Gauss3::isotropic([100.0, 0.0, 20.0], 0.25)));
        h.observe(Gauss3::isotropic([200.3, 0.0, 40.0], 0.25), Some(Gauss3::isotropic([100.0, 5.0, 20.0], 0.25)));
        let (d_va, d_sp) = h.drifts();
        // 0.3^2 / 0.5 = 0.18 and 5^2 / 0.5 = 50.
        assert!((d_va - 0.18).abs() < 1e-9, "{d_va}");
        assert!((d_sp - 50.0).abs() < 1e-9, "{d_sp}");
        let fused = h.va_fused.mean().unwrap();
        assert!((fused[0] - 200.15).abs() < 1e-9);
    }

    #[test]
    fn fusion_of_equal_gaussians_halves_the_covariance() {
        let f = fuse(&Gauss3::isotropic([0.0; 3], 2.0), &Gauss3::isotropic([2.0, 0.0, 0.0], 2.0));
        assert!((f.mean_m[0] - 1.0).abs() < 1e-12 && (f.cov_m2[0][0] - 1.0).abs() < 1e-12);
    }
}
