//! The filter on simulated worlds.

use mmtrack_core::slam::{PathOrigin, norm3, sub3};
use mmtrack_core::wrap_angle_rad;
use mmtrack_sim::slam::{SlamRun, SlamScenario};
use mmtrack_slam::{SlamConfig, SlamFilter, SourceStatus};

/// Runs the filter over a run; returns per-epoch (position error, heading error, bias error) and the filter.
fn run(run: &SlamRun, config: SlamConfig, seed: u64) -> (Vec<[f64; 3]>, SlamFilter) {
    let prior = run.truth[0].ue;
    let mut filter = SlamFilter::new(config, prior, seed).unwrap();
    let mut errors = Vec::new();
    for (epoch, truth) in run.epochs.iter().zip(&run.truth) {
        let report = filter.step(epoch).unwrap();
        let e = report.estimate.state;
        errors.push([
            norm3(sub3(e.position_m, truth.ue.position_m)),
            wrap_angle_rad(e.heading_rad - truth.ue.heading_rad).abs(),
            (e.clock_bias_m - truth.ue.clock_bias_m).abs(),
        ]);
    }
    (errors, filter)
}

#[test]
#[ignore = "diagnostic: prints one paper run (cargo test --release -- --ignored --nocapture)"]
fn diagnostic_paper_run() {
    let scenario = SlamScenario::default();
    let r = scenario.realise(1, 0).unwrap();
    let (errors, filter) = run(&r, SlamConfig::default(), 1);
    for (k, e) in errors.iter().enumerate() {
        let n_va = filter
            .sources()
            .iter()
            .filter(|s| s.status == SourceStatus::VirtualAnchor && s.confirmed_epoch.is_some_and(|c| c <= k))
            .count();
        println!("{k:3} pos {:.3} head {:.4} bias {:.3} va {n_va}", e[0], e[1], e[2]);
    }
    for s in filter.sources() {
        println!("{:?} {:?} {:?} seen {} conf {:?}", s.id, s.status, s.belief.mean_m, s.sightings, s.confirmed_epoch);
    }
    println!("true VAs {:?}", r.world.virtual_anchors_m);
    println!("true SPs {:?}", r.world.scattering_points_m);
    let _ = PathOrigin::Clutter;
}
