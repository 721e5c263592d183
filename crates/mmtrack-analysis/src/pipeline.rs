//! What `mmtrack analyze` does, without the terminal: find the tables that
//! exist, pick the metrics that apply, compute them per sequence.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Context;
use mmtrack_core::plausible::{ANGLE_RAD, COORDINATE_M};
use mmtrack_core::stats::rms;
use mmtrack_core::{
    MpcDetection, MpcLongTermEntry, MpcSetStats, MpcTrack, MpcTruth, OdometryEstimate, Se2, StampedPose,
};
use mmtrack_io::table::{
    BEAM_SWEEPS_TRACKED, BeamSweepTracked, DriftPerLength, GEOMETRIC_PER_EPOCH, GROUND_TRUTH, GeometricEpochRow,
    GroundTruthPose, GroundTruthRxPose, GroundTruthTxPose, MPC_DETECTIONS, MPC_LONG_TERM, MPC_SETS, MPC_TRACKS,
    MpcSnapshotStats, ODOMETRY, POSES, RelativePoseErrorRow, SLAM_UE, SPEBT_PER_SLOT, SPEBT_SUMMARY, SpebtSlotRow,
    SpebtSummaryRow, TableRow, TableTimeBase, TrajectoryMetrics, read_table, read_table_dir, table_path,
};

use crate::beam::BeamResults;
use crate::beam::geometric_analysis::{self, GeometricResults};
use crate::beam::spebt_analysis::{self, SpebtResults};
use crate::beam::sweeps::analyze_beam_sweeps;
use crate::mpc::{DistanceSource, MpcInput, MpcOptions, MpcResult, analyze_mpc};
use crate::trajectory::{
    Association, DriftOptions, FirstFrameStep, KittiDrift, RelativePoseError, TrajectoryError,
    absolute_trajectory_error, associate, kitti_drift, relative_pose_errors, trajectory_distances_m, unaligned_errors,
};

/// Tables found under a table directory: table name -> sequences, sorted.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Inventory {
    /// The directory.
    pub root: PathBuf,
    /// Table name -> sequences with a `part-0.parquet`.
    pub tables: BTreeMap<String, Vec<String>>,
}

impl Inventory {
    /// Sequences of `table` (empty when absent).
    #[must_use]
    pub fn sequences(&self, table: &str) -> &[String] {
        self.tables.get(table).map_or(&[], Vec::as_slice)
    }

    /// `table (n sequences), ...` or `no tables`, for messages.
    #[must_use]
    pub fn describe(&self) -> String {
        if self.tables.is_empty() {
            return "no tables".into();
        }
        let parts: Vec<String> = self
            .tables
            .iter()
            .map(|(t, s)| format!("{t} ({})", mmtrack_core::words::counted(s.len() as u64, "sequence")))
            .collect();
        parts.join(", ")
    }
}

/// Lists `<root>/<table>/sequence=<id>/part-0.parquet`.
pub fn inventory(root: &Path) -> anyhow::Result<Inventory> {
    let mut tables = BTreeMap::new();
    let entries =
        std::fs::read_dir(root).with_context(|| format!("{}: cannot read table directory", root.display()))?;
    for entry in entries {
        let entry = entry.with_context(|| root.display().to_string())?;
        if !entry.path().is_dir() {
            continue;
        }
        let mut sequences = Vec::new();
        for part in std::fs::read_dir(entry.path()).with_context(|| entry.path().display().to_string())? {
            let part = part.with_context(|| entry.path().display().to_string())?;
            let name = part.file_name().to_string_lossy().into_owned();
            if let Some(seq) = name.strip_prefix("sequence=")
                && part.path().join("part-0.parquet").is_file()
            {
                sequences.push(seq.to_string());
            }
        }
        if !sequences.is_empty() {
            sequences.sort();
            tables.insert(entry.file_name().to_string_lossy().into_owned(), sequences);
        }
    }
    Ok(Inventory { root: root.to_path_buf(), tables })
}

