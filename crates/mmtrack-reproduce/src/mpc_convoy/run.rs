//! The runs of the convoy experiment: each scene simulated and detected
//! once, short-term tracked once per short-term search (the paper's
//! configuration for all but one variant), and long-term tracked by every
//! variant on its search's full-lifetime tracks; then each (truth, variant)
//! pair scored by `mmtrack_analysis::mpc`.

use mmtrack_analysis::mpc::{DistanceSource, MpcInput, MpcOptions, analyze_mpc};
use mmtrack_core::progress::Progress;
use mmtrack_core::{MpcDetection, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth, StampedPose};
use mmtrack_io::table::MpcSummary;
use mmtrack_mpc::short_term::is_full_lifetime;
use mmtrack_mpc::{
    CandidateGate, DelayRate, LongTermConfig, LongTermTracker, MpcConfig, MpcPipeline, ShortTermConfig,
    ShortTermPrediction, SounderPulse, short_term_tracks,
};
use mmtrack_sim::sounder::{ConvoyConfig, ConvoySimulator, PathKind, SounderSet};

use super::causes::{Diagnosis, Tables, diagnose};

/// One tracker of the comparison: a short-term search and a long-term
/// tracker on its full-lifetime tracks.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    /// Short name for tables and metric keys.
    pub name: &'static str,
    /// Whose it is and what it changes, as the report prints it.
    pub what: &'static str,
    /// Its long-term configuration (the paper's defaults but for the gate
    /// and gap).
    pub config: LongTermConfig,
    /// Its short-term configuration (the paper's but for [`LS_OURS`]).
    pub short_term: ShortTermConfig,
    /// Whether it runs on the detections of the refined search
    /// ([`mmtrack_mpc::DetectionConfig::refine_overlapping`] and
    /// [`mmtrack_mpc::DetectionConfig::refit_unwindowed`], ours) instead of
    /// the paper's search and subtract.
    pub refined_detection: bool,
}

/// The paper's eq. (35) as printed (the default configuration).
pub const LITERAL: &str = "eq35-literal";
/// Ours: gated around the Doppler-predicted delay, one missed set allowed.
pub const OURS: &str = "doppler-gated+gap";
/// Ours with the least-squares short-term search
/// ([`ShortTermPrediction::LeastSquares`]): the long-term tracker of
/// [`OURS`] on the full-lifetime tracks of a search that predicts from the
/// line through all the track's points instead of its last two (the traced
/// cause of the scatter-free miss: the cars' delay noise against eq. (17)).
pub const LS_OURS: &str = "ls-search+doppler-gated+gap";
/// Ours with the chain's delay slope ([`DelayRate::ChainSlope`]): the
/// long-term tracker of [`OURS`] predicting a continued track from the
/// slope of its last two mean delays (10 ms or more apart) instead of its
/// in-set Doppler (eq. (30), 3.6 ms; the traced cause of the failed links).
pub const CHAIN_OURS: &str = "chain-slope+gated+gap";
/// [`CHAIN_OURS`] on the detections of a search that re-estimates
/// overlapping paths jointly
/// ([`mmtrack_mpc::DetectionConfig::refine_overlapping`], not the paper's
/// steps 3-6: the traced cause of the long-term tracks on no true path, the
/// LOS and the wall bounce 1.1 ns behind it fitted one pulse at a time
/// leave a residue before the LOS) and then re-estimates every detection on
/// the unwindowed, unzeroed CIR
/// ([`mmtrack_mpc::DetectionConfig::refit_unwindowed`]: the traced cause of
/// the cars' broken short-term tracks, the delay noise the Kaiser window and
/// the zeroing add).
pub const REFINED_CHAIN: &str = "refined+chain-slope+gated+gap";

