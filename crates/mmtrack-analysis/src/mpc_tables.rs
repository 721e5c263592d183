//! Result tables of the MPC statistics (see [`crate::mpc`]), with units.

use std::sync::Arc;

use arrow_array::{Array, ArrayRef, BooleanArray, Float64Array, Int64Array, StringArray, UInt64Array};
use mmtrack_io::table::{ColumnSpec, ColumnType, Columns, TableRow, TableSpec};

use crate::mpc::{ChiClassShare, CountBin, MpcSummary, SetMetrics, TrackPowerStd};

use ColumnType::{Boolean, Float64, Int64, UInt64, Utf8};

const fn col(name: &'static str, ty: ColumnType, unit: &'static str, meaning: &'static str) -> ColumnSpec {
    ColumnSpec { name, ty, nullable: false, unit, meaning }
}

const fn opt(name: &'static str, ty: ColumnType, unit: &'static str, meaning: &'static str) -> ColumnSpec {
    ColumnSpec { name, ty, nullable: true, unit, meaning }
}

fn u64s(v: impl Iterator<Item = u64>) -> ArrayRef {
    Arc::new(UInt64Array::from_iter_values(v))
}
fn opt_u64s(v: impl Iterator<Item = Option<u64>>) -> ArrayRef {
    Arc::new(v.collect::<UInt64Array>())
}
fn f64s(v: impl Iterator<Item = f64>) -> ArrayRef {
    Arc::new(Float64Array::from_iter_values(v))
}
fn opt_f64s(v: impl Iterator<Item = Option<f64>>) -> ArrayRef {
    Arc::new(v.collect::<Float64Array>())
}
fn of(a: &Float64Array, i: usize) -> Option<f64> {
    a.is_valid(i).then(|| a.value(i))
}
fn ou(a: &UInt64Array, i: usize) -> Option<u64> {
    a.is_valid(i).then(|| a.value(i))
}

/// `mpc_set_metrics`: one row per set.
pub const MPC_SET_METRICS: TableSpec = TableSpec {
    name: "mpc_set_metrics",
    description: "MPC statistics of one sounder set per row, in set order: long-term MPC count (Fig. 12), births and \
deaths across the pair (previous set, this set) and their rates (Fig. 13), channel gains and power losses (Figs. 8-9). \
Transition columns are null for the first set.",
    columns: &[
        col("set_index", UInt64, "", "the set"),
        col("t_ns", Int64, "ns", "time of its first snapshot"),
        col("long_term_mpcs", UInt64, "", "full-lifetime MPCs entered in long-term tracks in this set"),
        col("detections", UInt64, "", "detections over the set"),
        col("full_lifetime_tracks", UInt64, "", "short-term tracks spanning the set"),
        opt("births", UInt64, "", "long-term tracks whose first entry is this set"),
        opt("deaths", UInt64, "", "long-term tracks whose last entry is the previous set"),
        opt("distance_m", Float64, "m", "distance driven since the previous set (both vehicles summed when known)"),
        opt("birth_rate_per_m", Float64, "1/m", "births / distance_m"),
        opt("death_rate_per_m", Float64, "1/m", "deaths / distance_m"),
        opt("birth_rate_per_s", Float64, "1/s", "births / time since the previous set"),
        opt("death_rate_per_s", Float64, "1/s", "deaths / time since the previous set"),
        col("channel_gain_db", Float64, "dB", "channel gain after thresholding and windowing (mpc_sets)"),
        col("detected_gain_db", Float64, "dB", "gain captured by the detections"),
        col("tracked_gain_db", Float64, "dB", "gain captured by the short-term tracks"),
        col("full_lifetime_gain_db", Float64, "dB", "gain captured by the full-lifetime tracks"),
        opt("gmphd_tracked_gain_db", Float64, "dB", "gain captured by the GM-PHD tracks; null without them"),
        col("detection_loss_db", Float64, "dB", "channel_gain_db - detected_gain_db"),
        col("tracking_loss_db", Float64, "dB", "channel_gain_db - tracked_gain_db"),
        opt("gmphd_tracking_loss_db", Float64, "dB", "channel_gain_db - gmphd_tracked_gain_db"),
        opt(
            "true_births",
            UInt64,
            "",
            "true paths above the floor appearing since the previous set; null without truth",
        ),
        opt("true_deaths", UInt64, "", "true paths above the floor gone since the previous set; null without truth"),
    ],
};

