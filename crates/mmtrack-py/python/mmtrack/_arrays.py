"""The algorithms on numpy arrays, without files.

Each call runs the library function the CLI's pipeline runs and returns the
rows of the table the CLI writes for the same input (same columns, types and
units), as a polars DataFrame.
"""

from __future__ import annotations

import io
import math
import os
from dataclasses import dataclass
from typing import Any, Optional, Sequence, Union

import numpy as np
import polars as pl

from . import _native

PathLike = Union[str, "os.PathLike[str]"]


def _frame(data: bytes) -> pl.DataFrame:
    return pl.read_parquet(io.BytesIO(data))


def _le(array: Any, dtype: str) -> bytes:
    return np.ascontiguousarray(np.asarray(array), dtype=np.dtype(dtype).newbyteorder("<")).tobytes()


@dataclass(frozen=True)
class MpcDetections:
    """Detected multipath components, strongest first within each snapshot."""

    #: Row of the input CIR array of each detection.
    snapshot: np.ndarray
    #: Estimated delay, seconds.
    delay_s: np.ndarray
    #: Complex amplitude.
    amplitude: np.ndarray
    #: The ``mpc_detections`` rows (t_ns, set_index, snapshot_index, delay_s,
    #: amplitude_re, amplitude_im, power_db), as ``process mpc`` writes them.
    table: pl.DataFrame


def detect_mpc(
    cir: Any,
    *,
    tap_spacing_s: float,
    t_ns: Optional[Any] = None,
    set_index: Optional[Any] = None,
    snapshot_index: Optional[Any] = None,
    config: Optional[PathLike] = None,
    pulse: Optional[Any] = None,
) -> MpcDetections:
    """CLEAN detection of multipath components (Mahler et al. 2017, Sec. III-A).

    ``cir``: complex taps, shape (taps,) or (snapshots, taps), spaced
    ``tap_spacing_s`` apart. ``config``: the path of an MPC configuration
    TOML file (as ``process mpc --config``; its ``[detection]`` applies). ``pulse``: a
    back-to-back CIR of the sounder (as ``--pulse FILE.npy``), else the band's
    flat spectrum. ``t_ns``, ``set_index``, ``snapshot_index`` label the rows
    (default: 0, 1, ...; set 0; the row).
    """
    taps = np.asarray(cir)
    if taps.ndim == 1:
        taps = taps[np.newaxis, :]
    if taps.ndim != 2:
        raise _native.MmtrackError(f"cir: expected shape (taps,) or (snapshots, taps), got {taps.shape}")
    n, k = taps.shape
    t = np.arange(n, dtype=np.int64) if t_ns is None else np.asarray(t_ns, dtype=np.int64)
    sets = [0] * n if set_index is None else [int(v) for v in np.asarray(set_index).ravel()]
    rows = list(range(n)) if snapshot_index is None else [int(v) for v in np.asarray(snapshot_index).ravel()]
    data = _native.detect_mpc(
        _le(taps.astype(np.complex128), "c16"),
        k,
        _le(t, "i8"),
        sets,
        rows,
        float(tap_spacing_s),
        None if config is None else os.fspath(config),
        None if pulse is None else _le(np.asarray(pulse).astype(np.complex128).ravel(), "c16"),
    )
    table = _frame(data)
    # Rows of the input array: t_ns is unique per snapshot only when given so;
    # detections come snapshot by snapshot, so count them in order.
    keys = list(zip(t.tolist(), sets, rows))
    index = {key: i for i, key in enumerate(keys)}
    snapshot = np.array(
        [
            index[(a, b, c)]
            for a, b, c in zip(table["t_ns"].to_list(), table["set_index"].to_list(), table["snapshot_index"].to_list())
        ],
        dtype=np.int64,
    )
    amplitude = table["amplitude_re"].to_numpy() + 1j * table["amplitude_im"].to_numpy()
    return MpcDetections(snapshot=snapshot, delay_s=table["delay_s"].to_numpy(), amplitude=amplitude, table=table)


