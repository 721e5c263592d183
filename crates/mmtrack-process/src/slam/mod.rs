//! The 5G mmWave SLAM filter
//! (Kim et al. 2018, `mmtrack_slam`; `mmtrack process slam`) on a recording's per-epoch path
//! measurements (`/slam/paths`), writing per sequence the tables
//! `slam_ue` (UE estimate per epoch, with the truth when the recording has
//! it), `slam_map` (every map source after every epoch), `slam_associations`
//! (the source each path was given) and `slam_true_sources` (the base
//! station and, from a simulation, the true VAs and SPs).
//!
//! The filter needs the base station's position (the `bs` message on
//! `/slam/sources`) and a prior UE state: the recording's first true state
//! (as the paper's Sec. V-A centres its prior on it), else [`SlamOptions::prior`]. When
//! the recording says which detection probability it was simulated with,
//! the filter assumes it (at most its configured 0.99, eq. (3)).
//!
//! Unusable paths (a NaN, an elevation outside [-pi/2, pi/2]) are skipped
//! and counted in `slam_ue.skipped_paths`, or with `--strict` refused with an
//! error naming the file, the epoch and the field; an epoch without paths
//! only predicts. The particles run on rayon with random streams fixed by
//! the seed and the chunking, so the tables do not depend on the thread count.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use mmtrack_core::slam::{PathOrigin, SlamEpoch, SourceType, UeState};
use mmtrack_io::RecordingEvent;
use mmtrack_io::recording::RecordingMetadata;
use mmtrack_io::table::Frame;
use mmtrack_io::table::{RunInfo, TableWriteSummary};
use mmtrack_io::table::{
    SLAM_ASSOCIATIONS, SLAM_MAP, SLAM_TRUE_SOURCES, SLAM_UE, SlamAssociationRow, SlamMapRow, SlamTrueSourceRow,
    SlamUeRow,
};
use mmtrack_sim::slam::SlamScenario;
use mmtrack_slam::{Decision, EpochReport, SlamConfig, SlamFilter, SourceStatus};

use crate::events::for_each_event;
use crate::output::OutputOptions;

/// Recording metadata key holding the simulated scenario as JSON (written by
/// `mmtrack simulate slam`).
pub const SCENARIO_JSON_KEY: &str = "slam.scenario_json";

/// The options of [`process_slam`].
#[derive(Clone, Debug)]
pub struct SlamOptions {
    /// Filter parameters, a TOML file of any field of the SLAM filter
    /// configuration; the others keep their defaults (the paper's).
    pub config: Option<PathBuf>,
    /// UE particles (overrides the configuration's).
    pub particles: Option<usize>,
    /// Seed of the filter's random streams.
    pub seed: u64,
    /// Prior UE state x, y, z, heading, speed, turn rate, clock bias (m,
    /// rad, m/s, rad/s, m) for recordings without ground truth.
    pub prior: Option<Vec<f64>>,
    /// Refuse a recording with an unusable path instead of skipping it.
    pub strict: bool,
    /// Where the tables go.
    pub output: OutputOptions,
}

impl Default for SlamOptions {
    fn default() -> Self {
        Self { config: None, particles: None, seed: 1, prior: None, strict: false, output: OutputOptions::default() }
    }
}

/// What a SLAM recording holds.
#[derive(Debug, Default)]
pub struct SlamRecording {
    /// The recording's sequence id.
    pub sequence_id: String,
    /// The path measurements per epoch.
    pub epochs: Vec<SlamEpoch>,
    /// The truth per epoch time.
    pub truth: BTreeMap<i64, (UeState, Vec<PathOrigin>)>,
    /// (kind, index, position) in file order.
    pub sources: Vec<(SourceType, usize, [f64; 3])>,
    /// The scenario the recording was simulated from, when it says.
    pub scenario: Option<SlamScenario>,
    /// The recording's metadata (time base, frame keys); `None` only before it is read.
    pub metadata: Option<RecordingMetadata>,
}

