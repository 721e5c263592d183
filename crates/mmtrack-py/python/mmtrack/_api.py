"""ingest, process, analyze, reproduce: the CLI's commands as library calls."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Optional, Sequence, Union

from . import _native

PathLike = Union[str, "os.PathLike[str]"]

#: Options of each ``ingest`` kind (beyond the recording flags) and their
#: defaults, as the CLI's ``mmtrack ingest <kind> --help`` lists them.
INGEST_OPTIONS: dict[str, dict[str, Any]] = {
    "oxford": {"threads": 0, "range_resolution_m": None, "bins": "3768", "decode": False, "sequence_id": None},
    "boreas": {"threads": 0, "range_resolution_m": None, "decode": False, "sequence_id": None},
    "mulran": {
        "threads": 0,
        "range_resolution_m": None,
        "stamp_at": "end",
        "scan_period_s": 0.25,
        "sequence_id": None,
    },
    "cir": {"format": None, "sidecar": None},
    "nmea": {"add_to": None},
    "beams": {"format": "deepsense", "scenario": None, "positions": "auto", "sweep_period_s": 0.1},
    "poses": {"format": None, "add_to": None, "estimate": False, "times": None, "t0_ns": 0, "plane": "xy"},
    "ros2": {
        "pose_topic": "/odom",
        "poses_are_ground_truth": False,
        "ground_truth_topic": None,
        "gnss_topic": None,
        "radar_topic": None,
        "radar_range_resolution_m": None,
        "stamp_at": "end",
        "scan_period_s": 0.25,
    },
}

#: Options of each ``process`` pipeline and their defaults.
PROCESS_OPTIONS: dict[str, dict[str, Any]] = {
    "odometry": {
        "preset": "cfear",
        "config": None,
        "sequence": None,
        "force": False,
        "run_id": None,
        "threads": 0,
    },
    "poses": {
        "sequence": None,
        "force": False,
        "run_id": None,
    },
    "raw": {
        "sequence": None,
        "force": False,
        "run_id": None,
    },
    "mpc": {
        "config": None,
        "pulse": None,
        "link": None,
        "gmphd": False,
        "sequence": None,
        "force": False,
        "run_id": None,
        "threads": 0,
    },
    "beam": {
        "tracker": ("window", "gnss-window", "last-full-sweep", "gnss-map"),
        "reacquire": "coarse",
        "force": False,
        "run_id": None,
        # --tracker spebt
        "odometry": None,
        "odometry_run": None,
        "link": None,
        "sigma_r_m": None,
        "sigma_theta_deg": None,
        "seed": None,
        "runs": None,
        # --tracker geometric
        "beam_schedule": None,
        "epoch_ms": None,
        "doppler_seed": None,
    },
    "slam": {
        "config": None,
        "particles": None,
        "seed": 1,
        "prior": None,
        "strict": False,
        "sequence": None,
        "force": False,
        "run_id": None,
        "threads": 0,
    },
}


def _path(p: Optional[PathLike]) -> Optional[str]:
    return None if p is None else os.fspath(p)


def _options(command: str, defaults: dict[str, Any], given: dict[str, Any]) -> dict[str, Any]:
    unknown = sorted(set(given) - set(defaults))
    if unknown:
        raise TypeError(f"{command}: unexpected keyword argument(s) {unknown}; it takes {sorted(defaults)}")
    return {**defaults, **given}


def ingest(
    kind: str,
    input: PathLike,
    output: PathLike,
    *,
    force: bool = False,
    compression: str = "zstd",
    zstd_level: int = 1,
    no_foxglove_views: bool = False,
    no_radar_cartesian: bool = False,
    radar_cartesian_m_per_px: Optional[float] = None,
    radar_cartesian_size_px: Optional[int] = None,
    no_sync: bool = False,
    **options: Any,
) -> Any:
    """``mmtrack ingest <kind> <input> -o <output>``: a raw dataset into a canonical recording.

    ``kind``: oxford, boreas, mulran, poses, cir, nmea, ros2 or beams; ``options`` are the
    kind's own flags (:data:`INGEST_OPTIONS`), e.g. ``bins="auto"`` for
    oxford, ``format="npy", sidecar="cir.toml"`` for cir. Returns the
    recording written (path, bytes, message counts and the kind's counts);
    for beams, one per pass.
    """
    defaults = INGEST_OPTIONS.get(kind)
    if defaults is None:
        raise _native.MmtrackError(f"ingest: unknown kind '{kind}': expected one of {', '.join(INGEST_OPTIONS)}")
    o = _options(f"ingest {kind}", defaults, options)
    flags = {
        "force": force,
        "compression": compression,
        "zstd_level": zstd_level,
        "no_foxglove_views": no_foxglove_views,
        "no_radar_cartesian": no_radar_cartesian,
        "radar_cartesian_m_per_px": radar_cartesian_m_per_px,
        "radar_cartesian_size_px": radar_cartesian_size_px,
        "no_sync": no_sync,
    }
    i, out = os.fspath(input), os.fspath(output)
    if kind == "oxford":
        return _native.ingest_oxford(
            i, out, flags, o["threads"], o["range_resolution_m"], str(o["bins"]), o["decode"], o["sequence_id"]
        )
    if kind == "boreas":
        return _native.ingest_boreas(i, out, flags, o["threads"], o["range_resolution_m"], o["decode"], o["sequence_id"])
    if kind == "mulran":
        return _native.ingest_mulran(
            i, out, flags, o["threads"], o["range_resolution_m"], o["stamp_at"], o["scan_period_s"], o["sequence_id"]
        )
    if kind == "cir":
        if o["format"] is None:
            raise _native.MmtrackError("ingest cir: give format= (npy, npz, mat, hdf5, sigmf, csv or decawave)")
        return _native.ingest_cir(i, out, flags, o["format"], _path(o["sidecar"]))
    if kind == "nmea":
        return _native.ingest_nmea(i, out, flags, _path(o["add_to"]))
    if kind == "poses":
        if o["format"] is None:
            raise _native.MmtrackError("ingest poses: give format= (tum, kitti or oxford)")
        return _native.ingest_poses(
            i, out, flags, o["format"], _path(o["add_to"]), o["estimate"], _path(o["times"]), o["t0_ns"], o["plane"]
        )
    if kind == "ros2":
        return _native.ingest_ros2(
            i,
            out,
            flags,
            o["pose_topic"],
            o["poses_are_ground_truth"],
            o["ground_truth_topic"],
            o["gnss_topic"],
            o["radar_topic"],
            o["radar_range_resolution_m"],
            o["stamp_at"],
            o["scan_period_s"],
        )
    if o["format"] != "deepsense":
        raise _native.MmtrackError(f"--format '{o['format']}': expected deepsense")
    return _native.ingest_beams(i, out, flags, o["scenario"], o["positions"], o["sweep_period_s"])


def process(pipeline: str, recording: Union[PathLike, Sequence[PathLike]], output: PathLike, **options: Any) -> Any:
    """``mmtrack process <pipeline> <recording> -o <output>``: a pipeline's tables.

    ``pipeline``: odometry, poses (the recording's own estimate and ground
    truth, to score another odometry), raw (its radar scans, CIR snapshots,
    GNSS fixes and ground truth as tables), mpc, beam (``recording`` may be a list
    of recordings or folders) or slam; ``options`` are its flags
    (:data:`PROCESS_OPTIONS`). Returns the tables written (path, rows) and
    the pipeline's counts.
    """
    defaults = PROCESS_OPTIONS.get(pipeline)
    if defaults is None:
        raise _native.MmtrackError(
            f"process: unknown pipeline '{pipeline}': expected one of {', '.join(PROCESS_OPTIONS)}"
        )
    o = _options(f"process {pipeline}", defaults, options)
    out = os.fspath(output)
    if pipeline == "beam":
        recordings = [recording] if isinstance(recording, (str, os.PathLike)) else list(recording)
        tracker = [o["tracker"]] if isinstance(o["tracker"], str) else list(o["tracker"])
        spebt = {k: o[k] for k in ("odometry", "odometry_run", "link", "sigma_r_m", "sigma_theta_deg", "seed", "runs")}
        spebt = {k: (_path(v) if k in ("odometry", "link") else v) for k, v in spebt.items()}
        geometric = {k: o[k] for k in ("beam_schedule", "epoch_ms", "doppler_seed")}
        return _native.process_beam(
            [os.fspath(r) for r in recordings], out, tracker, o["reacquire"], o["force"], o["run_id"], spebt, geometric
        )
    if not isinstance(recording, (str, os.PathLike)):
        raise TypeError(f"process {pipeline}: one recording (a path), not {type(recording).__name__}")
    rec = os.fspath(recording)
    if pipeline == "odometry":
        return _native.process_odometry(
            rec, out, o["preset"], _path(o["config"]), o["sequence"], o["force"], o["run_id"], o["threads"]
        )
    if pipeline == "poses":
        return _native.process_poses(rec, out, o["sequence"], o["force"], o["run_id"])
    if pipeline == "raw":
        return _native.process_raw(rec, out, o["sequence"], o["force"], o["run_id"])
    if pipeline == "mpc":
        return _native.process_mpc(
            rec,
            out,
            _path(o["config"]),
            None if o["pulse"] is None else os.fspath(o["pulse"]),
            o["link"],
            o["gmphd"],
            o["sequence"],
            o["force"],
            o["run_id"],
            o["threads"],
        )
    prior = None if o["prior"] is None else [float(v) for v in o["prior"]]
    return _native.process_slam(
        rec,
        out,
        _path(o["config"]),
        o["particles"],
        o["seed"],
        prior,
        o["strict"],
        o["sequence"],
        o["force"],
        o["run_id"],
        o["threads"],
    )


def effective_config(pipeline: str, *, preset: str = "cfear", config: Optional[PathLike] = None, gmphd: bool = False) -> str:
    """``mmtrack process odometry|mpc --print-config``: the effective configuration as TOML."""
    return _native.effective_config(pipeline, preset, _path(config), gmphd)


def analyze(
    tables: Union[PathLike, Sequence[PathLike]],
    output: PathLike,
    *,
    force: bool = False,
    segment_lengths_m: Optional[Sequence[float]] = None,
    step_frames: Optional[int] = None,
    step_m: Optional[float] = None,
    first_path_range_db: Optional[float] = None,
) -> dict[str, Any]:
    """``mmtrack analyze <tables>... -o <output>``: metrics, result tables, plots and a report.

    Returns the output directory, the number of files, the tables, plots and
    report paths, and the run ids compared (empty for one run). Read the
    result tables with ``mmtrack.tables(result["tables"])``.
    """
    dirs = [tables] if isinstance(tables, (str, os.PathLike)) else list(tables)
    lengths = None if segment_lengths_m is None else [float(v) for v in segment_lengths_m]
    return _native.analyze_tables(
        [os.fspath(d) for d in dirs], os.fspath(output), force, lengths, step_frames, step_m, first_path_range_db
    )


@dataclass(frozen=True)
class Claim:
    """A paper's claim against what the run measured."""

    experiment: str
    claim: str
    unit: str
    #: The paper's number, where the claim has one.
    paper_value: Optional[float]
    #: The paper's side as the report prints it.
    paper: str
    #: The measured value in ``unit`` (None for orderings or when nothing was measured).
    measured: Optional[float]
    #: The measurement as the report prints it.
    measured_text: str
    met: bool
    #: Reported beside the paper's claims, not counted (a variant, diagnostic or speed target of ours).
    informational: bool
    #: "met", "missed", or for informational claims whether the relation holds.
    verdict: str


@dataclass(frozen=True)
class Reproduced:
    """What ``reproduce`` measured."""

    experiment: str
    #: Every target claim met (the CLI exits 1 when not).
    targets_met: bool
    claims: list[Claim]
    #: The numbers measured: key, value, unit, paper.
    metrics: list[dict[str, Any]] = field(default_factory=list)
    files: list[str] = field(default_factory=list)
    #: The Markdown report (reproduce.md).
    report: str = ""


def reproduce(
    experiment: str,
    *,
    output: Optional[PathLike] = None,
    force: bool = False,
    quick: bool = False,
    threads: int = 0,
    runs: Optional[int] = None,
    readme: Optional[PathLike] = None,
    experiment_file: Optional[PathLike] = None,
    scenario: Optional[PathLike] = None,
    trajectory: Optional[PathLike] = None,
    trajectory_format: Optional[str] = None,
    max_distance_m: Optional[float] = None,
    skip_odometry: bool = False,
    particles: Optional[int] = None,
    pulse: Optional[str] = None,
    keep_taps_below_threshold: bool = False,
) -> Reproduced:
    """``mmtrack reproduce <experiment>``: a paper's experiment against its published numbers.

    ``experiment``: odometry, mpc-artificial, mpc-convoy, shaham, spebt, zoechmann, kim,
    or ``all`` (``reproduce --all``; ``quick`` is ``--smoke``). ``quick`` is
    the CI version; ``experiment_file`` is ``--experiment``. Returns the
    claims with the paper's value, the measured value and the verdict. A
    missed target is a result, not an error (the CLI exits 1 on it; here
    ``targets_met`` is False).
    """
    if experiment == "all":
        given = {
            "threads": threads != 0,
            "runs": runs is not None,
            "force": force,
            "experiment_file": experiment_file is not None,
            "scenario": scenario is not None,
            "trajectory": trajectory is not None,
            "trajectory_format": trajectory_format is not None,
            "max_distance_m": max_distance_m is not None,
            "skip_odometry": skip_odometry,
            "particles": particles is not None,
            "pulse": pulse is not None,
            "keep_taps_below_threshold": keep_taps_below_threshold,
        }
        extra = [k for k, v in given.items() if v]
        if extra:
            raise _native.MmtrackError(f"reproduce all: takes output, quick and readme only, not {extra}")
        out = os.fspath(output) if output is not None else "out/reproduce/all"
        done = _native.reproduce_all(out, quick, _path(readme))
        claims = [Claim(**c) for c in done["claims"]]
        return Reproduced(
            experiment="all",
            targets_met=all(c.met or c.informational for c in claims) and done["misses"] == 0,
            claims=claims,
            report=done["summary"],
        )
    request = {
        "output": _path(output),
        "force": force,
        "quick": quick,
        "runs": runs,
        "readme": _path(readme),
        "experiment_file": _path(experiment_file),
        "scenario": _path(scenario),
        "trajectory": _path(trajectory),
        "trajectory_format": trajectory_format,
        "max_distance_m": max_distance_m,
        "skip_odometry": skip_odometry,
        "particles": particles,
        "pulse": pulse,
        "keep_taps_below_threshold": keep_taps_below_threshold,
    }
    done = _native.reproduce_experiment(experiment, threads, request)
    return Reproduced(
        experiment=done["experiment"],
        targets_met=done["targets_met"],
        claims=[Claim(**c) for c in done["claims"]],
        metrics=done["metrics"],
        files=done["files"],
        report=done["report"],
    )
