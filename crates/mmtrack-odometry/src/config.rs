//! Parameters of the pipeline and the two presets.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use crate::OdometryError;

/// Every parameter of the pipeline. Start from [`OdometryConfig::fast_cfear`]
/// or [`OdometryConfig::cfear`]; a config file may override single fields.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OdometryConfig {
    /// Points kept per azimuth by the k-strongest filter (K).
    pub k_strongest: usize,
    /// Minimum power of a kept point, counts of 0..255 (kappa_min / z_min).
    pub min_power: u8,
    /// Nearest range considered, metres.
    pub min_range_m: f64,
    /// Farthest range considered, metres.
    pub max_range_m: f64,
    /// Surface-point radius and grid scale d_D, metres.
    pub grid_m: f64,
    /// Resampling factor f_D: downsampling cells have side `grid_m / resample_factor`.
    pub resample_factor: f64,
    /// Fewest filtered points within `grid_m` for a surface point (authors' code: 6).
    pub min_surface_neighbours: usize,
    /// Largest eigenvalue ratio of a surface point's covariance (authors' code: 1e5).
    pub max_condition_number: f64,
    /// Largest angle between the normals of associated surface points, degrees (Theta).
    pub max_normal_angle_deg: f64,
    /// Huber loss threshold delta on the point-to-line distance, metres.
    pub huber_delta_m: f64,
    /// Association rounds: associate, solve, re-associate at the new estimate, ...
    pub association_rounds: usize,
    /// Gauss-Newton iterations per association round, at most.
    pub max_iterations: usize,
    /// Keyframes in the registration submap (1: register to one reference scan).
    pub submap_keyframes: usize,
    /// A scan becomes a keyframe after this much translation from the last keyframe,
    /// metres (0: every scan, i.e. consecutive-scan registration).
    pub keyframe_min_distance_m: f64,
    /// ... or this much rotation, degrees.
    pub keyframe_min_rotation_deg: f64,
    /// Undo the motion during the sweep: each scan's bins are placed at the
    /// middle of its sweep with the previous step's velocity (once per scan,
    /// as the CFEAR authors' code does).
    pub motion_compensation: bool,
    /// Fewest correspondences for a trusted estimate; fewer flags it low-confidence.
    pub min_correspondences: usize,
}

impl OdometryConfig {
    /// Fast-CFEAR as published (Liu et al., SPEBT, Table I and Sec. III-A):
    /// K = 3, kappa_min = 55, 5..100 m, d_D = 3.5 m, f_D = 1, Theta = 30 deg,
    /// Huber delta = 0.1, registration of each scan to the previous one with a
    /// constant-velocity initial guess, no motion compensation.
    #[must_use]
    pub fn fast_cfear() -> Self {
        Self {
            k_strongest: 3,
            min_power: 55,
            min_range_m: 5.0,
            max_range_m: 100.0,
            grid_m: 3.5,
            resample_factor: 1.0,
            min_surface_neighbours: 6,
            max_condition_number: 1e5,
            max_normal_angle_deg: 30.0,
            huber_delta_m: 0.1,
            association_rounds: 1,
            max_iterations: 30,
            submap_keyframes: 1,
            keyframe_min_distance_m: 0.0,
            keyframe_min_rotation_deg: 0.0,
            motion_compensation: false,
            min_correspondences: 10,
        }
    }

    /// CFEAR-3 (Adolfsson et al., T-RO 2023) with the authors' Oxford
    /// parameters (their `oxford_cfear-3` evaluation script: k = 40,
    /// z_min = 60, resolution 3 m, keyframes 1.5 m apart) and its
    /// improvements over Fast-CFEAR: a submap of the last 3 keyframes (a new
    /// one after 1.5 m or 5 deg), per-azimuth motion compensation, and three
    /// association rounds. The point-to-line cost and Huber loss stay as in
    /// Fast-CFEAR.
    #[must_use]
    pub fn cfear() -> Self {
        Self {
            k_strongest: 40,
            min_power: 60,
            grid_m: 3.0,
            association_rounds: 3,
            submap_keyframes: 3,
            keyframe_min_distance_m: 1.5,
            keyframe_min_rotation_deg: 5.0,
            motion_compensation: true,
            ..Self::fast_cfear()
        }
    }

    /// A preset by name: `fast-cfear` or `cfear`.
    #[must_use]
    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "fast-cfear" => Some(Self::fast_cfear()),
            "cfear" => Some(Self::cfear()),
            _ => None,
        }
    }

    /// Names accepted by [`OdometryConfig::preset`].
    pub const PRESETS: &'static [&'static str] = &["fast-cfear", "cfear"];

    /// Checks every field.
    pub fn validate(&self) -> Result<(), OdometryError> {
        fn bad(field: &'static str, value: impl ToString, expected: &'static str) -> Result<(), OdometryError> {
            Err(OdometryError::BadConfig { field, value: value.to_string(), expected })
        }
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if self.k_strongest == 0 {
            return bad("k_strongest", self.k_strongest, "at least 1");
        }
        if !(self.min_range_m.is_finite() && self.min_range_m >= 0.0) {
            return bad("min_range_m", self.min_range_m, "a finite range >= 0");
        }
        if !(positive(self.max_range_m) && self.max_range_m > self.min_range_m) {
            return bad("max_range_m", self.max_range_m, "a finite range above min_range_m");
        }
        if !positive(self.grid_m) {
            return bad("grid_m", self.grid_m, "a positive length");
        }
        if !positive(self.resample_factor) {
            return bad("resample_factor", self.resample_factor, "a positive factor");
        }
        if self.min_surface_neighbours < 2 {
            return bad(
                "min_surface_neighbours",
                self.min_surface_neighbours,
                "at least 2 (a covariance needs 2 points)",
            );
        }
        if !(self.max_condition_number.is_finite() && self.max_condition_number >= 1.0) {
            return bad("max_condition_number", self.max_condition_number, "a finite ratio >= 1");
        }
        if !(self.max_normal_angle_deg.is_finite() && (0.0..=90.0).contains(&self.max_normal_angle_deg)) {
            return bad("max_normal_angle_deg", self.max_normal_angle_deg, "an angle in [0, 90] degrees");
        }
        if !positive(self.huber_delta_m) {
            return bad("huber_delta_m", self.huber_delta_m, "a positive length");
        }
        let iterations = mmtrack_core::limits::ITERATIONS;
        if self.association_rounds == 0 || !iterations.allows_count(self.association_rounds as u64) {
            return bad("association_rounds", self.association_rounds, iterations.expected);
        }
        if self.max_iterations == 0 || !iterations.allows_count(self.max_iterations as u64) {
            return bad("max_iterations", self.max_iterations, iterations.expected);
        }
        if self.submap_keyframes == 0 {
            return bad("submap_keyframes", self.submap_keyframes, "at least 1");
        }
        if !(self.keyframe_min_distance_m.is_finite() && self.keyframe_min_distance_m >= 0.0) {
            return bad("keyframe_min_distance_m", self.keyframe_min_distance_m, "a finite length >= 0");
        }
        if !(self.keyframe_min_rotation_deg.is_finite() && self.keyframe_min_rotation_deg >= 0.0) {
            return bad("keyframe_min_rotation_deg", self.keyframe_min_rotation_deg, "a finite angle >= 0");
        }
        if self.min_correspondences < 3 {
            return bad("min_correspondences", self.min_correspondences, "at least 3 (three unknowns)");
        }
        Ok(())
    }

    /// Theta in radians.
    #[must_use]
    pub fn max_normal_angle_rad(&self) -> f64 {
        self.max_normal_angle_deg * PI / 180.0
    }
}
