//! The beam-sweep trackers and their baselines (`mmtrack process beam`) on
//! recordings of measured beam sweeps (e.g. from `mmtrack ingest beams`),
//! one `beam_sweeps_tracked` partition per recording (sequence).
//!
//! Every recording must hold full sweeps (every beam measured): a tracker
//! sees only the beams it asks for through `mmtrack_beam::sweep::BeamProbe`,
//! and the full sweep scores its choice (`mmtrack_beam::sweep::evaluate`).
//!
//! The GNSS-driven policies (`gnss-window`, `gnss-map`) need the beam map
//! (beam index against the car's bearing from the array, with the array's
//! boresight, beam spacing and GNSS time offset fitted from data). It is
//! fitted leave-one-pass-out over the recordings given together:
//! each recording is predicted by a map fitted on the other recordings of the
//! same site (metadata `beam.site`; a recording without it is a site of its
//! own), so a map is never scored on the sweeps it was fitted to. Those
//! policies therefore need at least two recordings per site, and their
//! numbers depend on which recordings are given together.
//!
//! The car's position at each sweep is its `/gnss/fix` track, and the
//! array's its `/gnss/array` track, each interpolated linearly in latitude
//! and longitude at the sweep's time (exact where a fix has the sweep's
//! time, as `ingest beams` writes them); east/north metres from the array
//! come from the WGS-84 local tangent plane.
//!
//! SPEBT ([`super::spebt`]) and geometric tracking ([`super::geometric`])
//! are other kinds of trackers with their own calls.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use mmtrack_beam::sweep::{
    BeamMap, BeamMapConfig, GnssMapOnly, GnssPass, GnssTrackerConfig, GnssWindowTracker, LastFullSweep, MapPass,
    Reacquisition, SearchConfig, SweepPass, SweepRecord, SweepSummary, SweepTracker, WindowTracker,
    WindowTrackerConfig, evaluate,
};
use mmtrack_core::progress::Progress;
use mmtrack_core::{BeamSweep, GnssFix};
use mmtrack_ingest::nmea::{EnuOrigin, geodetic_to_enu_m};
use mmtrack_io::recording::{BEAM_SITE_KEY, RecordingMetadata, TimeBase};
use mmtrack_io::table::{BEAM_SWEEPS_TRACKED, BeamSweepTracked, RunInfo, TableWriteSummary};
use mmtrack_io::{RecordingEvent, RecordingReader};

use crate::output::OutputOptions;

/// The beam-sweep policies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum SweepTrackerKind {
    /// Constant-velocity Kalman filter on the beam index, from the measured beams alone.
    Window,
    /// The car's GNSS position through the beam map moves the window (SPEBT with GNSS for radar odometry).
    GnssWindow,
    /// Baseline: every sweep measures all beams and uses the previous sweep's best beam.
    LastFullSweep,
    /// Baseline: the beam nearest the GNSS prediction of the beam map, no beam measured.
    GnssMap,
}

impl SweepTrackerKind {
    /// Name in tables and messages.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Window => "window",
            Self::GnssWindow => "gnss-window",
            Self::LastFullSweep => "last-full-sweep",
            Self::GnssMap => "gnss-map",
        }
    }

    fn needs_map(self) -> bool {
        matches!(self, Self::GnssWindow | Self::GnssMap)
    }
}

/// How the window trackers find the beam at a pass start and after a loss.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reacquire {
    /// Every 4th beam, then a climb to the local peak.
    Coarse,
    /// A full sweep (every beam).
    Full,
}

/// One recording, read: its full sweeps and both units' positions.
#[derive(Debug, Clone)]
pub struct BeamRecording {
    /// The file.
    pub path: PathBuf,
    /// Sequence id (recording metadata).
    pub sequence_id: String,
    /// What its `t_ns` counts from (recording metadata).
    pub time_base: TimeBase,
    /// Site (metadata `beam.site`, else the sequence id).
    pub site: String,
    /// Full sweeps in time order.
    pub sweeps: Vec<BeamSweep>,
    /// The car's GNSS fixes (`/gnss/fix`).
    pub vehicle: Vec<GnssFix>,
    /// The array's GNSS fixes (`/gnss/array`).
    pub array: Vec<GnssFix>,
}

