//! The benchmarks of `mmtrack_reproduce::bench` called as library functions
//! at tiny sizes: the structure of each result (rows present, ratios finite
//! and positive, each target flag agreeing with the measured value it
//! judges) and the Markdown it renders. No time is asserted (STYLE.md:
//! tests never assert wall-clock time); the numbers only have to be sane.

use std::path::Path;
use std::process::Command;

use mmtrack_core::progress::NoProgress;
use mmtrack_reproduce::bench::{ingest, io, mpc, odometry, slam};
use mmtrack_sim::radar::{ConstantTurn, RadarSimulator, ScanLimits, Scenario, SimOptions, Trajectory};

fn assert_positive(name: &str, value: f64) {
    assert!(value.is_finite() && value > 0.0, "{name} = {value}");
}

/// An Oxford folder of `scans` simulated Oxford-size scans (400 x 3768) at `dir`.
fn simulated_oxford_folder(dir: &Path, scans: usize) {
    let scenario: Scenario = toml::from_str("seed = 3\n[generator]\n").unwrap();
    let motion = ConstantTurn { speed_mps: 8.0, yaw_rate_radps: 0.05 };
    let trajectory = Trajectory::constant_turn(motion, 1_700_000_000_000_000_000, scans as f64 * 0.25 + 1.0).unwrap();
    let world = scenario.build_world(&trajectory).unwrap();
    let options =
        SimOptions { limits: ScanLimits { max_scans: Some(scans), max_distance_m: None }, ..scenario.options() };
    let simulator = RadarSimulator::new(&world, &scenario.sensor, &trajectory, options).unwrap();
    mmtrack_process::simulate::radar::write_oxford_streaming(
        &scenario,
        simulator,
        mmtrack_io::recording::TimeBase::ScenarioStart,
        dir,
        mmtrack_io::Overwrite::Refuse,
        &NoProgress,
    )
    .unwrap();
}

#[test]
fn bench_mpc_gives_a_row_per_thread_count_with_consistent_verdicts() {
    let options = mpc::MpcBenchOptions { snapshots: 12, mpcs: 40, threads: vec![1, 2] };
    let bench = mpc::run(&options).unwrap();
    assert_eq!(bench.rows.iter().map(|r| r.threads).collect::<Vec<_>>(), [1, 2]);
    assert_eq!((bench.target_snapshots, bench.target_s), (mpc::MPC_TARGET_SNAPSHOTS, mpc::MPC_TARGET_S));
    assert_positive("fft_s", bench.fft_s);
    for row in &bench.rows {
        assert_positive("snapshots_per_s", row.snapshots_per_s);
        assert_positive("ratio_to_fft", row.ratio_to_fft);
        assert!(row.detection_s.is_finite() && row.tracking_s >= 0.0, "{row:?}");
        let met = row.s_per_target_snapshots <= bench.target_s
            && row.ratio_to_fft <= mpc::MPC_TARGET_FFT_RATIO
            && row.detections_per_path <= mpc::MPC_TARGET_DETECTIONS_PER_PATH;
        assert_eq!(row.target_met, met, "{row:?}");
        assert_eq!(row.detections_per_path, row.detections_per_snapshot / 40.0, "{row:?}");
        // 40 paths, 15..50 dB over a -140 dB floor and several pulse widths
        // apart: each is found; noise peaks above floor + 6 dB add a few (the
        // same bound as the CLI's `bench mpc` test).
        assert!((38.0..=60.0).contains(&row.detections_per_snapshot), "{row:?}");
    }
    // Both thread counts see the same snapshots and find the same detections.
    assert_eq!(bench.rows[0].detections_per_snapshot, bench.rows[1].detections_per_snapshot);
    assert_eq!(bench.target_met(), bench.rows.iter().any(|r| r.threads == 1 && r.target_met));
    let text = mpc::markdown(&bench);
    assert!(text.starts_with("`mmtrack bench mpc`: 12 simulated snapshots"), "{text}");
    assert_eq!(text.lines().filter(|l| l.starts_with("| 1 |") || l.starts_with("| 2 |")).count(), 2, "{text}");
    // GM-PHD alone on drawn detections: 13 paths x 0.95 + 0.5 false ones
    // (12.85 per snapshot) and 147 x 0.95 + 0.5 (140.15); the bounds are
    // about 5 standard deviations of the mean over the 12 snapshots.
    let gmphd: Vec<_> = bench.gmphd_rows.iter().map(|r| (r.label, r.paths, r.snapshots)).collect();
    assert_eq!(gmphd, [("sparse", 13, 12), ("dense", 147, 12)]);
    for (row, (lo, hi)) in bench.gmphd_rows.iter().zip([(11.0, 14.5), (136.0, 144.5)]) {
        assert!((lo..=hi).contains(&row.detections_per_snapshot), "{row:?}");
        assert_positive("us_per_snapshot", row.us_per_snapshot);
        assert!(row.tracks > 0, "{row:?}");
    }
    assert!(text.contains("| sparse | 13 | 12 |") && text.contains("| dense | 147 | 12 |"), "{text}");
    assert!(text.contains("Target (one thread): "), "{text}");

    let error = mpc::run(&mpc::MpcBenchOptions { snapshots: 0, ..options }).unwrap_err();
    assert!(error.to_string().contains("snapshots"), "{error}");
}

