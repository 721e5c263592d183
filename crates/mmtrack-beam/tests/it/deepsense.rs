//! The beam-sweep trackers on real 60 GHz vehicle beam sweeps: DeepSense 6G
//! scenarios 1 and 3 (a roadside 16-element array sweeping 64 beams about 10
//! times a second while a car with an RTK GPS drives past), all passes,
//! against the "last full sweep" and "GNSS through the beam map" baselines.
//!
//! Data: `../shared/realdata/deepsense-60ghz-beams/` (arrays as packaged by
//! Morais and Alkhateeb, ICC 2023). Skipped, visibly, where it is absent.
//!
//! Accounting, for every policy alike: each sweep's loss is `10 log10(P_best
//! / P_chosen)` against the best beam of the full measured sweep; beams are
//! the distinct beams the policy read from the sweep (a full sweep 64, an
//! acquisition its coarse beams and climb plus anything read before a loss
//! was noticed; a re-acquisition is assumed to fit in the same sweep
//! interval, as the sweeps here were taken). The last-full-sweep baseline
//! uses the previous sweep's best beam; a pass's first sweep has none and
//! counts as a full sweep with its own best beam (0 dB). Leaving those
//! first sweeps out instead gives 0.358 dB (scenario 1) and 1.066 dB
//! (scenario 3), the numbers a numpy check finds; the 0.42 / 1.10 dB quoted
//! when this experiment was planned match neither definition (nor a mean
//! of per-pass means, 0.398 / 1.309 dB, nor a loss in linear power).
//!
//! Beam maps are fitted leave-one-pass-out: each pass is predicted by a map
//! fitted on the other passes. Scenario 3 ships calibrated car positions
//! (`scenario3_unit2_loc_cal`); the GNSS policies use them when present and
//! the raw positions are run too, for comparison.

use std::path::{Path, PathBuf};

use mmtrack_beam::sweep::{
    BeamMap, BeamMapConfig, GnssMapOnly, GnssPass, GnssTrackerConfig, GnssWindowTracker, LastFullSweep, MapPass,
    Reacquisition, SearchConfig, SweepPass, SweepRecord, SweepSummary, SweepTracker, WindowTracker,
    WindowTrackerConfig, evaluate,
};
use mmtrack_core::BeamSweep;
use mmtrack_ingest::nmea::{EnuOrigin, geodetic_to_enu_m};

/// No per-sweep timestamps in the arrays: about 10 sweeps per second.
const SWEEP_NS: i64 = 100_000_000;
const BEAMS: usize = 64;

fn realdata(folder: &str) -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/realdata").join(folder);
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("skipped: real data not found at {}", dir.display());
        None
    }
}

/// A little-endian, C-order `.npy` array of `<f8` or `<i8`: its shape and
/// values as f64 (test-only: the ingest crate's reader is private to it).
fn read_npy(path: &Path) -> (Vec<usize>, Vec<f64>) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(&bytes[..6], b"\x93NUMPY", "{}: not a .npy file", path.display());
    let (header_len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        _ => (u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize, 12),
    };
    let header = std::str::from_utf8(&bytes[start..start + header_len]).unwrap();
    assert!(header.contains("'fortran_order': False"), "{header}");
    let shape_text = header.split("'shape': (").nth(1).and_then(|s| s.split(')').next()).unwrap();
    let shape: Vec<usize> =
        shape_text.split(',').filter(|s| !s.trim().is_empty()).map(|s| s.trim().parse().unwrap()).collect();
    let data = &bytes[start + header_len..];
    let count: usize = shape.iter().product();
    assert_eq!(data.len(), 8 * count, "{}: {header}", path.display());
    let words = data.chunks_exact(8).map(|c| <[u8; 8]>::try_from(c).unwrap());
    let values = if header.contains("'<f8'") {
        words.map(f64::from_le_bytes).collect()
    } else if header.contains("'<i8'") {
        words.map(|w| i64::from_le_bytes(w) as f64).collect()
    } else {
        panic!("{}: unsupported dtype in {header}", path.display())
    };
    (shape, values)
}

/// One pass: full sweeps, their times, and the car's east/north metres from
/// the roadside unit at each sweep.
#[derive(Default)]
struct Pass {
    sweeps: Vec<BeamSweep>,
    t_ns: Vec<i64>,
    east_north_m: Vec<[f64; 2]>,
}

struct Scenario {
    passes: Vec<Pass>,
}

