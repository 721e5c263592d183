//! Detection on real channel measurements from `../shared/realdata` (never
//! copied into the repository):
//!
//! - UWB: 252 CIRs of a Decawave DW1000 (channel 2, 1016 taps of 1.0016 ns),
//!   Kolakowski, Zenodo 10.5281/zenodo.4742391, CC BY 4.0. Our first detected
//!   path is compared with the chip's own leading-edge index HLP.
//! - 60 GHz: a measured static indoor 4x4 MIMO channel (Brno University of
//!   Technology, from jirimilos/802.11ad-phy-sim, MIT; Liu, Blumenstein,
//!   Perovic, Di Renzo and Springer, IEEE Trans. Commun. 66(1), 2018):
//!   detected MPCs per link.

use std::path::PathBuf;

use mmtrack_core::CirSnapshot;
use mmtrack_core::sounder::SounderBand;
use mmtrack_ingest::cir::{DecawaveConfig, MatCirLayout, read_decawave_log, read_mat_cir_file};
use mmtrack_mpc::{DetectionConfig, Detector, NoiseFloor, SounderPulse, first_path};

fn realdata(folder: &str) -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/realdata").join(folder);
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("skipped: real data not found at {}", dir.display());
        None
    }
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

/// Leading edge: the earliest detection this far above the floor, see
/// [`first_path`]. 12 dB: the largest of ~750 exponential noise taps before
/// the first path lies about 8.2 dB above their mean, and the DW1000
/// accumulator's noise is not stationary (32-tap window means of the first
/// frame range over 40.5..47.4 dB), so about 3 dB more.
const FIRST_PATH_MARGIN_DB: f64 = 12.0;

/// The DW1000 places the first path near accumulator tap 745 (HLP median
/// 747.5 in this log): its first 600 taps hold noise only, which is the
/// "part of the impulse response where no MPCs occur" the paper estimates
/// the floor in. The quietest-windows default would pick the accumulator's
/// quietest stretches, 3-4 dB below the noise around the first path.
fn dw1000_detection_config(tap_spacing_s: f64) -> DetectionConfig {
    DetectionConfig {
        noise_floor: NoiseFloor::DelayRange { start_s: 0.0, end_s: 600.0 * tap_spacing_s },
        ..DetectionConfig::default()
    }
}

#[test]
fn uwb_first_path_against_the_chips_leading_edge() {
    let Some(dir) = realdata("uwb-cirs-2018") else { return };
    let log = read_decawave_log(&dir.join("1.log"), &DecawaveConfig::default()).unwrap();
    let snapshots: Vec<_> = log.frames.iter().map(|frame| frame.cir.clone()).collect();
    assert_eq!(snapshots.len(), 252);
    let band = SounderBand::new(snapshots[0].taps.len(), snapshots[0].tap_spacing_s).unwrap();
    // Channel 2: 499.2 MHz wide, sampled at 998.4 MHz; the DW1000 transmit
    // pulse fills the channel (802.15.4a mask); roll-off 0.5 is our model.
    let pulse = SounderPulse::raised_cosine(&band, 499.2e6, 0.5).unwrap();
    let detector = Detector::new(dw1000_detection_config(band.tap_spacing_s()), band.tap_spacing_s(), &pulse).unwrap();
    let mut differences_ns = Vec::new();
    let mut detections = 0;
    for (index, snapshot) in snapshots.iter().enumerate() {
        let found = detector.detect(snapshot, index).unwrap();
        detections += found.detections.len();
        let hint_s = snapshot.first_path_hint_s.unwrap();
        if index < 2 {
            let mut near: Vec<_> = found.detections.iter().filter(|d| (d.delay_s - hint_s).abs() < 12e-9).collect();
            near.sort_by(|a, b| a.delay_s.total_cmp(&b.delay_s));
            for d in near {
                println!(
                    "  cir {index}: {:+6.2} ns from HLP, {:5.1} dB above floor",
                    (d.delay_s - hint_s) * 1e9,
                    d.power_db() - found.noise_floor_db
                );
            }
        }
        if let Some(first) = first_path(&found, FIRST_PATH_MARGIN_DB) {
            differences_ns.push((first.delay_s - hint_s) * 1e9);
        }
    }
    assert_eq!(differences_ns.len(), 252, "every CIR has a first path");
    let mut absolute: Vec<f64> = differences_ns.iter().map(|d| d.abs()).collect();
    absolute.sort_by(f64::total_cmp);
    let mut signed = differences_ns.clone();
    signed.sort_by(f64::total_cmp);
    let (median_abs, p90_abs) = (percentile(&absolute, 0.5), percentile(&absolute, 0.9));
    println!(
        "UWB DW1000, 252 CIRs: {:.1} MPCs per CIR; first path - HLP: median {:+.2} ns, |median| {median_abs:.2} ns, 90th percentile of |difference| {p90_abs:.2} ns (target: median within 1 ns: {})",
        detections as f64 / 252.0,
        percentile(&signed, 0.5),
        if percentile(&signed, 0.5).abs() <= 1.0 { "met" } else { "missed" },
    );
    // Regression bound, not the target: the README reports the measured
    // median (-1.58 ns) against the 1 ns target and why. The detections
    // printed above show it: with a modelled raised-cosine pulse narrower than
    // the DW1000's, search and subtract leaves residues about 1.5 and 3.4 ns
    // ahead of the strongest early peak (~19 and ~30 dB below it) in every
    // frame; a measured (back-to-back) pulse would remove them.
    assert!(percentile(&signed, 0.5).abs() <= 2.0, "median difference {} ns", percentile(&signed, 0.5));
}

