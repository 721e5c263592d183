//! Per-path truth of an overtaking manoeuvre between two walls: the
//! line-of-sight path and the two single wall bounces, each with its own
//! bearing and Doppler, so a geometric tracker can follow reflected
//! (non-line-of-sight) paths (Zoechmann et al. 2019, Sec. VI: "our approach
//! works for specular reflections as well").
//!
//! # Geometry (image method)
//! The road is straight between two walls parallel to the receiver's
//! heading, at `y = left_wall_m > 0` and `y = right_wall_m < 0` in the
//! receiver's frame (the receiver drives parallel to them, so they stay put
//! in its frame). A bounce off the wall `y = w` arrives from the transmitter's
//! mirror image `(x, 2 w - y)`; the image moves with the mirrored relative
//! velocity `(vx, -vy)`, again on a straight line at constant speed, so the
//! geometric model applies to it unchanged. The path's length is the
//! image's range, its angle of arrival the image's azimuth, its Doppler the
//! image's range rate over the wavelength, and the reflection point is where
//! the line from the receiver to the image meets the wall.
//!
//! Paths are assumed resolved (in delay) and measured separately: each
//! path's azimuth is its own strongest beam, its Doppler has its own noise
//! (drawn from `(seed, manoeuvre, run, path)`); walls have no loss or
//! blockage here.

use mmtrack_core::random::{hash_words, standard_normal, stream};
use serde::{Deserialize, Serialize};

use super::overtaking::{EpochTruth, Manoeuvre, OvertakingScenario};
use crate::SimError;
use crate::error::invalid;

/// The walls, in the receiver's frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Walls {
    /// Lateral position of the left wall, metres (> 0).
    pub left_wall_m: f64,
    /// Lateral position of the right wall, metres (< 0).
    pub right_wall_m: f64,
}

impl Default for Walls {
    /// A 11 m tunnel: the receiver 3.5 m from the right wall, 7.5 m from the
    /// left one.
    fn default() -> Self {
        Self { left_wall_m: 7.5, right_wall_m: -3.5 }
    }
}

/// Which path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathKind {
    /// The direct path.
    LineOfSight,
    /// One bounce off the left wall.
    LeftWall,
    /// One bounce off the right wall.
    RightWall,
}

impl PathKind {
    /// Name in tables (`los`, `left-wall`, `right-wall`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::LineOfSight => "los",
            Self::LeftWall => "left-wall",
            Self::RightWall => "right-wall",
        }
    }

    /// All paths, in table order.
    pub const ALL: [PathKind; 3] = [Self::LineOfSight, Self::LeftWall, Self::RightWall];
}

/// One path at one epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathEpoch {
    /// The apparent source (the transmitter or its image) and its
    /// measurements, in [`EpochTruth`]'s form.
    pub truth: EpochTruth,
    /// Velocity of the apparent source relative to the receiver, m/s.
    pub velocity_mps: [f64; 2],
    /// Where the path meets the wall, metres; `None` for line of sight.
    pub reflection_point_m: Option<[f64; 2]>,
}

/// One path of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct PathRun {
    /// Which path.
    pub kind: PathKind,
    /// Per epoch.
    pub epochs: Vec<PathEpoch>,
}

