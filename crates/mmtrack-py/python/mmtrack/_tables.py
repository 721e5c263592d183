"""Tables as polars LazyFrames, with their declared units, time base and frame.

A table directory (what ``process`` and ``analyze`` write) holds
``<root>/<table>/sequence=<id>/part-0.parquet``, or one such tree per run
under ``<root>/run=<ID>/``. :func:`read_table` scans every partition of one
table lazily, with the Hive columns ``sequence`` (and ``run``) as strings.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional, Union

import polars as pl

from . import _native

PathLike = Union[str, "os.PathLike[str]"]


@dataclass(frozen=True)
class Column:
    """One declared column of a table."""

    name: str
    #: Arrow type as the schema documents name it (int64, float64, list<float64>, ...).
    type: str
    nullable: bool
    #: Unit as the files state it ("1" for a dimensionless number, "none" for a string, flag or bytes).
    unit: str
    meaning: str


@dataclass(frozen=True)
class TableSpec:
    """A table as mmtrack-io declares it (the source of ``schemas/tables/<name>.md``)."""

    name: str
    description: str
    #: The frame of its positions and angles as declared (``not_applicable``, fixed, or the run's).
    frame: str
    columns: list[Column]

    @property
    def units(self) -> dict[str, str]:
        """Column name -> unit ("1" for dimensionless, "none" for strings and flags)."""
        return {c.name: c.unit for c in self.columns}


@dataclass(frozen=True)
class TableInfo:
    """What a table directory says about one table."""

    spec: Optional[TableSpec]
    #: Column -> unit, from the files' ``units`` metadata.
    units: dict[str, str]
    #: Column -> description, from the files' Arrow field metadata.
    descriptions: dict[str, str]
    #: The run configuration (``mmtrack.run_config``) of the first file.
    run_config: dict[str, Any]
    #: The coordinate frame of the positions and angles (key ``frame``, e.g.
    #: ``ground_truth``; ``not_applicable`` for a table without any).
    frame: Optional[str]
    #: What the frame is (``frame.meaning``).
    frame_meaning: Optional[str]
    #: The frame's origin where the recording names one (``frame.origin``), e.g.
    #: a GNSS origin's ``latitude_deg``, ``longitude_deg``, ``altitude_m``.
    frame_origin: Optional[dict[str, str]]
    #: The time base of ``t_ns`` (key ``time_base``: ``unix_epoch``,
    #: ``scenario_start``, ``sim_time``, ``relative``; ``mixed`` when pooled).
    time_base: Optional[str]
    #: What the time base means (``time_base.meaning``).
    time_base_meaning: Optional[str]
    #: The partition files, sorted.
    files: list[str]


_SPECS: Optional[dict[str, TableSpec]] = None


def _specs() -> dict[str, TableSpec]:
    global _SPECS
    if _SPECS is None:
        _SPECS = {
            s["name"]: TableSpec(s["name"], s["description"], s["frame"], [Column(**c) for c in s["columns"]])
            for s in _native.table_specs()
        }
    return _SPECS


def table_names() -> list[str]:
    """Every declared table: those ``process`` writes and the result tables of ``analyze``."""
    return list(_specs())


def table_spec(name: str) -> TableSpec:
    """The declaration of table ``name``: description, columns, types, units, meanings."""
    spec = _specs().get(name)
    if spec is None:
        raise _native.MmtrackError(f"unknown table '{name}': expected one of {', '.join(sorted(_specs()))}")
    return spec


def _files(root: Path, name: str) -> list[Path]:
    direct = sorted(root.glob(f"{name}/sequence=*/*.parquet"))
    runs = sorted(root.glob(f"run=*/{name}/sequence=*/*.parquet"))
    return direct + runs


def read_table(root: PathLike, name: str) -> pl.LazyFrame:
    """Every partition of table ``name`` under ``root`` as one polars LazyFrame.

    The Hive columns ``sequence`` (and ``run`` for ``run=<ID>`` folders) are
    strings. Row order is file order (runs, then sequences, sorted) and row
    order within each file; sort explicitly after joins. ``.collect()`` for a
    DataFrame, ``.collect().to_pandas()`` for pandas.
    """
    base = Path(os.fspath(root))
    direct = sorted(base.glob(f"{name}/sequence=*/*.parquet"))
    runs = sorted(base.glob(f"run=*/{name}/sequence=*/*.parquet"))
    if direct and runs:
        raise _native.MmtrackError(
            f"{base}: table {name} both directly and in run= folders; read {base}/run=<ID> or the table itself"
        )
    if not direct and not runs:
        raise _native.MmtrackError(f"{base}: no table {name} (expected {name}/sequence=<id>/part-0.parquet)")
    hive = {"sequence": pl.String} if direct else {"run": pl.String, "sequence": pl.String}
    pattern = f"{base}/{name}/sequence=*/*.parquet" if direct else f"{base}/run=*/{name}/sequence=*/*.parquet"
    return pl.scan_parquet(pattern, hive_partitioning=True, hive_schema=hive, try_parse_hive_dates=False)


def tables(root: PathLike) -> dict[str, pl.LazyFrame]:
    """Every table under ``root`` (directly or in ``run=<ID>`` folders), by name, as LazyFrames."""
    base = Path(os.fspath(root))
    names = {p.parent.parent.name for p in base.glob("*/sequence=*/*.parquet") if not p.parent.parent.name.startswith("run=")}
    names |= {p.parent.parent.name for p in base.glob("run=*/*/sequence=*/*.parquet")}
    if not names:
        raise _native.MmtrackError(f"{base}: no tables (expected <table>/sequence=<id>/part-0.parquet)")
    return {name: read_table(base, name) for name in sorted(names)}


def table_info(root: PathLike, name: str) -> TableInfo:
    """Units, run configuration, frame and time base of table ``name`` under ``root``."""
    base = Path(os.fspath(root))
    files = _files(base, name)
    if not files:
        raise _native.MmtrackError(f"{base}: no table {name} (expected {name}/sequence=<id>/part-0.parquet)")
    meta = _native.table_file_metadata(str(files[0]))
    units = json.loads(meta.get("units", "{}"))
    descriptions = {name: m.get("description", "") for name, m in _native.table_field_metadata(str(files[0]))}
    run_config = json.loads(meta.get("mmtrack.run_config", "{}") or "{}")
    time_base = meta.get("time_base")
    meaning = meta.get("time_base.meaning")
    recording = run_config.get("recording") if isinstance(run_config, dict) else None
    if time_base is None and isinstance(recording, str) and Path(recording).is_file():
        # Tables written before the key existed: the recording's word.
        rec = _native.recording_metadata(recording)
        time_base = rec.get("time_base")
        meaning = rec.get("time_base.meaning")
    origin = meta.get("frame.origin")
    return TableInfo(
        spec=_specs().get(name),
        units=units,
        descriptions=descriptions,
        run_config=run_config if isinstance(run_config, dict) else {},
        frame=meta.get("frame"),
        frame_meaning=meta.get("frame.meaning"),
        frame_origin=json.loads(origin) if origin else None,
        time_base=time_base,
        time_base_meaning=meaning,
        files=[str(f) for f in files],
    )
