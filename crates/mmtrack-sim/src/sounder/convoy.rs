//! The convoy scenario's parameters (the `[convoy]` table of a sounder
//! scenario) and their checks.

use serde::Deserialize;

use super::pulse::SounderConfig;
use crate::SimError;
use crate::error::{ensure_finite, ensure_non_negative, ensure_positive, invalid};

/// Where the convoy drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum RoadKind {
    /// A tunnel: two walls at `+-half_width_m` that reflect (image method),
    /// block (visibility) and scatter diffusely.
    #[default]
    Tunnel,
    /// An open highway: no walls (nothing reflects specularly or blocks);
    /// the diffuse scatterers stand at the roadside (`+-half_width_m`:
    /// guard-rail posts, signs, vegetation).
    Highway,
}

/// The road: kind, curvature, width and wall model.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RoadConfig {
    /// Tunnel or highway.
    pub kind: RoadKind,
    /// Signed radius of the centreline arc, metres (positive: the road turns
    /// left); 0 for a straight road.
    pub radius_m: f64,
    /// Distance from the centreline to each wall (or roadside), metres.
    pub half_width_m: f64,
    /// Length of the wall polyline segments along the centreline, metres.
    pub wall_segment_m: f64,
    /// Power lost per wall bounce, dB.
    pub wall_reflection_loss_db: f64,
    /// Also trace wall-to-wall double bounces.
    pub double_bounces: bool,
}

impl Default for RoadConfig {
    fn default() -> Self {
        Self {
            kind: RoadKind::Tunnel,
            radius_m: 600.0,
            half_width_m: 7.5,
            wall_segment_m: 4.0,
            wall_reflection_loss_db: 8.0,
            double_bounces: true,
        }
    }
}

/// The two sounder cars.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ConvoyVehicles {
    /// Lateral offset of the convoy's lane from the centreline, metres (left positive).
    pub lane_m: f64,
    /// Distance along the lane from the receiver (behind) to the
    /// transmitter (ahead) at the start, metres.
    pub start_distance_m: f64,
    /// Receiver speed range `[min, max]`, km/h; the speed swings between
    /// them as a sine of period `speed_period_s` (random phase).
    pub rx_speed_kmh: [f64; 2],
    /// Transmitter speed range `[min, max]`, km/h.
    pub tx_speed_kmh: [f64; 2],
    /// Period of the speed swings, seconds.
    pub speed_period_s: f64,
}

impl Default for ConvoyVehicles {
    fn default() -> Self {
        Self {
            lane_m: -5.25,
            start_distance_m: 80.0,
            rx_speed_kmh: [42.0, 48.0],
            tx_speed_kmh: [46.0, 52.0],
            speed_period_s: 9.0,
        }
    }
}

/// One explicit traffic car.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrafficCar {
    /// Position along its lane at the start of the run, metres (the
    /// receiver starts at 0).
    pub start_s_m: f64,
    /// Lateral offset of its lane, metres (left positive).
    pub lane_m: f64,
    /// Speed, km/h; negative drives against the convoy (oncoming).
    pub speed_kmh: f64,
}

/// Other cars: reflectors that appear and disappear with the geometry.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrafficConfig {
    /// Oncoming cars per kilometre of road (Poisson, placed along the road
    /// so that they meet the convoy during the run).
    pub oncoming_per_km: f64,
    /// Lane of oncoming cars, metres.
    pub oncoming_lane_m: f64,
    /// Speed range of oncoming cars, km/h.
    pub oncoming_speed_kmh: [f64; 2],
    /// Same-direction cars per kilometre (Poisson).
    pub same_direction_per_km: f64,
    /// Lane of same-direction cars (the overtaking lane), metres.
    pub same_direction_lane_m: f64,
    /// Speed range of same-direction cars, km/h.
    pub same_direction_speed_kmh: [f64; 2],
    /// Bistatic radar cross-section of a car, dBsm.
    pub rcs_dbsm: f64,
    /// Explicit cars, added to the random ones.
    pub cars: Vec<TrafficCar>,
}

impl Default for TrafficConfig {
    fn default() -> Self {
        Self {
            oncoming_per_km: 4.0,
            oncoming_lane_m: 3.5,
            oncoming_speed_kmh: [40.0, 55.0],
            same_direction_per_km: 3.0,
            same_direction_lane_m: -1.75,
            same_direction_speed_kmh: [50.0, 65.0],
            rcs_dbsm: 10.0,
            cars: Vec::new(),
        }
    }
}

