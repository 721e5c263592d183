//! `mmtrack simulate sounder`: the recording carries the CIRs, the true MPCs
//! and both cars' poses exactly as the simulator makes them; inspect lists
//! the channels; overwrite refusal; bad scenarios named.

use mmtrack_core::{CirSnapshot, MpcTruth, StampedPose};
use mmtrack_io::recording::PoseStream;
use mmtrack_io::recording::pulse::{PULSE_SPECTRUM_KEY, decode_pulse_spectrum};
use mmtrack_io::{RecordingEvent, RecordingReader};
use mmtrack_sim::sounder::{ConvoySimulator, SounderScenario, artificial_channel};

use super::common::{files, mmtrack, root, text};

fn scenario(name: &str) -> SounderScenario {
    let text = std::fs::read_to_string(root().join("data/sounder").join(name)).unwrap();
    toml::from_str(&text).unwrap()
}

#[derive(Default)]
struct Recording {
    cirs: Vec<CirSnapshot>,
    truth: Vec<MpcTruth>,
    tx: Vec<StampedPose>,
    rx: Vec<StampedPose>,
    other_poses: usize,
}

fn read(path: &std::path::Path) -> (Recording, std::collections::BTreeMap<String, String>) {
    let mut reader = RecordingReader::open(path).unwrap();
    let mut out = Recording::default();
    for event in reader.by_ref() {
        match event.unwrap() {
            RecordingEvent::Cir(c) => out.cirs.push(c),
            RecordingEvent::MpcTruth(t) => out.truth.push(t),
            RecordingEvent::Pose { stream: PoseStream::GroundTruthTx, pose } => out.tx.push(pose),
            RecordingEvent::Pose { stream: PoseStream::GroundTruthRx, pose } => out.rx.push(pose),
            RecordingEvent::Pose { .. } => out.other_poses += 1,
            other => panic!("unexpected event {other:?}"),
        }
    }
    (out, reader.metadata().unwrap().clone())
}

#[test]
fn convoy_recording_holds_what_the_simulator_makes_and_inspect_lists_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = root().join("data/sounder/convoy-tunnel.toml");
    let args = ["simulate", "sounder", "--scenario", path.to_str().unwrap(), "-o", "rec.mcap", "--sets", "3"];
    let out = mmtrack(dir.path(), &args);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("rec.mcap: 3 sets, 18 CIR snapshots"), "{stdout}");

    let (recording, metadata) = read(&dir.path().join("rec.mcap"));
    let scenario = scenario("convoy-tunnel.toml");
    // `--sets 3`: the first three sets of the scenario's own (1666-set) run.
    let config = scenario.convoy.unwrap();
    let simulator = ConvoySimulator::new(&config, scenario.seed).unwrap();
    let pulse = simulator.pulse_spectrum().to_vec();
    let sets: Vec<_> = simulator.take(3).collect();
    let cirs: Vec<CirSnapshot> = sets.iter().flat_map(|s| s.snapshots.clone()).collect();
    let truth: Vec<MpcTruth> = sets.iter().flat_map(|s| s.truth.clone()).collect();
    assert_eq!(recording.cirs, cirs);
    assert_eq!(recording.truth, truth);
    assert!(recording.truth.len() >= 18 * 5, "LOS, two single and two double bounces per snapshot at least");
    assert_eq!(recording.tx, sets.iter().map(|s| s.tx_pose.clone()).collect::<Vec<_>>());
    assert_eq!(recording.rx, sets.iter().map(|s| s.rx_pose.clone()).collect::<Vec<_>>());
    assert_eq!(recording.other_poses, 0, "no /ground_truth/pose: it would mix the two cars");
    assert_eq!(decode_pulse_spectrum(&metadata[PULSE_SPECTRUM_KEY]).unwrap(), pulse);
    assert_eq!(metadata["sounder.channel"], "convoy");
    assert_eq!(metadata["time_base"], "scenario_start");

    // A longer cut starts with the same sets: the world does not depend on --sets.
    let longer = ["simulate", "sounder", "--scenario", path.to_str().unwrap(), "-o", "longer.mcap", "--sets", "8"];
    assert!(mmtrack(dir.path(), &longer).status.success());
    let (longer, _) = read(&dir.path().join("longer.mcap"));
    assert_eq!(longer.cirs.len(), 48);
    assert_eq!(longer.cirs[..18], recording.cirs[..]);
    assert_eq!(longer.truth[..recording.truth.len()], recording.truth[..]);
    std::fs::remove_file(dir.path().join("longer.mcap")).unwrap();

    let inspect = mmtrack(dir.path(), &["inspect", "--json", "rec.mcap"]);
    let summary: serde_json::Value = serde_json::from_slice(&inspect.stdout).unwrap();
    let channel = |topic: &str| {
        summary["channels"].as_array().unwrap().iter().find(|c| c["topic"] == topic).cloned().unwrap_or_default()
    };
    assert_eq!(
        (channel("/channel/cir")["messages"].as_u64(), channel("/channel/cir")["schema"].as_str()),
        (Some(18), Some("mmtrack.CirSnapshot"))
    );
    assert_eq!(channel("/channel/mpc_truth")["messages"].as_u64(), Some(truth.len() as u64));
    assert_eq!(channel("/channel/mpc_truth")["schema"].as_str(), Some("mmtrack.MpcTruth"));
    assert_eq!(channel("/ground_truth/tx")["messages"].as_u64(), Some(3));
    assert_eq!(channel("/ground_truth/rx")["messages"].as_u64(), Some(3));
    let plain = mmtrack(dir.path(), &["inspect", "rec.mcap"]);
    let (stdout, _) = text(&plain);
    assert!(stdout.contains("/channel/mpc_truth") && stdout.contains("mmtrack.MpcTruth"), "{stdout}");

    // Refused without --force, output untouched and no temporary file left.
    let before = std::fs::read(dir.path().join("rec.mcap")).unwrap();
    let mut quiet = args.to_vec();
    quiet.push("--quiet");
    let out = mmtrack(dir.path(), &quiet);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("rec.mcap") && stderr.contains("--force"), "{stderr}");
    assert_eq!(std::fs::read(dir.path().join("rec.mcap")).unwrap(), before);
    assert_eq!(files(dir.path()), vec![std::path::PathBuf::from("rec.mcap")]);
    assert!(stdout.is_empty());
    quiet.push("--force");
    let out = mmtrack(dir.path(), &quiet);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success() && stdout.is_empty(), "{stderr}");
    // Same scenario and seed: identical bytes, whatever the thread count.
    quiet.extend(["--threads", "1"]);
    assert!(mmtrack(dir.path(), &quiet).status.success());
    assert_eq!(std::fs::read(dir.path().join("rec.mcap")).unwrap(), before);
}