/// What was planned for each sequence.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Plan {
    /// Sequences with both an estimate and ground truth: trajectory metrics.
    pub trajectory: Vec<String>,
    /// Sequences with MPC tables (`mpc_sets` and the others of `process mpc`):
    /// MPC statistics.
    pub mpc: Vec<String>,
    /// Sequences with a `beam_sweeps_tracked` table (`process beam`):
    /// beam-sweep accounting.
    pub beam: Vec<String>,
    /// Sequences with `spebt_summary` and `spebt_per_slot` tables (`process
    /// beam --tracker spebt`): SPEBT accuracy.
    pub spebt: Vec<String>,
    /// Sequences with a `geometric_per_epoch` table (`process beam --tracker
    /// geometric`): the geometric tracker's summary.
    pub geometric: Vec<String>,
    /// Sequences with `slam_ue`, `slam_map` and `slam_true_sources` tables
    /// (`process slam`): the SLAM metrics.
    pub slam: Vec<String>,
    /// Sequences that have tables but no metric applies, with the reason.
    pub skipped: Vec<(String, String)>,
}

/// Picks the metrics that apply: `odometry` or `poses` + `ground_truth` of
/// the same sequence -> trajectory metrics; `mpc_sets` (with the other tables of
/// `process mpc`) -> MPC statistics; `beam_sweeps_tracked` -> beam-sweep
/// accounting.
#[must_use]
pub fn plan(inventory: &Inventory) -> Plan {
    let mut plan = Plan {
        beam: inventory.sequences(BEAM_SWEEPS_TRACKED.name).to_vec(),
        geometric: inventory.sequences(GEOMETRIC_PER_EPOCH.name).to_vec(),
        ..Plan::default()
    };
    for seq in inventory.sequences(SPEBT_SUMMARY.name) {
        if inventory.sequences(SPEBT_PER_SLOT.name).contains(seq) {
            plan.spebt.push(seq.clone());
        } else {
            plan.skipped.push((
                seq.clone(),
                format!(
                    "has an {} table but no {} table: SPEBT accuracy needs both",
                    SPEBT_SUMMARY.name, SPEBT_PER_SLOT.name
                ),
            ));
        }
    }
    for seq in inventory.sequences(SLAM_UE.name) {
        let missing: Vec<&str> =
            crate::slam::analysis::INPUT_TABLES.into_iter().filter(|t| !inventory.sequences(t).contains(seq)).collect();
        if missing.is_empty() {
            plan.slam.push(seq.clone());
        } else {
            plan.skipped.push((
                seq.clone(),
                format!("has a slam_ue table but not {}: the SLAM metrics need them", missing.join(", ")),
            ));
        }
    }
    for seq in inventory.sequences(MPC_SETS.name) {
        let missing: Vec<&str> = [MPC_DETECTIONS.name, MPC_TRACKS.name, MPC_LONG_TERM.name]
            .into_iter()
            .filter(|t| !inventory.sequences(t).contains(seq))
            .collect();
        if missing.is_empty() {
            plan.mpc.push(seq.clone());
        } else {
            plan.skipped.push((
                seq.clone(),
                format!("has an {} table but not {}: MPC statistics need them all", MPC_SETS.name, missing.join(", ")),
            ));
        }
    }
    let truth = inventory.sequences(GROUND_TRUTH.name);
    let estimated = estimates_of(inventory);
    for (seq, tables) in &estimated {
        match tables[..] {
            [_] if truth.contains(seq) => plan.trajectory.push(seq.clone()),
            [table] => plan.skipped.push((
                seq.clone(),
                format!("has the {table} table but no {} table: trajectory metrics need both", GROUND_TRUTH.name),
            )),
            _ => plan.skipped.push((seq.clone(), two_estimates(tables))),
        }
    }
    for seq in truth.iter().filter(|s| !estimated.contains_key(*s)) {
        plan.skipped.push((
            seq.clone(),
            format!("has {} but no estimate ({} or {} table)", GROUND_TRUTH.name, ODOMETRY.name, POSES.name),
        ));
    }
    plan
}

