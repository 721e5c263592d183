//! Tables of the core types: what each looks like on disk.

use super::TableFrame;

use mmtrack_core::{
    AzimuthSample, CirSnapshot, Complex64, GnssFix, GnssFixQuality, MpcDetection, MpcTrack, PolarScan, PolarScanHeader,
    Se2, StampedPose,
};

use super::{ArrayRef, Columns, TableRow, TableSpec};

crate::define_table! {
    /// `poses`: a trajectory.
    pub const POSES = "poses",
        "One pose world_from_vehicle per row, in time order (ground truth or an estimate; the run config says which).",
        frame: TableFrame::Run;
    StampedPose {
        t_ns: i64, "ns", "time of validity";
        x_m: f64, "m", "x of the vehicle in the world frame", |r| r.parent_from_child.x_m;
        y_m: f64, "m", "y of the vehicle in the world frame", |r| r.parent_from_child.y_m;
        yaw_rad: f64, "rad", "heading, counter-clockwise from world x", |r| r.parent_from_child.yaw_rad;
    } => StampedPose { t_ns, parent_from_child: Se2::new(x_m, y_m, yaw_rad) }
}

crate::define_table! {
    /// `gnss_fixes`: GNSS positions.
    pub const GNSS_FIXES = "gnss_fixes", "One WGS-84 GNSS fix per row (`mmtrack process raw`: the recording's /gnss/fix).",
        frame: TableFrame::Fixed {
            id: "wgs84",
            meaning: "WGS-84 geodetic latitude and longitude in degrees (the GNSS convention), altitude as the receiver gives it (the recording names its datum)",
        };
    GnssFix {
        t_ns: i64, "ns", "fix time";
        latitude_deg: f64, "deg", "geodetic latitude, north positive";
        longitude_deg: f64, "deg", "geodetic longitude, east positive";
        altitude_m: Option<f64>, "m", "height; null when not reported (an NMEA RMC without GGA)";
        horizontal_sigma_m: Option<f64>, "m", "1-sigma horizontal uncertainty; null when not reported";
        num_satellites: Option<u32>, "", "satellites used; null when not reported";
        quality: u32, "",
            "0 unknown, 1 no fix, 2 autonomous, 3 differential, 4 RTK fixed, 5 RTK float, 6 dead reckoning",
            |r| r.quality.code();
    } =>? GnssFixQuality::from_code(quality)
        .map(|quality| GnssFix {
            t_ns, latitude_deg, longitude_deg, altitude_m, horizontal_sigma_m, num_satellites, quality,
        })
        .ok_or_else(|| format!("column 'quality': unknown code {quality}"))
}

crate::define_table! {
    /// `radar_scans`: polar radar scans, one per row.
    pub const RADAR_SCANS = "radar_scans",
        "One polar radar scan per row (`mmtrack process raw`); power is row-major azimuth x bin, one byte per bin.",
        frame: TableFrame::Fixed {
            id: "radar_sensor",
            meaning: "azimuth_rad in the radar sensor's own frame, clockwise from its forward axis seen from above, as the sensor reports it",
        };
    PolarScan {
        t_ns: i64, "ns", "scan timestamp", |r| r.header.t_ns;
        range_resolution_m: f64, "m", "range bin size", |r| r.header.range_resolution_m;
        range_offset_m: f64, "m", "range of bin 0", |r| r.header.range_offset_m;
        // Bin counts beyond 32 bits cannot come from a PolarScan built by any reader.
        bins_per_azimuth: u32, "", "range bins per azimuth",
            |r| u32::try_from(r.header.bins_per_azimuth).unwrap_or(u32::MAX);
        azimuth_t_ns: Vec<i64>, "ns", "time of each azimuth",
            |r| r.header.azimuths.iter().map(|a| a.t_ns).collect::<Vec<_>>();
        azimuth_rad: Vec<f64>, "rad", "angle of each azimuth",
            |r| r.header.azimuths.iter().map(|a| a.azimuth_rad).collect::<Vec<_>>();
        valid: Vec<bool>, "", "validity of each azimuth",
            |r| r.header.azimuths.iter().map(|a| a.valid).collect::<Vec<_>>();
        power: Vec<u8>, "", "raw power counts 0-255, azimuth-major";
    } =>? if azimuth_rad.len() != azimuth_t_ns.len() || valid.len() != azimuth_t_ns.len() {
        Err("azimuth_t_ns, azimuth_rad and valid differ in length".to_string())
    } else {
        let azimuths = azimuth_t_ns
            .into_iter()
            .zip(azimuth_rad)
            .zip(valid)
            .map(|((t_ns, azimuth_rad), valid)| AzimuthSample { t_ns, azimuth_rad, valid })
            .collect();
        let bins_per_azimuth = bins_per_azimuth as usize;
        let header = PolarScanHeader { t_ns, range_resolution_m, range_offset_m, bins_per_azimuth, azimuths };
        PolarScan::new(header, power).map_err(|e| e.to_string())
    }
}