/// The seven trackers: the paper's long-term tracker, ours, each of our two
/// long-term changes alone (which of them moves the births), all on the
/// paper's short-term search; ours on the least-squares search; ours
/// predicting continued tracks from the chain's delay slope; and that one on
/// the refined detections (last: the variants on the paper's detections
/// come first, as the scenes are run).
#[must_use]
pub fn variants() -> Vec<Variant> {
    let with = |candidate_gate, max_missed_sets| LongTermConfig {
        candidate_gate,
        max_missed_sets,
        ..LongTermConfig::default()
    };
    let chain = LongTermConfig { delay_rate: DelayRate::ChainSlope, ..with(CandidateGate::PredictedDelay, 1) };
    vec![
        Variant {
            name: LITERAL,
            what: "the paper's eq. (35): 1 ns gate on the raw delay change, adjacent sets only",
            config: with(CandidateGate::RawDelay, 0),
            short_term: ShortTermConfig::default(),
            refined_detection: false,
        },
        Variant {
            name: "doppler-gated",
            what: "ours, gate only: 1 ns around the eq. (37) prediction, adjacent sets only",
            config: with(CandidateGate::PredictedDelay, 0),
            short_term: ShortTermConfig::default(),
            refined_detection: false,
        },
        Variant {
            name: "gap",
            what: "ours, gap only: the paper's raw gate, one missed set bridged",
            config: with(CandidateGate::RawDelay, 1),
            short_term: ShortTermConfig::default(),
            refined_detection: false,
        },
        Variant {
            name: OURS,
            what: "ours: 1 ns around the eq. (37) prediction, one missed set bridged",
            config: with(CandidateGate::PredictedDelay, 1),
            short_term: ShortTermConfig::default(),
            refined_detection: false,
        },
        Variant {
            name: LS_OURS,
            what: "ours with the least-squares short-term search: each point predicted from the line through all \
                   the track's points (eq. (17): the last two), epsilon_tau = 0.5 ns of eq. (23) unchanged; \
                   long-term as doppler-gated+gap",
            config: with(CandidateGate::PredictedDelay, 1),
            short_term: ShortTermConfig { prediction: ShortTermPrediction::LeastSquares, ..ShortTermConfig::default() },
            refined_detection: false,
        },
        Variant {
            name: CHAIN_OURS,
            what: "ours with the chain's delay slope: a continued track predicted (eqs. (35), (37), (41)) from the \
                   slope of its last two mean delays instead of its own Doppler; the backward prediction (39) \
                   keeps the candidate's Doppler; otherwise as doppler-gated+gap",
            config: chain.clone(),
            short_term: ShortTermConfig::default(),
            refined_detection: false,
        },
        Variant {
            name: REFINED_CHAIN,
            what: "chain-slope+gated+gap on the detections of a search that re-estimates each new detection and \
                   those within 3 taps of it jointly, dropping any that falls below the threshold, then every \
                   detection on the CIR without window or zeroing (ours, not the paper's steps 1-6)",
            config: chain,
            short_term: ShortTermConfig::default(),
            refined_detection: true,
        },
    ]
}

/// What the truth holds in one scored row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Truth {
    /// The tunnel as simulated, scored against the specular paths only (as
    /// before issue 25: the diffuse scatterers' tracks count as false).
    SpecularOnly,
    /// The same run, the diffuse scatterers in the truth too (those whose
    /// mean power over a set reaches floor + 6 dB are present there).
    WithDiffuse,
    /// The tunnel with the diffuse scatterers off (nothing to leave out).
    NoDiffuse,
}

impl Truth {
    /// Every truth definition, in report order.
    pub const ALL: [Self; 3] = [Self::SpecularOnly, Self::WithDiffuse, Self::NoDiffuse];
    /// The two fair truths of issue 25, in report order.
    pub const FAIR: [Self; 2] = [Self::WithDiffuse, Self::NoDiffuse];

    /// Short name for metric keys.
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::SpecularOnly => "specular truth",
            Self::WithDiffuse => "diffuse in truth",
            Self::NoDiffuse => "no diffuse",
        }
    }

    /// As the report prints it.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Self::SpecularOnly => "tunnel; truth: specular paths only (the score before issue 25)",
            Self::WithDiffuse => "tunnel; truth: specular paths and the diffuse scatterers",
            Self::NoDiffuse => "tunnel without diffuse scatterers",
        }
    }
}

/// One (truth, variant) pair scored.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The truth it is scored against.
    pub truth: Truth,
    /// The long-term tracker's name ([`Variant::name`]).
    pub variant: &'static str,
    /// Everything `analyze` reports for it.
    pub summary: MpcSummary,
    /// Births of long-term tracks on true paths by the kind of path they
    /// follow, in [`PATH_KINDS`] order.
    pub births_by_kind: [u64; 5],
}

/// The path kinds births on true paths are split by.
pub const PATH_KINDS: [(PathKind, &str); 5] = [
    (PathKind::Los, "LOS"),
    (PathKind::SingleBounce, "wall bounce"),
    (PathKind::DoubleBounce, "double bounce"),
    (PathKind::Traffic, "traffic"),
    (PathKind::Diffuse, "diffuse"),
];

