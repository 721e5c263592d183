"""Reads every Parquet table file under a `mmtrack demo` output with pyarrow
and checks that it explains itself: the key-value metadata holds a non-empty
`time_base`, `time_base.meaning`, `frame` and `frame.meaning` (a `frame.origin`,
where present, is a JSON object), and every field carries a non-empty `unit`
and `description`.

Usage: table_metadata.py <demo-out>
Prints one line per table file; exits non-zero naming the first file, key or
field that lacks them.
"""

import json
import pathlib
import sys

import pyarrow.parquet as pq

TABLE_KEYS = ["time_base", "time_base.meaning", "frame", "frame.meaning"]


def check(path, root):
    name = path.relative_to(root)
    schema = pq.read_schema(path)
    footer = pq.read_metadata(path).metadata or {}
    meta = {k.decode(): v.decode() for k, v in (schema.metadata or {}).items()}
    for key in TABLE_KEYS:
        if not meta.get(key):
            sys.exit(f"{name}: no '{key}' in the table's key-value metadata")
        if footer.get(key.encode(), b"").decode() != meta[key]:
            sys.exit(f"{name}: '{key}' differs between the Arrow schema and the Parquet footer")
    if "frame.origin" in meta and not isinstance(json.loads(meta["frame.origin"]), dict):
        sys.exit(f"{name}: frame.origin is not a JSON object: {meta['frame.origin']}")
    if len(schema) == 0:
        sys.exit(f"{name}: no fields")
    for field in schema:
        field_meta = {k.decode(): v.decode() for k, v in (field.metadata or {}).items()}
        for key in ["unit", "description"]:
            if not field_meta.get(key):
                sys.exit(f"{name}: field '{field.name}' has no '{key}' in its metadata")
    print(f"{name}: time_base={meta['time_base']} frame={meta['frame']} fields={len(schema)}")


def main():
    root = pathlib.Path(sys.argv[1])
    files = sorted(root.rglob("*.parquet"))
    if not files:
        sys.exit(f"{root}: no Parquet files")
    for path in files:
        check(path, root)
    print(f"checked {len(files)} table files")


main()
