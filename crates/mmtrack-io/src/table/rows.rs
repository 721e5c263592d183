//! Tables of the core types: what each looks like on disk.

use std::sync::Arc;

use arrow_array::builder::{BooleanBuilder, Float64Builder, Int64Builder, ListBuilder};
use arrow_array::{Array, ArrayRef, BinaryArray, Float64Array, Int64Array, UInt32Array, UInt64Array};
use mmtrack_core::{
    AzimuthSample, CirSnapshot, Complex64, GnssFix, GnssFixQuality, MpcDetection, MpcTrack, PolarScan, PolarScanHeader,
    Se2, StampedPose,
};

use super::{ColumnSpec, ColumnType, Columns, TableRow, TableSpec};

pub(super) const fn col(name: &'static str, ty: ColumnType, unit: &'static str, meaning: &'static str) -> ColumnSpec {
    ColumnSpec { name, ty, nullable: false, unit, meaning }
}

pub(super) const fn nullable(
    name: &'static str,
    ty: ColumnType,
    unit: &'static str,
    meaning: &'static str,
) -> ColumnSpec {
    ColumnSpec { name, ty, nullable: true, unit, meaning }
}

use ColumnType::{Binary, Float64, Int64, ListBoolean, ListFloat64, ListInt64, UInt32, UInt64};

pub(super) fn i64s(values: impl Iterator<Item = i64>) -> ArrayRef {
    Arc::new(Int64Array::from_iter_values(values))
}
pub(super) fn u64s(values: impl Iterator<Item = u64>) -> ArrayRef {
    Arc::new(UInt64Array::from_iter_values(values))
}
pub(super) fn u32s(values: impl Iterator<Item = u32>) -> ArrayRef {
    Arc::new(UInt32Array::from_iter_values(values))
}
pub(super) fn f64s(values: impl Iterator<Item = f64>) -> ArrayRef {
    Arc::new(Float64Array::from_iter_values(values))
}
fn list_f64<'a>(rows: impl Iterator<Item = &'a [f64]>) -> ArrayRef {
    let mut b = ListBuilder::new(Float64Builder::new());
    for row in rows {
        b.values().append_slice(row);
        b.append(true);
    }
    Arc::new(b.finish())
}
fn list_i64<'a>(rows: impl Iterator<Item = &'a [i64]>) -> ArrayRef {
    let mut b = ListBuilder::new(Int64Builder::new());
    for row in rows {
        b.values().append_slice(row);
        b.append(true);
    }
    Arc::new(b.finish())
}
fn list_bool<'a>(rows: impl Iterator<Item = &'a [bool]>) -> ArrayRef {
    let mut b = ListBuilder::new(BooleanBuilder::new());
    for row in rows {
        b.values().append_slice(row);
        b.append(true);
    }
    Arc::new(b.finish())
}

/// `poses`: a trajectory.
pub const POSES: TableSpec = TableSpec {
    name: "poses",
    description: "One pose world_from_vehicle per row, in time order (ground truth or an estimate; the run config says which).",
    columns: &[
        col("t_ns", Int64, "ns", "time of validity"),
        col("x_m", Float64, "m", "x of the vehicle in the world frame"),
        col("y_m", Float64, "m", "y of the vehicle in the world frame"),
        col("yaw_rad", Float64, "rad", "heading, counter-clockwise from world x"),
    ],
};

impl TableRow for StampedPose {
    const SPEC: &'static TableSpec = &POSES;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![
            i64s(rows.iter().map(|r| r.t_ns)),
            f64s(rows.iter().map(|r| r.parent_from_child.x_m)),
            f64s(rows.iter().map(|r| r.parent_from_child.y_m)),
            f64s(rows.iter().map(|r| r.parent_from_child.yaw_rad)),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (t, x, y, yaw) = (c.i64("t_ns")?, c.f64("x_m")?, c.f64("y_m")?, c.f64("yaw_rad")?);
        Ok((0..c.num_rows())
            .map(|i| StampedPose {
                t_ns: t.value(i),
                parent_from_child: Se2::new(x.value(i), y.value(i), yaw.value(i)),
            })
            .collect())
    }
}

/// `gnss_fixes`: GNSS positions.
pub const GNSS_FIXES: TableSpec = TableSpec {
    name: "gnss_fixes",
    description: "One WGS-84 GNSS fix per row.",
    columns: &[
        col("t_ns", Int64, "ns", "fix time"),
        col("latitude_deg", Float64, "deg", "geodetic latitude, north positive"),
        col("longitude_deg", Float64, "deg", "geodetic longitude, east positive"),
        col("altitude_m", Float64, "m", "height"),
        nullable("horizontal_sigma_m", Float64, "m", "1-sigma horizontal uncertainty; null when not reported"),
        nullable("num_satellites", UInt32, "", "satellites used; null when not reported"),
        col(
            "quality",
            UInt32,
            "",
            "0 unknown, 1 no fix, 2 autonomous, 3 differential, 4 RTK fixed, 5 RTK float, 6 dead reckoning",
        ),
    ],
};