/// The tables an estimated trajectory comes in: our radar odometry
/// (`process odometry`) or a recording's own estimate (`process poses`).
const ESTIMATE_TABLES: [&str; 2] = [ODOMETRY.name, POSES.name];

/// Each sequence with an estimate, with the estimate tables it has (one, or
/// both when it has two estimates).
fn estimates_of(inventory: &Inventory) -> BTreeMap<String, Vec<&'static str>> {
    let mut out: BTreeMap<String, Vec<&'static str>> = BTreeMap::new();
    for table in ESTIMATE_TABLES {
        for seq in inventory.sequences(table) {
            out.entry(seq.clone()).or_default().push(table);
        }
    }
    out
}

/// Why a sequence with both estimate tables is not scored.
fn two_estimates(tables: &[&str]) -> String {
    format!(
        "has two estimates ({} tables): which one to score is ambiguous; write them as separate runs (`--run-id`) \
         to compare them side by side",
        tables.join(" and ")
    )
}

/// Everything computed for one sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryResult {
    /// Sequence id.
    pub sequence: String,
    /// The table the estimate came from (`odometry` or `poses`) when read
    /// from tables ([`analyze_all`]); `None` for poses given directly.
    pub estimate_table: Option<&'static str>,
    /// Estimate and ground truth at the same times, both from the identity.
    pub association: Association,
    /// KITTI drift.
    pub drift: KittiDrift,
    /// Per-frame relative pose errors.
    pub rpe: Vec<RelativePoseError>,
    /// Summary row.
    pub metrics: TrajectoryMetrics,
}

impl TrajectoryResult {
    /// Rows of `drift_per_length`.
    #[must_use]
    pub fn drift_rows(&self) -> Vec<DriftPerLength> {
        self.drift
            .per_length
            .iter()
            .map(|l| DriftPerLength {
                length_m: l.length_m,
                segments: l.segments as u64,
                translational_pct: l.translational_pct,
                rotational_deg_per_100m: 100.0 * l.rotational_deg_per_m,
            })
            .collect()
    }

    /// Rows of `relative_pose_errors`.
    #[must_use]
    pub fn rpe_rows(&self) -> Vec<RelativePoseErrorRow> {
        self.rpe
            .iter()
            .map(|e| RelativePoseErrorRow {
                frame: e.frame as u64,
                t_ns: e.t_ns,
                distance_m: e.distance_m,
                translation_error_m: e.translation_error_m,
                yaw_error_rad: e.yaw_error_rad,
            })
            .collect()
    }
}

fn path_length(poses: &[Se2]) -> f64 {
    trajectory_distances_m(poses).last().copied().unwrap_or(0.0)
}

/// All trajectory metrics of one sequence.
pub fn analyze_trajectory(
    sequence: &str,
    estimate: &[StampedPose],
    ground_truth: &[StampedPose],
    options: &DriftOptions,
) -> Result<TrajectoryResult, TrajectoryError> {
    let association = associate(estimate, ground_truth)?;
    let (est, gt) = (&association.estimate, &association.ground_truth);
    let drift = kitti_drift(est, gt, options)?;
    let rpe = relative_pose_errors(&association.t_ns, est, gt)?;
    let ate = absolute_trajectory_error(est, gt)?;
    let unaligned = unaligned_errors(est, gt)?;
    let summary = drift.summary;
    let (step_frames, step_m) = match options.step {
        FirstFrameStep::Frames(n) => (Some(n as u64), None),
        FirstFrameStep::Metres(m) => (None, Some(m)),
    };
    let metrics = TrajectoryMetrics {
        estimate_poses: estimate.len() as u64,
        associated_poses: association.len() as u64,
        interpolated_poses: association.interpolated as u64,
        dropped_poses: association.dropped() as u64,
        first_t_ns: association.t_ns.first().copied().unwrap_or(0),
        last_t_ns: association.t_ns.last().copied().unwrap_or(0),
        path_length_m: drift.path_length_m,
        estimate_path_length_m: path_length(est),
        segment_lengths_m: options.segment_lengths_m.clone(),
        step_frames,
        step_m,
        kitti_segments: drift.segments.len() as u64,
        kitti_translational_pct: summary.map(|s| s.translational_pct),
        kitti_rotational_deg_per_100m: summary.map(|s| s.rotational_deg_per_100m()),
        ate_rmse_m: ate.position_rmse_m,
        ate_max_m: ate.position_max_m,
        x_rmse_m: unaligned.x_rmse_m,
        y_rmse_m: unaligned.y_rmse_m,
        position_rmse_m: unaligned.position_rmse_m,
        yaw_rmse_rad: unaligned.yaw_rmse_rad,
        final_position_error_m: unaligned.final_position_error_m,
        rpe_translation_rmse_m: rms(rpe.iter().map(|e| e.translation_error_m)).unwrap_or(0.0),
        rpe_yaw_rmse_rad: rms(rpe.iter().map(|e| e.yaw_error_rad)).unwrap_or(0.0),
    };
    Ok(TrajectoryResult { sequence: sequence.to_string(), estimate_table: None, association, drift, rpe, metrics })
}

