"""Independent readers of mmtrack's outputs.

Reads the files written by `crates/mmtrack-cli/tests/it/independent_readers.rs`
(given as argv[1]) with tools that share no code with mmtrack: the Python `mcap`
package (protobuf messages decoded from the descriptors embedded in the file),
pyarrow and duckdb. Exits non-zero with a message on the first mismatch.
"""

import json
import math
import pathlib
import sys
from collections import Counter

import duckdb
import pyarrow.dataset as ds
import pyarrow.parquet as pq
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory


def check(condition, message):
    if not condition:
        print(f"FAILED: {message}")
        sys.exit(1)


def read_mcap(path):
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        messages = [(c.topic, s.name, m, d) for s, c, m, d in reader.iter_decoded_messages()]
    return metadata, messages


def check_all_types(root):
    metadata, messages = read_mcap(root / "all.mcap")
    check(metadata["mmtrack.recording"]["sequence_id"] == "seq-a", f"metadata: {metadata}")
    counts = Counter((topic, schema) for topic, schema, _, _ in messages)
    expected = {
        ("/ground_truth/pose", "mmtrack.Pose2D"): 5,
        ("/viz/ground_truth", "foxglove.PoseInFrame"): 5,
        # world -> base_link per pose; once, the static mount base_link -> gnss.
        ("/tf", "foxglove.FrameTransforms"): 5,
        ("/tf_static", "foxglove.FrameTransforms"): 1,
        # The delay x time view of the one CIR set.
        ("/viz/cir", "foxglove.RawImage"): 1,
        ("/gnss/fix", "mmtrack.GnssFix"): 1,
        ("/viz/gnss", "foxglove.LocationFix"): 1,
        ("/channel/cir", "mmtrack.CirSnapshot"): 1,
        ("/channel/mpc_truth", "mmtrack.MpcTruth"): 1,
    }
    check(dict(counts) == expected, f"channel counts {dict(counts)}")
    poses = [d for t, _, _, d in messages if t == "/ground_truth/pose"]
    check([p.x_m for p in poses] == [0.0, 1.0, 2.0, 3.0, 4.0], "pose x_m")
    check(poses[3].yaw_rad == 0.1 * 3 and poses[0].child_frame == "base_link", "pose yaw/frame")
    viz = [d for t, _, _, d in messages if t == "/viz/ground_truth"]
    yaw = 2 * math.atan2(viz[3].pose.orientation.z, viz[3].pose.orientation.w)
    check(abs(yaw - 0.3) < 1e-12 and viz[3].frame_id == "world", "foxglove pose view")
    fix = next(d for t, _, _, d in messages if t == "/gnss/fix")
    check(fix.latitude_deg == 51.762042 and fix.HasField("horizontal_sigma_m") and not fix.HasField("num_satellites"), "gnss optional fields")
    loc = next(d for t, _, _, d in messages if t == "/viz/gnss")
    check(loc.longitude == -1.262751, "location fix")
    cir = next(d for t, _, _, d in messages if t == "/channel/cir")
    check(list(cir.taps_re) == [float(k) for k in range(16)] and list(cir.taps_im) == [-float(k) for k in range(16)], "cir taps")
    check(cir.set_index == 3 and cir.snapshot_index == 2 and cir.carrier_hz == 5.7e9, "cir indices")
    truth = next(d for t, _, _, d in messages if t == "/channel/mpc_truth")
    check(truth.path_id == 7 and truth.delay_s == 4.25e-9 and truth.doppler_hz == -321.5, "mpc truth fields")
    check(truth.amplitude_re == 1e-5 and truth.amplitude_im == -2e-5 and truth.snapshot_index == 2, "mpc truth amplitude")
    log_times = [m.log_time for t, _, m, _ in messages if t == "/ground_truth/pose"]
    check(log_times == [1_000_000_000 + i * 100_000_000 for i in range(5)], "log time = t_ns")
    print("mcap (all types): ok")