impl TableRow for GnssFix {
    const SPEC: &'static TableSpec = &GNSS_FIXES;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        vec![
            i64s(rows.iter().map(|r| r.t_ns)),
            f64s(rows.iter().map(|r| r.latitude_deg)),
            f64s(rows.iter().map(|r| r.longitude_deg)),
            f64s(rows.iter().map(|r| r.altitude_m)),
            Arc::new(rows.iter().map(|r| r.horizontal_sigma_m).collect::<Float64Array>()),
            Arc::new(rows.iter().map(|r| r.num_satellites).collect::<UInt32Array>()),
            u32s(rows.iter().map(|r| r.quality.code())),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (t, lat, lon, alt) =
            (c.i64("t_ns")?, c.f64("latitude_deg")?, c.f64("longitude_deg")?, c.f64("altitude_m")?);
        let (sigma, sats, quality) = (c.f64("horizontal_sigma_m")?, c.u32("num_satellites")?, c.u32("quality")?);
        (0..c.num_rows())
            .map(|i| {
                let code = quality.value(i);
                Ok(GnssFix {
                    t_ns: t.value(i),
                    latitude_deg: lat.value(i),
                    longitude_deg: lon.value(i),
                    altitude_m: alt.value(i),
                    horizontal_sigma_m: sigma.is_valid(i).then(|| sigma.value(i)),
                    num_satellites: sats.is_valid(i).then(|| sats.value(i)),
                    quality: GnssFixQuality::from_code(code)
                        .ok_or_else(|| format!("row {i}: column 'quality': unknown code {code}"))?,
                })
            })
            .collect()
    }
}

/// `radar_scans`: polar radar scans, one per row.
pub const RADAR_SCANS: TableSpec = TableSpec {
    name: "radar_scans",
    description: "One polar radar scan per row; power is row-major azimuth x bin, one byte per bin.",
    columns: &[
        col("t_ns", Int64, "ns", "scan timestamp"),
        col("range_resolution_m", Float64, "m", "range bin size"),
        col("range_offset_m", Float64, "m", "range of bin 0"),
        col("bins_per_azimuth", UInt32, "", "range bins per azimuth"),
        col("azimuth_t_ns", ListInt64, "ns", "time of each azimuth"),
        col("azimuth_rad", ListFloat64, "rad", "angle of each azimuth"),
        col("valid", ListBoolean, "", "validity of each azimuth"),
        col("power", Binary, "", "raw power counts 0-255, azimuth-major"),
    ],
};

impl TableRow for PolarScan {
    const SPEC: &'static TableSpec = &RADAR_SCANS;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        let az_t: Vec<Vec<i64>> = rows.iter().map(|r| r.header.azimuths.iter().map(|a| a.t_ns).collect()).collect();
        let az_rad: Vec<Vec<f64>> =
            rows.iter().map(|r| r.header.azimuths.iter().map(|a| a.azimuth_rad).collect()).collect();
        let valid: Vec<Vec<bool>> = rows.iter().map(|r| r.header.azimuths.iter().map(|a| a.valid).collect()).collect();
        vec![
            i64s(rows.iter().map(|r| r.header.t_ns)),
            f64s(rows.iter().map(|r| r.header.range_resolution_m)),
            f64s(rows.iter().map(|r| r.header.range_offset_m)),
            // Bin counts beyond 32 bits cannot come from a PolarScan built by any reader.
            u32s(rows.iter().map(|r| u32::try_from(r.header.bins_per_azimuth).unwrap_or(u32::MAX))),
            list_i64(az_t.iter().map(Vec::as_slice)),
            list_f64(az_rad.iter().map(Vec::as_slice)),
            list_bool(valid.iter().map(Vec::as_slice)),
            Arc::new(BinaryArray::from_iter_values(rows.iter().map(|r| r.power.as_slice()))),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (t, res, off, bins, power) = (
            c.i64("t_ns")?,
            c.f64("range_resolution_m")?,
            c.f64("range_offset_m")?,
            c.u32("bins_per_azimuth")?,
            c.binary("power")?,
        );
        (0..c.num_rows())
            .map(|i| {
                let az_t = c.list_i64("azimuth_t_ns", i)?;
                let az_rad = c.list_f64("azimuth_rad", i)?;
                let valid = c.list_bool("valid", i)?;
                if az_rad.len() != az_t.len() || valid.len() != az_t.len() {
                    return Err(format!("row {i}: azimuth_t_ns, azimuth_rad and valid differ in length"));
                }
                let azimuths = (0..az_t.len())
                    .map(|k| AzimuthSample { t_ns: az_t[k], azimuth_rad: az_rad[k], valid: valid[k] })
                    .collect();
                let header = PolarScanHeader {
                    t_ns: t.value(i),
                    range_resolution_m: res.value(i),
                    range_offset_m: off.value(i),
                    bins_per_azimuth: bins.value(i) as usize,
                    azimuths,
                };
                PolarScan::new(header, power.value(i).to_vec()).map_err(|e| format!("row {i}: {e}"))
            })
            .collect()
    }
}

