//! The trackers of the Shaham experiment set up on a simulated overpass
//! run, and the pointing error they achieve on it.
//!
//! Shared by the experiment and by the tests of the trackers (which used
//! to copy it): the set-up needs the simulator's types, and mmtrack-beam
//! may not depend on mmtrack-sim, so it lives here.

use mmtrack_beam::{
    AngleEkf, AngleEkfConfig, PilotTracker, PositionVelocityEkf, PositionVelocityEkfConfig, ProcessModel,
};
use mmtrack_sim::beam::overpass::{OverpassRun, OverpassScenario};

/// The position-velocity EKF of Shaham et al. 2020 with `model`, started
/// from the true state of block 0 (the "channel estimate").
///
/// # Errors
/// The scenario's parameters are not a valid filter configuration.
pub fn pv_ekf(
    scenario: &OverpassScenario,
    run: &OverpassRun,
    model: ProcessModel,
) -> anyhow::Result<PositionVelocityEkf> {
    let start = run.states()[0];
    let config = PositionVelocityEkfConfig {
        height_m: scenario.height_m,
        elements: scenario.elements,
        block_s: scenario.block_s,
        rho: scenario.rho,
        speed_sigma_mps: scenario.speed_sigma_mps,
        noise_variance: scenario.noise_variance(),
        process_model: model,
    };
    Ok(PositionVelocityEkf::new(&config, start.distance_m, start.speed_mps, start.alpha)?)
}

/// The angle-state EKF of Va et al. 2016 with additive angle noise of
/// `angle_sigma_deg` per block, started from the true angles of block 0.
///
/// # Errors
/// The scenario's parameters are not a valid filter configuration.
pub fn angle_ekf(scenario: &OverpassScenario, run: &OverpassRun, angle_sigma_deg: f64) -> anyhow::Result<AngleEkf> {
    let start = run.states()[0];
    let config = AngleEkfConfig {
        elements: scenario.elements,
        rho: scenario.rho,
        angle_sigma_rad: angle_sigma_deg.to_radians(),
        noise_variance: scenario.noise_variance(),
    };
    let h = scenario.height_m;
    Ok(AngleEkf::new(&config, start.aoa_rad(h), start.aod_rad(h), start.alpha)?)
}

/// Pointing error of the transmit beam per block, radians: block 0 is the
/// channel estimate (error 0), then each block's beam, pointed from the
/// prediction, minus the true AoD.
///
/// # Errors
/// A tracker step fails.
pub fn track(
    scenario: &OverpassScenario,
    run: &OverpassRun,
    tracker: &mut impl PilotTracker,
) -> anyhow::Result<Vec<f64>> {
    let mut errors = Vec::with_capacity(scenario.blocks + 1);
    errors.push(0.0);
    for block in 1..=scenario.blocks {
        let beams = tracker.predict()?;
        tracker.update(run.pilot(block, beams.rx_steer_u, beams.tx_steer_u))?;
        errors.push(beams.tx_angle_rad() - run.states()[block].aod_rad(scenario.height_m));
    }
    Ok(errors)
}