/// An estimate and (when present) its ground truth, as read from tables.
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryInput {
    /// The table the estimate came from (`odometry` or `poses`).
    pub estimate_table: &'static str,
    /// The estimate as poses.
    pub estimate: Vec<StampedPose>,
    /// The `ground_truth` table, when the sequence has one.
    pub ground_truth: Option<Vec<StampedPose>>,
}

/// Reads the estimate (`odometry` or `poses`) and `ground_truth` tables of
/// every sequence under `root` (errors name the file). Sequences without an
/// estimate are absent.
///
/// # Errors
/// A table that cannot be read, implausible poses, or a sequence with both
/// estimate tables.
pub fn read_trajectories(root: &Path) -> anyhow::Result<BTreeMap<String, TrajectoryInput>> {
    let inv = inventory(root)?;
    let estimated = estimates_of(&inv);
    let mut out = BTreeMap::new();
    if estimated.is_empty() {
        return Ok(out);
    }
    if let Some((seq, tables)) = estimated.iter().find(|(_, t)| t.len() > 1) {
        anyhow::bail!("{}: sequence {seq} {}", root.display(), two_estimates(tables));
    }
    let mut estimates: BTreeMap<String, (&'static str, Vec<StampedPose>)> = BTreeMap::new();
    if !inv.sequences(ODOMETRY.name).is_empty() {
        for (sequence, rows) in read_table_dir::<OdometryEstimate>(root)? {
            let poses = rows.iter().map(|e| StampedPose { t_ns: e.t_ns, parent_from_child: e.world_from_vehicle });
            estimates.insert(sequence, (ODOMETRY.name, poses.collect()));
        }
    }
    if !inv.sequences(POSES.name).is_empty() {
        for (sequence, rows) in read_table_dir::<StampedPose>(root)? {
            estimates.insert(sequence, (POSES.name, rows));
        }
    }
    let mut truths = if inv.sequences(GROUND_TRUTH.name).is_empty() {
        BTreeMap::new()
    } else {
        read_table_dir::<GroundTruthPose>(root)?
    };
    for (sequence, (estimate_table, estimate)) in estimates {
        check_plausible_poses(&table_path(root, estimate_table, &sequence)?, &estimate)?;
        let ground_truth: Option<Vec<StampedPose>> =
            truths.remove(&sequence).map(|g| g.into_iter().map(|p| p.0).collect());
        if let Some(truth) = &ground_truth {
            check_plausible_poses(&table_path(root, GROUND_TRUTH.name, &sequence)?, truth)?;
        }
        out.insert(sequence, TrajectoryInput { estimate_table, estimate, ground_truth });
    }
    Ok(out)
}

/// Refuses poses beyond the plausibility bounds of
/// [`mmtrack_core::plausible`], naming the file, the row and the column:
/// coordinates of 1e308 gave NaN and infinite metrics with exit 0.
fn check_plausible_poses(path: &Path, poses: &[StampedPose]) -> anyhow::Result<()> {
    for (row, pose) in poses.iter().enumerate() {
        let p = pose.parent_from_child;
        for (column, bound, value) in
            [("x_m", &COORDINATE_M, p.x_m), ("y_m", &COORDINATE_M, p.y_m), ("yaw_rad", &ANGLE_RAD, p.yaw_rad)]
        {
            bound.check(value).map_err(|e| anyhow::anyhow!("{}: row {row}: {column}: {e}", path.display()))?;
        }
    }
    Ok(())
}

/// Analyzes every sequence of `plan`; an error names the sequence and the
/// table files it came from.
pub fn analyze_all(root: &Path, plan: &Plan, options: &DriftOptions) -> anyhow::Result<Vec<TrajectoryResult>> {
    let inputs = read_trajectories(root)?;
    let mut results = Vec::new();
    for sequence in &plan.trajectory {
        let input = inputs.get(sequence).with_context(|| format!("sequence {sequence}: estimate table vanished"))?;
        let truth = input.ground_truth.as_deref().unwrap_or_default();
        let result = analyze_trajectory(sequence, &input.estimate, truth, options).with_context(|| {
            let file = |t: &str| root.join(t).join(format!("sequence={sequence}")).join("part-0.parquet");
            format!(
                "sequence {sequence} (estimate {}, ground truth {})",
                file(input.estimate_table).display(),
                file(GROUND_TRUTH.name).display()
            )
        })?;
        results.push(TrajectoryResult { estimate_table: Some(input.estimate_table), ..result });
    }
    Ok(results)
}

/// Reads one partition of table `T`, or `None` when the file is absent.
fn read_optional<T: TableRow>(root: &Path, sequence: &str) -> anyhow::Result<Option<Vec<T>>> {
    let path = table_path(root, T::SPEC.name, sequence)?;
    if !path.is_file() {
        return Ok(None);
    }
    Ok(Some(read_table::<T>(&path)?))
}

fn read_required<T: TableRow>(root: &Path, sequence: &str) -> anyhow::Result<Vec<T>> {
    read_optional::<T>(root, sequence)?
        .with_context(|| format!("sequence {sequence}: table {} vanished under {}", T::SPEC.name, root.display()))
}

/// The distance source of a sequence: both sounder vehicles' ground truth,
/// else `ground_truth`, else `odometry`, else none.
fn read_distance(root: &Path, sequence: &str) -> anyhow::Result<DistanceSource> {
    let tx = read_optional::<GroundTruthTxPose>(root, sequence)?;
    let rx = read_optional::<GroundTruthRxPose>(root, sequence)?;
    if let (Some(tx), Some(rx)) = (tx, rx)
        && tx.len() >= 2
        && rx.len() >= 2
    {
        return Ok(DistanceSource::BothVehicles {
            tx: tx.into_iter().map(|p| p.0).collect(),
            rx: rx.into_iter().map(|p| p.0).collect(),
        });
    }
    if let Some(gt) = read_optional::<GroundTruthPose>(root, sequence)?.filter(|g| g.len() >= 2) {
        let poses = gt.into_iter().map(|p| p.0).collect();
        return Ok(DistanceSource::OneVehicle { table: GROUND_TRUTH.name.into(), poses });
    }
    if let Some(odo) = read_optional::<OdometryEstimate>(root, sequence)?.filter(|o| o.len() >= 2) {
        let poses = odo.iter().map(|e| StampedPose { t_ns: e.t_ns, parent_from_child: e.world_from_vehicle }).collect();
        return Ok(DistanceSource::OneVehicle { table: ODOMETRY.name.into(), poses });
    }
    Ok(DistanceSource::None)
}

/// Reads the MPC tables of one sequence partition (errors name the file).
pub fn read_mpc(root: &Path, sequence: &str) -> anyhow::Result<MpcInput> {
    Ok(MpcInput {
        detections: read_required::<MpcDetection>(root, sequence)?,
        tracks: read_required::<MpcTrack>(root, sequence)?,
        long_term: read_required::<MpcLongTermEntry>(root, sequence)?,
        sets: read_required::<MpcSetStats>(root, sequence)?,
        snapshots: read_optional::<MpcSnapshotStats>(root, sequence)?,
        truth: read_optional::<MpcTruth>(root, sequence)?,
        distance: read_distance(root, sequence)?,
    })
}

/// MPC statistics of every sequence of `plan`.
pub fn analyze_mpc_all(root: &Path, plan: &Plan, options: &MpcOptions) -> anyhow::Result<Vec<MpcResult>> {
    plan.mpc
        .iter()
        .map(|sequence| {
            let input = read_mpc(root, sequence).with_context(|| format!("sequence {sequence}: MPC tables"))?;
            Ok(analyze_mpc(sequence, input, options))
        })
        .collect()
}

/// Beam-tracking results of every sequence of `plan`: beam-sweep accounting
/// (table `beam_sweeps_tracked`) per sequence and pooled per site, and SPEBT
/// accuracy (tables `spebt_summary`, `spebt_per_slot`) per sequence and
/// pooled per experiment kind, and the geometric tracker's summary (table
/// `geometric_per_epoch`) per sequence.
pub fn analyze_beam_all(root: &Path, plan: &Plan) -> anyhow::Result<BeamResults> {
    let mut tables = BTreeMap::new();
    for sequence in &plan.beam {
        tables.insert(sequence.clone(), read_required::<BeamSweepTracked>(root, sequence)?);
    }
    let sweeps = analyze_beam_sweeps(tables)
        .map_err(|e| anyhow::anyhow!("{}: {e}", root.join(BEAM_SWEEPS_TRACKED.name).display()))?;
    let mut spebt = SpebtResults::default();
    for sequence in &plan.spebt {
        let summary = read_required::<SpebtSummaryRow>(root, sequence)?;
        let per_slot = read_required::<SpebtSlotRow>(root, sequence)?;
        let result = spebt_analysis::sequence_result(sequence, summary, per_slot)
            .map_err(|e| anyhow::anyhow!("{}: {e}", root.display()))?;
        spebt.sequences.push(result);
    }
    spebt.pooled = spebt_analysis::pool(&spebt.sequences);
    let mut geometric = GeometricResults::default();
    for sequence in &plan.geometric {
        let path = table_path(root, GEOMETRIC_PER_EPOCH.name, sequence)?;
        let rows = read_required::<GeometricEpochRow>(root, sequence)?;
        let result = geometric_analysis::sequence_result(sequence, rows)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        geometric.sequences.push(result);
    }
    Ok(BeamResults { sweeps, spebt, geometric })
}

/// Everything one run's analysis produced (one table directory).
#[derive(Debug, Clone, Default)]
pub struct RunResults {
    /// Trajectory metrics per sequence.
    pub trajectory: Vec<TrajectoryResult>,
    /// MPC statistics per sequence.
    pub mpc: Vec<MpcResult>,
    /// Beam-sweep accounting and SPEBT accuracy.
    pub beam: BeamResults,
    /// SLAM metrics per sequence.
    pub slam: Vec<crate::slam::analysis::SlamSequenceResult>,
    /// Sequences with tables but no metric, and why.
    pub skipped: Vec<(String, String)>,
    /// The time base of each sequence as its input tables state it
    /// ([`time_bases`]); the result tables of a sequence carry it.
    pub time_bases: BTreeMap<String, TableTimeBase>,
}

/// The time base of each sequence under `root`, as its tables state it (key
/// `time_base`): one sequence's tables agree unless they came from different
/// recordings of one sequence id (then `mixed`). A sequence whose tables
/// state none (written by an mmtrack before the key existed) is left out.
///
/// # Errors
/// An unreadable table file.
pub fn time_bases(root: &Path) -> anyhow::Result<BTreeMap<String, TableTimeBase>> {
    let mut stated: BTreeMap<String, Vec<TableTimeBase>> = BTreeMap::new();
    for (table, sequences) in &inventory(root)?.tables {
        for sequence in sequences {
            let path = table_path(root, table, sequence)?;
            if let Some(time_base) = TableTimeBase::of_table_file(&path)? {
                stated.entry(sequence.clone()).or_default().push(time_base);
            }
        }
    }
    Ok(stated.into_iter().filter_map(|(s, bases)| TableTimeBase::pooled(&bases).map(|t| (s, t))).collect())
}

/// Where the tables probably are when `root` holds none: a `tables`
/// directory inside it (a run's or the demo's output directory was given),
/// or the directory above `root` when `root` is itself one table's folder
/// (`<table>/`, with `sequence=<id>/part-0.parquet` inside) or one sequence's
/// (`sequence=<id>/`). Empty otherwise.
fn layout_hint(root: &Path, found: &Inventory) -> String {
    if !found.tables.is_empty() {
        return String::new();
    }
    let inner = root.join("tables");
    if inventory(&inner).is_ok_and(|i| !i.tables.is_empty()) {
        return format!(" (the tables are in {}: pass that directory)", inner.display());
    }
    let is_sequence = |p: &Path| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("sequence="));
    let holds_sequences = std::fs::read_dir(root).is_ok_and(|entries| {
        entries.flatten().any(|e| is_sequence(&e.path()) && e.path().join("part-0.parquet").is_file())
    });
    let (table_dir, what) = if holds_sequences {
        (Some(root), "one table's folder")
    } else if is_sequence(root) && root.join("part-0.parquet").is_file() {
        (root.parent(), "one sequence of one table")
    } else {
        (None, "")
    };
    match table_dir.and_then(Path::parent) {
        Some(tables) => format!(
            " ({} is {what}; pass the directory that holds the tables, {})",
            root.display(),
            if tables.as_os_str().is_empty() { Path::new(".") } else { tables }.display()
        ),
        None => String::new(),
    }
}