def track_beams(
    power: Any,
    *,
    tracker: Union[str, Sequence[str]] = ("window", "last-full-sweep"),
    t_ns: Optional[Any] = None,
    sweep_period_s: float = 0.1,
    reacquire: str = "coarse",
    site: str = "array",
    pass_index: Optional[Any] = None,
    car_east_north_m: Optional[Any] = None,
    car_lat_lon_deg: Optional[Any] = None,
    array_lat_lon_deg: Optional[Any] = None,
) -> pl.DataFrame:
    """The beam-sweep trackers on full sweeps: ``power`` of shape (sweeps, beams), linear power per beam.

    ``tracker``: window (constant-velocity Kalman filter on the beam index),
    gnss-window (the car's GNSS bearing through a beam map moves the window),
    last-full-sweep and gnss-map (baselines). Sweep ``i`` is at ``t_ns[i]``
    (default ``i * sweep_period_s``) and belongs to pass ``pass_index[i]``
    (default: one pass; a pass's sweeps are consecutive rows).

    The GNSS policies need the car's position at each sweep, either
    ``car_east_north_m`` (N, 2) metres from the array, or ``car_lat_lon_deg``
    (N, 2) with ``array_lat_lon_deg`` ((2,) or (N, 2)), and at least two
    passes: the beam map is fitted leave-one-pass-out over the passes given,
    as ``process("beam", ...)`` fits it over the recordings of a site.

    Returns the ``beam_sweeps_tracked`` rows: per tracker and sweep the chosen
    and best beam, beams measured, re-initialisation and received-power loss
    (dB); with ``pass_index``, a first column ``pass`` names each row's pass.
    """
    p = np.asarray(power, dtype=np.float64)
    if p.ndim != 2:
        raise _native.MmtrackError(f"power: expected shape (sweeps, beams), got {p.shape}")
    n, beams = p.shape
    if t_ns is None:
        period = float(sweep_period_s)
        # As ingest beams --sweep-period-s (NaN became a time of -2^63 ns before).
        if not (math.isfinite(period) and 0.0 < period < 3600.0):
            raise _native.MmtrackError(f"sweep_period_s {period}: expected a positive number of seconds below 3600")
        t = np.round(np.arange(n) * period * 1e9).astype(np.int64)
    else:
        t = np.asarray(t_ns, dtype=np.int64)
        if t.shape != (n,):
            raise _native.MmtrackError(f"t_ns: one time per sweep of power ({n}), got shape {t.shape}")
    names = [tracker] if isinstance(tracker, str) else list(tracker)
    passes = None if pass_index is None else _le(np.asarray(pass_index).ravel(), "i8")
    if car_east_north_m is not None and car_lat_lon_deg is not None:
        raise _native.MmtrackError("give car_east_north_m or car_lat_lon_deg, not both")
    if car_lat_lon_deg is not None:
        car, frame = _le(np.asarray(car_lat_lon_deg, dtype=np.float64), "f8"), "lat_lon_deg"
    elif car_east_north_m is not None:
        car, frame = _le(np.asarray(car_east_north_m, dtype=np.float64), "f8"), "east_north_m"
    else:
        car, frame = None, "east_north_m"
    array = None if array_lat_lon_deg is None else _le(np.asarray(array_lat_lon_deg, dtype=np.float64), "f8")
    tables = _native.track_beams(_le(p, "f8"), beams, _le(t, "i8"), names, reacquire, site, passes, car, frame, array)
    frames = [_frame(data) for _, data in tables]
    if pass_index is None:
        return frames[0]
    return pl.concat(
        [f.select(pl.lit(index, dtype=pl.Int64).alias("pass"), pl.all()) for (index, _), f in zip(tables, frames)]
    )


@dataclass(frozen=True)
class TrajectoryMetrics:
    """Trajectory metrics of an estimate against ground truth, as ``analyze`` computes them."""

    #: The ``trajectory_metrics`` row as a dict (KITTI drift, ATE, RPE, RMSEs).
    metrics: dict[str, Any]
    #: The same row as a one-row DataFrame.
    table: pl.DataFrame
    #: KITTI drift per segment length (``drift_per_length``).
    drift_per_length: pl.DataFrame
    #: Frame-to-frame relative pose errors (``relative_pose_errors``).
    relative_pose_errors: pl.DataFrame


def _poses(which: str, poses: Any) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(poses, pl.LazyFrame):
        poses = poses.collect()
    if isinstance(poses, tuple) and len(poses) == 2:
        t, xyyaw = poses
        return np.asarray(t, dtype=np.int64), np.asarray(xyyaw, dtype=np.float64)
    if hasattr(poses, "__getitem__") and not isinstance(poses, np.ndarray):
        try:
            t = np.asarray(poses["t_ns"], dtype=np.int64)
            xyyaw = np.column_stack([np.asarray(poses[c], dtype=np.float64) for c in ("x_m", "y_m", "yaw_rad")])
            return t, xyyaw
        except (KeyError, pl.exceptions.ColumnNotFoundError):
            pass
    raise _native.MmtrackError(
        f"{which}: expected a table with columns t_ns, x_m, y_m, yaw_rad (polars, pandas, dict) "
        "or a tuple (t_ns int64 array, (N, 3) array of x_m, y_m, yaw_rad)"
    )


def trajectory_metrics(
    estimate: Any,
    ground_truth: Any,
    *,
    segment_lengths_m: Optional[Sequence[float]] = None,
    step_frames: Optional[int] = None,
    step_m: Optional[float] = None,
    sequence: str = "array",
) -> TrajectoryMetrics:
    """KITTI drift, relative pose error and absolute trajectory error of ``estimate`` against ``ground_truth``.

    Each trajectory: a table with columns t_ns, x_m, y_m, yaw_rad (the
    ``odometry`` and ``ground_truth`` tables, polars or pandas), or a tuple
    (t_ns int64 array, (N, 3) array of x_m, y_m, yaw_rad). The estimate is
    associated with ground truth by time (interpolated), as ``analyze`` does;
    ``segment_lengths_m`` (default 100..800 m), ``step_frames`` (default 10)
    or ``step_m`` as its flags.
    """
    et, ep = _poses("estimate", estimate)
    gt, gp = _poses("ground truth", ground_truth)
    lengths = None if segment_lengths_m is None else [float(v) for v in segment_lengths_m]
    m, d, r = _native.trajectory_metrics(
        sequence, _le(et, "i8"), _le(ep, "f8"), _le(gt, "i8"), _le(gp, "f8"), lengths, step_frames, step_m
    )
    table = _frame(m)
    return TrajectoryMetrics(
        metrics=table.row(0, named=True),
        table=table,
        drift_per_length=_frame(d),
        relative_pose_errors=_frame(r),
    )
