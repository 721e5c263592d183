//! # mmtrack-odometry
//!
//! Radar odometry on spinning-radar polar scans: Fast-CFEAR as published by
//! Liu et al. (SPEBT, 2024, Sec. III-A) and the improvements of the original
//! CFEAR (Adolfsson et al., T-RO 2023): a keyframe submap, per-azimuth motion
//! compensation and re-association rounds.
//!
//! Per scan ([`RadarOdometry::process`]):
//! 1. [`filter::k_strongest`]: the K strongest bins per azimuth above `min_power`
//!    between `min_range_m` and `max_range_m`, as points in the vehicle frame;
//! 2. grid downsampling with cells of `grid_m / resample_factor`;
//! 3. [`surface::surface_points`]: one oriented surface point (mean, normal)
//!    per cell from the filtered points within `grid_m`;
//! 4. [`register::solve`]: point-to-line registration with a Huber loss on
//!    SE(2) (eq. (9)), from a constant-velocity guess.
//!
//! Presets: [`OdometryConfig::fast_cfear`] (the paper's Table I) and
//! [`OdometryConfig::cfear`]. The results table of
//! docs/results/radar-odometry.md says how each does on the real Oxford
//! sample and on simulated drives.
//!
//! Differences from the authors' C++ code, on purpose: (a) association is done
//! with the current scan placed at the initial guess (the authors' code
//! associates in the raw scan frames, which biases steps towards zero); (b) the
//! Huber threshold is the paper's delta = 0.1 m (the code passes delta / sqrt 2
//! to Ceres); (c) Gauss-Newton with Huber weights instead of Ceres' BFGS line
//! search (same minimum, exact 3x3 steps); (d) the downsampled point of a cell
//! is its centroid, as the paper says (the code takes the point nearest the
//! cell centre); (e) `fast-cfear` registers each scan to the previous one, as
//! the paper says (the code keeps a keyframe until 1.5 m or 1.5 deg of motion);
//! (f) motion compensation places each sweep once, at its middle, with the
//! previous step's velocity, as the code does, but the first scan is placed
//! again once the second gives a velocity (the code keeps it as placed
//! without one).
//!
//! This crate is pure computation: no files, no printing. It sits in the
//! `process` step: recording -> scans -> [`RadarOdometry`] -> odometry table.

mod config;
mod error;
pub mod filter;
mod grid;
mod pipeline;
pub mod register;
pub mod surface;

pub use config::OdometryConfig;
pub use error::OdometryError;
pub use pipeline::{MIN_TRANSLATION_OBSERVABILITY, RadarOdometry, ScanOdometry};

#[cfg(test)]
pub(crate) mod real_scans {
    //! The real scans the unit tests check against.

    /// The 11 real Oxford Radar RobotCar scans of the shared sample (Barnes
    /// et al., ICRA 2020, CC BY-NC-SA 4.0), read where the integration
    /// tests read them.
    pub fn oxford() -> Option<Vec<mmtrack_core::PolarScan>> {
        use mmtrack_ingest::oxford::{self, OxfordFolder};
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/realdata/oxford-radar-tiny");
        if !dir.is_dir() {
            eprintln!("skipped: real data not found at {}", dir.display());
            return None;
        }
        let folder = OxfordFolder::open(&dir).unwrap();
        let scans: Vec<_> = folder
            .scans
            .iter()
            .map(|file| {
                let png = std::fs::read(&file.path).unwrap();
                oxford::decode_scan_png(&file.path, &png, file.t_ns, &oxford::OXFORD).unwrap().into_scan()
            })
            .collect();
        assert_eq!(scans.len(), 11);
        Some(scans)
    }
}