/// The three paths of realisation `run` of `manoeuvre` between `walls`.
///
/// # Errors
/// [`SimError::InvalidParameter`] when the scenario does not validate, the
/// walls are not on either side of the receiver, or the transmitter leaves
/// the space between them.
pub fn realise_paths(
    scenario: &OvertakingScenario,
    manoeuvre: &Manoeuvre,
    walls: &Walls,
    seed: u64,
    run: u64,
) -> Result<Vec<PathRun>, SimError> {
    if !(walls.left_wall_m.is_finite() && walls.left_wall_m > 0.0) {
        return Err(invalid(
            "walls.left_wall_m",
            walls.left_wall_m,
            "a positive lateral position (left of the receiver)",
        ));
    }
    if !(walls.right_wall_m.is_finite() && walls.right_wall_m < 0.0) {
        return Err(invalid(
            "walls.right_wall_m",
            walls.right_wall_m,
            "a negative lateral position (right of the receiver)",
        ));
    }
    let los = scenario.realise(manoeuvre, seed, run)?;
    if let Some(e) =
        los.epochs.iter().find(|e| e.position_m[1] >= walls.left_wall_m || e.position_m[1] <= walls.right_wall_m)
    {
        return Err(invalid(
            "walls",
            format!("transmitter at y = {:.2} m at t = {:.2} s", e.position_m[1], e.t_s),
            "walls on either side of the transmitter for the whole manoeuvre",
        ));
    }
    let lambda = scenario.wavelength_m();
    let tag = manoeuvre.name.bytes().fold(0x7061_7468_u64, |h, b| hash_words(&[h, u64::from(b)]));
    Ok(PathKind::ALL
        .iter()
        .enumerate()
        .map(|(index, &kind)| {
            let mut rng = stream(seed, &[tag, run, index as u64]);
            let wall = match kind {
                PathKind::LineOfSight => None,
                PathKind::LeftWall => Some(walls.left_wall_m),
                PathKind::RightWall => Some(walls.right_wall_m),
            };
            let epochs = los
                .epochs
                .iter()
                .map(|e| {
                    let (position_m, velocity_mps) = match wall {
                        None => (e.position_m, los.velocity_mps),
                        Some(w) => {
                            ([e.position_m[0], 2.0 * w - e.position_m[1]], [los.velocity_mps[0], -los.velocity_mps[1]])
                        }
                    };
                    let range_m = position_m[0].hypot(position_m[1]);
                    let range_rate_mps = (position_m[0] * velocity_mps[0] + position_m[1] * velocity_mps[1]) / range_m;
                    // The line receiver -> image crosses y = w at the share
                    // w / y_image of the way.
                    let reflection_point_m = wall.map(|w| {
                        let share = w / position_m[1];
                        [share * position_m[0], w]
                    });
                    let doppler_noise_hz = if index == 0 {
                        e.doppler_noise_hz
                    } else {
                        scenario.doppler_sigma_hz * standard_normal(&mut rng)
                    };
                    PathEpoch {
                        truth: EpochTruth {
                            t_s: e.t_s,
                            position_m,
                            range_m,
                            azimuth_rad: position_m[1].atan2(position_m[0]),
                            doppler_hz: range_rate_mps / lambda,
                            doppler_noise_hz,
                        },
                        velocity_mps,
                        reflection_point_m,
                    }
                })
                .collect();
            PathRun { kind, epochs }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_mirror_the_transmitter_and_path_lengths_add_up() {
        let scenario = OvertakingScenario::default();
        let full = Manoeuvre::full_overtaking();
        let walls = Walls::default();
        let paths = realise_paths(&scenario, &full, &walls, 3, 1).unwrap();
        assert_eq!(paths.len(), 3);
        let los = &paths[0];
        assert_eq!(los.epochs[0].truth, scenario.realise(&full, 3, 1).unwrap().epochs[0]);
        for path in &paths[1..] {
            for (p, direct) in path.epochs.iter().zip(&los.epochs) {
                let tx = direct.truth.position_m;
                let bounce = p.reflection_point_m.unwrap();
                // Receiver -> wall -> transmitter is as long as receiver -> image.
                let length = bounce[0].hypot(bounce[1]) + (tx[0] - bounce[0]).hypot(tx[1] - bounce[1]);
                assert!((length - p.truth.range_m).abs() < 1e-9, "{length} vs {}", p.truth.range_m);
                // Angle of incidence equals angle of reflection: the two legs
                // make opposite slopes against the wall.
                let slope_in = bounce[1] / bounce[0];
                let slope_out = (tx[1] - bounce[1]) / (tx[0] - bounce[0]);
                assert!((slope_in + slope_out).abs() < 1e-9 * slope_in.abs().max(1.0));
            }
            // The image is farther than the transmitter: a longer path.
            assert!(path.epochs[100].truth.range_m > los.epochs[100].truth.range_m);
        }
        // Path-wise Doppler noise differs from the direct path's.
        assert_ne!(paths[1].epochs[5].truth.doppler_noise_hz, los.epochs[5].truth.doppler_noise_hz);
    }

    #[test]
    fn walls_must_enclose_the_cars() {
        let scenario = OvertakingScenario::default();
        let full = Manoeuvre::full_overtaking();
        let narrow = Walls { left_wall_m: 3.0, right_wall_m: -3.5 };
        assert!(realise_paths(&scenario, &full, &narrow, 1, 0).unwrap_err().to_string().starts_with("walls"));
        let bad = Walls { left_wall_m: 7.5, right_wall_m: 1.0 };
        assert!(realise_paths(&scenario, &full, &bad, 1, 0).is_err());
    }
}
