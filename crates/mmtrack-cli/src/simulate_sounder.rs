//! `mmtrack simulate sounder --scenario <toml> -o <rec.mcap>`: reads a
//! channel-sounder scenario, streams the simulator's CIR snapshots, true MPCs
//! and (convoy) both cars' poses into a recording.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use mmtrack_core::{CirSnapshot, Complex64, MpcTruth};
use mmtrack_io::RecordingWriter;
use mmtrack_io::recording::pulse::{PULSE_SPECTRUM_KEY, encode_pulse_spectrum};
use mmtrack_io::recording::{PoseStream, RecordingMetadata, TimeBase};
use mmtrack_sim::sounder::{
    ArtificialChannelConfig, ConvoyConfig, ConvoySimulator, SounderConfig, SounderScenario, artificial_channel,
};

use crate::ingest::OutputArgs;
use crate::threads::ThreadsArg;

#[derive(Args)]
pub struct SounderArgs {
    /// Scenario file (TOML): seed and one of [artificial] or [convoy] (see data/sounder/).
    #[arg(long, value_name = "SCENARIO.toml")]
    scenario: PathBuf,
    /// Write only the first N sets of the scenario's run (the same sets as the full run's first N).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    sets: Option<u64>,
    #[command(flatten)]
    pub threads: ThreadsArg,
    #[command(flatten)]
    output: OutputArgs,
}

/// Parses and checks a sounder scenario file.
pub fn load_sounder_scenario(path: &Path) -> anyhow::Result<SounderScenario> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
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

fn metadata(args: &SounderArgs, seed: u64, extra: BTreeMap<String, String>) -> RecordingMetadata {
    let mut extra = extra;
    extra.insert("simulator.seed".into(), seed.to_string());
    extra.insert("simulator.scenario".into(), args.scenario.display().to_string());
    RecordingMetadata {
        sequence_id: args
            .output
            .output
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "simulated".into()),
        source: format!("simulate:{}", args.scenario.display()),
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

struct Written {
    sets: u64,
    snapshots: u64,
    truths: u64,
    detail: String,
}

fn write_convoy(args: &SounderArgs, seed: u64, config: &ConvoyConfig, quiet: bool) -> anyhow::Result<Written> {
    // `--sets N` keeps the first N sets of the scenario's run: the world (its
    // length, traffic and scatterers) is laid out for the scenario's own
    // number of sets, so a shorter run is a prefix of the full one.
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
    let output = &args.output;
    let mut writer =
        RecordingWriter::create(&output.output, &metadata(args, seed, extra), &output.recording_options())?;
    let bar = crate::progress::bar(sets as u64, "simulate sounder", "sets", quiet);
    let mut written = Written { sets: 0, snapshots: 0, truths: 0, detail };
    for set in simulator.take(sets) {
        writer.write_pose(PoseStream::GroundTruthTx, &set.tx_pose, "world", "tx")?;
        writer.write_pose(PoseStream::GroundTruthRx, &set.rx_pose, "world", "rx")?;
        for cir in &set.snapshots {
            write_snapshot(&mut writer, cir, &set.truth)?;
        }
        written.sets += 1;
        written.snapshots += set.snapshots.len() as u64;
        written.truths += set.truth.len() as u64;
        bar.inc(1);
    }
    writer.finish()?;
    bar.finish_and_clear();
    Ok(written)
}

fn write_artificial(args: &SounderArgs, seed: u64, config: &ArtificialChannelConfig) -> anyhow::Result<Written> {
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
    let output = &args.output;
    let mut writer =
        RecordingWriter::create(&output.output, &metadata(args, seed, extra), &output.recording_options())?;
    let mut written = Written { sets: 0, snapshots: 0, truths: 0, detail: "two MPCs".into() };
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

pub fn run_sounder(args: &SounderArgs, quiet: bool) -> anyhow::Result<()> {
    let scenario = load_sounder_scenario(&args.scenario)?;
    let written = match (&scenario.convoy, &scenario.artificial) {
        (Some(convoy), _) => write_convoy(args, scenario.seed, convoy, quiet)?,
        (None, Some(artificial)) => write_artificial(args, scenario.seed, artificial)?,
        (None, None) => anyhow::bail!("{}: no [convoy] or [artificial] table", args.scenario.display()),
    };
    if !quiet {
        println!(
            "{}: {} sets, {} CIR snapshots, {} true MPCs ({})",
            args.output.output.display(),
            written.sets,
            written.snapshots,
            written.truths,
            written.detail
        );
    }
    Ok(())
}
