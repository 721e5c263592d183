//! A spinning FMCW radar (Navtech CTS350-X-like) driving through a planar
//! world, rendered as polar scans with ground truth.
//!
//! # Geometry and time
//!
//! Row `a` of a sweep stamped `t` is measured at `t_a = t + a * T / N`
//! (`T` the sweep period, `N` the azimuth count) from the pose
//! `world_from_vehicle(t_a)`, so motion during the sweep distorts the scan as
//! on the real sensor. Its azimuth angle `theta_a = 2 pi a / N` counts
//! clockwise from the vehicle's forward axis seen from above (Navtech
//! encoders): the beam direction in the vehicle frame is
//! `(cos theta, -sin theta)`, so a target on the vehicle's left is at 270 deg.
//! Bin `k` is at range `k * range_resolution_m`. The ground truth of a sweep
//! is `world_from_vehicle` at its stamp (the time of its first azimuth).
//!
//! # Return model
//!
//! Powers are linear in a unit where the sensor's output is
//! `counts = round(k ln n)` for the integer amplitude `n = round(sqrt(P))`
//! (0 for `n <= 1`), `k = 8.56`, saturating at 255. That is the log
//! compression of the real CTS350-X: its low counts take only the values
//! 0, 6, 9, 12, 14, 15, 17, 18, ..., which is `round(8.56 ln n)` for
//! n = 1, 2, 3, ... (about 0.99 counts per dB of power). Strengths are given
//! in dB of this unit at 10 m (`strength_db`, about equal to the counts a
//! return peaks at when seen at 10 m).
//!
//! - Point targets (poles, clutter), radar equation:
//!   `P = P10 * G(d)^2 * (10 m / r)^4`, with the two-way Gaussian beam
//!   pattern `G(d)^2 = exp(-8 ln2 (d / w)^2)` of the azimuth offset `d`
//!   (`w = beam_width_deg`, one-way -3 dB), so a point spreads over its
//!   neighbouring rows.
//! - Extended surfaces (segments: walls, building outlines, car sides,
//!   vegetation), beam-filled footprint growing with range:
//!   `P = P10 * (f + (1 - f) cos^2 i) * (10 m / r)^3`, `i` the incidence
//!   angle, `f` the material's diffuse fraction. Surfaces are sampled by the
//!   beam's centre ray (their beam-width blur at edges is not modelled).
//! - Occlusion: along a beam, surfaces are met nearest first; each multiplies
//!   what lies behind by its transmission twice (out and back): 0 for
//!   buildings, walls and cars (opaque: nothing behind is seen), 0.5 for
//!   fences, 0.35 for vegetation. Points are thin and occlude nothing.
//! - Multipath: when the first surface is a building facade, the beam
//!   reflected specularly off it is traced to its first surface, which
//!   appears at the summed path length (a ghost behind the facade) with
//!   `multipath_loss_db` less power (`multipath_ghosts = false` in the
//!   `[sensor]` table turns them off).
//! - Speckle: each return's power is multiplied by
//!   `|sqrt(f) z_static + sqrt(1 - f) z_sweep|^2 / 2` (unit complex Gaussians
//!   from hashes of the seed, the scatterer and, for `z_sweep`, the sweep),
//!   exponential with mean 1; a static scene's consecutive sweeps correlate
//!   by `f^2` in intensity (`f = speckle_static_fraction`). A surface's
//!   scatterer is its 0.5 m patch, so a moving beam sees fresh speckle.
//! - Range profile: each return spreads as a Gaussian of
//!   `range_profile_sigma_bins` along the row.
//! - Noise floor: K-distributed, `P_noise = mean(r) * |z|^2 * g`, `z` complex
//!   Gaussian smoothed along range, `g` gamma texture of shape
//!   `noise_texture_shape`; `mean(r) = N0 (1 + (C - 1) / (1 + (r / r_c)^4))`
//!   with `N0 = noise_power_db`, `C = ground_clutter_db`,
//!   `r_c = ground_clutter_range_m`. Noise adds to the returns in power.
//!
//! # Calibration against real scans
//!
//! Measured on the 11 real Oxford Radar RobotCar scans in
//! `../shared/realdata/oxford-radar-tiny` (Barnes et al., ICRA 2020, CC
//! BY-NC-SA 4.0; sequence 2019-01-10-14-36-48) and on 40 sweeps (every 10th
//! of 400) of the default generated city along a 1 km, 10 m/s drive turning
//! at 0.01 rad/s (seed 5, default sensor: 400 x 3768 bins). The
//! `calibration_regime_matches_the_real_scans` test keeps the simulator in
//! this regime.
//!
//! | statistic | real | simulated |
//! |---|---|---|
//! | k-strongest points per scan (K = 3, >= 55 counts, 5-100 m) | 1199 | 1039 (774-1140 per scan) |
//! | bins >= 55 per azimuth in 5-100 m, median (mean) | 69 (94) | 44 (50) |
//! | share of zero counts, all bins | 0.35 | 0.35 |
//! | far floor (120-163 m): share of zero counts | 0.46 | 0.44 |
//! | far floor: share >= 12 counts | 0.23 | 0.25 |
//! | per-azimuth median count in 5-100 m, median | 9 | 9 |
//! | strongest count per azimuth (5-100 m), median (5th, 95th pct) | 99 (76, 124) | 96 (29, 115) |
//! | range of the k-strongest points, median (95th pct), m | 15.6 (71) | 17.5 (71) |
//! | bins >= 55 around a 100-130 count peak, median | 28 | 23 |
//! | range -6 dB width of strong peaks, bins | 9 | 9 (sigma 2.7 bins) |
//! | azimuth -6 dB width of strong peaks, rows | 2 | 2 (1.8 deg) |
//!
//! The k-strongest filter is nearly saturated on real urban scans (every
//! azimuth has three bins >= 55 within 5-100 m). The simulator lands close:
//! its shortfall comes from the about 10 % of azimuths that look along the
//! street, where the generated city has nothing within 100 m (the real
//! street has traffic, bends and street furniture there), and from fewer
//! strong returns per azimuth (44 vs 69 bins >= 55). The noise floor matches
//! closely, including the gaps of the log compression.
//!
//! # Speed
//!
//! See the crate docs.

mod generator;
mod grid;
mod render;
mod scenario;
mod sensor;
mod simulator;
mod trajectory;
mod world;

pub use generator::{GeneratorConfig, distance_to_path_m, generate_world};
pub use scenario::{Motion, Scenario, simulate_scenario};
pub use sensor::Sensor;
pub use simulator::{RadarSimulator, SimOptions};
pub use trajectory::{ConstantTurn, ScanLimits, Trajectory, scan_stamps};
pub use world::{Material, POLE_STRENGTH_DB, ReflectorSpec, SurfaceProperties, World, point_segment_distance_m};