impl TableRow for SetMetrics {
    const SPEC: &'static TableSpec = &MPC_SET_METRICS;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        let f = |g: fn(&Self) -> f64| f64s(rows.iter().map(g));
        let o = |g: fn(&Self) -> Option<f64>| opt_f64s(rows.iter().map(g));
        let u = |g: fn(&Self) -> u64| u64s(rows.iter().map(g));
        let ou = |g: fn(&Self) -> Option<u64>| opt_u64s(rows.iter().map(g));
        vec![
            u(|r| r.set_index),
            Arc::new(Int64Array::from_iter_values(rows.iter().map(|r| r.t_ns))),
            u(|r| r.long_term_mpcs),
            u(|r| r.detections),
            u(|r| r.full_lifetime_tracks),
            ou(|r| r.births),
            ou(|r| r.deaths),
            o(|r| r.distance_m),
            o(|r| r.birth_rate_per_m),
            o(|r| r.death_rate_per_m),
            o(|r| r.birth_rate_per_s),
            o(|r| r.death_rate_per_s),
            f(|r| r.channel_gain_db),
            f(|r| r.detected_gain_db),
            f(|r| r.tracked_gain_db),
            f(|r| r.full_lifetime_gain_db),
            o(|r| r.gmphd_tracked_gain_db),
            f(|r| r.detection_loss_db),
            f(|r| r.tracking_loss_db),
            o(|r| r.gmphd_tracking_loss_db),
            ou(|r| r.true_births),
            ou(|r| r.true_deaths),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (set, t, mpcs, det, full) = (
            c.u64("set_index")?,
            c.i64("t_ns")?,
            c.u64("long_term_mpcs")?,
            c.u64("detections")?,
            c.u64("full_lifetime_tracks")?,
        );
        let (births, deaths, tb, td) =
            (c.u64("births")?, c.u64("deaths")?, c.u64("true_births")?, c.u64("true_deaths")?);
        let f = |n: &str| c.f64(n);
        let (dist, brm, drm, brs, drs) = (
            f("distance_m")?,
            f("birth_rate_per_m")?,
            f("death_rate_per_m")?,
            f("birth_rate_per_s")?,
            f("death_rate_per_s")?,
        );
        let (cg, dg, tg, fg, gg) = (
            f("channel_gain_db")?,
            f("detected_gain_db")?,
            f("tracked_gain_db")?,
            f("full_lifetime_gain_db")?,
            f("gmphd_tracked_gain_db")?,
        );
        let (dl, tl, gl) = (f("detection_loss_db")?, f("tracking_loss_db")?, f("gmphd_tracking_loss_db")?);
        Ok((0..c.num_rows())
            .map(|i| SetMetrics {
                set_index: set.value(i),
                t_ns: t.value(i),
                long_term_mpcs: mpcs.value(i),
                detections: det.value(i),
                full_lifetime_tracks: full.value(i),
                births: ou(births, i),
                deaths: ou(deaths, i),
                distance_m: of(dist, i),
                birth_rate_per_m: of(brm, i),
                death_rate_per_m: of(drm, i),
                birth_rate_per_s: of(brs, i),
                death_rate_per_s: of(drs, i),
                channel_gain_db: cg.value(i),
                detected_gain_db: dg.value(i),
                tracked_gain_db: tg.value(i),
                full_lifetime_gain_db: fg.value(i),
                gmphd_tracked_gain_db: of(gg, i),
                detection_loss_db: dl.value(i),
                tracking_loss_db: tl.value(i),
                gmphd_tracking_loss_db: of(gl, i),
                true_births: ou(tb, i),
                true_deaths: ou(td, i),
            })
            .collect())
    }
}

/// `mpc_track_power_std`: one row per short-term track.
pub const MPC_TRACK_POWER_STD: TableSpec = TableSpec {
    name: "mpc_track_power_std",
    description: "Power standard deviation of each short-term track over its set (Mahler et al. 2017, Fig. 7), in \
the order of mpc_tracks: sample standard deviation (n - 1) of its detections' power_db, 0 for one detection.",
    columns: &[
        col("track_id", UInt64, "", "track_id in mpc_tracks"),
        col("set_index", UInt64, "", "set of the track"),
        col("detections", UInt64, "", "detections of the track"),
        col("full_lifetime", Boolean, "", "true when the track spans every processed snapshot of its set"),
        col("power_std_db", Float64, "dB", "standard deviation of power_db over the track"),
    ],
};

