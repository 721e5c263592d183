//! The GM-PHD baseline tracker of Mahler et al. 2017 (Sec. III-B, Table I),
//! run on the same detections as the proposed short-term tracker. Its filter
//! is `mmtrack-filter`'s labelled GM-PHD (`GmPhdFilter` with the roles below)
//! written out for this two-state model on stack arrays (`gmphd/filter.rs`),
//! with the same results number for number (checked against the generic
//! filter by the integration test `gmphd_generic`).
//!
//! # Model
//! - State `x = [d, d_dot]`: path length `d = c tau` (m, `c` =
//!   [`crate::SPEED_OF_LIGHT_M_PER_S`]) and its rate (m/s), constant velocity
//!   driven by white acceleration of standard deviation `sigma_process_mps2`
//!   ([`mmtrack_filter::ConstantVelocity`] in one axis). Table I is in metres,
//!   hence `d` rather than `tau`.
//! - Measurement `z = d + e`, `e ~ N(0, sigma_measurement_m^2)`, one per detection.
//! - The time step is the difference of the snapshots' `t_ns`, so set gaps
//!   (6.4 ms between sets of 0.717 ms snapshots) are handled as longer steps.
//! - Births (measurement-driven): each detection of the previous snapshot
//!   whose association weight `sum_i w_i(z)` stayed below
//!   `birth_association_threshold` (no existing component explained it) adds a
//!   birth term `w_b N([d_z, 0], diag(sigma_measurement^2, birth_sigma_rate^2))`
//!   moved forward to the current snapshot by the motion model. The first
//!   snapshot therefore only seeds births.
//! - Gates (the paper's "maximum delay/magnitude change" filters): a
//!   component may be updated by a detection only if the delay innovation is at
//!   most `max_delay_change_s` and the detection's power is within
//!   `max_magnitude_change_db` of the power last associated with the
//!   component's label (a birth's label starts with the power of the detection
//!   it was born from; a label without a power passes the magnitude gate).
//!
//! # Output
//! One [`MpcTrack`] per label that was extracted at `min_track_detections` or
//! more snapshots, ordered by `track_id` (= the label). Each extraction adds one
//! [`MpcDetection`] with the snapshot's `t_ns`, `set_index` and
//! `snapshot_index`, `delay_s` = the filter's estimated `d / c`, and the
//! amplitude of the detection that produced the extracted component: after
//! merging, the heaviest member's, i.e. the detection with the largest
//! association weight `w_i(z)` among the merged components. An extracted
//! component that no detection produced (possible only with a high weight
//! after a missed detection) repeats the track's last amplitude. `doppler_hz`
//! is `-f_c` times the least-squares slope of the track's `delay_s` over time
//! (eqs. (30)-(31)), `None` with fewer than two times.
//!
//! # Input
//! Snapshots are [`GmPhdSnapshot`]s (time, set/snapshot index and the
//! detections, possibly none) in strictly increasing time: an empty snapshot
//! still advances the filter (targets go undetected) and is needed to know its
//! time and indices, which is why the input is not a bare list of detection
//! vectors.
//!
//! # References
//! T. Mahler et al., "Tracking of wideband multipath components in a vehicular
//! communication scenario", IEEE TVT 66(1), 2017, Sec. III-B and Table I;
//! B.-N. Vo and W.-K. Ma, IEEE TSP 54(11), 2006 (the filter).

mod config;
mod filter;
mod small;
mod tracks;

pub use config::GmPhdConfig;

use std::collections::{BTreeMap, BTreeSet};

use mmtrack_core::{MpcDetection, MpcTrack};
use mmtrack_filter::{FilterError, Label};
use thiserror::Error;

use crate::SPEED_OF_LIGHT_M_PER_S;
use filter::{ChangeGate, Filter, Params};
use tracks::TrackBook;