/// The `.mcap` files of `inputs` (directories expanded, sorted), in order.
///
/// # Errors
/// A directory that cannot be listed or holds no `.mcap` file.
pub fn expand(inputs: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(input)
                .with_context(|| format!("{}: cannot list", input.display()))?
                .map(|e| e.map(|e| e.path()))
                .collect::<Result<_, _>>()
                .with_context(|| format!("{}: cannot list", input.display()))?;
            found.retain(|p| p.extension().is_some_and(|e| e == "mcap") && p.is_file());
            if found.is_empty() {
                bail!("{}: no .mcap recordings in this directory", input.display());
            }
            found.sort();
            out.extend(found);
        } else {
            out.push(input.clone());
        }
    }
    Ok(out)
}

/// Reads a recording's sweeps and fixes; errors name the file.
pub fn read_beam_recording(path: &Path) -> anyhow::Result<BeamRecording> {
    let mut reader = RecordingReader::open(path)?;
    let (mut sweeps, mut vehicle, mut array) = (Vec::new(), Vec::new(), Vec::new());
    for event in reader.by_ref() {
        match event? {
            RecordingEvent::BeamSweep { sweep, .. } => sweeps.push(sweep),
            RecordingEvent::Gnss(fix) => vehicle.push(fix),
            RecordingEvent::ArrayGnss(fix) => array.push(fix),
            _ => {}
        }
    }
    let metadata = reader.metadata().cloned().unwrap_or_default();
    let (sequence_id, time_base) = RecordingMetadata::from_map(&metadata)
        .map(|m| (m.sequence_id, m.time_base))
        .with_context(|| format!("{}: no mmtrack recording metadata (sequence id)", path.display()))?;
    if sweeps.is_empty() {
        bail!("{}: no beam sweeps (topic /beam/sweeps); nothing to track", path.display());
    }
    let site = metadata.get(BEAM_SITE_KEY).cloned().unwrap_or_else(|| sequence_id.clone());
    Ok(BeamRecording { path: path.to_path_buf(), sequence_id, time_base, site, sweeps, vehicle, array })
}

/// Latitude and longitude of `fixes` (time order) at `t_ns`: the fix at
/// that time, else linear between its neighbours; `None` outside their span.
fn lat_lon_at(fixes: &[GnssFix], t_ns: i64) -> Option<[f64; 2]> {
    let after = fixes.partition_point(|f| f.t_ns < t_ns);
    let b = fixes.get(after)?;
    if b.t_ns == t_ns {
        return Some([b.latitude_deg, b.longitude_deg]);
    }
    let a = fixes.get(after.checked_sub(1)?)?;
    let w = (t_ns - a.t_ns) as f64 / (b.t_ns - a.t_ns) as f64;
    Some([
        a.latitude_deg + w * (b.latitude_deg - a.latitude_deg),
        a.longitude_deg + w * (b.longitude_deg - a.longitude_deg),
    ])
}

/// The car's east/north metres from the array at each sweep.
fn east_north_m(recording: &BeamRecording) -> anyhow::Result<Vec<[f64; 2]>> {
    let sorted = |fixes: &[GnssFix], topic: &str| -> anyhow::Result<()> {
        if fixes.is_empty() {
            bail!(
                "{}: no {topic} fixes; the GNSS policies need the car (/gnss/fix) and the array (/gnss/array)",
                recording.path.display()
            );
        }
        if let Some(pair) = fixes.windows(2).find(|p| p[1].t_ns <= p[0].t_ns) {
            bail!(
                "{}: {topic} fix times do not increase ({} ns then {} ns)",
                recording.path.display(),
                pair[0].t_ns,
                pair[1].t_ns
            );
        }
        Ok(())
    };
    sorted(&recording.vehicle, "/gnss/fix")?;
    sorted(&recording.array, "/gnss/array")?;
    recording
        .sweeps
        .iter()
        .map(|sweep| {
            let t_ns = sweep.t_ns();
            let position = |fixes: &[GnssFix], topic: &str| {
                lat_lon_at(fixes, t_ns).with_context(|| {
                    format!(
                        "{}: sweep at {t_ns} ns lies outside the {topic} fixes' time span",
                        recording.path.display()
                    )
                })
            };
            Ok(car_east_north_m(position(&recording.vehicle, "/gnss/fix")?, position(&recording.array, "/gnss/array")?))
        })
        .collect()
}