/// `cir_snapshots`: channel impulse responses, one per row.
pub const CIR_SNAPSHOTS: TableSpec = TableSpec {
    name: "cir_snapshots",
    description: "One channel impulse response per row; tap k is at delay delay_offset_s + k * tap_spacing_s.",
    columns: &[
        col("t_ns", Int64, "ns", "measurement time"),
        col("set_index", UInt64, "", "sounder set"),
        col("snapshot_index", UInt32, "", "snapshot within the set"),
        col("tx_antenna", UInt32, "", "transmit antenna (0 for SISO)"),
        col("rx_antenna", UInt32, "", "receive antenna (0 for SISO)"),
        col("carrier_hz", Float64, "Hz", "carrier frequency"),
        col("tap_spacing_s", Float64, "s", "delay between taps"),
        col("delay_offset_s", Float64, "s", "delay of tap 0"),
        col("taps_re", ListFloat64, "", "real parts of the taps"),
        col("taps_im", ListFloat64, "", "imaginary parts of the taps"),
        nullable(
            "first_path_hint_s",
            Float64,
            "s",
            "the receiver's own first-path estimate on the taps' delay axis (e.g. DW1000 HLP); null when not given",
        ),
    ],
};

impl TableRow for CirSnapshot {
    const SPEC: &'static TableSpec = &CIR_SNAPSHOTS;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        let re: Vec<Vec<f64>> = rows.iter().map(|r| r.taps.iter().map(|t| t.re).collect()).collect();
        let im: Vec<Vec<f64>> = rows.iter().map(|r| r.taps.iter().map(|t| t.im).collect()).collect();
        vec![
            i64s(rows.iter().map(|r| r.t_ns)),
            u64s(rows.iter().map(|r| r.set_index)),
            u32s(rows.iter().map(|r| r.snapshot_index)),
            u32s(rows.iter().map(|r| r.tx_antenna)),
            u32s(rows.iter().map(|r| r.rx_antenna)),
            f64s(rows.iter().map(|r| r.carrier_hz)),
            f64s(rows.iter().map(|r| r.tap_spacing_s)),
            f64s(rows.iter().map(|r| r.delay_offset_s)),
            list_f64(re.iter().map(Vec::as_slice)),
            list_f64(im.iter().map(Vec::as_slice)),
            Arc::new(rows.iter().map(|r| r.first_path_hint_s).collect::<Float64Array>()),
        ]
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (t, set, snap, tx, rx) =
            (c.i64("t_ns")?, c.u64("set_index")?, c.u32("snapshot_index")?, c.u32("tx_antenna")?, c.u32("rx_antenna")?);
        let (fc, dt, d0) = (c.f64("carrier_hz")?, c.f64("tap_spacing_s")?, c.f64("delay_offset_s")?);
        let hint = c.f64("first_path_hint_s")?;
        (0..c.num_rows())
            .map(|i| {
                let re = c.list_f64("taps_re", i)?;
                let im = c.list_f64("taps_im", i)?;
                if re.len() != im.len() {
                    return Err(format!("row {i}: taps_re has {} values, taps_im {}", re.len(), im.len()));
                }
                Ok(CirSnapshot {
                    t_ns: t.value(i),
                    set_index: set.value(i),
                    snapshot_index: snap.value(i),
                    tx_antenna: tx.value(i),
                    rx_antenna: rx.value(i),
                    carrier_hz: fc.value(i),
                    tap_spacing_s: dt.value(i),
                    delay_offset_s: d0.value(i),
                    taps: re.into_iter().zip(im).map(|(re, im)| Complex64::new(re, im)).collect(),
                    first_path_hint_s: hint.is_valid(i).then(|| hint.value(i)),
                })
            })
            .collect()
    }
}

/// `mpc_detections`: detected multipath components.
pub const MPC_DETECTIONS: TableSpec = TableSpec {
    name: "mpc_detections",
    description: "One detected multipath component per row.",
    columns: &[
        col("t_ns", Int64, "ns", "time of the snapshot"),
        col("set_index", UInt64, "", "sounder set"),
        col("snapshot_index", UInt32, "", "snapshot within the set"),
        col("delay_s", Float64, "s", "estimated delay"),
        col("amplitude_re", Float64, "", "real part of the complex amplitude"),
        col("amplitude_im", Float64, "", "imaginary part of the complex amplitude"),
        col("power_db", Float64, "dB", "20 log10 |amplitude| (derived, for convenience)"),
    ],
};