fn load(dir: &Path, scenario: u32, calibrated: bool) -> Scenario {
    let file = |stem: &str| {
        let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with(&format!("scenario{scenario}_{stem}_1-")))
            .collect();
        found.sort();
        found.pop()
    };
    let (power_shape, power) = read_npy(&file("unit1_pwr_60ghz").unwrap());
    assert_eq!(power_shape[1], BEAMS);
    let rows = power_shape[0];
    let (_, pass_index) = read_npy(&file("seq_index").unwrap());
    let (_, unit) = read_npy(&file("unit1_loc").unwrap());
    // Scenario 3 ships calibrated car positions beside the raw ones.
    let car_file = if calibrated { file("unit2_loc_cal").unwrap() } else { file("unit2_loc").unwrap() };
    let (_, car) = read_npy(&car_file);
    assert_eq!((pass_index.len(), unit.len(), car.len()), (rows, 2 * rows, 2 * rows));
    let mut passes: Vec<Pass> = Vec::new();
    for row in 0..rows {
        if row == 0 || pass_index[row] != pass_index[row - 1] {
            passes.push(Default::default());
        }
        let t_ns = row as i64 * SWEEP_NS;
        let sweep = BeamSweep::full(t_ns, power[row * BEAMS..(row + 1) * BEAMS].to_vec()).unwrap();
        let origin = EnuOrigin { latitude_deg: unit[2 * row], longitude_deg: unit[2 * row + 1], altitude_m: 0.0 };
        let enu = geodetic_to_enu_m(&origin, car[2 * row], car[2 * row + 1], 0.0);
        let pass = passes.last_mut().unwrap();
        pass.sweeps.push(sweep);
        pass.t_ns.push(t_ns);
        pass.east_north_m.push([enu[0], enu[1]]);
    }
    Scenario { passes }
}

/// Leave-one-pass-out beam maps (each fitted on the other passes) and the
/// map fitted on every pass (for the report).
fn beam_maps(scenario: &Scenario) -> (Vec<BeamMap>, BeamMap) {
    let best: Vec<Vec<usize>> =
        scenario.passes.iter().map(|p| p.sweeps.iter().map(BeamSweep::best_measured_beam).collect()).collect();
    let map_passes: Vec<MapPass<'_>> = scenario
        .passes
        .iter()
        .zip(&best)
        .map(|(p, b)| MapPass { gnss: GnssPass { t_ns: &p.t_ns, east_north_m: &p.east_north_m }, best_beam: b })
        .collect();
    let config = BeamMapConfig::default();
    let maps = BeamMap::fit_leave_one_pass_out(&map_passes, BEAMS, &config).unwrap();
    (maps, BeamMap::fit(&map_passes, BEAMS, &config).unwrap())
}

/// Runs one tracker per pass (built by `make` from that pass's map) and
/// returns every sweep's record.
fn run(scenario: &Scenario, maps: &[BeamMap], make: &dyn Fn(&BeamMap) -> Box<dyn SweepTracker>) -> Vec<SweepRecord> {
    let mut records = Vec::new();
    for (pass, map) in scenario.passes.iter().zip(maps) {
        let gnss = map.predict_pass(&GnssPass { t_ns: &pass.t_ns, east_north_m: &pass.east_north_m }).unwrap();
        let mut tracker = make(map);
        records
            .extend(evaluate(tracker.as_mut(), &[SweepPass { sweeps: &pass.sweeps, gnss_beam: Some(&gnss) }]).unwrap());
    }
    records
}

fn print_row(name: &str, s: &SweepSummary) {
    println!(
        "  {name:<34} {:>6.3} {:>6.3} {:>6.3} {:>6.3} {:>6.2} {:>5}",
        s.mean_loss_db, s.median_loss_db, s.top1, s.within_one, s.mean_beams_per_sweep, s.reinitialisations
    );
}

fn window(reacquisition: Reacquisition) -> WindowTrackerConfig {
    WindowTrackerConfig { search: SearchConfig { reacquisition, ..SearchConfig::default() }, ..Default::default() }
}

fn gnss(map: &BeamMap, reacquisition: Reacquisition) -> GnssTrackerConfig {
    // The pass's map residual (fitted on the other passes) is the GNSS
    // beam's noise.
    GnssTrackerConfig {
        window: window(reacquisition),
        gnss_sigma_beams: map.rms_residual_beams(),
        ..Default::default()
    }
}