/// Reads the SLAM channels of a recording.
///
/// # Errors
/// A bad record, no metadata or no `/slam/paths`, naming the file.
pub fn read_recording(path: &Path) -> anyhow::Result<SlamRecording> {
    let mut out = SlamRecording::default();
    let metadata = for_each_event(path, |event, _| {
        match event {
            RecordingEvent::SlamPaths(epoch) => out.epochs.push(epoch),
            RecordingEvent::SlamUeTruth { t_ns, ue, origins } => {
                out.truth.insert(t_ns, (ue, origins));
            }
            RecordingEvent::SlamSource { kind, index, position_m, .. } => out.sources.push((kind, index, position_m)),
            _ => {}
        }
        Ok(())
    })?;
    let metadata = metadata.as_ref().and_then(RecordingMetadata::from_map);
    out.metadata = metadata.clone();
    out.sequence_id = metadata
        .as_ref()
        .map(|m| m.sequence_id.clone())
        .with_context(|| format!("{}: no mmtrack recording metadata (sequence id)", path.display()))?;
    if let Some(json) = metadata.as_ref().and_then(|m| m.extra.get(SCENARIO_JSON_KEY)) {
        let scenario = serde_json::from_str(json)
            .with_context(|| format!("{}: recording metadata {SCENARIO_JSON_KEY}", path.display()))?;
        out.scenario = Some(scenario);
    }
    if out.epochs.is_empty() {
        bail!("{}: the recording has no /slam/paths messages; nothing written", path.display());
    }
    Ok(out)
}

/// The filter configuration: defaults, the TOML file, `--particles`, the
/// recording's base station and detection probability.
fn filter_config(path: &Path, args: &SlamOptions, recording: &SlamRecording) -> anyhow::Result<SlamConfig> {
    let mut config = match &args.config {
        Some(path) => {
            let text = mmtrack_io::paths::read_config_text(path)?;
            toml::from_str::<SlamConfig>(&text).with_context(|| path.display().to_string())?
        }
        None => SlamConfig::default(),
    };
    if let Some(p) = args.particles {
        let limit = mmtrack_core::limits::PARTICLES;
        if !(p >= 2 && limit.allows_count(p as u64)) {
            let message = format!("--particles {p}: expected {} (nothing was done)", limit.expected);
            return Err(mmtrack_core::error::UsageError(message).into());
        }
        config.particles = p;
    }
    config.strict = config.strict || args.strict;
    let bs = recording.sources.iter().find(|(kind, _, _)| *kind == SourceType::BaseStation);
    let Some((_, _, bs_m)) = bs else {
        bail!("{}: no base station (kind bs) on /slam/sources: the filter needs its position", path.display());
    };
    config.bs_m = *bs_m;
    if let Some(scenario) = &recording.scenario {
        config.detection_probability = config.detection_probability.min(scenario.detection_probability);
    }
    config
        .validate()
        .with_context(|| args.config.as_ref().map_or("filter configuration".into(), |p| p.display().to_string()))?;
    Ok(config)
}

/// With `--strict`, the first unusable path as an error naming the file,
/// the epoch and the field (the filter would only name the epoch index).
fn check_strict(path: &Path, epochs: &[SlamEpoch]) -> anyhow::Result<()> {
    for (k, epoch) in epochs.iter().enumerate() {
        for (i, z) in epoch.paths.iter().enumerate() {
            z.validate().with_context(|| {
                format!("{}: /slam/paths epoch {} (t_ns {}), path {i}", path.display(), k + 1, epoch.t_ns)
            })?;
        }
    }
    Ok(())
}

/// The tables of one run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SlamTables {
    /// `slam_ue` rows.
    pub ue: Vec<SlamUeRow>,
    /// `slam_map` rows.
    pub map: Vec<SlamMapRow>,
    /// `slam_associations` rows.
    pub associations: Vec<SlamAssociationRow>,
    /// `slam_true_sources` rows.
    pub true_sources: Vec<SlamTrueSourceRow>,
}

fn ue_row(k: usize, epoch: &SlamEpoch, report: &EpochReport, truth: Option<&UeState>) -> SlamUeRow {
    let e = &report.estimate;
    let s = &e.state;
    SlamUeRow {
        epoch: k as u64 + 1,
        t_ns: epoch.t_ns,
        initialised: report.initialised,
        x_m: s.position_m[0],
        y_m: s.position_m[1],
        z_m: s.position_m[2],
        heading_rad: s.heading_rad,
        speed_mps: s.speed_mps,
        turn_rate_radps: s.turn_rate_radps,
        clock_bias_m: s.clock_bias_m,
        position_std_m: e.position_std_m,
        heading_std_rad: e.heading_std_rad,
        clock_bias_std_m: e.clock_bias_std_m,
        paths: epoch.paths.len() as u64,
        skipped_paths: report.skipped_paths as u64,
        paths_in_update: report.paths_in_update as u64,
        ess: report.ess,
        true_x_m: truth.map(|t| t.position_m[0]),
        true_y_m: truth.map(|t| t.position_m[1]),
        true_z_m: truth.map(|t| t.position_m[2]),
        true_heading_rad: truth.map(|t| t.heading_rad),
        true_speed_mps: truth.map(|t| t.speed_mps),
        true_turn_rate_radps: truth.map(|t| t.turn_rate_radps),
        true_clock_bias_m: truth.map(|t| t.clock_bias_m),
    }
}

