//! The streaming MPC pipeline of one TX/RX link: a set of CIR snapshots in,
//! detections, short-term tracks, optional GM-PHD tracks, long-term entries
//! and set statistics out (Mahler et al. 2017, Secs. III and V).
//!
//! One set at a time: [`MpcPipeline::push_set`] holds the CIRs of the set it
//! is given and nothing else; between sets it keeps only the previous set's
//! long-term summaries, the last time stamp and id counters. So a run of any
//! length streams in memory bounded by one set.
//!
//! Per set:
//! 1. checks: at least one snapshot, strictly increasing `t_ns` (also across
//!    sets, [`MpcError::NonMonotonicTime`]), one `set_index` and one link
//!    (TX/RX antenna) in the set, the pipeline's carrier;
//! 2. detection of each snapshot ([`Detector`]) on the current rayon pool
//!    (`ThreadPool::install` around the call chooses the threads); results
//!    are kept in snapshot order and the first error in snapshot order is
//!    returned, so the output does not depend on the thread count;
//! 3. short-term tracks ([`short_term_tracks`]) with ids running on across
//!    sets;
//! 4. optionally the GM-PHD baseline ([`track_gmphd`]) on the same detections
//!    of the set, a fresh filter per set (the paper compares the trackers
//!    within sets); its tracks are renumbered to ids running on across sets,
//!    in the filter's label order;
//! 5. long-term entries ([`LongTermTracker`]) of the set's full-lifetime
//!    tracks, related to the previous set's;
//! 6. statistics ([`MpcSetStats`]).
//!
//! Gains in the statistics are means over the set's measured (not skipped)
//! snapshots of linear gains, converted to dB (`None`, a null in the tables,
//! when every snapshot was skipped or nothing was captured: not `-inf`). The
//! detected, tracked and full-lifetime gains (and the GM-PHD baseline's tracked gain, when it runs) are
//! `sum |alpha|^2 (w^H w)` over the respective detections (`w^H w`
//! = [`Detector::pulse_energy`]), the scale of the detector's
//! `detected_gain_db`, so each compares directly with the channel gain.
//! The channel gain is the windowed CIR's energy and so includes the cross
//! terms of paths that overlap within the windowed pulse, while the captured
//! gains sum each path's own energy: where resolved paths interfere
//! destructively (two paths 1.1 ns apart after the Kaiser window, as a
//! convoy's LOS and a wall bounce) the detected gain exceeds the channel
//! gain, and the power loss of Mahler et al.'s Fig. 9 is negative.

use mmtrack_core::{CirSnapshot, MpcLongTermEntry, MpcSetStats, MpcTrack};
use rayon::prelude::*;

use crate::detect::power_db;
use crate::short_term::is_full_lifetime;
use crate::{
    Detector, GmPhdConfig, GmPhdSnapshot, LongTermTracker, MpcConfig, MpcError, SnapshotDetections, SounderPulse,
    short_term_tracks, track_gmphd,
};

/// What one set produced.
#[derive(Debug, Clone, PartialEq)]
pub struct SetOutput {
    /// The detector's output per snapshot, in snapshot order.
    pub per_snapshot: Vec<SnapshotDetections>,
    /// Short-term tracks of the proposed tracker (Sec. III-B).
    pub short_term_tracks: Vec<MpcTrack>,
    /// GM-PHD tracks on the same detections, when
    /// [`MpcConfig::run_gmphd`] is set.
    pub gmphd_tracks: Option<Vec<MpcTrack>>,
    /// Long-term entries of this set's full-lifetime short-term tracks, with
    /// their links from the previous set (Sec. V).
    pub long_term_entries: Vec<MpcLongTermEntry>,
    /// Counts and gains of the set.
    pub stats: MpcSetStats,
}

/// Detection and tracking of one link's sets, in time order (see the module
/// docs).
#[derive(Debug)]
pub struct MpcPipeline {
    config: MpcConfig,
    detector: Detector,
    carrier_hz: f64,
    long_term: LongTermTracker,
    next_short_id: u64,
    next_gmphd_id: u64,
    last_t_ns: Option<i64>,
    snapshots_seen: usize,
}