/// The table of one scenario; returns (window tracker, GNSS tracker,
/// last-full-sweep) summaries over every sweep.
fn scenario_table(label: &str, scenario: &Scenario) -> [SweepSummary; 3] {
    let (maps, full_map) = beam_maps(scenario);
    let sweeps: usize = scenario.passes.iter().map(|p| p.sweeps.len()).sum();
    println!("\nDeepSense {label}: {} passes, {sweeps} sweeps", scenario.passes.len());
    let boresights: Vec<f64> = maps.iter().map(|m| m.boresight_bearing_rad().to_degrees()).collect();
    println!(
        "  beam map (all passes): boresight {:.1} deg from north, {:.3} deg per beam ({}), GNSS offset {:+.1} s, \
         RMS residual {:.2} beams; leave-one-pass-out boresights {:.1}..{:.1} deg",
        full_map.boresight_bearing_rad().to_degrees(),
        full_map.beam_spacing_rad().to_degrees(),
        if full_map.beams_per_rad() < 0.0 { "index falls clockwise" } else { "index rises clockwise" },
        full_map.gnss_time_offset_s(),
        full_map.rms_residual_beams(),
        boresights.iter().copied().fold(f64::INFINITY, f64::min),
        boresights.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    println!(
        "  {:<34} {:>6} {:>6} {:>6} {:>6} {:>6} {:>5}",
        "policy", "mean", "median", "top1", "+-1", "beams", "reinit"
    );
    let summary = |records: &[SweepRecord]| SweepSummary::from_records(records).unwrap();
    let coarse = Reacquisition::Coarse { stride: 4 };
    let window_coarse = summary(&run(scenario, &maps, &|_| Box::new(WindowTracker::new(window(coarse)).unwrap())));
    print_row("window tracker (coarse reacq.)", &window_coarse);
    let window_full =
        summary(&run(scenario, &maps, &|_| Box::new(WindowTracker::new(window(Reacquisition::FullSweep)).unwrap())));
    print_row("window tracker (full-sweep reacq.)", &window_full);
    let gnss_coarse = summary(&run(scenario, &maps, &|m| Box::new(GnssWindowTracker::new(gnss(m, coarse)).unwrap())));
    print_row("GNSS tracker (coarse reacq.)", &gnss_coarse);
    let gnss_full = summary(&run(scenario, &maps, &|m| {
        Box::new(GnssWindowTracker::new(gnss(m, Reacquisition::FullSweep)).unwrap())
    }));
    print_row("GNSS tracker (full-sweep reacq.)", &gnss_full);
    let last_records = run(scenario, &maps, &|_| Box::new(LastFullSweep::new()));
    let last = summary(&last_records);
    print_row("last full sweep (1st: own, 0 dB)", &last);
    print_row(
        "last full sweep (no 1st sweeps)",
        &summary(&last_records.iter().filter(|r| r.sweep > 0).copied().collect::<Vec<_>>()),
    );
    print_row("GNSS through the beam map", &summary(&run(scenario, &maps, &|_| Box::new(GnssMapOnly))));
    [window_coarse, gnss_coarse, last]
}

/// The target: each tracker's mean loss below the last-full-sweep
/// baseline's (every sweep; a pass's first sweep uses its own best beam at
/// zero loss) while measuring at most 5 beams per sweep on average,
/// acquisitions and re-acquisitions included.
fn assert_target(label: &str, name: &str, tracker: &SweepSummary, last: &SweepSummary) {
    assert!(
        tracker.mean_loss_db < last.mean_loss_db && tracker.mean_beams_per_sweep <= 5.0,
        "{label} {name}: {:.3} dB mean loss at {:.2} beams per sweep; last full sweep {:.3} dB",
        tracker.mean_loss_db,
        tracker.mean_beams_per_sweep,
        last.mean_loss_db
    );
}

#[test]
fn trackers_beat_the_last_full_sweep_with_at_most_five_beams_per_sweep() {
    let Some(dir) = realdata("deepsense-60ghz-beams") else { return };
    for (label, number, calibrated) in [("scenario 1", 1, false), ("scenario 3 (calibrated car positions)", 3, true)] {
        let scenario = load(&dir, number, calibrated);
        let [window, gnss, last] = scenario_table(label, &scenario);
        assert_target(label, "window tracker", &window, &last);
        assert_target(label, "GNSS tracker", &gnss, &last);
    }
    // Scenario 3's raw car positions, for comparison (not asserted).
    scenario_table("scenario 3 (raw car positions)", &load(&dir, 3, false));
}

/// One setting of the grid of [`defaults_chosen_on_one_scenario_hold_on_the_other`].
#[derive(Debug, Clone, Copy)]
struct Setting {
    half_window_beams: usize,
    max_extension_beams: usize,
    drop_db: f64,
    /// Acceleration noise of both trackers' constant-velocity filter,
    /// beams/s^2.
    motion_noise: f64,
}

fn grid(motion_noise: [f64; 3]) -> Vec<Setting> {
    let mut out = Vec::new();
    for half_window_beams in [1, 2] {
        for max_extension_beams in [2, 4, 6] {
            for drop_db in [3.0, 6.0, 9.0] {
                for noise in motion_noise {
                    out.push(Setting { half_window_beams, max_extension_beams, drop_db, motion_noise: noise });
                }
            }
        }
    }
    out
}

fn search(s: &Setting) -> SearchConfig {
    SearchConfig {
        half_window_beams: s.half_window_beams,
        max_extension_beams: s.max_extension_beams,
        drop_db: s.drop_db,
        ..SearchConfig::default()
    }
}

/// Held-out check of the defaults. They were picked after a small grid on
/// both scenarios together, so the main test's margins are in-sample. Here
/// each tracker's setting is chosen on one scenario alone (lowest mean loss
/// among the grid's settings with at most 5 beams per sweep) and evaluated
/// on the other, against that scenario's last-full-sweep baseline. Printed
/// in both directions; docs/results/deepsense.md reports it.
#[test]
fn defaults_chosen_on_one_scenario_hold_on_the_other() {
    let Some(dir) = realdata("deepsense-60ghz-beams") else { return };
    let scenarios = [("scenario 1", load(&dir, 1, false)), ("scenario 3", load(&dir, 3, true))];
    let maps: Vec<Vec<BeamMap>> = scenarios.iter().map(|(_, s)| beam_maps(s).0).collect();
    let summary = |records: &[SweepRecord]| SweepSummary::from_records(records).unwrap();
    let window_of = |s: &Setting| WindowTrackerConfig {
        search: search(s),
        sigma_accel_beams_per_s2: s.motion_noise,
        ..WindowTrackerConfig::default()
    };
    let gnss_of = |s: &Setting, map: &BeamMap| GnssTrackerConfig {
        window: window_of(s),
        gnss_sigma_beams: map.rms_residual_beams(),
        ..GnssTrackerConfig::default()
    };
    let evaluate_setting = |tracker: &str, k: usize, s: &Setting| -> SweepSummary {
        let scenario = &scenarios[k].1;
        match tracker {
            "window" => summary(&run(scenario, &maps[k], &|_| Box::new(WindowTracker::new(window_of(s)).unwrap()))),
            _ => summary(&run(scenario, &maps[k], &|m| Box::new(GnssWindowTracker::new(gnss_of(s, m)).unwrap()))),
        }
    };
    let last: Vec<SweepSummary> =
        (0..2).map(|k| summary(&run(&scenarios[k].1, &maps[k], &|_| Box::new(LastFullSweep::new())))).collect();
    println!("\nHeld-out settings (chosen on one scenario, evaluated on the other):");
    let mut over_budget = Vec::new();
    for (tracker, noise) in [("window", [10.0, 30.0, 60.0]), ("gnss-window", [10.0, 30.0, 60.0])] {
        for (tune, test) in [(0, 1), (1, 0)] {
            let settings = grid(noise);
            let chosen = settings
                .iter()
                .map(|s| (s, evaluate_setting(tracker, tune, s)))
                .filter(|(_, r)| r.mean_beams_per_sweep <= 5.0)
                .min_by(|a, b| a.1.mean_loss_db.total_cmp(&b.1.mean_loss_db))
                .expect("some setting measures at most 5 beams per sweep");
            let held_out = evaluate_setting(tracker, test, chosen.0);
            println!(
                "  {tracker:<11} chosen on {}: {:?} ({:.3} dB, {:.2} beams there) -> {}: {:.3} dB mean loss at {:.2} \
                 beams per sweep (last full sweep {:.3} dB)",
                scenarios[tune].0,
                chosen.0,
                chosen.1.mean_loss_db,
                chosen.1.mean_beams_per_sweep,
                scenarios[test].0,
                held_out.mean_loss_db,
                held_out.mean_beams_per_sweep,
                last[test].mean_loss_db
            );
            // Asserted: the loss half of the target holds out of sample.
            assert!(
                held_out.mean_loss_db < last[test].mean_loss_db,
                "{tracker} chosen on {}: {:.3} dB on {}, last full sweep {:.3} dB",
                scenarios[tune].0,
                held_out.mean_loss_db,
                scenarios[test].0,
                last[test].mean_loss_db
            );
            if held_out.mean_beams_per_sweep > 5.0 {
                over_budget.push(format!("{tracker} chosen on {} on {}", scenarios[tune].0, scenarios[test].0));
            }
        }
    }
    // Reported, not asserted (docs/results/deepsense.md): the beam budget does not always
    // transfer (measured: the window tracker tuned on scenario 1 reads 5.74
    // beams per sweep on scenario 3).
    println!("  over the 5-beam budget out of sample: {over_budget:?}");
}