crate::define_table! {
    /// `cir_snapshots`: channel impulse responses, one per row.
    pub const CIR_SNAPSHOTS = "cir_snapshots",
        "One channel impulse response per row (`mmtrack process raw`); tap k is at delay delay_offset_s + k * tap_spacing_s.",
        frame: TableFrame::NotApplicable;
    CirSnapshot {
        t_ns: i64, "ns", "measurement time";
        set_index: u64, "", "sounder set";
        snapshot_index: u32, "", "snapshot within the set";
        tx_antenna: u32, "", "transmit antenna (0 for SISO)";
        rx_antenna: u32, "", "receive antenna (0 for SISO)";
        carrier_hz: f64, "Hz", "carrier frequency";
        tap_spacing_s: f64, "s", "delay between taps";
        delay_offset_s: f64, "s", "delay of tap 0";
        taps_re: Vec<f64>, "", "real parts of the taps", |r| r.taps.iter().map(|t| t.re).collect::<Vec<_>>();
        taps_im: Vec<f64>, "", "imaginary parts of the taps", |r| r.taps.iter().map(|t| t.im).collect::<Vec<_>>();
        first_path_hint_s: Option<f64>, "s",
            "the receiver's own first-path estimate on the taps' delay axis (e.g. DW1000 HLP); null when not given";
    } =>? if taps_re.len() == taps_im.len() {
        let taps = taps_re.into_iter().zip(taps_im).map(|(re, im)| Complex64::new(re, im)).collect();
        Ok(CirSnapshot {
            t_ns, set_index, snapshot_index, tx_antenna, rx_antenna, carrier_hz, tap_spacing_s, delay_offset_s, taps,
            first_path_hint_s,
        })
    } else {
        Err(format!("taps_re has {} values, taps_im {}", taps_re.len(), taps_im.len()))
    }
}

crate::define_table! {
    /// `mpc_detections`: detected multipath components.
    pub const MPC_DETECTIONS = "mpc_detections", "One detected multipath component per row.",
        frame: TableFrame::NotApplicable;
    MpcDetection {
        t_ns: i64, "ns", "time of the snapshot";
        set_index: u64, "", "sounder set";
        snapshot_index: u32, "", "snapshot within the set";
        delay_s: f64, "s", "estimated delay";
        amplitude_re: f64, "", "real part of the complex amplitude", |r| r.amplitude.re;
        amplitude_im: f64, "", "imaginary part of the complex amplitude", |r| r.amplitude.im;
        power_db: f64, "dB", "20 log10 |amplitude| (derived, for convenience); dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)", MpcDetection::power_db;
    } => {
        let amplitude = Complex64::new(amplitude_re, amplitude_im);
        MpcDetection { t_ns, set_index, snapshot_index, delay_s, amplitude }
    }
}

/// One row of `mpc_tracks`: a detection and the track it belongs to.
struct TrackPoint {
    track_id: u64,
    doppler_hz: Option<f64>,
    detection: MpcDetection,
}

crate::define_table! {
    /// `mpc_tracks`: tracked multipath components, one row per track point.
    pub const MPC_TRACKS = "mpc_tracks",
        "One associated detection of a multipath-component track per row; rows of a track are consecutive and in time order.",
        frame: TableFrame::NotApplicable;
    TrackPoint {
        track_id: u64, "", "track identifier, unique within the run";
        doppler_hz: Option<f64>, "Hz", "Doppler of the track from its delay slope; null when not estimated";
        t_ns: i64, "ns", "time of the snapshot", |r| r.detection.t_ns;
        set_index: u64, "", "sounder set", |r| r.detection.set_index;
        snapshot_index: u32, "", "snapshot within the set", |r| r.detection.snapshot_index;
        delay_s: f64, "s", "estimated delay", |r| r.detection.delay_s;
        amplitude_re: f64, "", "real part of the complex amplitude", |r| r.detection.amplitude.re;
        amplitude_im: f64, "", "imaginary part of the complex amplitude", |r| r.detection.amplitude.im;
        power_db: f64, "dB", "20 log10 |amplitude|; dB re 1 CIR tap unit squared: |a|^2 with a in the units of the recording's CIR taps, uncalibrated (not dBm)", |r| r.detection.power_db();
    } => {
        let amplitude = Complex64::new(amplitude_re, amplitude_im);
        let detection = MpcDetection { t_ns, set_index, snapshot_index, delay_s, amplitude };
        TrackPoint { track_id, doppler_hz, detection }
    }
}