/// The detections of one snapshot, with the snapshot's time and indices.
#[derive(Debug, Clone, PartialEq)]
pub struct GmPhdSnapshot {
    /// Time of the snapshot, ns; must increase strictly from one snapshot to
    /// the next, and every detection must carry it.
    pub t_ns: i64,
    /// Set of the snapshot.
    pub set_index: u64,
    /// Snapshot within its set.
    pub snapshot_index: u32,
    /// Detected MPCs (any order; may be empty).
    pub detections: Vec<MpcDetection>,
}

impl GmPhdSnapshot {
    /// The detections of `snapshot`, stamped with its time and indices.
    #[must_use]
    pub fn of(snapshot: &mmtrack_core::CirSnapshot, detections: Vec<MpcDetection>) -> Self {
        Self { t_ns: snapshot.t_ns, set_index: snapshot.set_index, snapshot_index: snapshot.snapshot_index, detections }
    }
}

/// Errors of the GM-PHD baseline.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum GmPhdError {
    /// A configuration value is out of range.
    #[error("gmphd config: {field} = {value} is invalid: expected {expected}")]
    BadConfig {
        /// The field, as written in the config file.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What was expected.
        expected: &'static str,
    },
    /// A detection holds NaN or an infinity.
    #[error("snapshot {snapshot}, detection {detection}: {field} is not finite ({value})")]
    BadDetection {
        /// Position of the snapshot in the input, 0-based.
        snapshot: usize,
        /// Position of the detection in its snapshot, 0-based.
        detection: usize,
        /// `delay_s` or `amplitude`.
        field: &'static str,
        /// The offending value (for the amplitude, the non-finite part).
        value: f64,
    },
    /// A detection's time is not its snapshot's.
    #[error("snapshot {snapshot}, detection {detection}: t_ns {t_ns} differs from the snapshot's {snapshot_t_ns}")]
    DetectionTime {
        /// Position of the snapshot in the input, 0-based.
        snapshot: usize,
        /// Position of the detection in its snapshot, 0-based.
        detection: usize,
        /// The detection's time.
        t_ns: i64,
        /// The snapshot's time.
        snapshot_t_ns: i64,
    },
    /// Snapshots are not in strictly increasing time.
    #[error("snapshot {snapshot} (t_ns {t_ns}) is not after the previous one (t_ns {previous_t_ns})")]
    TimeNotIncreasing {
        /// Position of the offending snapshot, 0-based.
        snapshot: usize,
        /// Its time.
        t_ns: i64,
        /// The previous snapshot's time.
        previous_t_ns: i64,
    },
    /// The filter failed at a snapshot (not expected for validated input).
    #[error("snapshot {snapshot}: {source}")]
    Filter {
        /// Position of the snapshot in the input, 0-based.
        snapshot: usize,
        /// The filter's error.
        source: FilterError,
    },
}

