"""mmtrack from Python: the library calls behind the ``mmtrack`` command line.

- :func:`ingest`, :func:`process`, :func:`analyze`, :func:`reproduce`: the CLI's
  commands as functions, keyword arguments named as the CLI's flags
  (``--range-resolution-m`` is ``range_resolution_m``), returning what they
  wrote;
- :func:`tables`, :func:`read_table`: result tables as polars LazyFrames
  (``.collect().to_pandas()`` for pandas), :func:`table_spec` and
  :func:`table_info` for each column's unit, the time base and the frame;
- :func:`detect_mpc`, :func:`track_beams`, :func:`trajectory_metrics`: the
  algorithms on numpy arrays, without files; each returns the rows of the
  table the CLI writes for the same input.

Errors raise :class:`MmtrackError` with the one line the CLI prints after
``error:``.
"""

from __future__ import annotations

from ._polars_version import check_polars_version as _check_polars_version

_check_polars_version()

from ._api import Claim, Reproduced, analyze, effective_config, ingest, process, reproduce
from ._arrays import MpcDetections, TrajectoryMetrics, detect_mpc, track_beams, trajectory_metrics
from ._native import MmtrackError, __version__
from ._tables import Column, TableInfo, TableSpec, read_table, table_info, table_names, table_spec, tables

__all__ = [
    "Claim",
    "Column",
    "MmtrackError",
    "MpcDetections",
    "Reproduced",
    "TableInfo",
    "TableSpec",
    "TrajectoryMetrics",
    "__version__",
    "analyze",
    "detect_mpc",
    "effective_config",
    "ingest",
    "process",
    "read_table",
    "reproduce",
    "table_info",
    "table_names",
    "table_spec",
    "tables",
    "track_beams",
    "trajectory_metrics",
]
