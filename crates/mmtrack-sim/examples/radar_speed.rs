//! Rendering speed of Oxford-size sweeps (400 x 3768) in the default
//! generated city: `cargo run --release -p mmtrack-sim --example radar_speed [scans] [threads]`.

use std::time::Instant;

use mmtrack_sim::radar::{
    ConstantTurn, GeneratorConfig, RadarSimulator, ScanLimits, Sensor, SimOptions, Trajectory, World, generate_world,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let scans: usize = args.next().map_or(Ok(200), |a| a.parse())?;
    let threads: usize = args.next().map_or(Ok(0), |a| a.parse())?;
    // Rendering runs on rayon's global pool; 0 keeps rayon's default (RAYON_NUM_THREADS or all cores).
    rayon::ThreadPoolBuilder::new().num_threads(threads).build_global()?;
    let motion = ConstantTurn { speed_mps: 10.0, yaw_rate_radps: 0.01 };
    let trajectory = Trajectory::constant_turn(motion, 0, scans as f64 * 0.25 + 1.0)?;
    let start = Instant::now();
    let world = World::new(&generate_world(&GeneratorConfig::default(), &trajectory, 5)?)?;
    let world_s = start.elapsed().as_secs_f64();
    let sensor = Sensor::default();
    let limits = ScanLimits { max_scans: Some(scans), max_distance_m: None };
    let start = Instant::now();
    let mut checksum = 0u64;
    let simulator = RadarSimulator::new(&world, &sensor, &trajectory, SimOptions { seed: 5, limits })?;
    let rendered = simulator.len();
    for (scan, _) in simulator {
        checksum = checksum.wrapping_add(scan.power.iter().map(|v| u64::from(*v)).sum::<u64>());
    }
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "{rendered} scans of 400 x 3768 in {seconds:.2} s: {:.1} scans/s (threads {threads}, world of {} surfaces and {} points built in {world_s:.2} s, checksum {checksum})",
        rendered as f64 / seconds,
        world.segment_count(),
        world.point_count()
    );
    Ok(())
}
