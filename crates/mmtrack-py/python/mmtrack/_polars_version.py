"""The oldest polars that reads mmtrack's Parquet files, checked at import.

The tables (and every array call's result) are written by parquet-rs 60,
whose footer carries a column-order field that polars before 1.43.2 rejects
("parquet: File out of specification: Invalid thrift: bad data", or in
1.42 and 1.43.0 "ColumnOrder union has no variant set"): nothing could be
read. Measured on a table file: 1.42.0 and 1.43.0 fail, 1.43.2, 1.44.2,
2.0.0 and 2.1.0 read it (1.43.1 is not on PyPI). ``pyproject.toml``
requires the same version.
"""

from __future__ import annotations

import re

import polars as pl

#: The oldest polars that reads the files (docs/campaigns.md, "Polars versions").
MIN_POLARS = (1, 43, 2)


def polars_version_problem(version: str) -> "str | None":
    """Why polars `version` cannot read mmtrack's files, or None when it can
    (also for a version string this does not understand)."""
    found = re.match(r"(\d+)\.(\d+)(?:\.(\d+))?", version)
    if found is None:
        return None
    if tuple(int(part or 0) for part in found.groups()) >= MIN_POLARS:
        return None
    wanted = ".".join(map(str, MIN_POLARS))
    return (
        f"mmtrack needs polars >= {wanted} to read its Parquet files; polars {version} is installed "
        f"(older polars rejects the files' footer). "
        f"Upgrade it: pip install 'polars>={wanted}'"
    )


def check_polars_version() -> None:
    """Raises ImportError naming the polars version needed when an older one is installed."""
    problem = polars_version_problem(pl.__version__)
    if problem is not None:
        raise ImportError(problem)