/// Diffuse components: many weak point scatterers on the walls.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DiffuseConfig {
    /// Scatterers per metre of each wall (Poisson).
    pub scatterers_per_m: f64,
    /// Power of each scatterer relative to a specular wall reflection of the
    /// same path length, dB, uniform in `[min, max]` (times a Rayleigh draw
    /// and the Lambertian factor `cos(incidence) cos(departure)`).
    pub relative_power_db: [f64; 2],
    /// List the scatterers in the truth like the specular paths (path id
    /// `1_000_000 +` the scatterer's index, with their geometry, when at
    /// least `truth_min_power_db` strong). Off by default: they are the
    /// diffuse part of the channel, which the paper's tracker is not meant
    /// to follow; but rendered as discrete points they are trackable, so a
    /// score that leaves them out counts their tracks as false.
    pub in_truth: bool,
}

impl Default for DiffuseConfig {
    fn default() -> Self {
        Self { scatterers_per_m: 0.25, relative_power_db: [-20.0, -10.0], in_truth: false }
    }
}

/// The convoy scenario (Mahler et al. 2017, Sec. II-B).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ConvoyConfig {
    /// The sounder (defaults: 5.7 GHz, 1 GHz, 512 taps, -140 dB, flat pulse).
    pub sounder: SounderConfig,
    /// Number of sets.
    pub sets: usize,
    /// Snapshots per set.
    pub snapshots_per_set: u32,
    /// Time between snapshots within a set, seconds.
    pub snapshot_interval_s: f64,
    /// Time between the starts of two sets, seconds.
    pub set_interval_s: f64,
    /// Time of the first snapshot, nanoseconds since the UNIX epoch
    /// (default [`crate::DEFAULT_START_T_NS`]).
    pub start_t_ns: i64,
    /// Delay of tap 0, seconds, fixed for the run (the sounder's clocks are
    /// synchronised, so delays are absolute and their slope is the Doppler).
    pub delay_offset_s: f64,
    /// Paths closer than this many taps to tap 0 are dropped (their pulse
    /// would wrap around the circular CIR).
    pub guard_taps: usize,
    /// The last this-many taps are kept free of paths: the noise-only region
    /// the detector estimates its floor from (paths beyond are dropped).
    pub noise_tail_taps: usize,
    /// Gain of antennas, cables and receiver on the tap scale, dB: a LOS
    /// path of length `d` has power `system_gain_db + 20 log10(lambda / (4 pi d))`.
    pub system_gain_db: f64,
    /// Paths weaker than this are rendered but not listed in the truth, dB.
    pub truth_min_power_db: f64,
    /// The road.
    pub road: RoadConfig,
    /// The two sounder cars.
    pub vehicles: ConvoyVehicles,
    /// Other traffic.
    pub traffic: TrafficConfig,
    /// Diffuse scattering.
    pub diffuse: DiffuseConfig,
}

impl Default for ConvoyConfig {
    fn default() -> Self {
        Self {
            sounder: SounderConfig { taps: 512, ..SounderConfig::default() },
            sets: 1666,
            snapshots_per_set: 6,
            snapshot_interval_s: 0.717e-3,
            set_interval_s: 10e-3,
            start_t_ns: crate::DEFAULT_START_T_NS,
            delay_offset_s: 200e-9,
            guard_taps: 4,
            noise_tail_taps: 64,
            system_gain_db: -15.0,
            truth_min_power_db: -140.0,
            road: RoadConfig::default(),
            vehicles: ConvoyVehicles::default(),
            traffic: TrafficConfig::default(),
            diffuse: DiffuseConfig::default(),
        }
    }
}

fn ensure_range(field: &str, r: [f64; 2], lo: f64) -> Result<(), SimError> {
    if r[0].is_finite() && r[1].is_finite() && r[0] >= lo && r[1] >= r[0] {
        Ok(())
    } else {
        Err(invalid(field, format!("[{}, {}]", r[0], r[1]), "a range [min, max] with min <= max, both finite"))
    }
}

fn interval_ns(field: &str, seconds: f64) -> Result<i64, SimError> {
    ensure_positive(field, seconds)?;
    let ns = (seconds * 1e9).round();
    if !(1.0..1e15).contains(&ns) {
        return Err(invalid(field, seconds, "an interval between 1 ns and 1e6 s"));
    }
    Ok(ns as i64)
}

impl ConvoyConfig {
    /// Snapshot and set intervals in nanoseconds (checked).
    pub fn intervals_ns(&self) -> Result<(i64, i64), SimError> {
        Ok((
            interval_ns("convoy.snapshot_interval_s", self.snapshot_interval_s)?,
            interval_ns("convoy.set_interval_s", self.set_interval_s)?,
        ))
    }