fn detection_columns<'a>(rows: impl Iterator<Item = &'a MpcDetection> + Clone) -> Vec<ArrayRef> {
    vec![
        i64s(rows.clone().map(|r| r.t_ns)),
        u64s(rows.clone().map(|r| r.set_index)),
        u32s(rows.clone().map(|r| r.snapshot_index)),
        f64s(rows.clone().map(|r| r.delay_s)),
        f64s(rows.clone().map(|r| r.amplitude.re)),
        f64s(rows.clone().map(|r| r.amplitude.im)),
        f64s(rows.map(MpcDetection::power_db)),
    ]
}

fn detections_from(c: &Columns<'_>) -> Result<Vec<MpcDetection>, String> {
    let (t, set, snap, delay, re, im) = (
        c.i64("t_ns")?,
        c.u64("set_index")?,
        c.u32("snapshot_index")?,
        c.f64("delay_s")?,
        c.f64("amplitude_re")?,
        c.f64("amplitude_im")?,
    );
    Ok((0..c.num_rows())
        .map(|i| MpcDetection {
            t_ns: t.value(i),
            set_index: set.value(i),
            snapshot_index: snap.value(i),
            delay_s: delay.value(i),
            amplitude: Complex64::new(re.value(i), im.value(i)),
        })
        .collect())
}

impl TableRow for MpcDetection {
    const SPEC: &'static TableSpec = &MPC_DETECTIONS;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        detection_columns(rows.iter())
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        detections_from(c)
    }
}

/// `mpc_tracks`: tracked multipath components, one row per track point.
pub const MPC_TRACKS: TableSpec = TableSpec {
    name: "mpc_tracks",
    description: "One associated detection of a multipath-component track per row; rows of a track are consecutive and in time order.",
    columns: &[
        col("track_id", UInt64, "", "track identifier, unique within the run"),
        nullable("doppler_hz", Float64, "Hz", "Doppler of the track from its delay slope; null when not estimated"),
        col("t_ns", Int64, "ns", "time of the snapshot"),
        col("set_index", UInt64, "", "sounder set"),
        col("snapshot_index", UInt32, "", "snapshot within the set"),
        col("delay_s", Float64, "s", "estimated delay"),
        col("amplitude_re", Float64, "", "real part of the complex amplitude"),
        col("amplitude_im", Float64, "", "imaginary part of the complex amplitude"),
        col("power_db", Float64, "dB", "20 log10 |amplitude|"),
    ],
};

impl TableRow for MpcTrack {
    const SPEC: &'static TableSpec = &MPC_TRACKS;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        let points = rows.iter().flat_map(|t| t.detections.iter().map(move |d| (t, d)));
        let mut columns = vec![
            u64s(points.clone().map(|(t, _)| t.track_id)),
            Arc::new(points.clone().map(|(t, _)| t.doppler_hz).collect::<Float64Array>()) as ArrayRef,
        ];
        columns.extend(detection_columns(points.map(|(_, d)| d)));
        columns
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let (ids, doppler) = (c.u64("track_id")?, c.f64("doppler_hz")?);
        let detections = detections_from(c)?;
        let mut tracks: Vec<MpcTrack> = Vec::new();
        for (i, detection) in detections.into_iter().enumerate() {
            let id = ids.value(i);
            let doppler_hz = doppler.is_valid(i).then(|| doppler.value(i));
            match tracks.last_mut() {
                Some(track) if track.track_id == id => track.detections.push(detection),
                _ => {
                    if tracks.iter().any(|t| t.track_id == id) {
                        return Err(format!("row {i}: rows of track {id} are not consecutive"));
                    }
                    tracks.push(MpcTrack { track_id: id, doppler_hz, detections: vec![detection] });
                }
            }
        }
        Ok(tracks)
    }
}

/// Every table of this module, for documentation and tests.
pub const ALL_TABLES: &[&TableSpec] = &[
    &POSES,
    &super::GROUND_TRUTH,
    &super::ODOMETRY,
    &super::ODOMETRY_TIMING,
    &GNSS_FIXES,
    &RADAR_SCANS,
    &CIR_SNAPSHOTS,
    &MPC_DETECTIONS,
    &MPC_TRACKS,
    &super::MPC_TRACKS_GMPHD,
    &super::MPC_LONG_TERM,
    &super::MPC_SETS,
    &super::MPC_TRUTH,
    &super::GROUND_TRUTH_TX,
    &super::GROUND_TRUTH_RX,
];