impl MpcPipeline {
    /// A pipeline for CIRs of `pulse.taps()` taps spaced `tap_spacing_s`
    /// apart at a carrier of `carrier_hz`.
    ///
    /// # Errors
    /// [`MpcError::BadConfig`] for an invalid config or carrier
    /// (the field is named), [`MpcError::GmPhd`] for an invalid GM-PHD
    /// config, [`MpcError::BadPulse`] for an unusable pulse or tap spacing.
    pub fn new(
        mut config: MpcConfig,
        pulse: &SounderPulse,
        tap_spacing_s: f64,
        carrier_hz: f64,
    ) -> Result<Self, MpcError> {
        if !(carrier_hz.is_finite() && carrier_hz > 0.0) {
            return Err(MpcError::BadConfig {
                field: "carrier_hz",
                value: carrier_hz.to_string(),
                expected: "a finite positive frequency",
            });
        }
        config.gmphd.carrier_hz = carrier_hz;
        config.validate()?;
        let detector = Detector::new(config.detection.clone(), tap_spacing_s, pulse)?;
        let long_term = LongTermTracker::new(config.long_term.clone(), carrier_hz, 0)?;
        Ok(Self {
            config,
            detector,
            carrier_hz,
            long_term,
            next_short_id: 0,
            next_gmphd_id: 0,
            last_t_ns: None,
            snapshots_seen: 0,
        })
    }

    /// The detector in use (its blocked width, pulse energy).
    #[must_use]
    pub fn detector(&self) -> &Detector {
        &self.detector
    }

    /// Processes one set: its snapshots in time order (one TX/RX link).
    /// The same as [`MpcPipeline::push_sets`] with one set.
    ///
    /// # Errors
    /// As [`MpcPipeline::push_sets`].
    pub fn push_set(&mut self, snapshots: &[CirSnapshot]) -> Result<SetOutput, MpcError> {
        let mut outputs = self.push_sets(std::slice::from_ref(&snapshots))?;
        outputs.pop().ok_or(MpcError::EmptySet { snapshots_before: self.snapshots_seen })
    }

    /// Sets per thread of the rayon pool worth handing to
    /// [`MpcPipeline::push_sets`] at once: one set (six snapshots) is too
    /// little work to share between threads.
    pub const SETS_PER_THREAD: usize = 4;

    /// Processes consecutive sets, each its snapshots in time order (one
    /// TX/RX link), with the same output as pushing them one by one: the
    /// snapshots of all the sets are detected in one parallel loop on the
    /// current rayon pool (and the GM-PHD baseline, a fresh filter per set,
    /// runs on the sets in parallel), then tracking runs set by set. A few
    /// sets at a time keep both cores busy where one set of six snapshots
    /// is too little work to share.
    ///
    /// # Errors
    /// [`MpcError::EmptySet`]; [`MpcError::NonMonotonicTime`] when a
    /// snapshot is not after the previous one (within a set or across
    /// sets); [`MpcError::BadSnapshot`] for a snapshot of another set, link
    /// or carrier, or one the detector refuses; [`MpcError::GmPhd`] if the
    /// baseline fails. The first error in snapshot order is returned;
    /// snapshot positions in errors count every snapshot pushed so far, from
    /// 0. After an error the pipeline is unchanged (no set of the call is
    /// taken).
    pub fn push_sets<S: AsRef<[CirSnapshot]> + Sync>(&mut self, sets: &[S]) -> Result<Vec<SetOutput>, MpcError> {
        // Checks in order; sets after a failing one are not processed.
        let (mut seen, mut last_t_ns) = (self.snapshots_seen, self.last_t_ns);
        let mut firsts = Vec::with_capacity(sets.len());
        let mut check = Ok(());
        for set in sets {
            let snapshots = set.as_ref();
            check = self.check_set(snapshots, seen, last_t_ns);
            if check.is_err() {
                break;
            }
            firsts.push(seen);
            seen += snapshots.len();
            last_t_ns = snapshots.last().map(|s| s.t_ns);
        }
        let checked = &sets[..firsts.len()];
        let detected = self.detect_all(checked, &firsts);
        let gmphd: Vec<Option<Result<Vec<MpcTrack>, MpcError>>> = checked
            .par_iter()
            .zip(&detected)
            .map(|(set, found)| match found {
                Ok(found) if self.config.run_gmphd => Some(self.gmphd(set.as_ref(), found)),
                _ => None,
            })
            .collect();
        // The first error in set order (within a set: detection, then GM-PHD),
        // then a failed check after the good sets.
        let mut done = Vec::with_capacity(checked.len());
        for (found, gmphd_tracks) in detected.into_iter().zip(gmphd) {
            done.push((found?, gmphd_tracks.transpose()?));
        }
        check?;
        // Nothing below fails: the pipeline changes only now.
        Ok(checked
            .iter()
            .zip(done)
            .map(|(set, (per_snapshot, gmphd_tracks))| self.track_set(set.as_ref(), per_snapshot, gmphd_tracks))
            .collect())
    }

