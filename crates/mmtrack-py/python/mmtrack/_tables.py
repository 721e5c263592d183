"""Tables as polars LazyFrames, with their declared units, time base and frame.

A table directory (what ``process`` and ``analyze`` write) holds
``<root>/<table>/sequence=<id>/part-0.parquet``, or one such tree per run
under ``<root>/run=<ID>/`` (``process --run-id``) or ``<root>/run=<ID>/tables/``
(a multi-run ``analyze``'s per-run results). :func:`read_table` scans every partition of one
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


#: Where a table's partitions sit under a root, with the Hive columns of each
#: layout: a table directory; ``process --run-id``'s ``run=<ID>/`` folders;
#: a multi-run ``analyze``'s per-run results, ``run=<ID>/tables/``.
_LAYOUTS = (
    ("{name}/sequence=*/*.parquet", {"sequence": pl.String}),
    ("run=*/{name}/sequence=*/*.parquet", {"run": pl.String, "sequence": pl.String}),
    ("run=*/tables/{name}/sequence=*/*.parquet", {"run": pl.String, "sequence": pl.String}),
)


def _layouts(root: Path, name: str) -> list[tuple[str, dict[str, Any], list[Path]]]:
    """The layouts table `name` has under `root`: glob pattern, Hive schema, files."""
    found = [(pattern, hive, sorted(root.glob(pattern.format(name=name)))) for pattern, hive in _LAYOUTS]
    found = [f for f in found if f[2]]
    if not found:
        raise _native.MmtrackError(
            f"{root}: no table {name} (expected {name}/sequence=<id>/part-0.parquet, or that under run=<ID>/ "
            f"or run=<ID>/tables/)"
        )
    return found


def _check_parquet_footer(file: Path) -> None:
    """Refuses a file that cannot be Parquet (shorter than a footer, or not
    ending in ``PAR1``), naming it: polars' own error at ``collect()`` names
    no file."""
    try:
        with open(file, "rb") as f:
            size = f.seek(0, os.SEEK_END)
            if size >= 12:
                f.seek(-4, os.SEEK_END)
                if f.read(4) == b"PAR1":
                    return
    except OSError as error:
        raise _native.MmtrackError(f"{file}: cannot be read: {error.strerror}") from error
    raise _native.MmtrackError(f"{file}: not a readable Parquet table (no Parquet footer: cut off or not Parquet)")


def _files(root: Path, name: str) -> list[Path]:
    return [file for _, _, files in _layouts(root, name) for file in files]


def read_table(root: PathLike, name: str) -> pl.LazyFrame:
    """Every partition of table ``name`` under ``root`` as one polars LazyFrame.

    ``root`` is a table directory (``<root>/<name>/sequence=<id>/``), a
    directory of runs (``<root>/run=<ID>/<name>/...``, what ``process
    --run-id`` writes), or the output of a multi-run ``analyze``, whose
    per-run result tables are under ``<root>/run=<ID>/tables/<name>/...``
    (its comparison tables: ``read_table(<root>/tables, "run_comparison")``).
    The Hive columns ``sequence`` (and ``run`` for ``run=<ID>`` folders) are
    strings; tables directly under ``root`` beside ``run=<ID>`` folders are a
    run named after ``root`` (as ``mmtrack analyze`` takes them). Row order is file order (runs, then sequences, sorted) and row
    order within each file; sort explicitly after joins. ``.collect()`` for a
    DataFrame, ``.collect().to_pandas()`` for pandas.
    """
    base = Path(os.fspath(root))
    layouts = _layouts(base, name)
    # polars takes every `key=value` folder of the path as a Hive column, also
    # those of `root` itself (e.g. `<analysis>/run=a/tables`): strings too.
    own = {part.split("=", 1)[0]: pl.String for part in base.parts if "=" in part}
    frames = []
    for pattern, hive, files in layouts:
        for file in files:
            _check_parquet_footer(file)
        frame = pl.scan_parquet(
            f"{base}/{pattern.format(name=name)}",
            hive_partitioning=True,
            hive_schema={**own, **hive},
            try_parse_hive_dates=False,
        )
        if len(layouts) > 1 and "run" not in hive and "run" not in own:
            # Tables directly under `root` beside run=<ID> folders: a run named
            # after the directory, as `mmtrack analyze` takes them.
            frame = frame.with_columns(pl.lit(base.name, dtype=pl.String).alias("run"))
        frames.append(frame)
    return frames[0] if len(frames) == 1 else pl.concat(frames, how="diagonal_relaxed")


def tables(root: PathLike) -> dict[str, pl.LazyFrame]:
    """Every table under ``root`` (directly, in ``run=<ID>`` folders, or in a
    multi-run ``analyze``'s ``run=<ID>/tables`` folders), by name, as LazyFrames."""
    base = Path(os.fspath(root))
    names = {p.parent.parent.name for p in base.glob("*/sequence=*/*.parquet") if not p.parent.parent.name.startswith("run=")}
    names |= {p.parent.parent.name for p in base.glob("run=*/*/sequence=*/*.parquet")}
    names |= {p.parent.parent.name for p in base.glob("run=*/tables/*/sequence=*/*.parquet")}
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
