//! `mmtrack simulate sounder`: a channel-sounder scenario's CIR snapshots,
//! true MPCs and (convoy) both cars' poses streamed into a recording.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Context;
use mmtrack_core::progress::Progress;
use mmtrack_core::{CirSnapshot, Complex64, MpcTruth};
use mmtrack_io::recording::pulse::{PULSE_SPECTRUM_KEY, encode_pulse_spectrum};
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase};
use mmtrack_io::{RecordingOptions, RecordingWriter};
use mmtrack_sim::sounder::{
    ArtificialChannelConfig, ConvoyConfig, ConvoySimulator, SounderConfig, SounderScenario, artificial_channel,
};

/// One `simulate sounder` run.
#[derive(Debug, Clone)]
pub struct SounderSimulation {
    /// Scenario file (TOML): seed and one of `[artificial]` or `[convoy]`.
    pub scenario: PathBuf,
    /// Only the first N sets of the scenario's run.
    pub sets: Option<u64>,
    /// The recording to write.
    pub output: PathBuf,
    /// How it is written.
    pub recording: RecordingOptions,
}

/// Parses and checks a sounder scenario file.
///
/// # Errors
/// The file cannot be read, parsed or checked, naming it.
pub fn load_sounder_scenario(path: &Path) -> anyhow::Result<SounderScenario> {
    let text = mmtrack_io::paths::read_config_text(path)?;
    let scenario: SounderScenario = toml::from_str(&text).with_context(|| format!("{}", path.display()))?;
    scenario.validate().with_context(|| format!("{}", path.display()))?;
    Ok(scenario)
}

fn sounder_metadata(extra: &mut BTreeMap<String, String>, sounder: &SounderConfig, pulse: &[Complex64]) {
    extra.insert("sounder.carrier_hz".into(), format!("{:?}", sounder.carrier_hz));
    extra.insert("sounder.bandwidth_hz".into(), format!("{:?}", sounder.bandwidth_hz));
    extra.insert("sounder.taps".into(), sounder.taps.to_string());
    extra.insert("sounder.noise_floor_db".into(), format!("{:?}", sounder.noise_floor_db));
    extra.insert("sounder.pulse".into(), format!("{:?}", sounder.pulse));
    extra.insert(PULSE_SPECTRUM_KEY.into(), encode_pulse_spectrum(pulse));
}

fn metadata(args: &SounderSimulation, seed: u64, extra: BTreeMap<String, String>) -> RecordingMetadata {
    let mut extra = extra;
    extra.insert("simulator.seed".into(), seed.to_string());
    extra.insert("simulator.scenario".into(), mmtrack_io::paths::canonical(&args.scenario));
    RecordingMetadata {
        sequence_id: args
            .output
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "simulated".into()),
        source: format!("simulate:{}", mmtrack_io::paths::canonical(&args.scenario)),
        time_base: TimeBase::ScenarioStart,
        extra,
    }
}

/// Writes one snapshot and its true MPCs.
fn write_snapshot(writer: &mut RecordingWriter, cir: &CirSnapshot, truth: &[MpcTruth]) -> anyhow::Result<()> {
    writer.write_cir(cir)?;
    for t in truth.iter().filter(|t| t.set_index == cir.set_index && t.snapshot_index == cir.snapshot_index) {
        writer.write_mpc_truth(t)?;
    }
    Ok(())
}

/// What [`simulate_sounder`] wrote.
#[derive(Debug, Clone)]
pub struct SounderSimulated {
    /// Sets written.
    pub sets: u64,
    /// CIR snapshots written.
    pub snapshots: u64,
    /// True MPCs written.
    pub truths: u64,
    /// What the channel held (traffic cars and scatterers, or the two MPCs).
    pub detail: String,
}