def check_demo_recording(root):
    demo = root / "demo"
    metadata, messages = read_mcap(demo / "recording.mcap")
    check(metadata["mmtrack.recording"]["sequence_id"] == "oxford-demo", "demo sequence id")
    images = [(m, d) for t, s, m, d in messages if t == "/radar/image"]
    metas = {m.sequence: d for t, s, m, d in messages if t == "/radar/scan_meta"}
    check(len(images) == 160 and len(metas) == 160, "160 scans (the demo drive)")
    for m, image in images:
        check(image.format == "png", "png format")
        meta = metas[m.sequence]
        png = demo / "input" / "oxford-demo" / "radar" / f"{meta.t_ns // 1000}.png"
        check(bytes(image.data) == png.read_bytes(), f"PNG bytes carried unchanged: {png.name}")
        check(len(meta.azimuth_t_ns) == 400 and meta.power_column_offset == 11 and meta.bins_per_azimuth == 900, "scan meta")
        check(all(b > a for a, b in zip(meta.azimuth_t_ns, meta.azimuth_t_ns[1:])), "azimuth times increase")
    print("mcap (demo radar recording): ok")


def check_tables(root):
    tables = root / "tables"
    dataset = ds.dataset(tables / "mpc_tracks", format="parquet", partitioning="hive")
    table = dataset.to_table()
    check(table.num_rows == 2, f"mpc_tracks rows {table.num_rows}")
    check(sorted(table.column("sequence").to_pylist()) == ["seq-a", "seq-b"], "hive partitions")
    check(table.column("delay_s").to_pylist() == [2.5e-8, 2.5e-8], "delay_s values")
    file = tables / "mpc_tracks" / "sequence=seq-a" / "part-0.parquet"
    kv = pq.read_metadata(file).metadata
    units = json.loads(kv[b"units"])
    check(units["delay_s"] == "s" and units["doppler_hz"] == "Hz" and units["power_db"] == "dB", f"units {units}")
    check(json.loads(kv[b"mmtrack.run_config"]) == {"who": "independent reader test"}, "run config")
    check(kv[b"mmtrack.table"] == b"mpc_tracks", "table name")
    schema = pq.read_schema(file)
    check(schema.field("delay_s").metadata[b"unit"] == b"s", "field unit metadata")
    # pandas/pyarrow users see the table's metadata on the schema they get.
    meta = pq.read_table(file).schema.metadata or {}
    check(json.loads(meta.get(b"units", b"{}")).get("delay_s") == "s", f"schema metadata units: {meta}")
    check(json.loads(meta.get(b"mmtrack.run_config", b"null")) == {"who": "independent reader test"}, "schema run config")
    check(pq.ParquetFile(file).metadata.row_group(0).column(0).compression == "ZSTD", "zstd")

    con = duckdb.connect()
    rows = con.execute(
        "SELECT sequence, count(*), max(doppler_hz) FROM read_parquet(?, hive_partitioning = true) GROUP BY 1 ORDER BY 1",
        [str(tables / "mpc_tracks" / "*" / "*.parquet")],
    ).fetchall()
    check(rows == [("seq-a", 1, 12.5), ("seq-b", 1, 12.5)], f"duckdb group by {rows}")
    taps = con.execute("SELECT len(taps_re), taps_im[2] FROM read_parquet(?)", [str(tables / "cir_snapshots" / "*" / "*.parquet")]).fetchall()
    check(taps == [(16, -1.0)], f"duckdb list columns {taps}")
    poses = con.execute("SELECT count(*) FROM read_parquet(?)", [str(root / "demo" / "tables" / "ground_truth" / "*" / "*.parquet")]).fetchone()
    check(poses == (160,), f"demo ground truth {poses}")
    print("parquet (pyarrow, duckdb): ok")


def main():
    root = pathlib.Path(sys.argv[1])
    check_all_types(root)
    check_demo_recording(root)
    check_tables(root)
    print("all checks passed")


if __name__ == "__main__":
    main()
