//! Tables of the multipath-component pipeline beyond detections and tracks
//! (those are in `rows.rs`): GM-PHD tracks, long-term tracks, per-set
//! statistics, the simulator's true MPCs and both sounder vehicles' ground
//! truth (Mahler et al. 2017, Secs. III-VI).

use std::sync::Arc;

use arrow_array::{Array, ArrayRef, Float64Array};
use mmtrack_core::{Complex64, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth, StampedPose};

use super::rows::{MPC_TRACKS, POSES, col, f64s, i64s, nullable, u32s, u64s};
use super::{ColumnType, Columns, TableRow, TableSpec};

use ColumnType::{Float64, Int64, UInt32, UInt64};

fn opt_f64s(values: impl Iterator<Item = Option<f64>>) -> ArrayRef {
    Arc::new(values.collect::<Float64Array>())
}

fn opt_value(a: &Float64Array, i: usize) -> Option<f64> {
    a.is_valid(i).then(|| a.value(i))
}

/// A track of the GM-PHD baseline: the columns of `mpc_tracks`, in its own
/// table so both trackers' results sit side by side.
#[derive(Debug, Clone, PartialEq)]
pub struct GmPhdTrack(pub MpcTrack);

/// `mpc_tracks_gmphd`: tracks of the GM-PHD baseline.
pub const MPC_TRACKS_GMPHD: TableSpec = TableSpec {
    name: "mpc_tracks_gmphd",
    description: "One associated detection of a GM-PHD baseline track (Mahler et al. 2017, Table I) per row; the \
columns of mpc_tracks; rows of a track are consecutive and in time order.",
    columns: MPC_TRACKS.columns,
};

impl TableRow for GmPhdTrack {
    const SPEC: &'static TableSpec = &MPC_TRACKS_GMPHD;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        let tracks: Vec<MpcTrack> = rows.iter().map(|r| r.0.clone()).collect();
        MpcTrack::to_columns(&tracks)
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        Ok(MpcTrack::from_columns(c)?.into_iter().map(GmPhdTrack).collect())
    }
}

/// `mpc_long_term`: long-term tracks across sets.
pub const MPC_LONG_TERM: TableSpec = TableSpec {
    name: "mpc_long_term",
    description: "One full-lifetime short-term track as an entry of a long-term track per row (Mahler et al. 2017, \
Sec. V), ordered by set then long-term track; a long-term track is the rows sharing long_track_id.",
    columns: &[
        col("long_track_id", UInt64, "", "long-term track identifier, unique within the run"),
        col("set_index", UInt64, "", "sounder set of this entry"),
        col("t_ns", Int64, "ns", "mean time of the short-term track's detections"),
        col("short_track_id", UInt64, "", "the full-lifetime short-term track (track_id in mpc_tracks)"),
        col("mean_delay_s", Float64, "s", "mean delay over the set (tau-bar, eq. 33)"),
        col("mean_power_db", Float64, "dB", "10 log10 of the mean linear power over the set (a-bar, eq. 33)"),
        col("doppler_hz", Float64, "Hz", "Doppler of the short-term track (nu, eq. 31)"),
        nullable(
            "link_error_s",
            Float64,
            "s",
            "larger two-way delay prediction error of the link from the previous set (eqs. 41-42); null for the first entry",
        ),
        nullable(
            "chi_class_s",
            Float64,
            "s",
            "smallest confidence class chi holding the link (eq. 40); null for the first entry",
        ),
    ],
};

