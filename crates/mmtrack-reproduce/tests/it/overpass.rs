//! Both EKFs of the Shaham experiment on the simulated overpass link, set up
//! as the experiment sets them up ([`mmtrack_reproduce::shaham::overpass`];
//! the test moved here from mmtrack-beam, which may not depend on the
//! simulator): at high SNR the position-velocity EKF keeps the beam on the
//! vehicle, the angle EKF stays finite; the same seed gives the same numbers.

use mmtrack_beam::{PilotTracker, ProcessModel};
use mmtrack_reproduce::shaham::overpass::{angle_ekf, pv_ekf, track};
use mmtrack_sim::beam::overpass::{OverpassRun, OverpassScenario};

/// Transmit-beam pointing error per tracked block (block 0, the channel
/// estimate, left out), radians.
fn aod_errors(scenario: &OverpassScenario, run: &OverpassRun, tracker: &mut impl PilotTracker) -> Vec<f64> {
    track(scenario, run, tracker).unwrap()[1..].to_vec()
}

/// The speed takes a random-walk step of 0.28 m/s every block, which a pilot
/// barely observes, so even at 30 dB the position error grows like
/// `0.28 dt sqrt(k^3 / 3)`: 0.16 m after 100 blocks, 1.5 deg of AoD at the
/// start geometry, a third of the 4.5 deg half beamwidth.
#[test]
fn both_filters_keep_the_beam_at_high_snr() {
    let scenario = OverpassScenario { snr_db: 30.0, blocks: 100, ..OverpassScenario::default() };
    let half_beamwidth_rad =
        0.5 * scenario.array().unwrap().half_power_beamwidth_rad(scenario.initial_aod_deg.to_radians().abs());
    for run_index in 0..5 {
        let run = scenario.realise(11, run_index).unwrap();
        let mut pv = pv_ekf(&scenario, &run, ProcessModel::Kinematic).unwrap();
        let pv_errors = aod_errors(&scenario, &run, &mut pv);
        let worst = pv_errors.iter().fold(0f64, |m, e| m.max(e.abs()));
        assert!(worst < half_beamwidth_rad, "run {run_index}: PV-EKF error {:.2} deg", worst.to_degrees());
        let angle_errors = aod_errors(&scenario, &run, &mut angle_ekf(&scenario, &run, 0.5).unwrap());
        assert!(angle_errors.iter().all(|e| e.is_finite()));
    }
}

#[test]
fn same_seed_same_errors() {
    let scenario = OverpassScenario { blocks: 50, ..OverpassScenario::default() };
    let run = scenario.realise(5, 2).unwrap();
    let a = aod_errors(&scenario, &run, &mut pv_ekf(&scenario, &run, ProcessModel::Kinematic).unwrap());
    let b = aod_errors(
        &scenario,
        &scenario.realise(5, 2).unwrap(),
        &mut pv_ekf(&scenario, &run, ProcessModel::Kinematic).unwrap(),
    );
    assert_eq!(a, b);
}

/// Why the angle-state EKF holds the beam for 44 blocks at 0 dB, 60 km/h
/// where the paper's +49 % implies about 66 (docs/results/shaham.md): its
/// model, additive random-walk steps of 0.5 deg per block (the paper's
/// `(0.5 pi / 180)^2`), predicts no motion, while on the overpass the AoD
/// drifts by 0.16 deg per block at the start, 0.32 under the bridge. Its
/// error is then mostly lag: at block 50 the mean error is most of the RMS
/// one. On a truth drawn from its own model (same link, pilots, SNR and
/// channel, the angles a random walk of 0.5 deg per block), the same filter
/// holds the beam about twice as long.
#[test]
fn the_angle_ekf_lags_the_overpass_drift_and_holds_longer_on_its_own_model() {
    use mmtrack_beam::valid_tracking::{RmsPerBlock, valid_tracking_blocks};
    use mmtrack_core::Complex64;
    use mmtrack_core::random::{standard_normal, stream};

    let scenario = OverpassScenario { snr_db: 0.0, blocks: 150, ..OverpassScenario::default() };
    let array = scenario.array().unwrap();
    let threshold_rad = 0.5 * array.half_power_beamwidth_rad(scenario.initial_aod_deg.to_radians().abs());
    let (runs, sigma_rad) = (300, 0.5f64.to_radians());
    let sigma_n = (0.5 * scenario.noise_variance()).sqrt();
    let (mut overpass, mut own_model) = (RmsPerBlock::new(scenario.blocks + 1), RmsPerBlock::new(scenario.blocks + 1));
    let mut mean_error_50 = 0.0;
    for run_index in 0..runs {
        let run = scenario.realise(2020, run_index).unwrap();
        let errors = track(&scenario, &run, &mut angle_ekf(&scenario, &run, 0.5).unwrap()).unwrap();
        mean_error_50 += errors[50] / runs as f64;
        overpass.add_run(&errors);
        // The same start and channel; angles and receiver noise drawn here.
        let mut rng = stream(2020, &[0x616e_676c, run_index]);
        let (mut theta, mut phi) = (run.states()[0].aoa_rad(3.0), run.states()[0].aod_rad(3.0));
        let mut tracker = angle_ekf(&scenario, &run, 0.5).unwrap();
        let mut errors = vec![0.0];
        for block in 1..=scenario.blocks {
            theta += sigma_rad * standard_normal(&mut rng);
            phi += sigma_rad * standard_normal(&mut rng);
            let beams = tracker.predict().unwrap();
            let noise = Complex64::new(sigma_n * standard_normal(&mut rng), sigma_n * standard_normal(&mut rng));
            let gain = array.array_factor(beams.rx_steer_u, theta.cos())
                * array.array_factor(beams.tx_steer_u, phi.cos()).conj();
            tracker.update(run.states()[block].alpha * gain + noise).unwrap();
            errors.push(beams.tx_angle_rad() - phi);
        }
        own_model.add_run(&errors);
    }
    let (overpass, own_model) = (overpass.rms_rad(), own_model.rms_rad());
    let on_overpass = valid_tracking_blocks(&overpass, threshold_rad).unwrap();
    let on_own_model = valid_tracking_blocks(&own_model, threshold_rad).unwrap();
    println!(
        "angle-ekf, 0 dB, {runs} runs: valid tracking {on_overpass} blocks on the overpass, {on_own_model} on its own \
         model; at block 50 on the overpass RMS {:.2} deg, mean {:.2} deg",
        overpass[50].to_degrees(),
        mean_error_50.to_degrees()
    );
    // 3000 runs (the experiment): 44 blocks, RMS 5.43 deg, mean 4.47 deg (82 %).
    assert!((40..=48).contains(&on_overpass), "{on_overpass}");
    assert!(mean_error_50 > 0.7 * overpass[50], "lag-dominated: mean {mean_error_50} of RMS {}", overpass[50]);
    assert!(on_own_model as f64 > 1.6 * on_overpass as f64, "{on_own_model} vs {on_overpass}");
}