#[test]
fn bench_slam_times_one_thread_and_the_pool_per_particle_count_with_consistent_verdicts() {
    let options = slam::SlamBenchOptions { particles: vec![50, 120], iterations: 1, epochs: 5, repeats: 1, threads: 2 };
    let bench = slam::run(&options).unwrap();
    assert_eq!((bench.threads, bench.epochs), (2, 5));
    assert_eq!(bench.rows.iter().map(|r| r.particles).collect::<Vec<_>>(), [50, 120]);
    assert_eq!(bench.target_ms_per_epoch, slam::TARGET_MS_PER_EPOCH);
    assert_eq!(bench.target_speed_up, slam::TARGET_SPEED_UP);
    for rows in &bench.rows {
        assert_eq!((rows.one_thread.threads, rows.pool.threads), (1, 2));
        assert!(!rows.is_target, "{rows:?}");
        for row in [&rows.one_thread, &rows.pool] {
            assert_positive("ms_per_epoch", row.ms_per_epoch);
            assert_positive("times_faster_than_real_time", row.times_faster_than_real_time);
            // The slowest epoch is at least the mean (ms_per_epoch is the mean).
            assert!(row.slowest_epoch_ms >= row.ms_per_epoch * (1.0 - 1e-9), "{row:?}");
            assert_eq!(row.target_met, row.ms_per_epoch < bench.target_ms_per_epoch, "{row:?}");
            // Real time over the measured time, by definition (to rounding).
            assert!(
                (row.times_faster_than_real_time * row.ms_per_epoch - bench.epoch_ms).abs() < 1e-6 * bench.epoch_ms
            );
        }
        assert!((rows.speed_up - rows.one_thread.ms_per_epoch / rows.pool.ms_per_epoch).abs() < 1e-9 * rows.speed_up);
    }
    // No row at the target's particle count: the target is not met.
    assert!(!bench.target_met());
    let text = slam::markdown(&bench);
    assert!(text.starts_with("`mmtrack bench slam`: the SLAM filter"), "{text}");
    assert!(
        text.contains("\n| 50 | 1 | ") && text.contains("\n| 50 | 2 | ") && text.contains("\n| 120 | 2 | "),
        "{text}"
    );
    assert!(!text.contains("**target**"), "{text}");

    let error = slam::run(&slam::SlamBenchOptions { particles: Vec::new(), ..options }).unwrap_err();
    assert!(error.to_string().contains("particle"), "{error}");
}

#[test]
fn bench_io_gives_a_row_per_compression_with_the_target_on_none_and_zstd() {
    let dir = tempfile::tempdir().unwrap();
    let options = io::IoBenchOptions { scans: 2, repeats: 1, dir: Some(dir.path().to_path_buf()) };
    let bench = io::run(&options).unwrap();
    assert_eq!(bench.rows.iter().map(|r| r.compression).collect::<Vec<_>>(), ["none", "zstd-1", "lz4"]);
    // 400 x 3768 bytes of power per scan.
    assert!((bench.message_mb - 400.0 * 3768.0 / 1e6).abs() < 1e-9, "{}", bench.message_mb);
    assert_positive("copy_mb_per_s", bench.copy_mb_per_s);
    for row in &bench.rows {
        for (name, value) in [
            ("file_mb", row.file_mb),
            ("write_ratio_to_copy", row.write_ratio_to_copy),
            ("write_fsync_ratio_to_copy_fsync", row.write_fsync_ratio_to_copy_fsync),
            ("read_ratio_to_copy", row.read_ratio_to_copy),
        ] {
            assert_positive(name, value);
        }
        let expected_target = (row.compression != "lz4").then_some(io::WRITE_TARGET_RATIO);
        assert_eq!(row.write_target_ratio, expected_target, "{row:?}");
        assert_eq!(row.target_met, row.write_target_ratio.map(|t| row.write_ratio_to_copy >= t), "{row:?}");
    }
    let json = io::json(&bench);
    assert_eq!(json["results"].as_array().unwrap().len(), 3);
    assert_eq!(json["target_met_by"].as_array().unwrap().len(), bench.target_met_by().len());
    let text = io::markdown(&bench);
    assert_eq!(text.lines().filter(|l| l.starts_with("| none |") || l.starts_with("| lz4 |")).count(), 2, "{text}");
}