/// What the experiment measured.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Sets per scene.
    pub sets: usize,
    /// The scenario's seed.
    pub seed: u64,
    /// Every (truth, variant) pair, truth-major in [`Truth::ALL`] order,
    /// variants in [`variants`] order.
    pub rows: Vec<Row>,
    /// Why the births on true paths happened, per (truth, variant) pair
    /// of [`Measured::rows`] (same order).
    pub diagnoses: Vec<Diagnosis>,
    /// The tunnel with other seeds ([`OTHER_SEEDS`]), with the diffuse
    /// scatterers in the truth and without them: the variants of
    /// [`SEED_VARIANTS`] against each truth.
    pub other_seeds: Vec<SeedRow>,
}

/// Seeds of the tunnel run beside the scenario's (both fair truths): other
/// draws of the traffic (Poisson arrivals, speeds), the diffuse scatterers,
/// path phases and noise, so that no birth-rate verdict is one draw's.
pub const OTHER_SEEDS: [u64; 4] = [1, 2, 3, 4];

/// The variants run on [`OTHER_SEEDS`]: the paper's, ours and the best row.
pub const SEED_VARIANTS: [&str; 3] = [LITERAL, OURS, REFINED_CHAIN];

/// One variant on the tunnel with another seed, against one fair truth.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedRow {
    /// The seed.
    pub seed: u64,
    /// [`Truth::WithDiffuse`] or [`Truth::NoDiffuse`].
    pub truth: Truth,
    /// The long-term tracker's name ([`Variant::name`]).
    pub variant: &'static str,
    /// Everything `analyze` reports for it.
    pub summary: MpcSummary,
}

impl Measured {
    /// The row of `truth` and `variant`.
    #[must_use]
    pub fn row(&self, truth: Truth, variant: &str) -> Option<&Row> {
        self.rows.iter().find(|r| r.truth == truth && r.variant == variant)
    }
}

/// One scene's tables: short-term tracks per distinct short-term search,
/// long-term entries per variant.
struct Scene {
    detections: Vec<MpcDetection>,
    /// Short-term tracks per search of `searches`.
    tracks: Vec<Vec<MpcTrack>>,
    /// The distinct short-term searches, the paper's (the pipeline's) first.
    searches: Vec<ShortTermConfig>,
    /// Index into `searches` / `tracks` of each variant's search.
    search_of: Vec<usize>,
    sets: Vec<MpcSetStats>,
    truth: Vec<MpcTruth>,
    tx: Vec<StampedPose>,
    rx: Vec<StampedPose>,
    long_term: Vec<Vec<MpcLongTermEntry>>,
    carrier_hz: f64,
    blocked_half_width_s: f64,
    snapshots_per_set: u32,
}

/// One detector's run over a scene: its pipeline (detection with the
/// paper's search and subtract, or with `refined` the refined search, and
/// the paper's short-term search), every other short-term search of its
/// variants (on the same detections, track ids from 0), and the long-term
/// tracker of every variant on its search's full-lifetime tracks.
struct Run {
    pipeline: MpcPipeline,
    trackers: Vec<LongTermTracker>,
    next_track_id: Vec<u64>,
    scene: Scene,
}

impl Run {
    fn new(
        variants: &[Variant],
        refined: bool,
        pulse: &SounderPulse,
        tap_spacing_s: f64,
        carrier_hz: f64,
        snapshots_per_set: u32,
    ) -> anyhow::Result<Self> {
        // The pipeline runs the paper's long-term tracker; the variants take
        // the same full-lifetime tracks.
        let mut config = MpcConfig::default();
        config.detection.refine_overlapping = refined;
        config.detection.refit_unwindowed = refined;
        let pipeline = MpcPipeline::new(config, pulse, tap_spacing_s, carrier_hz)?;
        let trackers: Vec<LongTermTracker> =
            variants.iter().map(|v| LongTermTracker::new(v.config.clone(), carrier_hz, 0)).collect::<Result<_, _>>()?;
        let mut searches = vec![ShortTermConfig::default()];
        let mut search_of = Vec::new();
        for v in variants {
            if let Some(i) = searches.iter().position(|c| *c == v.short_term) {
                search_of.push(i);
            } else {
                search_of.push(searches.len());
                searches.push(v.short_term.clone());
            }
        }
        let scene = Scene {
            detections: Vec::new(),
            tracks: vec![Vec::new(); searches.len()],
            searches,
            search_of,
            sets: Vec::new(),
            truth: Vec::new(),
            tx: Vec::new(),
            rx: Vec::new(),
            long_term: vec![Vec::new(); variants.len()],
            carrier_hz,
            blocked_half_width_s: 0.5 * pipeline.detector().blocked_width_s(),
            snapshots_per_set,
        };
        Ok(Self { pipeline, trackers, next_track_id: vec![0; scene.searches.len()], scene })
    }