impl TableRow for MpcLongTermEntry {
    const SPEC: &'static TableSpec = &MPC_LONG_TERM;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![
            u64s(rows.iter().map(|r| r.long_track_id)),
            u64s(rows.iter().map(|r| r.set_index)),
            i64s(rows.iter().map(|r| r.t_ns)),
            u64s(rows.iter().map(|r| r.short_track_id)),
            f64s(rows.iter().map(|r| r.mean_delay_s)),
            f64s(rows.iter().map(|r| r.mean_power_db)),
            f64s(rows.iter().map(|r| r.doppler_hz)),
            opt_f64s(rows.iter().map(|r| r.link_error_s)),
            opt_f64s(rows.iter().map(|r| r.chi_class_s)),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (long, set, t, short) =
            (c.u64("long_track_id")?, c.u64("set_index")?, c.i64("t_ns")?, c.u64("short_track_id")?);
        let (delay, power, doppler) = (c.f64("mean_delay_s")?, c.f64("mean_power_db")?, c.f64("doppler_hz")?);
        let (link, chi) = (c.f64("link_error_s")?, c.f64("chi_class_s")?);
        Ok((0..c.num_rows())
            .map(|i| MpcLongTermEntry {
                long_track_id: long.value(i),
                set_index: set.value(i),
                t_ns: t.value(i),
                short_track_id: short.value(i),
                mean_delay_s: delay.value(i),
                mean_power_db: power.value(i),
                doppler_hz: doppler.value(i),
                link_error_s: opt_value(link, i),
                chi_class_s: opt_value(chi, i),
            })
            .collect())
    }
}

/// `mpc_sets`: per-set statistics of detection and tracking.
pub const MPC_SETS: TableSpec = TableSpec {
    name: "mpc_sets",
    description: "One sounder set per row, in set order: counts of detections and tracks and the channel gains \
(Mahler et al. 2017, Figs. 8-9); gains are means over the set's snapshots of sum |a|^2 in dB, -inf when nothing \
was captured.",
    columns: &[
        col("set_index", UInt64, "", "the set"),
        col("t_ns", Int64, "ns", "time of its first snapshot"),
        col("snapshots", UInt32, "", "snapshots in the set"),
        col("skipped_snapshots", UInt32, "", "snapshots skipped (e.g. all-zero CIRs)"),
        col("detections", UInt32, "", "detections over the set"),
        col("short_term_tracks", UInt32, "", "short-term tracks of the set"),
        col("full_lifetime_tracks", UInt32, "", "short-term tracks spanning the whole set"),
        col("noise_floor_db", Float64, "dB", "mean noise floor of the set's snapshots"),
        col("channel_gain_db", Float64, "dB", "channel gain after thresholding and windowing"),
        col("detected_gain_db", Float64, "dB", "gain captured by the detections"),
        col("tracked_gain_db", Float64, "dB", "gain captured by the short-term tracks"),
        col("full_lifetime_gain_db", Float64, "dB", "gain captured by the full-lifetime tracks"),
    ],
};

impl TableRow for MpcSetStats {
    const SPEC: &'static TableSpec = &MPC_SETS;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![
            u64s(rows.iter().map(|r| r.set_index)),
            i64s(rows.iter().map(|r| r.t_ns)),
            u32s(rows.iter().map(|r| r.snapshots)),
            u32s(rows.iter().map(|r| r.skipped_snapshots)),
            u32s(rows.iter().map(|r| r.detections)),
            u32s(rows.iter().map(|r| r.short_term_tracks)),
            u32s(rows.iter().map(|r| r.full_lifetime_tracks)),
            f64s(rows.iter().map(|r| r.noise_floor_db)),
            f64s(rows.iter().map(|r| r.channel_gain_db)),
            f64s(rows.iter().map(|r| r.detected_gain_db)),
            f64s(rows.iter().map(|r| r.tracked_gain_db)),
            f64s(rows.iter().map(|r| r.full_lifetime_gain_db)),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (set, t) = (c.u64("set_index")?, c.i64("t_ns")?);
        let (snaps, skipped, det, short, full) = (
            c.u32("snapshots")?,
            c.u32("skipped_snapshots")?,
            c.u32("detections")?,
            c.u32("short_term_tracks")?,
            c.u32("full_lifetime_tracks")?,
        );
        let (floor, gain, detected, tracked, full_gain) = (
            c.f64("noise_floor_db")?,
            c.f64("channel_gain_db")?,
            c.f64("detected_gain_db")?,
            c.f64("tracked_gain_db")?,
            c.f64("full_lifetime_gain_db")?,
        );
        Ok((0..c.num_rows())
            .map(|i| MpcSetStats {
                set_index: set.value(i),
                t_ns: t.value(i),
                snapshots: snaps.value(i),
                skipped_snapshots: skipped.value(i),
                detections: det.value(i),
                short_term_tracks: short.value(i),
                full_lifetime_tracks: full.value(i),
                noise_floor_db: floor.value(i),
                channel_gain_db: gain.value(i),
                detected_gain_db: detected.value(i),
                tracked_gain_db: tracked.value(i),
                full_lifetime_gain_db: full_gain.value(i),
            })
            .collect())
    }
}