/// `bench ingest --from` the real Oxford sample with more scans than it
/// holds: the repeats are moved in time, rows included (the ingest refused
/// them before: "row 0: timestamp ... is -2.750 s from the scan's own
/// stamp").
#[test]
fn bench_ingest_repeats_the_real_oxford_scans_under_later_times() {
    let real = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/realdata/oxford-radar-tiny");
    assert!(real.is_dir(), "{}: the real samples belong beside the clone", real.display());
    let dir = tempfile::tempdir().unwrap();
    let options =
        ingest::IngestBenchOptions { scans: 24, repeats: 1, dir: Some(dir.path().to_path_buf()), from: Some(real) };
    let no_simulation = |_: &Path, _: &Path| -> Command { unreachable!("real PNGs given: nothing to simulate") };
    let bench = ingest::run(&options, &no_simulation).unwrap();
    assert_eq!((bench.scans, bench.small_scans, bench.real), (24, 6, true));
    assert!(bench.source.contains("re-encoded"), "{}", bench.source);
}

#[test]
fn bench_ingest_and_odometry_run_on_a_small_simulated_oxford_folder() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("oxford");
    simulated_oxford_folder(&folder, 4);

    let options = ingest::IngestBenchOptions {
        scans: 8,
        repeats: 1,
        dir: Some(dir.path().to_path_buf()),
        from: Some(folder.clone()),
    };
    let no_simulation = |_: &Path, _: &Path| -> Command { unreachable!("real PNGs given: nothing to simulate") };
    let bench = ingest::run(&options, &no_simulation).unwrap();
    assert_eq!((bench.scans, bench.small_scans, bench.real), (8, 2, true));
    assert_eq!(ingest::readme_block(&bench), ingest::README_BLOCK_REAL);
    for (name, value) in
        [("folder_mb", bench.folder_mb), ("scans_per_s", bench.scans_per_s), ("ratio", bench.ratio_to_copy)]
    {
        assert_positive(name, value);
    }
    assert_eq!(bench.target_met, bench.scans_per_s >= bench.target_scans_per_s);
    assert_eq!(bench.target_scans_per_s, ingest::INGEST_TARGET_SCANS_PER_S);
    assert!(ingest::markdown(&bench).contains("| ingest / copy |"));

    // The memory check samples whatever child the caller starts; a stand-in
    // here (the `process odometry` child is the CLI's, tested there).
    let stand_in = |_: &Path, _: &Path| {
        let mut command = Command::new("sleep");
        command.arg("0.1");
        command
    };
    let options = odometry::OdometryBenchOptions { from: folder, passes: 1, memory_scans: 8 };
    let bench = odometry::run(&options, &stand_in).unwrap();
    assert_eq!(bench.scans_per_pass, 4);
    let presets: Vec<&str> = bench.presets.iter().map(|r| r.preset.as_str()).collect();
    assert_eq!(presets, mmtrack_odometry::OdometryConfig::PRESETS);
    assert_positive("decode_only_scans_per_s", bench.decode_only_scans_per_s);
    for row in &bench.presets {
        assert_eq!(row.scans, 4, "{row:?}");
        assert_positive("scans_per_s", row.scans_per_s);
        assert_positive("ratio_to_decode_only", row.ratio_to_decode_only);
        assert!(row.filter_ms_per_scan >= 0.0 && row.register_ms_per_scan >= 0.0, "{row:?}");
        assert_eq!(row.target_met, row.scans_per_s >= bench.target_scans_per_s, "{row:?}");
        let ratio_met = row.ratio_to_decode_only >= odometry::CFEAR_TARGET_RATIO_TO_DECODE_ONLY;
        let expected = (row.preset == odometry::RATIO_TARGET_PRESET).then_some(ratio_met);
        assert_eq!(row.ratio_target_met, expected, "{row:?}");
    }
    assert_eq!(bench.presets.iter().filter(|r| r.ratio_target_met.is_some()).count(), 1);
    let memory = &bench.memory;
    assert_eq!((memory.short_scans, memory.long_scans), (2, 8));
    assert_positive("growth_ratio", memory.growth_ratio);
    assert_eq!(memory.target_met, memory.growth_ratio <= memory.growth_limit);
    let presets_met = bench.presets.iter().all(|r| r.target_met && r.ratio_target_met != Some(false));
    assert_eq!(bench.target_met(), presets_met && memory.target_met);
    let text = odometry::markdown(&bench);
    assert_eq!(text.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| preset")).count(), presets.len());
    assert!(text.contains("\nMemory (`cfear`"), "{text}");
}

