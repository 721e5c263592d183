//! The runs of the convoy experiment: each scene simulated once, detected
//! and short-term tracked once (the paper's configuration), and long-term
//! tracked by every variant of eq. (35) on the same full-lifetime tracks;
//! then each (truth, variant) pair scored by `mmtrack_analysis::mpc`.

use mmtrack_analysis::mpc::{DistanceSource, MpcInput, MpcOptions, analyze_mpc};
use mmtrack_core::progress::Progress;
use mmtrack_core::{MpcDetection, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth, StampedPose};
use mmtrack_io::table::MpcSummary;
use mmtrack_mpc::short_term::is_full_lifetime;
use mmtrack_mpc::{
    CandidateGate, LongTermConfig, LongTermTracker, MpcConfig, MpcPipeline, ShortTermConfig, SounderPulse,
};
use mmtrack_sim::sounder::{ConvoyConfig, ConvoySimulator, PathKind};

use super::causes::{Diagnosis, Tables, diagnose};

/// One long-term tracker of the comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    /// Short name for tables and metric keys.
    pub name: &'static str,
    /// Whose it is and what it changes, as the report prints it.
    pub what: &'static str,
    /// Its configuration (the paper's defaults but for the gate and gap).
    pub config: LongTermConfig,
}

/// The paper's eq. (35) as printed (the default configuration).
pub const LITERAL: &str = "eq35-literal";
/// Ours: gated around the Doppler-predicted delay, one missed set allowed.
pub const OURS: &str = "doppler-gated+gap";

