"""Reads every table of a `mmtrack demo` output with pyarrow and DuckDB and
checks it against its documented schema in schemas/tables/<table>.md.

Usage: demo_tables.py <demo-out> <schemas/tables>
Prints one line per table; exits non-zero on the first mismatch.
"""

import pathlib
import sys

import duckdb
import pyarrow as pa
import pyarrow.dataset as ds

# Documented type -> pyarrow's name for it.
ARROW_NAMES = {"float64": "double", "string": "string", "bool": "bool", "binary": "binary"}


def documented(schema_file):
    """[(column, type, nullable)] from the Markdown table of a schema document."""
    columns = []
    for line in schema_file.read_text().splitlines():
        if not line.startswith("| `"):
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        name, kind, nullable = cells[0].strip("`"), cells[1], cells[2] == "yes"
        columns.append((name, kind, nullable))
    return columns


def arrow_name(kind):
    if kind.startswith("list<"):
        return "list<item: " + arrow_name(kind[5:-1]) + ">"
    return ARROW_NAMES.get(kind, kind)


def check_table(table_dir, schemas_dir):
    schema_file = schemas_dir / (table_dir.name + ".md")
    if not schema_file.is_file():
        sys.exit(f"{table_dir}: no documented schema {schema_file}")
    expected = documented(schema_file)
    dataset = ds.dataset(table_dir, format="parquet", partitioning="hive")
    table = dataset.to_table()
    if table.num_rows == 0:
        sys.exit(f"{table_dir}: no rows")
    names = [f.name for f in table.schema if f.name != "sequence"]
    if names != [c[0] for c in expected]:
        sys.exit(f"{table_dir}: columns {names}, documented {[c[0] for c in expected]}")
    for name, kind, nullable in expected:
        field = table.schema.field(name)
        if str(field.type) != arrow_name(kind):
            sys.exit(f"{table_dir}: column {name} is {field.type}, documented {kind}")
        if not nullable and table.column(name).null_count:
            sys.exit(f"{table_dir}: column {name} has nulls but is documented non-nullable")
    con = duckdb.connect()
    glob = str(table_dir / "*" / "*.parquet")
    rows = con.execute(f"SELECT count(*) FROM read_parquet('{glob}', hive_partitioning = true)").fetchone()[0]
    duck_columns = [d[0] for d in con.execute(f"SELECT * FROM read_parquet('{glob}', hive_partitioning = true) LIMIT 0").description]
    if rows != table.num_rows:
        sys.exit(f"{table_dir}: DuckDB counts {rows} rows, pyarrow {table.num_rows}")
    if [c for c in duck_columns if c != "sequence"] != names or "sequence" not in duck_columns:
        sys.exit(f"{table_dir}: DuckDB columns {duck_columns}")
    sequences = sorted(table.column("sequence").unique().to_pylist())
    print(f"{table_dir.parent.name}/{table_dir.name}: {table.num_rows} rows, {len(names)} columns, sequences {sequences}")


def main():
    out, schemas_dir = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    checked = 0
    for tables in [out / "tables", out / "analysis" / "tables", out / "compare" / "tables"]:
        for table_dir in sorted(p for p in tables.iterdir() if p.is_dir()):
            check_table(table_dir, schemas_dir)
            checked += 1
    print(f"checked {checked} tables")


main()