/// Tracks MPCs over `snapshots` with the GM-PHD filter (see the module docs).
///
/// # Errors
/// [`GmPhdError::BadConfig`] for an invalid config; [`GmPhdError::BadDetection`],
/// [`GmPhdError::DetectionTime`] or [`GmPhdError::TimeNotIncreasing`] naming
/// the first bad snapshot (all input is checked before tracking starts).
pub fn track_gmphd(snapshots: &[GmPhdSnapshot], config: &GmPhdConfig) -> Result<Vec<MpcTrack>, GmPhdError> {
    config.validate()?;
    check_snapshots(snapshots)?;
    let c = SPEED_OF_LIGHT_M_PER_S;
    let mut filter = Filter::new(filter_params(config));
    let (sd, sv) = (config.sigma_measurement_m, config.birth_sigma_rate_mps);
    let birth_cov = [[sd * sd, 0.0], [0.0, sv * sv]];

    // (path length m, power dB) of the previous snapshot's unexplained detections.
    let mut unexplained: Vec<(f64, f64)> = Vec::new();
    let mut last_power_db: BTreeMap<Label, f64> = BTreeMap::new();
    let mut book = TrackBook::default();
    let mut previous_t_ns: Option<i64> = None;
    for (s, snap) in snapshots.iter().enumerate() {
        let wrap = |e: FilterError| GmPhdError::Filter { snapshot: s, source: e };
        let dt_s = previous_t_ns.map_or(0.0, |p| (i128::from(snap.t_ns) - i128::from(p)) as f64 * 1e-9);
        previous_t_ns = Some(snap.t_ns);

        let birth_d_m: Vec<f64> = unexplained.iter().map(|&(d, _)| d).collect();
        let births = filter.births(&birth_d_m, &birth_cov, dt_s).map_err(wrap)?;
        let labels = filter.predict(dt_s, &births, config.birth_weight).map_err(wrap)?;
        for (label, &(_, power_db)) in labels.iter().zip(&unexplained) {
            last_power_db.insert(*label, power_db);
        }

        let zs: Vec<f64> = snap.detections.iter().map(|d| c * d.delay_s).collect();
        let powers_db: Vec<f64> = snap.detections.iter().map(MpcDetection::power_db).collect();
        let gate = ChangeGate {
            max_innovation_m: c * config.max_delay_change_s,
            max_magnitude_change_db: config.max_magnitude_change_db,
            last_power_db: &last_power_db,
            powers_db: &powers_db,
        };
        let measurement_weights = filter.update(&zs, &gate).map_err(wrap)?;
        filter.reduce().map_err(wrap)?;

        for estimate in filter.extract() {
            let source = estimate.measurement.and_then(|j| snap.detections.get(j));
            if let Some(d) = source {
                last_power_db.insert(estimate.label, d.power_db());
            }
            let detection = MpcDetection {
                t_ns: snap.t_ns,
                set_index: snap.set_index,
                snapshot_index: snap.snapshot_index,
                delay_s: estimate.mean[0] / c,
                amplitude: mmtrack_core::Complex64::new(0.0, 0.0),
            };
            book.push(estimate.label, detection, source.map(|d| d.amplitude));
        }

        unexplained = zs
            .iter()
            .zip(&powers_db)
            .zip(&measurement_weights)
            .filter(|(_, w)| **w < config.birth_association_threshold)
            .map(|((z, p), _)| (*z, *p))
            .collect();
        // Forget the powers of labels that left the mixture (bounded memory).
        let alive: BTreeSet<Label> = filter.mixture().iter().map(|comp| comp.label).collect();
        last_power_db.retain(|label, _| alive.contains(label));
    }
    Ok(book.finish(config.min_track_detections, config.carrier_hz))
}

/// Checks time order, detection times and finiteness of every detection.
fn check_snapshots(snapshots: &[GmPhdSnapshot]) -> Result<(), GmPhdError> {
    let mut previous: Option<i64> = None;
    for (snapshot, snap) in snapshots.iter().enumerate() {
        if let Some(previous_t_ns) = previous
            && snap.t_ns <= previous_t_ns
        {
            return Err(GmPhdError::TimeNotIncreasing { snapshot, t_ns: snap.t_ns, previous_t_ns });
        }
        previous = Some(snap.t_ns);
        for (detection, d) in snap.detections.iter().enumerate() {
            if d.t_ns != snap.t_ns {
                return Err(GmPhdError::DetectionTime { snapshot, detection, t_ns: d.t_ns, snapshot_t_ns: snap.t_ns });
            }
            let bad = |field, value| GmPhdError::BadDetection { snapshot, detection, field, value };
            if !d.delay_s.is_finite() {
                return Err(bad("delay_s", d.delay_s));
            }
            for part in [d.amplitude.re, d.amplitude.im] {
                if !part.is_finite() {
                    return Err(bad("amplitude", part));
                }
            }
        }
    }
    Ok(())
}

/// The parameters of Table I for [`Filter`].
fn filter_params(config: &GmPhdConfig) -> Params {
    Params {
        sigma_process_mps2: config.sigma_process_mps2,
        r_m2: config.sigma_measurement_m * config.sigma_measurement_m,
        p_survival: config.p_survival,
        p_detection: config.p_detection,
        clutter_intensity_per_m: config.clutter_intensity_per_m,
        truncation_threshold: config.truncation_threshold,
        merge_threshold: config.merge_threshold,
        max_components: config.max_components,
        extraction_threshold: config.extraction_threshold,
    }
}