impl TableRow for TrackPowerStd {
    const SPEC: &'static TableSpec = &MPC_TRACK_POWER_STD;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![
            u64s(rows.iter().map(|r| r.track_id)),
            u64s(rows.iter().map(|r| r.set_index)),
            u64s(rows.iter().map(|r| r.detections)),
            Arc::new(rows.iter().map(|r| Some(r.full_lifetime)).collect::<BooleanArray>()),
            f64s(rows.iter().map(|r| r.power_std_db)),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (id, set, n, full, std) = (
            c.u64("track_id")?,
            c.u64("set_index")?,
            c.u64("detections")?,
            c.bool("full_lifetime")?,
            c.f64("power_std_db")?,
        );
        Ok((0..c.num_rows())
            .map(|i| TrackPowerStd {
                track_id: id.value(i),
                set_index: set.value(i),
                detections: n.value(i),
                full_lifetime: full.value(i),
                power_std_db: std.value(i),
            })
            .collect())
    }
}

/// `mpc_chi_classes`: power share per long-term confidence class.
pub const MPC_CHI_CLASSES: TableSpec = TableSpec {
    name: "mpc_chi_classes",
    description: "Long-term links per confidence class chi (Mahler et al. 2017, eq. 40, Sec. VI-A), in increasing \
chi: the share of the linked power (mean power of the entry each link leads to); a last row with a null chi gives \
the entries related to no adjacent set and their share of all full-lifetime power.",
    columns: &[
        opt("chi_class_s", Float64, "s", "confidence class; null for the unrelated entries"),
        col("entries", UInt64, "", "links of this class (or unrelated entries)"),
        col("power_share", Float64, "", "share of linked power (or of all long-term power for the null row), 0..1"),
    ],
};

impl TableRow for ChiClassShare {
    const SPEC: &'static TableSpec = &MPC_CHI_CLASSES;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![
            opt_f64s(rows.iter().map(|r| r.chi_class_s)),
            u64s(rows.iter().map(|r| r.entries)),
            f64s(rows.iter().map(|r| r.power_share)),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (chi, n, share) = (c.f64("chi_class_s")?, c.u64("entries")?, c.f64("power_share")?);
        Ok((0..c.num_rows())
            .map(|i| ChiClassShare { chi_class_s: of(chi, i), entries: n.value(i), power_share: share.value(i) })
            .collect())
    }
}

/// `mpc_count_distribution`: distribution of the number of MPCs per set.
pub const MPC_COUNT_DISTRIBUTION: TableSpec = TableSpec {
    name: "mpc_count_distribution",
    description: "Distribution of the number of long-term (full-lifetime) MPCs per set (Mahler et al. 2017, \
Fig. 12), one row per count that occurs, in increasing count.",
    columns: &[
        col("mpcs", UInt64, "", "number of MPCs in a set"),
        col("sets", UInt64, "", "sets with that many"),
        col("cdf", Float64, "", "share of sets with at most that many, 0..1"),
    ],
};

impl TableRow for CountBin {
    const SPEC: &'static TableSpec = &MPC_COUNT_DISTRIBUTION;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![u64s(rows.iter().map(|r| r.mpcs)), u64s(rows.iter().map(|r| r.sets)), f64s(rows.iter().map(|r| r.cdf))]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (m, s, cdf) = (c.u64("mpcs")?, c.u64("sets")?, c.f64("cdf")?);
        Ok((0..c.num_rows()).map(|i| CountBin { mpcs: m.value(i), sets: s.value(i), cdf: cdf.value(i) }).collect())
    }
}