    /// Steps 3-6 of the module docs for one detected set; advances the
    /// counters.
    fn track_set(
        &mut self,
        snapshots: &[CirSnapshot],
        per_snapshot: Vec<SnapshotDetections>,
        mut gmphd_tracks: Option<Vec<MpcTrack>>,
    ) -> SetOutput {
        let detections: Vec<Vec<_>> = per_snapshot.iter().map(|s| s.detections.clone()).collect();
        let short_term_tracks =
            short_term_tracks(&detections, self.carrier_hz, &self.config.short_term, self.next_short_id);
        self.next_short_id += short_term_tracks.len() as u64;
        let full_lifetime: Vec<MpcTrack> =
            short_term_tracks.iter().filter(|t| is_full_lifetime(t, snapshots.len())).cloned().collect();
        let long_term_entries = self.long_term.push_set(&full_lifetime);
        if let Some(tracks) = &mut gmphd_tracks {
            for (k, track) in tracks.iter_mut().enumerate() {
                track.track_id = self.next_gmphd_id + k as u64;
            }
            self.next_gmphd_id += tracks.len() as u64;
        }
        self.snapshots_seen += snapshots.len();
        self.last_t_ns = snapshots.last().map(|s| s.t_ns);

        let stats = self.stats(snapshots, &per_snapshot, &short_term_tracks, &full_lifetime, gmphd_tracks.as_deref());
        SetOutput { per_snapshot, short_term_tracks, gmphd_tracks, long_term_entries, stats }
    }

    /// Step 1 of the module docs for a set after `seen` snapshots, the last
    /// at `last_t_ns`; changes nothing.
    fn check_set(&self, snapshots: &[CirSnapshot], seen: usize, last_t_ns: Option<i64>) -> Result<(), MpcError> {
        let first = snapshots.first().ok_or(MpcError::EmptySet { snapshots_before: seen })?;
        let mut previous_t_ns = last_t_ns;
        for (position, snapshot) in snapshots.iter().enumerate() {
            let index = seen + position;
            if let Some(previous_t_ns) = previous_t_ns
                && snapshot.t_ns <= previous_t_ns
            {
                return Err(MpcError::NonMonotonicTime { snapshot: index, previous_t_ns, t_ns: snapshot.t_ns });
            }
            previous_t_ns = Some(snapshot.t_ns);
            let bad = |detail: String| MpcError::BadSnapshot {
                snapshot: index,
                set_index: snapshot.set_index,
                t_ns: snapshot.t_ns,
                detail,
            };
            if snapshot.set_index != first.set_index {
                return Err(bad(format!("set_index differs from the set's first snapshot ({})", first.set_index)));
            }
            if (snapshot.tx_antenna, snapshot.rx_antenna) != (first.tx_antenna, first.rx_antenna) {
                return Err(bad(format!(
                    "link tx{}:rx{} differs from the set's first snapshot (tx{}:rx{})",
                    snapshot.tx_antenna, snapshot.rx_antenna, first.tx_antenna, first.rx_antenna
                )));
            }
            let relative = (snapshot.carrier_hz - self.carrier_hz).abs() / self.carrier_hz;
            if relative.is_nan() || relative > 1e-9 {
                return Err(bad(format!(
                    "carrier {} Hz differs from the pipeline's {} Hz",
                    snapshot.carrier_hz, self.carrier_hz
                )));
            }
        }
        Ok(())
    }