fn write_convoy(
    args: &SounderSimulation,
    seed: u64,
    config: &ConvoyConfig,
    progress: &dyn Progress,
) -> anyhow::Result<SounderSimulated> {
    // `--sets N` keeps the first N sets of the scenario's run: the world (its
    // length, traffic and scatterers) is laid out for the scenario's own
    // number of sets, so a shorter run is a prefix of the full one.
    if let Some(n) = args.sets.filter(|&n| usize::try_from(n).map_or(true, |n| n > config.sets)) {
        let message = format!(
            "--sets {n}: the scenario {} runs {} sets (its `sets`); give at most that (nothing was done)",
            args.scenario.display(),
            config.sets
        );
        return Err(mmtrack_core::error::UsageError(message).into());
    }
    let simulator = ConvoySimulator::new(config, seed).with_context(|| args.scenario.display().to_string())?;
    let sets = args.sets.map_or(config.sets, |n| usize::try_from(n).unwrap_or(usize::MAX).min(config.sets));
    let mut extra = BTreeMap::from([
        ("sounder.channel".to_string(), "convoy".to_string()),
        ("sounder.road".to_string(), format!("{:?}", config.road)),
        ("sounder.delay_offset_s".to_string(), format!("{:?}", config.delay_offset_s)),
        ("sounder.snapshots_per_set".to_string(), config.snapshots_per_set.to_string()),
        ("sounder.snapshot_interval_s".to_string(), format!("{:?}", config.snapshot_interval_s)),
        ("sounder.set_interval_s".to_string(), format!("{:?}", config.set_interval_s)),
        (
            "sounder.path_ids".to_string(),
            "0 LOS; 100 + w single bounce off wall w (0 left, 1 right); 200 + w double bounce starting on wall w; \
             1000 + i traffic car i; diffuse scatterers are not in the truth"
                .to_string(),
        ),
    ]);
    sounder_metadata(&mut extra, &config.sounder, simulator.pulse_spectrum());
    let detail =
        format!("{} traffic cars, {} diffuse scatterers", simulator.traffic_cars(), simulator.diffuse_scatterers());
    let mut writer = RecordingWriter::create(&args.output, &metadata(args, seed, extra), &args.recording)?;
    progress.start("simulate sounder", sets as u64, "sets");
    let mut written = SounderSimulated { sets: 0, snapshots: 0, truths: 0, detail };
    for set in simulator.take(sets) {
        writer.write_pose(PoseStream::GroundTruthTx, &set.tx_pose, "world")?;
        writer.write_pose(PoseStream::GroundTruthRx, &set.rx_pose, "world")?;
        writer.write_mpc_paths(set.rx_pose.t_ns, &set.paths)?;
        for cir in &set.snapshots {
            write_snapshot(&mut writer, cir, &set.truth)?;
        }
        written.sets += 1;
        written.snapshots += set.snapshots.len() as u64;
        written.truths += set.truth.len() as u64;
        progress.advance(1);
        progress.check_cancelled()?;
    }
    writer.finish()?;
    progress.finish();
    Ok(written)
}

fn write_artificial(
    args: &SounderSimulation,
    seed: u64,
    config: &ArtificialChannelConfig,
) -> anyhow::Result<SounderSimulated> {
    let (snapshots, truth) = artificial_channel(config, seed).with_context(|| args.scenario.display().to_string())?;
    let keep = |set_index: u64| args.sets.is_none_or(|n| set_index < n);
    let band = config.sounder.band()?;
    let mut extra = BTreeMap::from([
        ("sounder.channel".to_string(), "artificial".to_string()),
        ("sounder.mpc_power_db".to_string(), format!("{:?}", config.mpc_power_db)),
        ("sounder.start_separation_s".to_string(), format!("{:?}", config.start_separation_s)),
        ("sounder.end_separation_s".to_string(), format!("{:?}", config.end_separation_s)),
        ("sounder.snapshot_interval_s".to_string(), format!("{:?}", config.snapshot_interval_s)),
        ("sounder.path_ids".to_string(), "0 the earlier MPC, 1 the later MPC".to_string()),
    ]);
    sounder_metadata(&mut extra, &config.sounder, &config.sounder.pulse.spectrum(&band));
    let mut writer = RecordingWriter::create(&args.output, &metadata(args, seed, extra), &args.recording)?;
    let mut written = SounderSimulated { sets: 0, snapshots: 0, truths: 0, detail: "two MPCs".into() };
    let mut last_set = None;
    for cir in snapshots.iter().filter(|c| keep(c.set_index)) {
        write_snapshot(&mut writer, cir, &truth)?;
        written.snapshots += 1;
        if last_set != Some(cir.set_index) {
            written.sets += 1;
            last_set = Some(cir.set_index);
        }
    }
    written.truths = truth.iter().filter(|t| keep(t.set_index)).count() as u64;
    writer.finish()?;
    Ok(written)
}

/// `mmtrack simulate sounder`: the scenario's channel into a recording.
///
/// # Errors
/// A bad scenario, an existing output without overwrite, or a write error.
pub fn simulate_sounder(args: &SounderSimulation, progress: &dyn Progress) -> anyhow::Result<SounderSimulated> {
    let scenario = load_sounder_scenario(&args.scenario)?;
    match (&scenario.convoy, &scenario.artificial) {
        (Some(convoy), _) => write_convoy(args, scenario.seed, convoy, progress),
        (None, Some(artificial)) => write_artificial(args, scenario.seed, artificial),
        (None, None) => anyhow::bail!("{}: no [convoy] or [artificial] table", args.scenario.display()),
    }
}