/// `mpc_summary`: one row per sequence.
pub const MPC_SUMMARY: TableSpec = TableSpec {
    name: "mpc_summary",
    description: "Summary of the MPC statistics of one sequence partition (one row). Rates per metre use the \
distance named by distance_source (both sounder vehicles' ground truth summed, as the paper; or one trajectory); \
they are null without one, and the per-second rates always apply. Truth columns are null without mpc_truth.",
    columns: &[
        col("sets", UInt64, "", "sets processed"),
        col("detections", UInt64, "", "detections"),
        col("short_term_tracks", UInt64, "", "short-term tracks"),
        col("full_lifetime_tracks", UInt64, "", "short-term tracks spanning their set"),
        col("long_term_tracks", UInt64, "", "long-term tracks"),
        col("mean_mpcs_per_set", Float64, "", "mean number of long-term MPCs per set"),
        col("median_mpcs_per_set", Float64, "", "median number of long-term MPCs per set"),
        col("distance_source", Utf8, "", "tables the distance comes from, or none"),
        opt("distance_m", Float64, "m", "distance driven from the first to the last set"),
        col("duration_s", Float64, "s", "time from the first to the last set"),
        col("births", UInt64, "", "long-term track births (not counting the first set)"),
        col("deaths", UInt64, "", "long-term track deaths (not counting the last set)"),
        opt("birth_rate_per_m", Float64, "1/m", "births / distance_m"),
        opt("death_rate_per_m", Float64, "1/m", "deaths / distance_m"),
        opt("birth_rate_per_s", Float64, "1/s", "births / duration_s"),
        opt("death_rate_per_s", Float64, "1/s", "deaths / duration_s"),
        opt("mean_detection_loss_db", Float64, "dB", "mean over sets of channel minus detected gain"),
        opt("mean_tracking_loss_db", Float64, "dB", "mean over sets of channel minus short-term tracked gain"),
        opt("mean_full_lifetime_loss_db", Float64, "dB", "mean over sets of channel minus full-lifetime gain"),
        opt("mean_gmphd_tracking_loss_db", Float64, "dB", "mean over sets of channel minus GM-PHD tracked gain"),
        opt("full_lifetime_std_below_1db", Float64, "", "share of full-lifetime tracks with power std < 1 dB"),
        opt("all_tracks_std_below_1_5db", Float64, "", "share of all short-term tracks with power std < 1.5 dB"),
        opt("chi_0_1ns_power_share", Float64, "", "share of linked power in classes chi <= 0.1 ns"),
        opt("unrelated_power_share", Float64, "", "share of long-term power in entries related to no adjacent set"),
        opt("truth_mpcs", UInt64, "", "resolvable true MPCs over all snapshots (true MPCs within 0.5 ns merged)"),
        opt("precision", Float64, "", "detections matching a true MPC within 0.5 ns / detections"),
        opt("recall", Float64, "", "true MPCs matched / true MPCs"),
        opt("recall_above_floor", Float64, "", "recall over true MPCs at least 6 dB above the noise floor"),
        opt(
            "track_purity",
            Float64,
            "",
            "over tracks with a matched detection: detection-weighted share on their majority path",
        ),
        opt("false_track_share", Float64, "", "share of short-term tracks without a matched detection"),
        opt("false_long_term_share", Float64, "", "share of long-term tracks that follow no true path"),
        opt("births_on_true_paths", UInt64, "", "births of long-term tracks that follow a true path"),
        opt("deaths_on_true_paths", UInt64, "", "deaths of long-term tracks that follow a true path"),
        opt("long_term_tracks_per_path", Float64, "", "long-term tracks following a true path / paths followed"),
        opt("true_births", UInt64, "", "true path births above the floor"),
        opt("true_deaths", UInt64, "", "true path deaths above the floor"),
        opt("true_birth_rate_per_m", Float64, "1/m", "true_births / distance_m"),
        opt("true_death_rate_per_m", Float64, "1/m", "true_deaths / distance_m"),
    ],
};