/// The car's east and north metres from the array, both given as latitude
/// and longitude (degrees, WGS-84), on the array's local tangent plane.
#[must_use]
pub fn car_east_north_m(car_lat_lon_deg: [f64; 2], array_lat_lon_deg: [f64; 2]) -> [f64; 2] {
    let origin = EnuOrigin { latitude_deg: array_lat_lon_deg[0], longitude_deg: array_lat_lon_deg[1], altitude_m: 0.0 };
    let enu = geodetic_to_enu_m(&origin, car_lat_lon_deg[0], car_lat_lon_deg[1], 0.0);
    [enu[0], enu[1]]
}

/// One pass of full sweeps as [`track_site`] takes it, from a recording or
/// from arrays.
#[derive(Debug, Clone, Copy)]
pub struct PassInput<'a> {
    /// Names the pass in errors (a recording's path, or `pass 3`).
    pub label: &'a str,
    /// Full sweeps in time order.
    pub sweeps: &'a [BeamSweep],
    /// The car's east/north metres from the array at each sweep; needed by
    /// the GNSS policies only.
    pub east_north_m: Option<&'a [[f64; 2]]>,
}

/// What [`track_site`] did for one site.
#[derive(Debug, Clone)]
pub struct SiteRun {
    /// The `beam_sweeps_tracked` rows of each pass (policy after policy).
    pub rows: Vec<Vec<BeamSweepTracked>>,
    /// Per policy, its summary over every pass.
    pub summaries: Vec<(SweepTrackerKind, SweepSummary)>,
    /// The beam map fitted on every pass, when a GNSS policy ran (for
    /// display; each pass was predicted by the map of the other passes).
    pub map: Option<BeamMap>,
}

