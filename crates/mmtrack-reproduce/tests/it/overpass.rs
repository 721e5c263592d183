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