impl TableRow for MpcSummary {
    const SPEC: &'static TableSpec = &MPC_SUMMARY;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        let u = |g: fn(&Self) -> u64| u64s(rows.iter().map(g));
        let ou = |g: fn(&Self) -> Option<u64>| opt_u64s(rows.iter().map(g));
        let f = |g: fn(&Self) -> f64| f64s(rows.iter().map(g));
        let o = |g: fn(&Self) -> Option<f64>| opt_f64s(rows.iter().map(g));
        vec![
            u(|r| r.sets),
            u(|r| r.detections),
            u(|r| r.short_term_tracks),
            u(|r| r.full_lifetime_tracks),
            u(|r| r.long_term_tracks),
            f(|r| r.mean_mpcs_per_set),
            f(|r| r.median_mpcs_per_set),
            Arc::new(StringArray::from_iter_values(rows.iter().map(|r| r.distance_source.as_str()))),
            o(|r| r.distance_m),
            f(|r| r.duration_s),
            u(|r| r.births),
            u(|r| r.deaths),
            o(|r| r.birth_rate_per_m),
            o(|r| r.death_rate_per_m),
            o(|r| r.birth_rate_per_s),
            o(|r| r.death_rate_per_s),
            o(|r| r.mean_detection_loss_db),
            o(|r| r.mean_tracking_loss_db),
            o(|r| r.mean_full_lifetime_loss_db),
            o(|r| r.mean_gmphd_tracking_loss_db),
            o(|r| r.full_lifetime_std_below_1db),
            o(|r| r.all_tracks_std_below_1_5db),
            o(|r| r.chi_0_1ns_power_share),
            o(|r| r.unrelated_power_share),
            ou(|r| r.truth_mpcs),
            o(|r| r.precision),
            o(|r| r.recall),
            o(|r| r.recall_above_floor),
            o(|r| r.track_purity),
            o(|r| r.false_track_share),
            o(|r| r.false_long_term_share),
            ou(|r| r.births_on_true_paths),
            ou(|r| r.deaths_on_true_paths),
            o(|r| r.long_term_tracks_per_path),
            ou(|r| r.true_births),
            ou(|r| r.true_deaths),
            o(|r| r.true_birth_rate_per_m),
            o(|r| r.true_death_rate_per_m),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let u = |n: &str| c.u64(n);
        let f = |n: &str| c.f64(n);
        let source = c.utf8("distance_source")?;
        let [sets, det, short, full, long, births, deaths, truth, tb, td, bp, dp] = [
            "sets",
            "detections",
            "short_term_tracks",
            "full_lifetime_tracks",
            "long_term_tracks",
            "births",
            "deaths",
            "truth_mpcs",
            "true_births",
            "true_deaths",
            "births_on_true_paths",
            "deaths_on_true_paths",
        ]
        .map(u);
        let (sets, det, short, full, long, births, deaths, truth, tb, td, bp, dp) =
            (sets?, det?, short?, full?, long?, births?, deaths?, truth?, tb?, td?, bp?, dp?);
        let floats = [
            "mean_mpcs_per_set",
            "median_mpcs_per_set",
            "distance_m",
            "duration_s",
            "birth_rate_per_m",
            "death_rate_per_m",
            "birth_rate_per_s",
            "death_rate_per_s",
            "mean_detection_loss_db",
            "mean_tracking_loss_db",
            "mean_full_lifetime_loss_db",
            "mean_gmphd_tracking_loss_db",
            "full_lifetime_std_below_1db",
            "all_tracks_std_below_1_5db",
            "chi_0_1ns_power_share",
            "unrelated_power_share",
            "precision",
            "recall",
            "recall_above_floor",
            "track_purity",
            "false_track_share",
            "false_long_term_share",
            "long_term_tracks_per_path",
            "true_birth_rate_per_m",
            "true_death_rate_per_m",
        ]
        .map(f);
        let mut it = floats.into_iter();
        let mut next = || it.next().ok_or_else(|| "internal: column list".to_string()).and_then(|r| r);
        let (mean, median, dist, dur, brm, drm, brs, drs) =
            (next()?, next()?, next()?, next()?, next()?, next()?, next()?, next()?);
        let (dl, tl, fl, gl, s1, s15, chi, unrel) =
            (next()?, next()?, next()?, next()?, next()?, next()?, next()?, next()?);
        let (prec, rec, recf, pur, fts, flt, ltp) = (next()?, next()?, next()?, next()?, next()?, next()?, next()?);
        let (tbr, tdr) = (next()?, next()?);
        Ok((0..c.num_rows())
            .map(|i| MpcSummary {
                sets: sets.value(i),
                detections: det.value(i),
                short_term_tracks: short.value(i),
                full_lifetime_tracks: full.value(i),
                long_term_tracks: long.value(i),
                mean_mpcs_per_set: mean.value(i),
                median_mpcs_per_set: median.value(i),
                distance_source: source.value(i).to_string(),
                distance_m: of(dist, i),
                duration_s: dur.value(i),
                births: births.value(i),
                deaths: deaths.value(i),
                birth_rate_per_m: of(brm, i),
                death_rate_per_m: of(drm, i),
                birth_rate_per_s: of(brs, i),
                death_rate_per_s: of(drs, i),
                mean_detection_loss_db: of(dl, i),
                mean_tracking_loss_db: of(tl, i),
                mean_full_lifetime_loss_db: of(fl, i),
                mean_gmphd_tracking_loss_db: of(gl, i),
                full_lifetime_std_below_1db: of(s1, i),
                all_tracks_std_below_1_5db: of(s15, i),
                chi_0_1ns_power_share: of(chi, i),
                unrelated_power_share: of(unrel, i),
                truth_mpcs: ou(truth, i),
                precision: of(prec, i),
                recall: of(rec, i),
                recall_above_floor: of(recf, i),
                track_purity: of(pur, i),
                false_track_share: of(fts, i),
                false_long_term_share: of(flt, i),
                births_on_true_paths: ou(bp, i),
                deaths_on_true_paths: ou(dp, i),
                long_term_tracks_per_path: of(ltp, i),
                true_births: ou(tb, i),
                true_deaths: ou(td, i),
                true_birth_rate_per_m: of(tbr, i),
                true_death_rate_per_m: of(tdr, i),
            })
            .collect())
    }
}