/// The 16 links of the 60 GHz MIMO sample, `None` when the data is absent.
fn mimo_60ghz_links() -> Option<Vec<CirSnapshot>> {
    let dir = realdata("but-60ghz-mimo")?;
    // 1001 CTF bins 10 MHz apart (55-65 GHz): taps 1 / (1001 x 10 MHz) = 99.9 ps apart.
    let layout = MatCirLayout {
        variable: "CIR_mat".into(),
        carrier_hz: 60e9,
        tap_spacing_s: 1.0 / (1001.0 * 10e6),
        delay_offset_s: 0.0,
        t_ns: 0,
        tap_axis: 2,
        tx_axis: Some(1),
        rx_axis: Some(0),
        allow_real: false,
    };
    let cirs = read_mat_cir_file(&dir.join("CIR.mat"), &layout).unwrap();
    assert_eq!(cirs.len(), 16);
    Some(cirs)
}

fn mimo_60ghz_detector(cirs: &[CirSnapshot]) -> Detector {
    let band = SounderBand::new(cirs[0].taps.len(), cirs[0].tap_spacing_s).unwrap();
    Detector::new(DetectionConfig::default(), band.tap_spacing_s(), &SounderPulse::flat(&band)).unwrap()
}

#[test]
fn mimo_60ghz_mpcs_per_link() {
    let Some(cirs) = mimo_60ghz_links() else { return };
    let detector = mimo_60ghz_detector(&cirs);
    println!(
        "60 GHz 4x4 MIMO: link (tx, rx): MPCs (within 30 dB of the strongest), strongest path delay and power, floor"
    );
    let mut strongest_delays_ns = Vec::new();
    for (index, cir) in cirs.iter().enumerate() {
        let found = detector.detect(cir, index).unwrap();
        let strongest = &found.detections[0];
        println!(
            "  ({}, {}): {:3} MPCs ({:2}), strongest at {:6.2} ns {:6.1} dB, floor {:6.1} dB",
            cir.tx_antenna,
            cir.rx_antenna,
            found.detections.len(),
            found.detections.iter().filter(|d| d.power_db() > strongest.power_db() - 30.0).count(),
            strongest.delay_s * 1e9,
            strongest.power_db(),
            found.noise_floor_db
        );
        strongest_delays_ns.push(strongest.delay_s * 1e9);
    }
    // A static 4x4 array a few centimetres across: every link sees the same
    // strongest path within a few array sizes of delay (1 ns = 30 cm).
    let spread = strongest_delays_ns.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - strongest_delays_ns.iter().copied().fold(f64::INFINITY, f64::min);
    println!("  spread of the strongest path's delay over the 16 links: {spread:.2} ns");
    assert!(spread < 1.0, "{strongest_delays_ns:?}");
}

#[test]
fn mimo_60ghz_detections_keep_out_of_each_others_blocked_range() {
    let Some(cirs) = mimo_60ghz_links() else { return };
    let detector = mimo_60ghz_detector(&cirs);
    let half_width_s = detector.blocked_width_s() / 2.0;
    let (mut closest_s, mut inside, mut pairs) = (f64::INFINITY, 0, 0);
    for (index, cir) in cirs.iter().enumerate() {
        let mut delays: Vec<f64> = detector.detect(cir, index).unwrap().detections.iter().map(|d| d.delay_s).collect();
        delays.sort_by(f64::total_cmp);
        for gap_s in delays.windows(2).map(|w| w[1] - w[0]) {
            pairs += 1;
            inside += usize::from(gap_s <= half_width_s);
            closest_s = closest_s.min(gap_s);
        }
    }
    println!(
        "60 GHz 4x4 MIMO: {pairs} adjacent detection pairs, {inside} within half the blocked range ({:.4} ns), closest {:.4} ns",
        half_width_s * 1e9,
        closest_s * 1e9
    );
    // Exact, as on the synthetic channels (detect.rs).
    assert!(closest_s > half_width_s, "closest pair {closest_s} s, half blocked width {half_width_s} s");
}