/// Analyzes every sequence of the table directory `root`: the metrics that
/// apply ([`plan`]). An error when nothing applies names what was looked for
/// and what was found.
pub fn analyze_run(root: &Path, options: &DriftOptions, mpc_options: &MpcOptions) -> anyhow::Result<RunResults> {
    let found = inventory(root)?;
    let mut plan = plan(&found);
    if plan.trajectory.is_empty()
        && plan.mpc.is_empty()
        && plan.beam.is_empty()
        && plan.spebt.is_empty()
        && plan.geometric.is_empty()
        && plan.slam.is_empty()
    {
        let reasons: String = plan.skipped.iter().map(|(s, r)| format!("; sequence {s} {r}")).collect();
        anyhow::bail!(
            "{}: nothing to analyze: looked for tables {} (or {}) and {} of the same sequence (trajectory metrics), \
             {} with {}, {}, {} (MPC statistics), {} (beam sweeps), {} with {} (SPEBT), {} (geometric tracker) and \
             slam_ue with slam_map and slam_true_sources (SLAM); found {}{reasons}{}",
            root.display(),
            ODOMETRY.name,
            POSES.name,
            GROUND_TRUTH.name,
            MPC_SETS.name,
            MPC_DETECTIONS.name,
            MPC_TRACKS.name,
            MPC_LONG_TERM.name,
            BEAM_SWEEPS_TRACKED.name,
            SPEBT_SUMMARY.name,
            SPEBT_PER_SLOT.name,
            GEOMETRIC_PER_EPOCH.name,
            found.describe(),
            layout_hint(root, &found)
        );
    }
    let trajectory = analyze_all(root, &plan, options)?;
    let mpc = analyze_mpc_all(root, &plan, mpc_options)?;
    let beam = analyze_beam_all(root, &plan)?;
    let (slam, slam_skipped) = crate::slam::analysis::analyze_slam_all(root, &plan.slam)?;
    plan.skipped.extend(slam_skipped);
    Ok(RunResults { trajectory, mpc, beam, slam, skipped: plan.skipped, time_bases: time_bases(root)? })
}
