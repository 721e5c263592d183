//! Behaviour of the radar simulator: geometry conventions, occlusion, motion
//! distortion, determinism, the world generator and the calibration regime.

use mmtrack_core::{PolarScan, Se2, StampedPose};
use mmtrack_sim::radar::{
    ConstantTurn, GeneratorConfig, Material, RadarSimulator, ReflectorSpec, ScanLimits, Sensor, SimOptions, Trajectory,
    World, distance_to_path_m, generate_world,
};

/// A quiet sensor (no speckle variation, no ghosts) for geometry tests.
fn sensor(bins: usize, resolution_m: f64) -> Sensor {
    Sensor { bins, range_resolution_m: resolution_m, multipath_ghosts: false, ..Sensor::default() }
}

fn still(seconds: f64) -> Trajectory {
    Trajectory::constant_turn(ConstantTurn { speed_mps: 0.0, yaw_rate_radps: 0.0 }, 0, seconds).unwrap()
}

fn render(
    world: &World,
    sensor: &Sensor,
    trajectory: &Trajectory,
    seed: u64,
    scans: usize,
) -> Vec<(PolarScan, StampedPose)> {
    let options = SimOptions { seed, limits: ScanLimits { max_scans: Some(scans), max_distance_m: None } };
    RadarSimulator::new(world, sensor, trajectory, options).unwrap().collect()
}

fn peak_bin(row: &[u8]) -> usize {
    row.iter().enumerate().max_by_key(|(i, v)| (**v, std::cmp::Reverse(*i))).unwrap().0
}

fn pole(x_m: f64, y_m: f64) -> ReflectorSpec {
    ReflectorSpec::Pole { x_m, y_m, strength_db: None }
}

fn wall(a: [f64; 2], b: [f64; 2], material: Material) -> ReflectorSpec {
    ReflectorSpec::Wall { a_m: a, b_m: b, material, strength_db: None }
}

#[test]
fn a_pole_on_the_left_appears_at_270_degrees_and_its_range() {
    // Vehicle at the origin facing +x; the pole 20 m to its left, (0, +20) in the vehicle frame.
    let world = World::new(&[pole(0.0, 20.0)]).unwrap();
    let s = sensor(600, 0.05);
    let scans = render(&world, &s, &still(1.0), 1, 1);
    let scan = &scans[0].0;
    let (best_row, best) =
        (0..400).map(|a| (a, scan.row(a).unwrap().iter().copied().max().unwrap())).max_by_key(|x| x.1).unwrap();
    assert_eq!(best_row, 300, "270 deg of 400 rows is row 300 (peak {best})");
    assert!((scan.header.azimuths[300].azimuth_rad.to_degrees() - 270.0).abs() < 1e-9);
    // 20 m / 0.05 m = bin 400; the profile (sigma 2.7 bins) and speckle keep the peak within 2 bins.
    let bin = peak_bin(scan.row(300).unwrap());
    assert!(bin.abs_diff(400) <= 2, "peak at bin {bin}");
    // The beam (1.8 deg, two-way -6 dB at +-0.9 deg = 1 row) spreads it over neighbouring rows only.
    let level = |a: usize| scan.row(a).unwrap()[400];
    assert!(level(299) > 40 && level(301) > 40, "{} {}", level(299), level(301));
    assert!(level(310) < 40 && level(100) < 40, "{} {}", level(310), level(100));
}

#[test]
fn a_wall_hides_the_pole_behind_it_and_vegetation_only_dims_it() {
    let s = sensor(800, 0.05);
    let open = render(&World::new(&[pole(30.0, 0.0)]).unwrap(), &s, &still(1.0), 2, 1);
    let seen = open[0].0.row(0).unwrap()[600];
    assert!(seen > 70, "pole at 30 m in the open: {seen}");
    let behind_wall = World::new(&[pole(30.0, 0.0), wall([15.0, -5.0], [15.0, 5.0], Material::Building)]).unwrap();
    let hidden = render(&behind_wall, &s, &still(1.0), 2, 1);
    let row = hidden[0].0.row(0).unwrap();
    assert!(row[300] > 80, "the wall itself at 15 m: {}", row[300]);
    // Behind an opaque wall only the noise floor is left (its 99.9th percentile is about 30 counts).
    let behind = row[580..620].iter().copied().max().unwrap();
    assert!(behind < 35, "pole behind the wall still visible: {behind}");
    let behind_hedge = World::new(&[pole(30.0, 0.0), wall([15.0, -5.0], [15.0, 5.0], Material::Vegetation)]).unwrap();
    let dimmed = render(&behind_hedge, &s, &still(1.0), 2, 1)[0].0.row(0).unwrap()[600];
    // Two-way transmission 0.35^2 = -9.1 dB, about 9 counts, with the same speckle.
    assert!(dimmed > 45 && dimmed < seen, "through vegetation: {dimmed} (open {seen})");
}