/// A track is its points, consecutive rows in time order.
impl TableRow for MpcTrack {
    const SPEC: &'static TableSpec = &MPC_TRACKS;

    fn to_columns(rows: &[Self]) -> Vec<ArrayRef> {
        let point = |t: &MpcTrack, d: &MpcDetection| TrackPoint {
            track_id: t.track_id,
            doppler_hz: t.doppler_hz,
            detection: d.clone(),
        };
        let points: Vec<TrackPoint> = rows.iter().flat_map(|t| t.detections.iter().map(move |d| point(t, d))).collect();
        TrackPoint::to_columns(&points)
    }

    fn from_columns(c: &Columns<'_>) -> Result<Vec<Self>, String> {
        let mut tracks: Vec<MpcTrack> = Vec::new();
        for (i, TrackPoint { track_id, doppler_hz, detection }) in TrackPoint::from_columns(c)?.into_iter().enumerate()
        {
            if let Some(track) = tracks.last_mut().filter(|t| t.track_id == track_id) {
                track.detections.push(detection);
            } else if tracks.iter().any(|t| t.track_id == track_id) {
                return Err(format!("row {i}: rows of track {track_id} are not consecutive"));
            } else {
                tracks.push(MpcTrack { track_id, doppler_hz, detections: vec![detection] });
            }
        }
        Ok(tracks)
    }
}

/// The recording and processing tables (poses, odometry, ground truth,
/// GNSS, radar scans, CIR snapshots, MPC and beam-sweep tables), for
/// documentation, tests and the schema check of [`inspect_table_dir`](super::inspect_table_dir);
/// the result tables (some of which `process` writes too) are [`RESULT_TABLES`].
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
    &super::MPC_SNAPSHOTS,
    &super::MPC_TRUTH,
    &super::GROUND_TRUTH_TX,
    &super::GROUND_TRUTH_RX,
    &super::BEAM_SWEEPS_TRACKED,
];

/// Every result table: what `mmtrack analyze` writes (and `reproduce` and
/// `process beam`/`process slam` for the tables they share with it), in the
/// order of `schemas/tables/results.md`.
pub const RESULT_TABLES: &[&TableSpec] = &[
    &super::TRAJECTORY_METRICS,
    &super::DRIFT_PER_LENGTH,
    &super::RELATIVE_POSE_ERRORS,
    &super::MPC_SUMMARY,
    &super::MPC_SET_METRICS,
    &super::MPC_COUNT_DISTRIBUTION,
    &super::MPC_TRACK_POWER_STD,
    &super::MPC_CHI_CLASSES,
    &super::MPC_FIRST_PATH,
    &super::BEAM_RMS_PER_BLOCK,
    &super::BEAM_VALID_TRACKING,
    &super::BEAM_SWEEP_SUMMARY,
    &super::BEAM_SWEEP_POOLED,
    &super::SPEBT_SUMMARY,
    &super::SPEBT_PER_SLOT,
    &super::SPEBT_POOLED,
    &super::ZOECHMANN_NMSE,
    &super::ZOECHMANN_SUMMARY,
    &super::ZOECHMANN_NLOS_ERROR,
    &super::ZOECHMANN_PATH_LABELS,
    &super::GEOMETRIC_PER_EPOCH,
    &super::GEOMETRIC_SUMMARY,
    &super::SLAM_SUMMARY,
    &super::SLAM_PER_EPOCH,
    &super::SLAM_UE,
    &super::SLAM_MAP,
    &super::SLAM_ASSOCIATIONS,
    &super::SLAM_TRUE_SOURCES,
    &super::RUN_COMPARISON,
];