/// Every bench refuses an absurd or empty count in one of its flags before
/// any work (no scan simulated, no pool of 100 000 threads started): the
/// error names the flag and the value. Each case returns at once; with the
/// checks gone, the large ones would allocate terabytes or run for days.
#[test]
fn every_bench_refuses_absurd_counts_naming_the_flag_before_any_work() {
    let refused = |result: anyhow::Result<()>, flag_and_value: &str| {
        let message = format!("{:#}", result.expect_err(flag_and_value));
        assert!(message.contains(flag_and_value) && message.contains("nothing was done"), "{message}");
    };
    let never = |_: &Path, _: &Path| -> Command { panic!("no child process may start") };
    let mpc_with = |snapshots, mpcs, threads: Vec<usize>| mpc::MpcBenchOptions { snapshots, mpcs, threads };
    refused(mpc::run(&mpc_with(1_000_000_000_000, 40, vec![1])).map(drop), "--snapshots 1000000000000");
    refused(mpc::run(&mpc_with(12, 0, vec![1])).map(drop), "--mpcs 0");
    refused(mpc::run(&mpc_with(12, 100_000_000, vec![1])).map(drop), "--mpcs 100000000");
    refused(mpc::run(&mpc_with(12, 40, vec![1, 100_000])).map(drop), "--threads 100000");
    refused(mpc::run(&mpc_with(12, 40, vec![0])).map(drop), "--threads 0");

    let slam_with = |f: &dyn Fn(&mut slam::SlamBenchOptions)| {
        let mut options = slam::SlamBenchOptions { particles: vec![100], epochs: 2, repeats: 1, ..Default::default() };
        f(&mut options);
        slam::run(&options).map(drop)
    };
    refused(slam_with(&|o| o.threads = 100_000), "--threads 100000");
    refused(slam_with(&|o| o.repeats = 0), "--repeats 0");
    refused(slam_with(&|o| o.particles = vec![100, 10_000_000_000]), "--particles 10000000000");
    refused(slam_with(&|o| o.epochs = 100_000_000), "--epochs 100000000");

    let io_with = |scans, repeats| io::IoBenchOptions { scans, repeats, dir: None };
    refused(io::run(&io_with(1_000_000, 1)).map(drop), "--scans 1000000");
    refused(io::run(&io_with(2, 0)).map(drop), "--repeats 0");

    let ingest_with = |scans, repeats| ingest::IngestBenchOptions { scans, repeats, dir: None, from: None };
    refused(ingest::run(&ingest_with(10_000_000, 1), &never).map(drop), "--scans 10000000");
    refused(ingest::run(&ingest_with(0, 1), &never).map(drop), "--scans 0");
    refused(ingest::run(&ingest_with(8, 5000), &never).map(drop), "--repeats 5000");

    let odometry_with =
        |passes, memory_scans| odometry::OdometryBenchOptions { from: "/nonexistent".into(), passes, memory_scans };
    refused(odometry::run(&odometry_with(0, 200), &never).map(drop), "--passes 0");
    refused(odometry::run(&odometry_with(100_000_000_000, 200), &never).map(drop), "--passes 100000000000");
    refused(odometry::run(&odometry_with(1, 1_000_000_000_000), &never).map(drop), "--memory-scans 1000000000000");
}