#[test]
fn artificial_recording_holds_two_true_mpcs_per_snapshot() {
    let dir = tempfile::tempdir().unwrap();
    let path = root().join("data/sounder/artificial.toml");
    let out = mmtrack(dir.path(), &["simulate", "sounder", "--scenario", path.to_str().unwrap(), "-o", "a.mcap", "-q"]);
    assert!(out.status.success(), "{}", text(&out).1);
    let (recording, metadata) = read(&dir.path().join("a.mcap"));
    let scenario = scenario("artificial.toml");
    let (cirs, truth) = artificial_channel(scenario.artificial.as_ref().unwrap(), scenario.seed).unwrap();
    assert_eq!((recording.cirs.len(), recording.truth.len()), (200, 400));
    assert_eq!((recording.cirs, recording.truth), (cirs, truth));
    assert!(recording.tx.is_empty() && recording.rx.is_empty());
    assert_eq!(metadata["sounder.channel"], "artificial");
    // --sets cuts to whole sets of the scenario's 6 snapshots.
    let out = mmtrack(
        dir.path(),
        &["simulate", "sounder", "--scenario", path.to_str().unwrap(), "-o", "a.mcap", "-q", "--force", "--sets", "2"],
    );
    assert!(out.status.success(), "{}", text(&out).1);
    assert_eq!(read(&dir.path().join("a.mcap")).0.cirs.len(), 12);
}

#[test]
fn bad_sounder_scenarios_are_named() {
    let dir = tempfile::tempdir().unwrap();
    for (scenario, expected) in [
        ("seed = 1\n[convoy.sounder]\nbandwidth_hz = -1e9\n", "convoy.sounder.bandwidth_hz: -1000000000 is invalid"),
        ("seed = 1\n[convoy]\nsnapshots_per_set = 0\n", "convoy.snapshots_per_set: 0 is invalid"),
        ("seed = 1\n[convoy]\nset_intervl_s = 0.01\n", "unknown field `set_intervl_s`"),
        ("seed = 1\n[artificial]\nsnapshots = 1\n", "artificial.snapshots: 1 is invalid"),
        ("seed = 1\n", "exactly one of them"),
    ] {
        std::fs::write(dir.path().join("s.toml"), scenario).unwrap();
        let out = mmtrack(dir.path(), &["simulate", "sounder", "--scenario", "s.toml", "-o", "o.mcap", "-q"]);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains(expected) && stderr.contains("s.toml"), "expected '{expected}' in: {stderr}");
        // Parse errors quote the offending TOML line (several lines); value errors are one line.
        if !expected.starts_with("unknown field") {
            assert_eq!(stderr.lines().count(), 1, "{stderr}");
        }
        assert!(!dir.path().join("o.mcap").exists());
    }
}
