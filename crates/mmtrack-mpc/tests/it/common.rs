//! Synthetic channels for the tests: a few paths through a known pulse plus
//! seeded complex white noise, on the signal model of `mmtrack_core::sounder`.

use mmtrack_core::random::standard_normal;
use mmtrack_core::sounder::{SounderBand, cir_from_spectrum};
use mmtrack_core::{CirSnapshot, Complex64};
use mmtrack_mpc::SounderPulse;
use rand::SeedableRng;
use rand_pcg::Pcg64;

/// 5.7 GHz carrier, as the paper's sounder.
pub const CARRIER_HZ: f64 = 5.7e9;
/// 1 GHz bandwidth: 1 ns taps.
pub const TAP_S: f64 = 1e-9;

pub fn band(taps: usize) -> SounderBand {
    SounderBand::new(taps, TAP_S).unwrap()
}

/// One path: delay relative to tap 0 (seconds), power (dB) and phase (rad).
#[derive(Clone, Copy, Debug)]
pub struct Path {
    pub delay_s: f64,
    pub power_db: f64,
    pub phase_rad: f64,
}

impl Path {
    pub fn amplitude(&self) -> Complex64 {
        Complex64::from_polar(10f64.powf(self.power_db / 20.0), self.phase_rad)
    }
}

/// A snapshot of `paths` through `pulse`, plus white noise of mean tap power
/// `noise_db` (none if `None`).
pub fn snapshot(
    band: &SounderBand,
    pulse: &SounderPulse,
    paths: &[Path],
    noise_db: Option<f64>,
    rng: &mut Pcg64,
    t_ns: i64,
) -> CirSnapshot {
    let mut spectrum = vec![Complex64::default(); band.taps()];
    for path in paths {
        band.add_path(&mut spectrum, pulse.spectrum(), path.delay_s, path.amplitude());
    }
    let mut taps = cir_from_spectrum(&spectrum);
    if let Some(noise_db) = noise_db {
        let sigma = (10f64.powf(noise_db / 10.0) / 2.0).sqrt();
        for tap in &mut taps {
            *tap += Complex64::new(sigma * standard_normal(rng), sigma * standard_normal(rng));
        }
    }
    CirSnapshot {
        t_ns,
        set_index: 0,
        snapshot_index: 0,
        tx_antenna: 0,
        rx_antenna: 0,
        carrier_hz: CARRIER_HZ,
        tap_spacing_s: band.tap_spacing_s(),
        delay_offset_s: 0.0,
        taps,
        first_path_hint_s: None,
    }
}

pub fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}