fn origin_columns(origin: Option<&PathOrigin>) -> (Option<String>, Option<u64>) {
    match origin {
        None => (None, None),
        Some(PathOrigin::LineOfSight) => (Some("bs".into()), Some(0)),
        Some(PathOrigin::VirtualAnchor(i)) => (Some("va".into()), Some(*i as u64)),
        Some(PathOrigin::ScatteringPoint(i)) => (Some("sp".into()), Some(*i as u64)),
        Some(PathOrigin::Clutter) => (Some("clutter".into()), None),
    }
}

/// Runs the filter over the recording's epochs.
pub fn run_filter(
    recording: &SlamRecording,
    config: &SlamConfig,
    prior: UeState,
    seed: u64,
) -> anyhow::Result<SlamTables> {
    let mut filter = SlamFilter::new(config.clone(), prior, seed)?;
    let mut tables = SlamTables::default();
    for (k, epoch) in recording.epochs.iter().enumerate() {
        let report =
            filter.step(epoch).with_context(|| format!("/slam/paths epoch {} (t_ns {})", k + 1, epoch.t_ns))?;
        let truth = recording.truth.get(&epoch.t_ns);
        tables.ue.push(ue_row(k, epoch, &report, truth.map(|t| &t.0)));
        for a in &report.associations {
            let (decision, source_id) = match a.decision {
                Decision::Source(id) => ("source", Some(id)),
                Decision::NewSource(id) => ("new_source", Some(id)),
                Decision::Initialisation => ("initialisation", None),
                Decision::Waiting => ("waiting", None),
            };
            let (true_source, true_source_index) = origin_columns(truth.and_then(|t| t.1.get(a.path)));
            tables.associations.push(SlamAssociationRow {
                epoch: k as u64 + 1,
                t_ns: epoch.t_ns,
                path: a.path as u64,
                decision: decision.into(),
                source_id,
                log_score: a.log_score,
                true_source,
                true_source_index,
            });
        }
        for s in filter.sources() {
            let confirmed_epoch = match s.status {
                SourceStatus::BaseStation => Some(0),
                _ => s.confirmed_epoch.map(|c| c as u64 + 1),
            };
            tables.map.push(SlamMapRow {
                epoch: k as u64 + 1,
                t_ns: epoch.t_ns,
                source_id: s.id,
                status: s.status.name().into(),
                confirmed: s.status != SourceStatus::Unconfirmed,
                x_m: s.belief.mean_m[0],
                y_m: s.belief.mean_m[1],
                z_m: s.belief.mean_m[2],
                spread_m: s.belief.spread_m(),
                first_seen_epoch: s.first_seen_epoch as u64 + 1,
                sightings: s.sightings as u64,
                confirmed_epoch,
            });
        }
    }
    let has_origins = !recording.truth.is_empty();
    tables.true_sources = recording
        .sources
        .iter()
        .map(|(kind, index, p)| {
            let detected = recording
                .truth
                .values()
                .filter(|(_, origins)| {
                    origins.iter().any(|o| match (kind, o) {
                        (SourceType::BaseStation, PathOrigin::LineOfSight) => true,
                        (SourceType::VirtualAnchor, PathOrigin::VirtualAnchor(i)) => i == index,
                        (SourceType::ScatteringPoint, PathOrigin::ScatteringPoint(i)) => i == index,
                        _ => false,
                    })
                })
                .count() as u64;
            SlamTrueSourceRow {
                kind: kind.name().into(),
                index: *index as u64,
                x_m: p[0],
                y_m: p[1],
                z_m: p[2],
                detected_epochs: has_origins.then_some(detected),
            }
        })
        .collect();
    Ok(tables)
}

/// Every table `process slam` writes.
pub const TABLE_NAMES: [&str; 4] = [SLAM_UE.name, SLAM_MAP.name, SLAM_ASSOCIATIONS.name, SLAM_TRUE_SOURCES.name];