#[test]
fn a_moving_sensor_sees_a_static_wall_skewed_over_the_sweep() {
    // Driving at 20 m/s towards a wall across the road 50 m ahead: row 0 (t = 0) sees it
    // at 50 m, row 399 (azimuth 359.1 deg, t = 0.249 s) 20 * 0.249 = 4.99 m closer.
    let world = World::new(&[wall([50.0, -100.0], [50.0, 100.0], Material::Building)]).unwrap();
    let s = sensor(1300, 0.05);
    let trajectory = Trajectory::constant_turn(ConstantTurn { speed_mps: 20.0, yaw_rate_radps: 0.0 }, 0, 1.0).unwrap();
    let scans = render(&world, &s, &trajectory, 3, 1);
    let scan = &scans[0].0;
    let first_m = peak_bin(scan.row(0).unwrap()) as f64 * 0.05;
    let last_m = peak_bin(scan.row(399).unwrap()) as f64 * 0.05;
    let t_last_s = (scan.header.azimuths[399].t_ns - scan.header.t_ns) as f64 * 1e-9;
    let expected_last_m = (50.0 - 20.0 * t_last_s) / (0.9f64.to_radians()).cos();
    // Tolerance: the peak of a speckled Gaussian profile sits within 2 bins (0.1 m).
    assert!((first_m - 50.0).abs() <= 0.1, "row 0: {first_m}");
    assert!((last_m - expected_last_m).abs() <= 0.1, "row 399: {last_m}, expected {expected_last_m}");
    // The ground truth is the pose at the stamp (first azimuth).
    assert_eq!(scans[0].1.parent_from_child, Se2::new(0.0, 0.0, 0.0));
}

fn city_trajectory() -> Trajectory {
    Trajectory::constant_turn(ConstantTurn { speed_mps: 10.0, yaw_rate_radps: 0.02 }, 0, 20.0).unwrap()
}

#[test]
fn same_seed_same_bytes_for_any_thread_count_and_a_new_seed_differs() {
    let trajectory = city_trajectory();
    let world = World::new(&generate_world(&GeneratorConfig::default(), &trajectory, 9).unwrap()).unwrap();
    let s = Sensor { bins: 400, ..Sensor::default() };
    let run = |seed, threads| -> Vec<(PolarScan, StampedPose)> {
        let limits = ScanLimits { max_scans: Some(5), max_distance_m: None };
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| RadarSimulator::new(&world, &s, &trajectory, SimOptions { seed, limits }).unwrap().collect())
    };
    let one = run(9, 1);
    assert_eq!(one.len(), 5);
    assert!(one == run(9, 1) && one == run(9, 3), "not deterministic");
    assert!(one != run(10, 1));
    // Consecutive sweeps of the scene are similar (shared speckle and geometry) but not identical.
    assert_ne!(one[0].0.power, one[1].0.power);
}

#[test]
fn the_generator_is_deterministic_and_keeps_the_road_clear() {
    // A drive with two sharp 90 degree turns and a return along its own path.
    let corners: [(f64, f64); 5] = [(0.0, 0.0), (200.0, 0.0), (200.0, 150.0), (0.0, 150.0), (0.0, 10.0)];
    let poses: Vec<StampedPose> = corners
        .windows(2)
        .flat_map(|w| {
            let (a, b) = (w[0], w[1]);
            let yaw = (b.1 - a.1).atan2(b.0 - a.0);
            (0..20).map(move |k| {
                let f = k as f64 / 20.0;
                Se2::new(a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1), yaw)
            })
        })
        .enumerate()
        .map(|(i, p)| StampedPose { t_ns: i as i64 * 500_000_000, parent_from_child: p })
        .collect();
    let trajectory = Trajectory::from_poses(poses).unwrap();
    let config = GeneratorConfig::default();
    let reflectors = generate_world(&config, &trajectory, 4).unwrap();
    assert_eq!(reflectors, generate_world(&config, &trajectory, 4).unwrap());
    assert_ne!(reflectors, generate_world(&config, &trajectory, 5).unwrap());
    let world = World::new(&reflectors).unwrap();
    assert!(
        world.segment_count() > 300 && world.point_count() > 50,
        "{} {}",
        world.segment_count(),
        world.point_count()
    );
    // Every metre of the path is at least clearance_m from every reflector (cars: their body).
    let path = trajectory.path_samples(0.5);
    let nearest = path.iter().map(|p| world.distance_to_nearest_m([p.x_m, p.y_m])).fold(f64::INFINITY, f64::min);
    assert!(nearest >= config.clearance_m, "a reflector {nearest:.2} m from the path");
    // And the street is lined: half of the path has a reflector within 20 m.
    let lined = path.iter().filter(|p| world.distance_to_nearest_m([p.x_m, p.y_m]) < 20.0).count();
    assert!(lined * 2 > path.len(), "{lined} of {}", path.len());
    assert!(distance_to_path_m([100.0, 0.0], &path) < 1e-9);
}

