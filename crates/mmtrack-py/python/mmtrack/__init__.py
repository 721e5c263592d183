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
``error:``; an argument that cannot be converted (a string array where
numbers are expected, a negative count, an unknown keyword) raises its
subclass :class:`MmtrackTypeError` or :class:`MmtrackValueError`, which are
also ``TypeError`` / ``ValueError``.
"""

from __future__ import annotations

from ._polars_version import check_polars_version as _check_polars_version

_check_polars_version()

from . import _api, _arrays, _tables
from ._api import INGEST_OPTIONS, PROCESS_OPTIONS, Claim, Reproduced
from ._arrays import MpcDetections, TrajectoryMetrics
from ._errors import MmtrackTypeError, MmtrackValueError, raises_mmtrack_errors
from ._native import MmtrackError, __version__
from ._tables import Column, TableInfo, TableSpec

analyze = raises_mmtrack_errors(_api.analyze)
effective_config = raises_mmtrack_errors(_api.effective_config)
ingest = raises_mmtrack_errors(_api.ingest)
process = raises_mmtrack_errors(_api.process)
reproduce = raises_mmtrack_errors(_api.reproduce)
detect_mpc = raises_mmtrack_errors(_arrays.detect_mpc)
track_beams = raises_mmtrack_errors(_arrays.track_beams)
trajectory_metrics = raises_mmtrack_errors(_arrays.trajectory_metrics)
read_table = raises_mmtrack_errors(_tables.read_table)
table_info = raises_mmtrack_errors(_tables.table_info)
table_names = _tables.table_names
table_spec = raises_mmtrack_errors(_tables.table_spec)
tables = raises_mmtrack_errors(_tables.tables)

__all__ = [
    "INGEST_OPTIONS",
    "Claim",
    "Column",
    "MmtrackError",
    "MmtrackTypeError",
    "MmtrackValueError",
    "PROCESS_OPTIONS",
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