    /// Detects and tracks the next `chunk` of sets.
    fn push(&mut self, chunk: &[SounderSet]) -> anyhow::Result<()> {
        let scene = &mut self.scene;
        let snapshots: Vec<_> = chunk.iter().map(|s| s.snapshots.as_slice()).collect();
        for (set, output) in chunk.iter().zip(self.pipeline.push_sets(&snapshots)?) {
            let per_snapshot: Vec<Vec<MpcDetection>> = output.per_snapshot.into_iter().map(|s| s.detections).collect();
            let mut by_search = vec![output.short_term_tracks];
            for (config, next_id) in scene.searches.iter().zip(&mut self.next_track_id).skip(1) {
                let tracks = short_term_tracks(&per_snapshot, scene.carrier_hz, config, *next_id);
                *next_id += tracks.len() as u64;
                by_search.push(tracks);
            }
            let full: Vec<Vec<MpcTrack>> = by_search
                .iter()
                .map(|tracks| tracks.iter().filter(|t| is_full_lifetime(t, set.snapshots.len())).cloned().collect())
                .collect();
            for ((tracker, entries), &search) in
                self.trackers.iter_mut().zip(&mut scene.long_term).zip(&scene.search_of)
            {
                entries.extend(tracker.push_set(&full[search]));
            }
            scene.detections.extend(per_snapshot.into_iter().flatten());
            for (table, tracks) in scene.tracks.iter_mut().zip(by_search) {
                table.extend(tracks);
            }
            scene.sets.push(output.stats);
            scene.truth.extend(set.truth.iter().cloned());
            scene.tx.push(set.tx_pose.clone());
            scene.rx.push(set.rx_pose.clone());
        }
        Ok(())
    }
}