/// `mpc_truth`: the true MPCs of a simulated recording.
pub const MPC_TRUTH: TableSpec = TableSpec {
    name: "mpc_truth",
    description: "One true multipath component of one snapshot per row, as the simulator knows it, in recording \
order; path_id is stable while the propagation path exists.",
    columns: &[
        col("t_ns", Int64, "ns", "time of the snapshot"),
        col("set_index", UInt64, "", "sounder set"),
        col("snapshot_index", UInt32, "", "snapshot within the set"),
        col("path_id", UInt64, "", "propagation path identifier"),
        col("delay_s", Float64, "s", "true delay on the recording's delay axis"),
        col("amplitude_re", Float64, "", "real part of the true complex amplitude"),
        col("amplitude_im", Float64, "", "imaginary part of the true complex amplitude"),
        col("power_db", Float64, "dB", "20 log10 |amplitude| (derived, for convenience)"),
        col("doppler_hz", Float64, "Hz", "true Doppler shift, -f_c d(tau)/dt"),
    ],
};

impl TableRow for MpcTruth {
    const SPEC: &'static TableSpec = &MPC_TRUTH;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![
            i64s(rows.iter().map(|r| r.t_ns)),
            u64s(rows.iter().map(|r| r.set_index)),
            u32s(rows.iter().map(|r| r.snapshot_index)),
            u64s(rows.iter().map(|r| r.path_id)),
            f64s(rows.iter().map(|r| r.delay_s)),
            f64s(rows.iter().map(|r| r.amplitude.re)),
            f64s(rows.iter().map(|r| r.amplitude.im)),
            f64s(rows.iter().map(MpcTruth::power_db)),
            f64s(rows.iter().map(|r| r.doppler_hz)),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (t, set, snap, path) = (c.i64("t_ns")?, c.u64("set_index")?, c.u32("snapshot_index")?, c.u64("path_id")?);
        let (delay, re, im, doppler) =
            (c.f64("delay_s")?, c.f64("amplitude_re")?, c.f64("amplitude_im")?, c.f64("doppler_hz")?);
        Ok((0..c.num_rows())
            .map(|i| MpcTruth {
                t_ns: t.value(i),
                set_index: set.value(i),
                snapshot_index: snap.value(i),
                path_id: path.value(i),
                delay_s: delay.value(i),
                amplitude: Complex64::new(re.value(i), im.value(i)),
                doppler_hz: doppler.value(i),
            })
            .collect())
    }
}

/// Ground truth of a channel sounder's transmitter vehicle.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundTruthTxPose(pub StampedPose);

/// Ground truth of a channel sounder's receiver vehicle.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundTruthRxPose(pub StampedPose);

/// `ground_truth_tx`: the transmitter car's trajectory.
pub const GROUND_TRUTH_TX: TableSpec = TableSpec {
    name: "ground_truth_tx",
    description: "One ground-truth pose world_from_vehicle of a channel sounder's transmitter car per row, in time \
order (recording topic /ground_truth/tx); the columns of poses.",
    columns: POSES.columns,
};

/// `ground_truth_rx`: the receiver car's trajectory.
pub const GROUND_TRUTH_RX: TableSpec = TableSpec {
    name: "ground_truth_rx",
    description: "One ground-truth pose world_from_vehicle of a channel sounder's receiver car per row, in time \
order (recording topic /ground_truth/rx); the columns of poses.",
    columns: POSES.columns,
};

macro_rules! pose_newtype_row {
    ($ty:ident, $spec:ident) => {
        impl TableRow for $ty {
            const SPEC: &'static TableSpec = &$spec;

            fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
                let poses: Vec<StampedPose> = rows.iter().map(|r| r.0.clone()).collect();
                StampedPose::to_columns(&poses)
            }

            fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
                Ok(StampedPose::from_columns(c)?.into_iter().map($ty).collect())
            }
        }
    };
}

pose_newtype_row!(GroundTruthTxPose, GROUND_TRUTH_TX);
pose_newtype_row!(GroundTruthRxPose, GROUND_TRUTH_RX);