/// The four long-term trackers: the paper's, ours, and each of our two
/// changes alone (which of them moves the births).
#[must_use]
pub fn variants() -> Vec<Variant> {
    let with = |candidate_gate, max_missed_sets| LongTermConfig {
        candidate_gate,
        max_missed_sets,
        ..LongTermConfig::default()
    };
    vec![
        Variant {
            name: LITERAL,
            what: "the paper's eq. (35): 1 ns gate on the raw delay change, adjacent sets only",
            config: with(CandidateGate::RawDelay, 0),
        },
        Variant {
            name: "doppler-gated",
            what: "ours, gate only: 1 ns around the eq. (37) prediction, adjacent sets only",
            config: with(CandidateGate::PredictedDelay, 0),
        },
        Variant {
            name: "gap",
            what: "ours, gap only: the paper's raw gate, one missed set bridged",
            config: with(CandidateGate::RawDelay, 1),
        },
        Variant {
            name: OURS,
            what: "ours: 1 ns around the eq. (37) prediction, one missed set bridged",
            config: with(CandidateGate::PredictedDelay, 1),
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
}

impl Measured {
    /// The row of `truth` and `variant`.
    #[must_use]
    pub fn row(&self, truth: Truth, variant: &str) -> Option<&Row> {
        self.rows.iter().find(|r| r.truth == truth && r.variant == variant)
    }
}

/// One scene's tables, long-term entries per variant.
struct Scene {
    detections: Vec<MpcDetection>,
    tracks: Vec<MpcTrack>,
    sets: Vec<MpcSetStats>,
    truth: Vec<MpcTruth>,
    tx: Vec<StampedPose>,
    rx: Vec<StampedPose>,
    long_term: Vec<Vec<MpcLongTermEntry>>,
    carrier_hz: f64,
    blocked_half_width_s: f64,
    snapshots_per_set: u32,
}

/// Simulates `convoy` (seed `seed`), detects and short-term tracks with the
/// paper's configuration, long-term tracks with every variant.
fn run_scene(convoy: &ConvoyConfig, seed: u64, variants: &[Variant]) -> anyhow::Result<Scene> {
    let simulator = ConvoySimulator::new(convoy, seed)?;
    let carrier_hz = convoy.sounder.carrier_hz;
    let pulse = SounderPulse::from_spectrum(simulator.pulse_spectrum().to_vec())?;
    let tap_spacing_s = simulator.band().tap_spacing_s();
    // The pipeline runs the paper's long-term tracker; the variants take the
    // same full-lifetime tracks.
    let mut pipeline = MpcPipeline::new(MpcConfig::default(), &pulse, tap_spacing_s, carrier_hz)?;
    let mut trackers: Vec<LongTermTracker> =
        variants.iter().map(|v| LongTermTracker::new(v.config.clone(), carrier_hz, 0)).collect::<Result<_, _>>()?;
    let mut scene = Scene {
        detections: Vec::new(),
        tracks: Vec::new(),
        sets: Vec::new(),
        truth: Vec::new(),
        tx: Vec::new(),
        rx: Vec::new(),
        long_term: vec![Vec::new(); variants.len()],
        carrier_hz,
        blocked_half_width_s: 0.5 * pipeline.detector().blocked_width_s(),
        snapshots_per_set: convoy.snapshots_per_set,
    };
    let batch = MpcPipeline::SETS_PER_THREAD * rayon::current_num_threads();
    let mut sets = simulator.peekable();
    while sets.peek().is_some() {
        let chunk: Vec<_> = sets.by_ref().take(batch).collect();
        let snapshots: Vec<_> = chunk.iter().map(|s| s.snapshots.as_slice()).collect();
        for (set, output) in chunk.iter().zip(pipeline.push_sets(&snapshots)?) {
            let full: Vec<MpcTrack> =
                output.short_term_tracks.iter().filter(|t| is_full_lifetime(t, set.snapshots.len())).cloned().collect();
            for (tracker, entries) in trackers.iter_mut().zip(&mut scene.long_term) {
                entries.extend(tracker.push_set(&full));
            }
            scene.detections.extend(output.per_snapshot.into_iter().flat_map(|s| s.detections));
            scene.tracks.extend(output.short_term_tracks);
            scene.sets.push(output.stats);
            scene.truth.extend(set.truth.iter().cloned());
            scene.tx.push(set.tx_pose.clone());
            scene.rx.push(set.rx_pose.clone());
        }
    }
    Ok(scene)
}

fn diagnosis(scene: &Scene, truth: &[MpcTruth], long_term: &[MpcLongTermEntry], config: &LongTermConfig) -> Diagnosis {
    let mut sets = scene.sets.clone();
    sets.sort_by_key(|s| s.set_index);
    diagnose(&Tables {
        truth,
        detections: &scene.detections,
        tracks: &scene.tracks,
        long_term,
        sets: &sets,
        config,
        short_term: &ShortTermConfig::default(),
        carrier_hz: scene.carrier_hz,
        blocked_half_width_s: scene.blocked_half_width_s,
        snapshots_per_set: scene.snapshots_per_set,
    })
}

fn score(scene: &Scene, truth: Vec<MpcTruth>, long_term: &[MpcLongTermEntry]) -> (MpcSummary, [u64; 5]) {
    let mut sets = scene.sets.clone();
    sets.sort_by_key(|s| s.set_index);
    let scores = mmtrack_analysis::mpc::truth::score(&truth, &scene.detections, &scene.tracks, long_term, &sets);
    let mut by_kind = [0u64; 5];
    for (&path, &births) in &scores.births_by_path {
        if let Some(k) = PATH_KINDS.iter().position(|(kind, _)| PathKind::of(path) == Some(*kind)) {
            by_kind[k] += births;
        }
    }
    (summarise(scene, truth, long_term), by_kind)
}

fn summarise(scene: &Scene, truth: Vec<MpcTruth>, long_term: &[MpcLongTermEntry]) -> MpcSummary {
    let input = MpcInput {
        detections: scene.detections.clone(),
        tracks: scene.tracks.clone(),
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
    let variants = variants();
    let mut rows = Vec::new();
    let mut diagnoses = Vec::new();
    let mut with_diffuse = convoy.clone();
    with_diffuse.sets = sets;
    with_diffuse.diffuse.in_truth = true;
    progress.note(&format!("simulating and tracking {sets} sets of the tunnel (diffuse scatterers in the truth)"));
    let scene = run_scene(&with_diffuse, seed, &variants)?;
    let specular: Vec<MpcTruth> =
        scene.truth.iter().filter(|t| PathKind::of(t.path_id) != Some(PathKind::Diffuse)).cloned().collect();
    for (truth, table) in [(Truth::SpecularOnly, specular), (Truth::WithDiffuse, scene.truth.clone())] {
        for (variant, entries) in variants.iter().zip(&scene.long_term) {
            let (summary, births_by_kind) = score(&scene, table.clone(), entries);
            diagnoses.push(diagnosis(&scene, &table, entries, &variant.config));
            rows.push(Row { truth, variant: variant.name, summary, births_by_kind });
        }
    }
    let mut no_diffuse = with_diffuse;
    no_diffuse.diffuse.scatterers_per_m = 0.0;
    progress.note(&format!("simulating and tracking {sets} sets of the tunnel without diffuse scatterers"));
    let scene = run_scene(&no_diffuse, seed, &variants)?;
    for (variant, entries) in variants.iter().zip(&scene.long_term) {
        let (summary, births_by_kind) = score(&scene, scene.truth.clone(), entries);
        diagnoses.push(diagnosis(&scene, &scene.truth, entries, &variant.config));
        rows.push(Row { truth: Truth::NoDiffuse, variant: variant.name, summary, births_by_kind });
    }
    Ok(Measured { sets, seed, rows, diagnoses })
}