    /// Checks every field (names in errors start with `convoy.`).
    pub fn validate(&self) -> Result<(), SimError> {
        self.sounder.validate("convoy.sounder")?;
        if self.sets == 0 {
            return Err(invalid("convoy.sets", 0, "at least 1 set"));
        }
        if self.snapshots_per_set == 0 {
            return Err(invalid("convoy.snapshots_per_set", 0, "at least 1 snapshot per set"));
        }
        let limit = mmtrack_core::limits::SNAPSHOTS_STREAMED;
        if !limit.allows(self.sets as f64 * f64::from(self.snapshots_per_set)) {
            return Err(invalid("convoy.sets", self.sets, limit.expected));
        }
        let (snapshot_ns, set_ns) = self.intervals_ns()?;
        if i64::from(self.snapshots_per_set - 1) * snapshot_ns >= set_ns {
            return Err(invalid(
                "convoy.set_interval_s",
                self.set_interval_s,
                "longer than a set's snapshots (snapshots_per_set - 1) * snapshot_interval_s",
            ));
        }
        ensure_non_negative("convoy.delay_offset_s", self.delay_offset_s)?;
        if self.guard_taps + self.noise_tail_taps + 8 > self.sounder.taps {
            return Err(invalid(
                "convoy.noise_tail_taps",
                self.noise_tail_taps,
                "guard_taps + noise_tail_taps leaving at least 8 taps for paths",
            ));
        }
        ensure_finite("convoy.system_gain_db", self.system_gain_db)?;
        ensure_finite("convoy.truth_min_power_db", self.truth_min_power_db)?;
        let road = &self.road;
        ensure_finite("convoy.road.radius_m", road.radius_m)?;
        ensure_positive("convoy.road.half_width_m", road.half_width_m)?;
        if road.radius_m != 0.0 && road.radius_m.abs() < 4.0 * road.half_width_m {
            return Err(invalid("convoy.road.radius_m", road.radius_m, "0 (straight) or |radius| >= 4 half widths"));
        }
        ensure_positive("convoy.road.wall_segment_m", road.wall_segment_m)?;
        if road.wall_segment_m < 0.1 {
            return Err(invalid("convoy.road.wall_segment_m", road.wall_segment_m, "at least 0.1 m"));
        }
        ensure_non_negative("convoy.road.wall_reflection_loss_db", road.wall_reflection_loss_db)?;
        let v = &self.vehicles;
        let lanes_inside = |field: &str, lane: f64| {
            if lane.is_finite() && lane.abs() < road.half_width_m {
                Ok(())
            } else {
                Err(invalid(field, lane, "a lane offset inside the road (|lane| < half_width_m)"))
            }
        };
        lanes_inside("convoy.vehicles.lane_m", v.lane_m)?;
        ensure_positive("convoy.vehicles.start_distance_m", v.start_distance_m)?;
        ensure_range("convoy.vehicles.rx_speed_kmh", v.rx_speed_kmh, 0.0)?;
        ensure_range("convoy.vehicles.tx_speed_kmh", v.tx_speed_kmh, 0.0)?;
        ensure_positive("convoy.vehicles.speed_period_s", v.speed_period_s)?;
        let t = &self.traffic;
        ensure_non_negative("convoy.traffic.oncoming_per_km", t.oncoming_per_km)?;
        ensure_non_negative("convoy.traffic.same_direction_per_km", t.same_direction_per_km)?;
        lanes_inside("convoy.traffic.oncoming_lane_m", t.oncoming_lane_m)?;
        lanes_inside("convoy.traffic.same_direction_lane_m", t.same_direction_lane_m)?;
        ensure_range("convoy.traffic.oncoming_speed_kmh", t.oncoming_speed_kmh, 0.0)?;
        ensure_range("convoy.traffic.same_direction_speed_kmh", t.same_direction_speed_kmh, 0.0)?;
        ensure_finite("convoy.traffic.rcs_dbsm", t.rcs_dbsm)?;
        for (i, car) in t.cars.iter().enumerate() {
            ensure_finite(&format!("convoy.traffic.cars[{i}].start_s_m"), car.start_s_m)?;
            lanes_inside(&format!("convoy.traffic.cars[{i}].lane_m"), car.lane_m)?;
            ensure_finite(&format!("convoy.traffic.cars[{i}].speed_kmh"), car.speed_kmh)?;
        }
        ensure_non_negative("convoy.diffuse.scatterers_per_m", self.diffuse.scatterers_per_m)?;
        ensure_range("convoy.diffuse.relative_power_db", self.diffuse.relative_power_db, f64::MIN)?;
        Ok(())
    }
}