/// Statistics of the real CTS350-X scans this model is calibrated to (see the
/// radar module docs): K = 3 strongest per azimuth with power >= 55 in 5-100 m
/// keep 1199 points per scan, 35 % of all bins are 0 counts.
#[test]
fn calibration_regime_matches_the_real_scans() {
    let trajectory = city_trajectory();
    let world = World::new(&generate_world(&GeneratorConfig::default(), &trajectory, 5).unwrap()).unwrap();
    let s = Sensor::default();
    let simulator =
        RadarSimulator::new(&world, &s, &trajectory, SimOptions { seed: 5, ..SimOptions::default() }).unwrap();
    let (lo, hi) = ((5.0 / 0.0432) as usize, (100.0 / 0.0432) as usize);
    let (mut kept_sum, mut zeros_sum) = (0, 0.0);
    for index in [10, 30, 50, 70] {
        let (scan, _) = simulator.render(index).unwrap();
        let kept: usize = (0..400)
            .map(|a| {
                let mut row = scan.row(a).unwrap()[lo..hi].to_vec();
                row.sort_unstable();
                row.iter().rev().take(3).filter(|v| **v >= 55).count()
            })
            .sum();
        let zeros = scan.power.iter().filter(|v| **v == 0).count() as f64 / scan.power.len() as f64;
        kept_sum += kept;
        zeros_sum += zeros;
    }
    // Real: 1199 and 0.35. The simulated mean over generated scenes is about 1030 and
    // 0.35 (module docs); single scenes spread by about +-150 points.
    let (kept, zeros) = (kept_sum / 4, zeros_sum / 4.0);
    assert!((900..=1200).contains(&kept), "k-strongest kept {kept} per scan");
    assert!((0.30..=0.40).contains(&zeros), "share of zero counts {zeros}");
}

#[test]
fn bad_sensors_and_cuts_are_named() {
    let world = World::new(&[]).unwrap();
    let t = still(1.0);
    let check = |s: Sensor, field: &str| {
        let err = RadarSimulator::new(&world, &s, &t, SimOptions::default()).err().unwrap();
        assert!(err.to_string().contains(field), "{err}");
    };
    check(Sensor { range_resolution_m: -0.1, ..Sensor::default() }, "sensor.range_resolution_m: -0.1 is invalid");
    check(Sensor { azimuths: 0, ..Sensor::default() }, "sensor.azimuths");
    check(Sensor { speckle_static_fraction: 1.5, ..Sensor::default() }, "sensor.speckle_static_fraction");
    let limits = ScanLimits { max_scans: None, max_distance_m: Some(-1.0) };
    let err = RadarSimulator::new(&world, &Sensor::default(), &t, SimOptions { limits, ..SimOptions::default() })
        .err()
        .unwrap();
    assert!(err.to_string().contains("max_distance_m"), "{err}");
}

#[test]
fn multipath_ghosts_appear_behind_a_facade_and_can_be_switched_off() {
    // A facade 10 m ahead (mirrors the beam straight back) and a building
    // front 15 m behind: the ghost of the rear front sits at 10 + 25 = 35 m
    // in the forward row, where nothing real is.
    let world = World::new(&[
        wall([10.0, -30.0], [10.0, 30.0], Material::Building),
        wall([-15.0, -30.0], [-15.0, 30.0], Material::Building),
    ])
    .unwrap();
    let forward_level_at = |ghosts: bool, range_m: f64| {
        let s = Sensor { bins: 900, range_resolution_m: 0.05, multipath_ghosts: ghosts, ..Sensor::default() };
        let scans = render(&world, &s, &still(1.0), 3, 1);
        let bin = (range_m / 0.05).round() as usize;
        // Rows around 0 deg (forward), the best of +-3 bins.
        (0..3).flat_map(|a| scans[0].0.row(a).unwrap()[bin - 3..=bin + 3].to_vec()).max().unwrap()
    };
    let with = forward_level_at(true, 35.0);
    let without = forward_level_at(false, 35.0);
    assert!(with >= without + 10, "ghost {with} counts vs {without} without ghosts");
    let floor = forward_level_at(true, 30.0);
    assert!(with >= floor + 10, "ghost {with} counts vs floor {floor} at 30 m");
    assert!(Sensor::default().multipath_ghosts, "on by default; `multipath_ghosts = false` in [sensor] turns them off");
}