/// Simulates `convoy` (seed `seed`) once and runs every detector of
/// `groups` (`(refined, variants)`, see [`Run`]) on the same snapshots; one
/// scene per group, in order.
fn run_scenes(
    convoy: &ConvoyConfig,
    seed: u64,
    groups: &[(bool, Vec<Variant>)],
    progress: &dyn Progress,
) -> anyhow::Result<Vec<Scene>> {
    let simulator = ConvoySimulator::new(convoy, seed)?;
    let pulse = SounderPulse::from_spectrum(simulator.pulse_spectrum().to_vec())?;
    let tap_spacing_s = simulator.band().tap_spacing_s();
    let mut runs = groups
        .iter()
        .map(|(refined, variants)| {
            Run::new(variants, *refined, &pulse, tap_spacing_s, convoy.sounder.carrier_hz, convoy.snapshots_per_set)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let batch = MpcPipeline::SETS_PER_THREAD * rayon::current_num_threads();
    let mut sets = simulator.peekable();
    while sets.peek().is_some() {
        progress.check_cancelled()?;
        let chunk: Vec<SounderSet> = sets.by_ref().take(batch).collect();
        for run in &mut runs {
            run.push(&chunk)?;
        }
    }
    Ok(runs.into_iter().map(|run| run.scene).collect())
}

/// Why the births of variant `v` (index into `variants`) happened.
fn diagnosis(scene: &Scene, truth: &[MpcTruth], v: usize, config: &LongTermConfig) -> Diagnosis {
    let mut sets = scene.sets.clone();
    sets.sort_by_key(|s| s.set_index);
    let search = scene.search_of[v];
    diagnose(&Tables {
        truth,
        detections: &scene.detections,
        tracks: &scene.tracks[search],
        long_term: &scene.long_term[v],
        sets: &sets,
        config,
        short_term: &scene.searches[search],
        carrier_hz: scene.carrier_hz,
        blocked_half_width_s: scene.blocked_half_width_s,
        snapshots_per_set: scene.snapshots_per_set,
    })
}

/// Scores variant `v` (index into `variants`) against `truth`.
fn score(scene: &Scene, truth: Vec<MpcTruth>, v: usize) -> (MpcSummary, [u64; 5]) {
    let mut sets = scene.sets.clone();
    sets.sort_by_key(|s| s.set_index);
    let tracks = &scene.tracks[scene.search_of[v]];
    let long_term = &scene.long_term[v];
    let scores = mmtrack_analysis::mpc::truth::score(&truth, &scene.detections, tracks, long_term, &sets);
    let mut by_kind = [0u64; 5];
    for (&path, &births) in &scores.births_by_path {
        if let Some(k) = PATH_KINDS.iter().position(|(kind, _)| PathKind::of(path) == Some(*kind)) {
            by_kind[k] += births;
        }
    }
    (summarise(scene, truth, tracks, long_term), by_kind)
}

/// The summary of one variant's tables. The per-set gains of `scene.sets`
/// are the pipeline's (the paper's search) for every variant; the report
/// uses none of them.
fn summarise(scene: &Scene, truth: Vec<MpcTruth>, tracks: &[MpcTrack], long_term: &[MpcLongTermEntry]) -> MpcSummary {
    let input = MpcInput {
        detections: scene.detections.clone(),
        tracks: tracks.to_vec(),
        long_term: long_term.to_vec(),
        sets: scene.sets.clone(),
        snapshots: None,
        truth: Some(truth),
        distance: DistanceSource::BothVehicles { tx: scene.tx.clone(), rx: scene.rx.clone() },
    };
    analyze_mpc("convoy", input, &MpcOptions::default()).summary
}

/// Runs both scenes of `convoy` cut to `sets` sets: the tunnel with its
/// diffuse scatterers listed in the truth (scored with and without them)
/// and the tunnel with them off; every variant on each.
///
/// # Errors
/// A bad scenario, a simulator or pipeline failure.
pub fn measure(convoy: &ConvoyConfig, seed: u64, sets: usize, progress: &dyn Progress) -> anyhow::Result<Measured> {
    let mut rows = Vec::new();
    let mut diagnoses = Vec::new();
    let mut with_diffuse = convoy.clone();
    with_diffuse.sets = sets;
    with_diffuse.diffuse.in_truth = true;
    let mut no_diffuse = with_diffuse.clone();
    no_diffuse.diffuse.scatterers_per_m = 0.0;
    for (scenario, truths, what) in [
        (&with_diffuse, &[Truth::SpecularOnly, Truth::WithDiffuse][..], "the tunnel (diffuse scatterers in the truth)"),
        (&no_diffuse, &[Truth::NoDiffuse][..], "the tunnel without diffuse scatterers"),
    ] {
        // One simulation, one scene per detector: the paper's search, then
        // the refined one.
        let groups = detector_groups(|_| true);
        progress
            .note(&format!("simulating and tracking {sets} sets of {what} (the paper's search and the refined one)"));
        let scenes: Vec<(Scene, Vec<Variant>)> = run_scenes(scenario, seed, &groups, progress)?
            .into_iter()
            .zip(groups.into_iter().map(|(_, g)| g))
            .collect();
        for &truth in truths {
            for (scene, group) in &scenes {
                let table: Vec<MpcTruth> = if truth == Truth::SpecularOnly {
                    scene.truth.iter().filter(|t| PathKind::of(t.path_id) != Some(PathKind::Diffuse)).cloned().collect()
                } else {
                    scene.truth.clone()
                };
                for (v, variant) in group.iter().enumerate() {
                    // Scoring one variant takes about a second: a Ctrl-C
                    // from Python waits for one score, not for all of them.
                    progress.check_cancelled()?;
                    let (summary, births_by_kind) = score(scene, table.clone(), v);
                    diagnoses.push(diagnosis(scene, &table, v, &variant.config));
                    rows.push(Row { truth, variant: variant.name, summary, births_by_kind });
                }
            }
        }
    }
    let mut other_seeds = Vec::new();
    for other in OTHER_SEEDS {
        for (scenario, truth) in [&with_diffuse, &no_diffuse].into_iter().zip(Truth::FAIR) {
            progress.note(&format!("simulating and tracking {sets} sets, seed {other}: {}", truth.describe()));
            let groups = detector_groups(|v| SEED_VARIANTS.contains(&v.name));
            for (scene, (_, group)) in run_scenes(scenario, other, &groups, progress)?.iter().zip(&groups) {
                for (v, variant) in group.iter().enumerate() {
                    progress.check_cancelled()?;
                    let (summary, _) = score(scene, scene.truth.clone(), v);
                    other_seeds.push(SeedRow { seed: other, truth, variant: variant.name, summary });
                }
            }
        }
    }
    Ok(Measured { sets, seed, rows, diagnoses, other_seeds })
}

/// The variants `keep` selects, grouped by detector: the paper's search,
/// then the refined one (groups without a variant left out).
fn detector_groups(keep: impl Fn(&Variant) -> bool) -> Vec<(bool, Vec<Variant>)> {
    [false, true]
        .into_iter()
        .map(|refined| {
            (refined, variants().into_iter().filter(|v| v.refined_detection == refined && keep(v)).collect())
        })
        .filter(|(_, group): &(bool, Vec<Variant>)| !group.is_empty())
        .collect()
}
