//! Both EKFs on the simulated overpass link: at high SNR the position-velocity
//! EKF keeps the beam on the vehicle, the angle EKF stays finite; the same seed
//! gives the same numbers.

use mmtrack_beam::{
    AngleEkf, AngleEkfConfig, PilotTracker, PositionVelocityEkf, PositionVelocityEkfConfig, ProcessModel,
};
use mmtrack_sim::beam::overpass::{OverpassRun, OverpassScenario};

fn pv_ekf(scenario: &OverpassScenario, run: &OverpassRun) -> PositionVelocityEkf {
    let start = run.states()[0];
    let config = PositionVelocityEkfConfig {
        height_m: scenario.height_m,
        elements: scenario.elements,
        block_s: scenario.block_s,
        rho: scenario.rho,
        speed_sigma_mps: scenario.speed_sigma_mps,
        noise_variance: scenario.noise_variance(),
        process_model: ProcessModel::Kinematic,
    };
    PositionVelocityEkf::new(&config, start.distance_m, start.speed_mps, start.alpha).unwrap()
}

fn angle_ekf(scenario: &OverpassScenario, run: &OverpassRun) -> AngleEkf {
    let start = run.states()[0];
    let config = AngleEkfConfig {
        elements: scenario.elements,
        rho: scenario.rho,
        angle_sigma_rad: 0.5f64.to_radians(),
        noise_variance: scenario.noise_variance(),
    };
    AngleEkf::new(&config, start.aoa_rad(scenario.height_m), start.aod_rad(scenario.height_m), start.alpha).unwrap()
}

/// Transmit-beam pointing error per block, radians.
fn aod_errors(scenario: &OverpassScenario, run: &OverpassRun, tracker: &mut impl PilotTracker) -> Vec<f64> {
    (1..=scenario.blocks)
        .map(|k| {
            let beams = tracker.predict().unwrap();
            tracker.update(run.pilot(k, beams.rx_steer_u, beams.tx_steer_u)).unwrap();
            beams.tx_angle_rad() - run.states()[k].aod_rad(scenario.height_m)
        })
        .collect()
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
        let mut pv = pv_ekf(&scenario, &run);
        let pv_errors = aod_errors(&scenario, &run, &mut pv);
        let worst = pv_errors.iter().fold(0f64, |m, e| m.max(e.abs()));
        assert!(worst < half_beamwidth_rad, "run {run_index}: PV-EKF error {:.2} deg", worst.to_degrees());
        let angle_errors = aod_errors(&scenario, &run, &mut angle_ekf(&scenario, &run));
        assert!(angle_errors.iter().all(|e| e.is_finite()));
    }
}

#[test]
fn same_seed_same_errors() {
    let scenario = OverpassScenario { blocks: 50, ..OverpassScenario::default() };
    let run = scenario.realise(5, 2).unwrap();
    let a = aod_errors(&scenario, &run, &mut pv_ekf(&scenario, &run));
    let b = aod_errors(&scenario, &scenario.realise(5, 2).unwrap(), &mut pv_ekf(&scenario, &run));
    assert_eq!(a, b);
}
