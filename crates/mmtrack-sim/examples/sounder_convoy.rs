//! Speed and channel statistics of the default convoy run (the paper's
//! set-up): `cargo run --release -p mmtrack-sim --example sounder_convoy [sets] [threads]`.

use std::collections::BTreeMap;
use std::time::Instant;

use mmtrack_sim::sounder::{ConvoyConfig, ConvoySimulator, PathKind, PulseModel};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let sets: usize = args.next().map_or(Ok(1666), |a| a.parse())?;
    let threads: usize = args.next().map_or(Ok(0), |a| a.parse())?;
    // Rendering runs on rayon's global pool; 0 keeps rayon's default (RAYON_NUM_THREADS or all cores).
    rayon::ThreadPoolBuilder::new().num_threads(threads).build_global()?;
    let mut config = ConvoyConfig { sets, ..ConvoyConfig::default() };
    config.sounder.pulse = PulseModel::measured_like();
    let start = Instant::now();
    let simulator = ConvoySimulator::new(&config, 5)?;
    let (cars, scatterers) = (simulator.traffic_cars(), simulator.diffuse_scatterers());
    let mut per_kind: BTreeMap<String, (usize, f64)> = BTreeMap::new();
    let (mut snapshots, mut truth_power, mut cir_power, mut ids) =
        (0usize, 0.0, 0.0, std::collections::BTreeSet::new());
    let mut first_distance = None;
    let mut last_distance = 0.0;
    for set in simulator {
        let (tx, rx) = (set.tx_pose.parent_from_child, set.rx_pose.parent_from_child);
        let d = (tx.x_m - rx.x_m).hypot(tx.y_m - rx.y_m);
        first_distance.get_or_insert(d);
        last_distance = d;
        snapshots += set.snapshots.len();
        for cir in &set.snapshots {
            // Signal power: all taps minus the noise floor's share.
            cir_power += cir.taps.iter().map(|t| t.norm_sqr()).sum::<f64>() - 1e-14 * cir.taps.len() as f64;
        }
        for t in &set.truth {
            let entry = per_kind.entry(format!("{:?}", PathKind::of(t.path_id))).or_insert((0, 0.0));
            entry.0 += 1;
            entry.1 += t.power_db();
            truth_power += t.amplitude.norm_sqr();
            ids.insert(t.path_id);
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "{sets} sets ({snapshots} snapshots of 512 taps) in {seconds:.2} s: {:.0} snapshots/s",
        snapshots as f64 / seconds
    );
    println!(
        "{cars} traffic cars, {scatterers} diffuse scatterers; distance {:.1} -> {last_distance:.1} m",
        first_distance.unwrap_or(0.0)
    );
    for (kind, (n, sum_db)) in &per_kind {
        println!("{kind}: {n} truth entries, mean power {:.1} dB", sum_db / *n as f64);
    }
    println!("distinct path ids: {}", ids.len());
    println!("specular (truth) share of the channel power: {:.1} dB", 10.0 * (truth_power / cir_power).log10());
    Ok(())
}