/// Every policy of `kinds` on every pass of one site. The GNSS policies
/// predict each pass with a beam map fitted on the site's other passes
/// (leave-one-pass-out), so they need at least two passes, each with the
/// car's positions.
///
/// # Errors
/// No policy or no pass; a GNSS policy with fewer than two passes or a pass
/// without positions (or with one per sweep missing); a degenerate map; the
/// trackers' errors; each naming the pass. [`Progress::check_cancelled`]'s
/// error, asked per pass and policy.
pub fn track_site(
    kinds: &[SweepTrackerKind],
    reacquire: Reacquire,
    site: &str,
    passes: &[PassInput<'_>],
    progress: &dyn Progress,
) -> anyhow::Result<SiteRun> {
    let mut kinds = kinds.to_vec();
    kinds.sort();
    kinds.dedup();
    if kinds.is_empty() {
        bail!("--tracker: name at least one of window, gnss-window, last-full-sweep, gnss-map");
    }
    if passes.is_empty() {
        bail!("site {site}: no passes to track");
    }
    let maps = if kinds.iter().any(|k| k.needs_map()) { Some(fit_maps(site, passes)?) } else { None };
    let mut rows: Vec<Vec<BeamSweepTracked>> = vec![Vec::new(); passes.len()];
    let mut summaries = Vec::new();
    for &kind in &kinds {
        let mut records_of_kind = Vec::new();
        for (i, pass) in passes.iter().enumerate() {
            progress.check_cancelled()?;
            let map = maps.as_ref().map(|m| &m.per_pass[i]);
            let gnss_beam = maps.as_ref().map(|m| m.gnss_beam[i].as_slice());
            let mut policy = tracker(kind, reacquire, map)?;
            let records = evaluate(policy.as_mut(), &[SweepPass { sweeps: pass.sweeps, gnss_beam }])
                .with_context(|| format!("{}: {}", pass.label, kind.name()))?;
            rows[i].extend(pass_rows(kind, site, pass.sweeps, &records, gnss_beam));
            records_of_kind.push(records);
        }
        let summary = SweepSummary::from_records(records_of_kind.iter().flatten()).context("no sweeps")?;
        summaries.push((kind, summary));
    }
    Ok(SiteRun { rows, summaries, map: maps.map(|m| m.all) })
}

struct SiteMaps {
    /// Map of each pass (fitted on the others).
    per_pass: Vec<BeamMap>,
    /// GNSS beam prediction of each sweep of each pass.
    gnss_beam: Vec<Vec<f64>>,
    /// The map fitted on every pass, for the summary.
    all: BeamMap,
}

fn fit_maps(site: &str, passes: &[PassInput<'_>]) -> anyhow::Result<SiteMaps> {
    if passes.len() < 2 {
        bail!(
            "site {site}: the GNSS policies need a beam map fitted leave-one-pass-out, so at least two passes of \
             the site ({} given: {}); give more passes, or choose --tracker window,last-full-sweep",
            passes.len(),
            passes.iter().map(|p| p.label).collect::<Vec<_>>().join(", ")
        );
    }
    let beam_count = passes[0].sweeps[0].beam_count();
    if beam_count < 2 {
        bail!(
            "{}: sweeps of {beam_count} beam: the GNSS policies fit a beam map (beam index against the car's \
             bearing), which needs a codebook of at least 2 beams",
            passes[0].label
        );
    }
    let positions: Vec<&[[f64; 2]]> = passes
        .iter()
        .map(|p| {
            let positions = p.east_north_m.with_context(|| {
                format!("{}: the GNSS policies need the car's position at each sweep; none given", p.label)
            })?;
            if positions.len() != p.sweeps.len() {
                bail!("{}: {} car positions for {} sweeps", p.label, positions.len(), p.sweeps.len());
            }
            Ok(positions)
        })
        .collect::<anyhow::Result<_>>()?;
    let t_ns: Vec<Vec<i64>> = passes.iter().map(|p| p.sweeps.iter().map(BeamSweep::t_ns).collect()).collect();
    let best: Vec<Vec<usize>> =
        passes.iter().map(|p| p.sweeps.iter().map(BeamSweep::best_measured_beam).collect()).collect();
    let gnss = |i: usize| GnssPass { t_ns: &t_ns[i], east_north_m: positions[i] };
    let map_passes: Vec<MapPass<'_>> =
        (0..passes.len()).map(|i| MapPass { gnss: gnss(i), best_beam: &best[i] }).collect();
    let config = BeamMapConfig::default();
    let per_pass = BeamMap::fit_leave_one_pass_out(&map_passes, beam_count, &config)
        .with_context(|| format!("site {site}: beam map"))?;
    for (i, map) in per_pass.iter().enumerate() {
        // Zero when the other passes' best beam never changes: the map then
        // predicts nothing, and the GNSS window (whose first sigma is this
        // residual) would have no width.
        if map.rms_residual_beams() > 0.0 {
            continue;
        }
        let mut others: Vec<usize> =
            best.iter().enumerate().filter(|&(j, _)| j != i).flat_map(|(_, b)| b.iter().copied()).collect();
        others.sort_unstable();
        others.dedup();
        let cause = match others.as_slice() {
            [beam] => format!(
                "their best beam is {beam} in every sweep: the power does not vary across the beams (all zero, or \
                 equal), so the beam does not follow the car's bearing"
            ),
            _ => "the best beams lie exactly on the map, which leaves the GNSS window no first width".to_string(),
        };
        bail!(
            "site {site}: the beam map for {} (fitted on the other passes) has an RMS residual of 0 beams: {cause}",
            passes[i].label
        );
    }
    let all = BeamMap::fit(&map_passes, beam_count, &config).with_context(|| format!("site {site}: beam map"))?;
    let gnss_beam = per_pass
        .iter()
        .enumerate()
        .map(|(i, map)| map.predict_pass(&gnss(i)).with_context(|| format!("{}: beam map prediction", passes[i].label)))
        .collect::<anyhow::Result<_>>()?;
    Ok(SiteMaps { per_pass, gnss_beam, all })
}

/// The `gnss-window` settings for a pass whose map (fitted on the other
/// passes) is `map`: the window tracker's, and the map's residual as the
/// GNSS beam's noise.
fn gnss_window_config(reacquire: Reacquire, map: &BeamMap) -> GnssTrackerConfig {
    GnssTrackerConfig {
        window: window_config(reacquire),
        gnss_sigma_beams: map.rms_residual_beams(),
        ..Default::default()
    }
}

fn window_config(reacquire: Reacquire) -> WindowTrackerConfig {
    WindowTrackerConfig { search: search(reacquire), ..Default::default() }
}

fn search(reacquire: Reacquire) -> SearchConfig {
    let reacquisition = match reacquire {
        Reacquire::Coarse => Reacquisition::Coarse { stride: 4 },
        Reacquire::Full => Reacquisition::FullSweep,
    };
    SearchConfig { reacquisition, ..SearchConfig::default() }
}

/// A fresh tracker of `kind` for a pass whose map is `map`.
fn tracker(
    kind: SweepTrackerKind,
    reacquire: Reacquire,
    map: Option<&BeamMap>,
) -> anyhow::Result<Box<dyn SweepTracker>> {
    Ok(match kind {
        SweepTrackerKind::Window => Box::new(WindowTracker::new(window_config(reacquire))?),
        SweepTrackerKind::GnssWindow => {
            let map = map.context("gnss-window without a beam map")?;
            Box::new(GnssWindowTracker::new(gnss_window_config(reacquire, map))?)
        }
        SweepTrackerKind::LastFullSweep => Box::new(LastFullSweep::new()),
        SweepTrackerKind::GnssMap => Box::new(GnssMapOnly),
    })
}

fn pass_rows(
    kind: SweepTrackerKind,
    site: &str,
    sweeps: &[BeamSweep],
    records: &[SweepRecord],
    gnss: Option<&[f64]>,
) -> Vec<BeamSweepTracked> {
    let as_u32 = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
    records
        .iter()
        .map(|r| BeamSweepTracked {
            tracker: kind.name().to_string(),
            site: site.to_string(),
            t_ns: r.t_ns,
            sweep: r.sweep as u64,
            beam_count: as_u32(sweeps.get(r.sweep).map_or(0, BeamSweep::beam_count)),
            chosen_beam: as_u32(r.chosen_beam),
            best_beam: as_u32(r.best_beam),
            beams_measured: as_u32(r.beams_measured),
            reinitialised: r.reinitialised,
            loss_db: r.loss_db,
            gnss_beam: if kind.needs_map() { gnss.and_then(|g| g.get(r.sweep).copied()) } else { None },
        })
        .collect()
}

/// One site of [`process_sweeps`]: its passes and, for the GNSS policies,
/// the beam map fitted on all of them.
#[derive(Debug, Clone)]
pub struct SiteReport {
    /// Site name.
    pub name: String,
    /// Recordings (passes) of the site.
    pub passes: usize,
    /// Sweeps over all passes.
    pub sweeps: usize,
    /// The beam map fitted on every pass (for display; each pass was
    /// predicted by the map of the other passes).
    pub map: Option<BeamMap>,
}

/// What [`process_sweeps`] did.
#[derive(Debug, Clone)]
pub struct SweepOutput {
    /// Per site, in site order.
    pub sites: Vec<SiteReport>,
    /// Per site and policy: (site, policy, summary over its passes).
    pub summaries: Vec<(String, SweepTrackerKind, SweepSummary)>,
    /// Each table written, with its row count.
    pub written: Vec<TableWriteSummary>,
    /// The run directory written.
    pub dir: PathBuf,
}

/// `mmtrack process beam --tracker window,...`: every policy of `kinds` on
/// the full sweeps of each recording, one `beam_sweeps_tracked` partition
/// per recording under `output`.
///
/// # Errors
/// A bad run id, an existing table (without `force`), a bad recording, a
/// sequence given twice, a site with too few passes for the beam map, or a
/// table that cannot be written.
pub fn process_sweeps(
    files: &[PathBuf],
    output: &Path,
    kinds: &[SweepTrackerKind],
    reacquire: Reacquire,
    options: &OutputOptions,
    progress: &dyn Progress,
) -> anyhow::Result<SweepOutput> {
    let out = options.resolve(output)?;
    let mut kinds = kinds.to_vec();
    kinds.sort();
    kinds.dedup();
    let recordings = files.iter().map(|f| read_beam_recording(f)).collect::<anyhow::Result<Vec<_>>>()?;
    let time_bases: BTreeMap<&str, TimeBase> =
        recordings.iter().map(|r| (r.sequence_id.as_str(), r.time_base)).collect();
    super::refuse_repeated_sequences(recordings.iter().map(|r| (r.sequence_id.as_str(), r.path.as_path())))?;
    for r in &recordings {
        out.refuse_existing(&[BEAM_SWEEPS_TRACKED.name], &r.sequence_id)?;
    }
    let mut sites: BTreeMap<&str, Vec<&BeamRecording>> = BTreeMap::new();
    for r in &recordings {
        sites.entry(&r.site).or_default().push(r);
    }
    let needs_map = kinds.iter().any(|k| k.needs_map());
    let mut tables: BTreeMap<String, Vec<BeamSweepTracked>> = BTreeMap::new();
    let mut summaries = Vec::new();
    let mut site_reports = Vec::new();
    for (name, mut passes) in sites {
        // Sequence order, so the maps do not depend on the order of the arguments.
        passes.sort_by(|a, b| a.sequence_id.cmp(&b.sequence_id));
        let positions: Vec<Option<Vec<[f64; 2]>>> =
            passes.iter().map(|p| needs_map.then(|| east_north_m(p)).transpose()).collect::<anyhow::Result<_>>()?;
        let labels: Vec<String> = passes.iter().map(|p| p.path.display().to_string()).collect();
        let inputs: Vec<PassInput<'_>> = passes
            .iter()
            .zip(&positions)
            .zip(&labels)
            .map(|((pass, positions), label)| PassInput {
                label,
                sweeps: &pass.sweeps,
                east_north_m: positions.as_deref(),
            })
            .collect();
        let run = track_site(&kinds, reacquire, name, &inputs, progress)?;
        for (pass, rows) in passes.iter().zip(run.rows) {
            tables.entry(pass.sequence_id.clone()).or_default().extend(rows);
        }
        summaries.extend(run.summaries.into_iter().map(|(kind, summary)| (name.to_string(), kind, summary)));
        site_reports.push(SiteReport {
            name: name.to_string(),
            passes: passes.len(),
            sweeps: passes.iter().map(|p| p.sweeps.len()).sum(),
            map: run.map,
        });
    }
    let config_json = serde_json::json!({
            "command": "process beam",
            "recordings": files.iter().map(|f| crate::provenance::canonical(f)).collect::<Vec<_>>(),
            "inputs": crate::provenance::input_files(files)?,
            "trackers": kinds.iter().map(|k| k.name()).collect::<Vec<_>>(),
            "reacquire": format!("{:?}", search(reacquire).reacquisition),
            "search": format!("{:?}", search(reacquire)),
            "window": format!("{:?}", window_config(reacquire)),
            "gnss_window": format!("{:?} (gnss_sigma_beams: each pass's map residual)", GnssTrackerConfig { window: window_config(reacquire), ..Default::default() }),
            "beam_map": "fitted leave-one-pass-out over the recordings of each site given together",
            "run_id": out.run_id(),
            "mmtrack_version": env!("CARGO_PKG_VERSION"),
        })
        .to_string();
    let mut staged = out.tables();
    for (sequence, rows) in &tables {
        // Each pass is one recording's sequence, on that recording's time base.
        let time_base = *time_bases.get(sequence.as_str()).context("a pass without its recording")?;
        staged.write(sequence, rows, &RunInfo::new(config_json.clone(), time_base))?;
    }
    let written = staged.publish()?;
    Ok(SweepOutput { sites: site_reports, summaries, written, dir: out.path })
}

impl SweepTrackerKind {
    /// The policy of a `--tracker` name.
    ///
    /// # Errors
    /// Not a sweep policy's name.
    pub fn parse(name: &str) -> anyhow::Result<Self> {
        match super::BeamTracker::parse(name)? {
            super::BeamTracker::Sweep(kind) => Ok(kind),
            _ => bail!("--tracker '{name}': not a beam-sweep policy (window, gnss-window, last-full-sweep, gnss-map)"),
        }
    }
}