    /// Detection of every snapshot of `sets` on the current rayon pool, in
    /// one parallel loop; per set, the detections in snapshot order or the
    /// first error in snapshot order. `firsts`: each set's first snapshot
    /// position.
    fn detect_all<S: AsRef<[CirSnapshot]> + Sync>(
        &self,
        sets: &[S],
        firsts: &[usize],
    ) -> Vec<Result<Vec<SnapshotDetections>, MpcError>> {
        let snapshots: Vec<(usize, &CirSnapshot)> = sets
            .iter()
            .zip(firsts)
            .flat_map(|(set, &first)| set.as_ref().iter().enumerate().map(move |(k, s)| (first + k, s)))
            .collect();
        let mut results = snapshots
            .par_iter()
            .map(|&(index, snapshot)| self.detector.detect(snapshot, index))
            .collect::<Vec<Result<SnapshotDetections, MpcError>>>()
            .into_iter();
        sets.iter().map(|set| results.by_ref().take(set.as_ref().len()).collect()).collect()
    }

    /// The GM-PHD baseline on one set's detections, a fresh filter, ids
    /// from 0 (renumbered by [`MpcPipeline::track_set`]).
    fn gmphd(&self, snapshots: &[CirSnapshot], found: &[SnapshotDetections]) -> Result<Vec<MpcTrack>, MpcError> {
        let input: Vec<GmPhdSnapshot> =
            snapshots.iter().zip(found).map(|(s, d)| GmPhdSnapshot::of(s, d.detections.clone())).collect();
        let config: &GmPhdConfig = &self.config.gmphd;
        track_gmphd(&input, config).map_err(|source| MpcError::GmPhd { source })
    }

    fn stats(
        &self,
        snapshots: &[CirSnapshot],
        per_snapshot: &[SnapshotDetections],
        tracks: &[MpcTrack],
        full_lifetime: &[MpcTrack],
        gmphd_tracks: Option<&[MpcTrack]>,
    ) -> MpcSetStats {
        let measured: Vec<&SnapshotDetections> = per_snapshot.iter().filter(|s| s.skipped.is_none()).collect();
        let n = measured.len();
        let energy = self.detector.pulse_energy();
        let captured = |tracks: &[MpcTrack]| -> f64 {
            tracks.iter().flat_map(|t| &t.detections).map(|d| d.amplitude.norm_sqr()).sum::<f64>() * energy
        };
        let detected: f64 =
            measured.iter().flat_map(|s| &s.detections).map(|d| d.amplitude.norm_sqr()).sum::<f64>() * energy;
        let (set_index, t_ns) = snapshots.first().map_or((0, 0), |s| (s.set_index, s.t_ns));
        MpcSetStats {
            set_index,
            t_ns,
            snapshots: count_u32(snapshots.len()),
            skipped_snapshots: count_u32(snapshots.len() - n),
            detections: count_u32(per_snapshot.iter().map(|s| s.detections.len()).sum()),
            short_term_tracks: count_u32(tracks.len()),
            full_lifetime_tracks: count_u32(full_lifetime.len()),
            noise_floor_db: mean_db(measured.iter().map(|s| from_db(s.noise_floor_db)).sum(), n),
            channel_gain_db: mean_db(measured.iter().map(|s| from_db(s.channel_gain_db)).sum(), n),
            detected_gain_db: mean_db(detected, n),
            tracked_gain_db: mean_db(captured(tracks), n),
            full_lifetime_gain_db: mean_db(captured(full_lifetime), n),
            gmphd_tracked_gain_db: gmphd_tracks.and_then(|tracks| mean_db(captured(tracks), n)),
        }
    }
}

/// The linear power of a level in dB; 0 for none.
fn from_db(db: Option<f64>) -> f64 {
    db.map_or(0.0, |db| 10f64.powf(db / 10.0))
}

/// `10 log10(sum / n)` ([`power_db`]); `None` for `n = 0` or nothing summed.
fn mean_db(sum: f64, n: usize) -> Option<f64> {
    if n == 0 { None } else { power_db(sum / n as f64) }
}

/// A count as `u32`, saturating (a set of 4 billion snapshots or detections
/// does not fit in memory anyway).
fn count_u32(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}
