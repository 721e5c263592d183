//! Deterministic sample values of every core type, with awkward numbers
//! (negative zero, subnormals, extremes) so round trips are tested bit for bit.

use std::collections::BTreeMap;

use mmtrack_core::{
    AzimuthSample, CirSnapshot, Complex64, GnssFix, GnssFixQuality, MpcDetection, MpcTrack, PolarScan, PolarScanHeader,
    Se2, StampedPose,
};
use mmtrack_io::recording::{RecordingMetadata, TimeBase};

/// The run of a table written by a test: `config` as its run configuration,
/// UNIX time, a test frame.
pub fn run_info(config: &str) -> mmtrack_io::table::RunInfo {
    mmtrack_io::table::RunInfo::new(config, TimeBase::UnixEpoch)
        .with_frame(mmtrack_io::table::Frame::new("test_world", "a test's world frame"))
}

pub const AWKWARD: [f64; 6] = [-0.0, 5e-324, 1.7976931348623157e308, -1.0e-300, std::f64::consts::PI, 0.1];

pub fn poses() -> Vec<StampedPose> {
    (0..7)
        .map(|i| StampedPose {
            t_ns: 1_547_131_046_353_776_000 + i * 250_000_000,
            parent_from_child: Se2::new(
                AWKWARD[i as usize % 6],
                -AWKWARD[(i as usize + 1) % 6],
                AWKWARD[(i as usize + 2) % 6] % 3.0,
            ),
        })
        .collect()
}

pub fn scan(t_ns: i64, azimuths: usize, bins: usize) -> PolarScan {
    let azimuths: Vec<AzimuthSample> = (0..azimuths)
        .map(|a| AzimuthSample {
            t_ns: t_ns + a as i64 * 625_000,
            azimuth_rad: a as f64 * std::f64::consts::TAU / 400.0,
            valid: a % 17 != 3,
        })
        .collect();
    let power = (0..azimuths.len() * bins).map(|i| ((i * 31 + i / 7) % 256) as u8).collect();
    let header =
        PolarScanHeader { t_ns, range_resolution_m: 0.0432, range_offset_m: -0.31, bins_per_azimuth: bins, azimuths };
    PolarScan::new(header, power).expect("sample scan is consistent")
}

pub fn gnss_fixes() -> Vec<GnssFix> {
    vec![
        GnssFix {
            t_ns: 1_580_000_000_000_000_000,
            latitude_deg: 37.422_131_5,
            longitude_deg: -122.084_051_2,
            altitude_m: Some(-0.0),
            horizontal_sigma_m: Some(0.7),
            num_satellites: Some(23),
            quality: GnssFixQuality::RtkFixed,
        },
        GnssFix {
            t_ns: 1_580_000_001_000_000_000,
            latitude_deg: -89.999_999_999,
            longitude_deg: 179.999_999_999,
            altitude_m: None,
            horizontal_sigma_m: None,
            num_satellites: None,
            quality: GnssFixQuality::Unknown,
        },
    ]
}

pub fn cir(set_index: u64, snapshot_index: u32, taps: usize) -> CirSnapshot {
    CirSnapshot {
        t_ns: 1_000_000 + set_index as i64 * 10_000_000 + i64::from(snapshot_index) * 717_000,
        set_index,
        snapshot_index,
        tx_antenna: snapshot_index % 4,
        rx_antenna: 3,
        carrier_hz: 5.7e9,
        tap_spacing_s: 1e-9,
        delay_offset_s: -2.5e-9,
        taps: (0..taps).map(|k| Complex64::new(AWKWARD[k % 6] * 1e-3, (k as f64).sin() * 1e-7)).collect(),
        // Present on even sets, absent on odd ones: both sides of the optional field round-trip.
        first_path_hint_s: set_index.is_multiple_of(2).then_some(3.25e-9),
    }
}

pub fn detections() -> Vec<MpcDetection> {
    (0..5)
        .map(|i| MpcDetection {
            t_ns: 1_000 * i,
            set_index: i as u64 / 2,
            snapshot_index: (i % 2) as u32,
            delay_s: 12.3456789e-9 + i as f64 * 1e-11,
            amplitude: Complex64::new(1e-6 * (i + 1) as f64, -3e-7),
        })
        .collect()
}

pub fn tracks() -> Vec<MpcTrack> {
    let d = detections();
    vec![
        MpcTrack { track_id: 7, doppler_hz: Some(-123.25), detections: d[..3].to_vec() },
        MpcTrack { track_id: 2, doppler_hz: None, detections: d[3..].to_vec() },
    ]
}

pub fn metadata() -> RecordingMetadata {
    RecordingMetadata {
        sequence_id: "test-seq".into(),
        source: "unit test".into(),
        time_base: TimeBase::UnixEpoch,
        extra: BTreeMap::from([("radar.model".to_string(), "CTS350-X".to_string())]),
    }
}

pub fn mpc_truth() -> Vec<mmtrack_core::MpcTruth> {
    (0..12u64)
        .map(|i| mmtrack_core::MpcTruth {
            t_ns: 1_000_000 + i as i64 * 717_000,
            set_index: i / 6,
            snapshot_index: (i % 6) as u32,
            path_id: [0, 100, 1003, u64::MAX][i as usize % 4],
            delay_s: 2.6e-7 + AWKWARD[i as usize % 6] * 1e-12,
            amplitude: Complex64::new(AWKWARD[(i as usize + 1) % 6], -AWKWARD[(i as usize + 3) % 6]),
            doppler_hz: [-0.0, 105.6, -3.3e3, 5e-324][i as usize % 4],
        })
        .collect()
}