fn prior_of(path: &Path, args: &SlamOptions, recording: &SlamRecording) -> anyhow::Result<UeState> {
    if let Some(p) = &args.prior {
        let [x, y, z, heading_rad, speed_mps, turn_rate_radps, clock_bias_m] = p[..] else {
            bail!("--prior: expected 7 values x,y,z,heading,speed,turn_rate,clock_bias, got {}", p.len());
        };
        return Ok(UeState { position_m: [x, y, z], heading_rad, speed_mps, turn_rate_radps, clock_bias_m });
    }
    let first = recording.epochs.first().map(|e| e.t_ns);
    match first.and_then(|t| recording.truth.get(&t)) {
        Some((ue, _)) => Ok(*ue),
        None => bail!(
            "{}: no /slam/ue_truth at the first epoch to centre the prior on; give --prior x,y,z,heading,speed,turn_rate,clock_bias",
            path.display()
        ),
    }
}

/// What [`process_slam`] did.
#[derive(Debug, Clone)]
pub struct SlamOutput {
    /// The configuration the filter ran with.
    pub config: SlamConfig,
    /// The tables written.
    pub tables: SlamTables,
    /// Each table written, with its row count.
    pub written: Vec<TableWriteSummary>,
}

impl SlamOutput {
    /// Virtual anchors and scattering points confirmed at the last epoch.
    #[must_use]
    pub fn confirmed_at_end(&self) -> (usize, usize) {
        let last = self.tables.ue.last().map(|u| u.epoch);
        self.tables.map.iter().filter(|r| Some(r.epoch) == last).fold((0, 0), |(va, sp), r| match r.status.as_str() {
            "va" => (va + 1, sp),
            "sp" => (va, sp + 1),
            _ => (va, sp),
        })
    }
}

/// `mmtrack process slam`: the SLAM filter on `recording`'s path
/// measurements, tables under `output`.
///
/// # Errors
/// A bad run id, an existing table (without `force`), a bad recording or
/// configuration, an unusable path with `strict`, or a table that cannot be
/// written.
pub fn process_slam(recording_path: &Path, output: &Path, args: &SlamOptions) -> anyhow::Result<SlamOutput> {
    let out = args.output.resolve(output)?;
    if let Some(sequence) = &args.output.sequence {
        out.refuse_existing(&TABLE_NAMES, sequence)?;
    }
    let recording = read_recording(recording_path)?;
    let sequence = args.output.sequence_or(&recording.sequence_id);
    out.refuse_existing(&TABLE_NAMES, &sequence)?;
    if args.strict {
        check_strict(recording_path, &recording.epochs)?;
    }
    let config = filter_config(recording_path, args, &recording)?;
    let prior = prior_of(recording_path, args, &recording)?;
    let tables =
        run_filter(&recording, &config, prior, args.seed).with_context(|| recording_path.display().to_string())?;
    // read_recording fails without metadata, so it is there.
    let metadata =
        recording.metadata.as_ref().with_context(|| format!("{}: no recording metadata", recording_path.display()))?;
    let info = RunInfo {
        config_json: serde_json::json!({
            "command": "process slam",
            "recording": crate::provenance::canonical(recording_path),
            "inputs": crate::provenance::input_files(&[recording_path])?,
            "seed": args.seed,
            "prior": [prior.position_m[0], prior.position_m[1], prior.position_m[2], prior.heading_rad,
                      prior.speed_mps, prior.turn_rate_radps, prior.clock_bias_m],
            "filter": config,
            "scenario": recording.scenario,
            "run_id": out.run_id(),
            "mmtrack_version": env!("CARGO_PKG_VERSION"),
        })
        .to_string(),
        time_base: metadata.time_base.into(),
        frame: Some(Frame::of_recording(
            "recording_world",
            "the world frame of the recording's SLAM channels (/slam/sources, /slam/ue_truth): the base station's \
             position as /slam/sources gives it, x, y, z in metres, headings counter-clockwise from world x",
            &metadata.extra,
        )),
    };
    let mut staged = out.tables();
    staged.write(&sequence, &tables.ue, &info)?;
    staged.write(&sequence, &tables.map, &info)?;
    staged.write(&sequence, &tables.associations, &info)?;
    staged.write(&sequence, &tables.true_sources, &info)?;
    let written: Vec<TableWriteSummary> = staged.publish()?;
    Ok(SlamOutput { config, tables, written })
}
