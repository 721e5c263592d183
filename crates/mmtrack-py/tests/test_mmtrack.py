"""The Python package against the CLI: the same calls give the same files and
tables, the array calls reproduce the CLI's tables to 1e-12, errors carry the
CLI's one line.

Environment: ``MMTRACK_BIN`` is the ``mmtrack`` binary to compare with (the
Rust test that runs this suite sets it); ``MMTRACK_REALDATA`` the real-data
samples (default ``../shared/realdata`` beside the workspace).
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import polars as pl
import pytest

import mmtrack

ROOT = Path(__file__).resolve().parents[3]
DEMO_FOLDER = ROOT / "data/demo/oxford-demo"
TOL = 1e-12


def cli(*args: object, cwd: Path | None = None, ok: bool = True) -> subprocess.CompletedProcess[str]:
    binary = os.environ.get("MMTRACK_BIN")
    if not binary:
        pytest.fail("MMTRACK_BIN is not set: the path of the mmtrack binary to compare with")
    done = subprocess.run([binary, *map(str, args)], capture_output=True, text=True, cwd=cwd)
    if ok:
        assert done.returncode == 0, done.stderr
    return done


def cli_error(*args: object) -> str:
    """The CLI's error line without `error: `."""
    done = cli(*args, ok=False)
    # 1: a failure on data; 2: a flag value refused after parsing (a usage error).
    assert done.returncode in (1, 2), (done.returncode, done.stderr)
    lines = [line for line in done.stderr.splitlines() if line.startswith("error: ")]
    assert len(lines) == 1, done.stderr
    return lines[0][len("error: ") :]


def realdata(name: str) -> Path:
    base = Path(os.environ.get("MMTRACK_REALDATA", ROOT.parent / "shared/realdata"))
    path = base / name
    if not path.is_dir():
        pytest.skip(f"real data {path} not found (set MMTRACK_REALDATA)")
    return path


def assert_frames_close(a: pl.DataFrame, b: pl.DataFrame, tol: float = TOL) -> None:
    """Same columns, dtypes and rows; floats within `tol` (absolute and relative)."""
    assert a.columns == b.columns
    assert a.dtypes == b.dtypes
    assert a.height == b.height
    assert a.height > 0
    for name in a.columns:
        x, y = a[name], b[name]
        if x.dtype.is_float():
            xa, ya = x.to_numpy(), y.to_numpy()
            assert np.array_equal(np.isnan(xa), np.isnan(ya)), name
            keep = ~np.isnan(xa)
            np.testing.assert_allclose(xa[keep], ya[keep], rtol=tol, atol=tol, err_msg=name)
        else:
            assert x.to_list() == y.to_list(), name


@pytest.fixture(scope="session")
def demo(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The demo drive ingested and processed by the CLI, analyzed by the CLI."""
    d = tmp_path_factory.mktemp("demo")
    cli("ingest", "oxford", DEMO_FOLDER, "-o", d / "cli.mcap", "--bins", "auto")
    cli("process", "odometry", d / "cli.mcap", "-o", d / "cli-tables")
    cli("analyze", d / "cli-tables", "-o", d / "cli-analysis", "--segment-lengths-m", "2,4,6,8")
    return {"dir": d, "recording": d / "cli.mcap", "tables": d / "cli-tables", "analysis": d / "cli-analysis"}


def test_version_is_the_crates() -> None:
    version = cli("--version").stdout.split()[-1]
    assert mmtrack.__version__ == version


def test_ingest_and_process_write_what_the_cli_writes(demo: dict[str, Path]) -> None:
    d = demo["dir"]
    done = mmtrack.ingest("oxford", DEMO_FOLDER, d / "py.mcap", bins="auto")
    assert done["scans"] == 8 and done["path"] == str(d / "py.mcap")
    assert (d / "py.mcap").read_bytes() == demo["recording"].read_bytes()

    written = mmtrack.process("odometry", demo["recording"], d / "py-tables")
    assert written["scans"] == 8 and written["sequence"] == "oxford-demo"
    names = sorted(Path(t["path"]).parts[-3] for t in written["tables"])
    assert names == ["ground_truth", "odometry", "odometry_timing"]
    for table in ("odometry", "ground_truth"):
        # The run configuration names the recording path as given; the rows are the CLI's.
        ours = mmtrack.read_table(d / "py-tables", table).collect()
        theirs = mmtrack.read_table(demo["tables"], table).collect()
        assert ours.equals(theirs), table


def test_ingest_ros2_writes_what_the_cli_writes(tmp_path: Path) -> None:
    bag = realdata("ros2-mcap") / "nav2_turtlebot.mcap"
    cli("ingest", "ros2", bag, "-o", tmp_path / "cli.mcap", "--pose-topic", "/amcl_pose", "-q")
    done = mmtrack.ingest("ros2", bag, tmp_path / "py.mcap", pose_topic="/amcl_pose")
    assert done["poses"] > 0 and done["radar_scans"] == 0
    assert (tmp_path / "py.mcap").read_bytes() == (tmp_path / "cli.mcap").read_bytes()
    # The bag's poses as a table (`process poses`), the CLI's rows.
    cli("process", "poses", tmp_path / "cli.mcap", "-o", tmp_path / "cli-tables", "-q")
    written = mmtrack.process("poses", tmp_path / "py.mcap", tmp_path / "py-tables")
    assert written["estimate_poses"] == done["poses"] and written["ground_truth_poses"] == 0
    ours = mmtrack.read_table(tmp_path / "py-tables", "poses").collect()
    assert ours.equals(mmtrack.read_table(tmp_path / "cli-tables", "poses").collect())
    assert ours.height == done["poses"]
    # A radar topic needs its range resolution (the images do not carry it).
    with pytest.raises(mmtrack.MmtrackError, match="give --radar-range-resolution-m"):
        mmtrack.ingest("ros2", bag, tmp_path / "radar.mcap", radar_topic="/radar")


def test_process_raw_gives_the_cli_s_tables_of_the_recording_s_measurements(tmp_path: Path) -> None:
    ingested = mmtrack.ingest("oxford", DEMO_FOLDER, tmp_path / "demo.mcap", bins="auto")
    cli("process", "raw", tmp_path / "demo.mcap", "-o", tmp_path / "cli-raw", "-q")
    done = mmtrack.process("raw", tmp_path / "demo.mcap", tmp_path / "py-raw")
    assert done["radar_scans"] == ingested["scans"] > 0
    assert done["cir_snapshots"] == 0 and done["ground_truth_poses"] > 0
    for table in ("radar_scans", "ground_truth"):
        ours = mmtrack.read_table(tmp_path / "py-raw", table).collect()
        assert ours.equals(mmtrack.read_table(tmp_path / "cli-raw", table).collect()), table
    scans = mmtrack.read_table(tmp_path / "py-raw", "radar_scans").collect()
    assert scans.height == done["radar_scans"]
    first = scans.row(0, named=True)
    assert len(first["power"]) == len(first["azimuth_rad"]) * first["bins_per_azimuth"]
    with pytest.raises(mmtrack.MmtrackError, match="radar_scans/sequence=oxford-demo/part-0.parquet: exists; use --force"):
        mmtrack.process("raw", tmp_path / "demo.mcap", tmp_path / "py-raw")


def test_ingest_poses_writes_what_the_cli_writes(tmp_path: Path) -> None:
    tum = tmp_path / "gt.tum"
    tum.write_text("".join(f"{1.7e9 + 0.25 * k:.2f} {2.0 * k} {0.1 * k} 0 0 0 0 1\n" for k in range(12)))
    # The sequence id is the output's file name: the same name in two folders.
    (tmp_path / "cli").mkdir()
    (tmp_path / "py").mkdir()
    cli("ingest", "poses", tum, "--format", "tum", "-o", tmp_path / "cli/gt.mcap", "-q")
    done = mmtrack.ingest("poses", tum, tmp_path / "py/gt.mcap", format="tum")
    assert done["poses"] == 12
    assert (tmp_path / "py/gt.mcap").read_bytes() == (tmp_path / "cli/gt.mcap").read_bytes()
    # Added to a copy of a recording as an estimate, as the CLI does.
    cli("ingest", "poses", tum, "--format", "tum", "--estimate", "--add-to", tmp_path / "cli/gt.mcap",
        "-o", tmp_path / "cli/est.mcap", "-q")
    mmtrack.ingest("poses", tum, tmp_path / "py/est.mcap", format="tum", estimate=True, add_to=tmp_path / "py/gt.mcap")
    assert (tmp_path / "py/est.mcap").read_bytes() == (tmp_path / "cli/est.mcap").read_bytes()
    with pytest.raises(mmtrack.MmtrackError, match="expected oxford, tum or kitti"):
        mmtrack.ingest("poses", tum, tmp_path / "x.mcap", format="evo")
    with pytest.raises(mmtrack.MmtrackError, match="give --times"):
        mmtrack.ingest("poses", tum, tmp_path / "x.mcap", format="kitti")


def test_tables_are_lazy_frames_with_units_time_base_and_frame(demo: dict[str, Path]) -> None:
    all_tables = mmtrack.tables(demo["tables"])
    assert sorted(all_tables) == ["ground_truth", "odometry", "odometry_timing"]
    odometry = all_tables["odometry"]
    assert isinstance(odometry, pl.LazyFrame)
    frame = odometry.collect()
    spec = mmtrack.table_spec("odometry")
    assert frame.columns == [c.name for c in spec.columns] + ["sequence"]
    assert frame["sequence"].unique().to_list() == ["oxford-demo"]
    assert frame.height == 8
    assert spec.units["x_m"] == "m" and spec.units["yaw_rad"] == "rad" and spec.units["t_ns"] == "ns"
    info = mmtrack.table_info(demo["tables"], "odometry")
    assert info.units == {c.name: c.unit for c in spec.columns}
    assert info.descriptions == {c.name: c.meaning for c in spec.columns}
    assert all(info.units.values()) and all(info.descriptions.values())
    # The demo recording has ground truth, so the odometry is in its frame.
    assert info.frame == "ground_truth" and info.frame_meaning
    assert mmtrack.table_info(demo["tables"], "odometry_timing").frame == "not_applicable"
    assert info.run_config["command"] == "process odometry"
    # The recording's time base: the demo's drive is simulated (the simulator's clock, not UNIX dates).
    assert info.time_base == "scenario_start"
    pandas = pytest.importorskip("pandas")
    assert isinstance(frame.to_pandas(), pandas.DataFrame)
    assert "trajectory_metrics" in mmtrack.table_names()


def test_analyze_writes_the_cli_results(demo: dict[str, Path]) -> None:
    out = demo["dir"] / "py-analysis"
    done = mmtrack.analyze(demo["tables"], out, segment_lengths_m=[2, 4, 6, 8])
    assert done["runs"] == [] and Path(done["report"]).is_file()
    for name in ("trajectory_metrics", "drift_per_length", "relative_pose_errors"):
        ours = mmtrack.read_table(out / "tables", name).collect()
        theirs = mmtrack.read_table(demo["analysis"] / "tables", name).collect()
        assert ours.equals(theirs), name


def test_trajectory_metrics_on_arrays_match_analyze(demo: dict[str, Path]) -> None:
    estimate = mmtrack.read_table(demo["tables"], "odometry").collect()
    truth = mmtrack.read_table(demo["tables"], "ground_truth").collect()
    got = mmtrack.trajectory_metrics(estimate, truth, segment_lengths_m=[2, 4, 6, 8], sequence="oxford-demo")
    cli_tables = demo["analysis"] / "tables"
    expected = mmtrack.read_table(cli_tables, "trajectory_metrics").collect().drop("sequence")
    assert_frames_close(got.table, expected)
    assert got.metrics["kitti_segments"] > 0
    assert_frames_close(
        got.drift_per_length, mmtrack.read_table(cli_tables, "drift_per_length").collect().drop("sequence")
    )
    assert_frames_close(
        got.relative_pose_errors, mmtrack.read_table(cli_tables, "relative_pose_errors").collect().drop("sequence")
    )
    # The same from plain arrays: (t_ns, [x_m, y_m, yaw_rad]).
    as_arrays = mmtrack.trajectory_metrics(
        (estimate["t_ns"].to_numpy(), estimate.select("x_m", "y_m", "yaw_rad").to_numpy()),
        (truth["t_ns"].to_numpy(), truth.select("x_m", "y_m", "yaw_rad").to_numpy()),
        segment_lengths_m=[2, 4, 6, 8],
        sequence="oxford-demo",
    )
    assert as_arrays.table.equals(got.table)


def test_detect_mpc_on_a_cir_array_matches_process_mpc(tmp_path: Path) -> None:
    rng = np.random.default_rng(27)
    snapshots, taps, spacing = 12, 128, 1e-9
    k = np.arange(taps)
    cir = np.zeros((snapshots, taps), dtype=np.complex128)
    for s in range(snapshots):
        for delay_taps, gain in ((20.3 + 0.05 * s, 1.0), (41.7 - 0.03 * s, 0.4j), (77.2, 0.1)):
            cir[s] += gain * np.sinc(k - delay_taps)
    cir += (rng.normal(size=cir.shape) + 1j * rng.normal(size=cir.shape)) * 1e-4
    np.save(tmp_path / "cir.npy", cir)
    (tmp_path / "cir.toml").write_text(
        f'carrier_hz = 5.9e9\ntap_spacing_s = {spacing}\nsnapshot_period_s = 1e-3\nsnapshots_per_set = 4\n'
        't0_ns = 1700000000000000000\naxes = ["snapshot", "tap"]\n'
    )
    cli("ingest", "cir", tmp_path / "cir.npy", "--format", "npy", "--sidecar", tmp_path / "cir.toml", "-o", tmp_path / "cir.mcap")
    cli("process", "mpc", tmp_path / "cir.mcap", "-o", tmp_path / "tables")
    expected = mmtrack.read_table(tmp_path / "tables", "mpc_detections").collect().drop("sequence")
    labels = mmtrack.read_table(tmp_path / "tables", "mpc_snapshots").collect().sort("t_ns")
    assert labels.height == snapshots
    got = mmtrack.detect_mpc(
        cir,
        tap_spacing_s=spacing,
        t_ns=labels["t_ns"].to_numpy(),
        set_index=labels["set_index"].to_numpy(),
        snapshot_index=labels["snapshot_index"].to_numpy(),
    )
    assert_frames_close(got.table, expected)
    assert got.delay_s.shape == got.amplitude.shape == got.snapshot.shape
    first = got.snapshot == 0
    strongest = int(np.argmax(np.abs(got.amplitude[first])))
    assert abs(got.delay_s[first][strongest] - 20.3e-9) < 0.1e-9


def test_track_beams_on_a_power_array_matches_process_beam(tmp_path: Path) -> None:
    folder = realdata("deepsense-60ghz-beams")
    passes = mmtrack.ingest("beams", folder, tmp_path / "rec", scenario=3)
    assert len(passes) >= 2
    cli("process", "beam", tmp_path / "rec", "-o", tmp_path / "tables", "--tracker", "window,last-full-sweep")
    tracked = mmtrack.read_table(tmp_path / "tables", "beam_sweeps_tracked").collect()
    seq_index = np.load(folder / "scenario3_seq_index_1-1487.npy").ravel()
    power = np.load(folder / "scenario3_unit1_pwr_60ghz_1-1487.npy")
    for p in passes[:2]:
        expected = tracked.filter(pl.col("sequence") == p["sequence_id"]).drop("sequence")
        rows = power[seq_index == p["pass"]]
        window = expected.filter(pl.col("tracker") == "window")
        got = mmtrack.track_beams(
            rows,
            tracker=["window", "last-full-sweep"],
            t_ns=window["t_ns"].to_numpy(),
            site=window["site"][0],
        )
        assert_frames_close(got.sort("tracker", maintain_order=True), expected.sort("tracker", maintain_order=True))


def test_track_beams_with_the_gnss_policies_matches_process_beam(tmp_path: Path) -> None:
    # Every policy, GNSS ones included, on all 52 passes of scenario 3: the
    # beam maps are fitted leave-one-pass-out over the passes given, as
    # `process beam` fits them over the recordings of the site.
    folder = realdata("deepsense-60ghz-beams")
    passes = mmtrack.ingest("beams", folder, tmp_path / "rec", scenario=3)
    trackers = ["window", "gnss-window", "last-full-sweep", "gnss-map"]
    cli("process", "beam", tmp_path / "rec", "-o", tmp_path / "tables", "--tracker", ",".join(trackers))
    tracked = mmtrack.read_table(tmp_path / "tables", "beam_sweeps_tracked").collect()
    seq_index = np.load(folder / "scenario3_seq_index_1-1487.npy").ravel()
    power = np.load(folder / "scenario3_unit1_pwr_60ghz_1-1487.npy")
    car = np.load(folder / "scenario3_unit2_loc_cal_1-1487.npy")
    array = np.load(folder / "scenario3_unit1_loc_1-1487.npy")
    times = tracked.filter(pl.col("tracker") == "window").sort("t_ns")["t_ns"].to_numpy()
    assert len(times) == len(power) == 1487
    got = mmtrack.track_beams(
        power,
        tracker=trackers,
        t_ns=times,
        site=tracked["site"][0],
        pass_index=seq_index,
        car_lat_lon_deg=car,
        array_lat_lon_deg=array,
    )
    assert got["pass"].n_unique() == len(passes) == 52
    assert got.filter(pl.col("tracker") == "gnss-window")["gnss_beam"].null_count() == 0
    by_pass = {p["pass"]: p["sequence_id"] for p in passes}
    for index, sequence in by_pass.items():
        expected = tracked.filter(pl.col("sequence") == sequence).drop("sequence")
        mine = got.filter(pl.col("pass") == index).drop("pass")
        key = ["tracker", "t_ns"]
        assert_frames_close(mine.sort(key), expected.sort(key))
    # One pass is not enough for a leave-one-pass-out map.
    with pytest.raises(mmtrack.MmtrackError, match="at least two passes"):
        mmtrack.track_beams(power[:5], tracker="gnss-window", car_east_north_m=np.zeros((5, 2)))
    with pytest.raises(mmtrack.MmtrackError, match="need the car's position at each sweep"):
        mmtrack.track_beams(power[:20], tracker="gnss-window", pass_index=seq_index[:20] * 0 + np.arange(20) // 10)


def test_reproduce_returns_the_claims_the_cli_reports(tmp_path: Path) -> None:
    done = mmtrack.reproduce("zoechmann", quick=True, output=tmp_path / "py")
    cli("reproduce", "zoechmann", "--quick", "-o", tmp_path / "cli", ok=False)
    assert done.claims and done.experiment == "zoechmann"
    report = (tmp_path / "cli" / "reproduce.md").read_text()
    for claim in done.claims:
        assert f"| {claim.claim} | {claim.paper} |" in report
        assert claim.verdict in ("met", "missed", "holds (ours, not counted)", "does not hold (ours, not counted)")
    assert done.targets_met == all(c.met or c.informational for c in done.claims)
    assert any(c.paper_value is not None and c.measured is not None for c in done.claims)
    # The measured numbers are the CLI's (seeded), except wall-clock times.
    theirs = json.loads((tmp_path / "cli" / "metrics.json").read_text())
    assert [m["key"] for m in done.metrics] == [m["key"] for m in theirs]
    compared = 0
    for ours, cli_metric in zip(done.metrics, theirs):
        if ours["unit"] == "s":
            continue
        assert ours["value"] == pytest.approx(cli_metric["value"], rel=TOL, abs=TOL), ours["key"]
        compared += 1
    assert compared > 0


def interrupted_after(delay_s: float, call) -> float:
    """Seconds from a Ctrl-C (``_thread.interrupt_main``, the SIGINT handler's
    KeyboardInterrupt) sent `delay_s` into `call` until `call` raised it."""
    import _thread
    import threading
    import time

    sent = []

    def interrupt() -> None:
        sent.append(time.monotonic())
        _thread.interrupt_main()

    timer = threading.Timer(delay_s, interrupt)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
    assert sent, "the call ended before the interrupt was sent: make it longer"
    return time.monotonic() - sent[0]


def test_ctrl_c_stops_a_long_call_and_leaves_no_partial_output(tmp_path: Path) -> None:
    # Before: the interrupt waited for the call to end (28 s for mpc-convoy,
    # all outputs written). Now the call stops at its next progress check.
    # The bound is loose for a shared 2-core machine: a check comes at least
    # once per batch of sets, well under a second apart.
    out = tmp_path / "convoy"
    waited_s = interrupted_after(2.0, lambda: mmtrack.reproduce("mpc-convoy", output=out))
    assert waited_s < 3.0, waited_s
    left = sorted(p.name for p in tmp_path.rglob("*"))
    assert left == [], left  # neither the output folder nor a hidden partial


def test_errors_carry_the_cli_line(tmp_path: Path) -> None:
    missing = tmp_path / "missing.mcap"
    with pytest.raises(mmtrack.MmtrackError) as caught:
        mmtrack.process("odometry", missing, tmp_path / "out")
    assert str(caught.value) == cli_error("process", "odometry", missing, "-o", tmp_path / "out")

    with pytest.raises(mmtrack.MmtrackError) as caught:
        mmtrack.ingest("oxford", DEMO_FOLDER, tmp_path / "x.mcap", bins="many")
    assert str(caught.value) == cli_error("ingest", "oxford", DEMO_FOLDER, "-o", tmp_path / "x.mcap", "--bins", "many")

    with pytest.raises(mmtrack.MmtrackError) as caught:
        mmtrack.analyze(tmp_path / "no-tables", tmp_path / "analysis")
    assert str(caught.value) == cli_error("analyze", tmp_path / "no-tables", "-o", tmp_path / "analysis")

    with pytest.raises(mmtrack.MmtrackError, match="the GNSS policies need a beam map fitted leave-one-pass-out"):
        mmtrack.track_beams(np.ones((3, 4)), tracker="gnss-map")
    with pytest.raises(mmtrack.MmtrackError, match="estimate: row 1: t_ns 0 does not increase"):
        t = np.array([0, 0, 1], dtype=np.int64)
        mmtrack.trajectory_metrics((t, np.zeros((3, 3))), (t + 5, np.zeros((3, 3))))
    with pytest.raises(mmtrack.MmtrackError, match="unknown table"):
        mmtrack.table_spec("no_such_table")
    with pytest.raises(TypeError, match="unexpected keyword"):
        mmtrack.process("odometry", missing, tmp_path / "out", presett="cfear")


def test_stubs_name_every_native_function_and_the_package_is_typed() -> None:
    import ast

    import mmtrack._native as native

    package = Path(mmtrack.__file__).parent
    assert (package / "py.typed").is_file()
    tree = ast.parse((package / "_native.pyi").read_text())
    stubbed = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    exported = {name for name in dir(native) if not name.startswith("_")}
    assert stubbed == exported
    assert set(mmtrack.__all__) <= set(dir(mmtrack))


def test_an_older_polars_is_named_at_import(monkeypatch: pytest.MonkeyPatch) -> None:
    # Before: pyproject allowed polars >= 1.0 and polars < 1.43.2 failed on
    # every read ("Invalid thrift: bad data"). Now import names the version needed.
    from mmtrack import _polars_version

    for old in ("1.42.1", "1.43.0", "1.43"):
        problem = _polars_version.polars_version_problem(old)
        assert problem is not None and "polars >= 1.43.2" in problem and f"polars {old} is" in problem, old
    for fine in ("1.43.2", "1.44.2", "1.100.0", "2.1.0", "2.2.0b1", "not-a-version"):
        assert _polars_version.polars_version_problem(fine) is None, fine
    monkeypatch.setattr(pl, "__version__", "1.30.0")
    with pytest.raises(ImportError, match=r"polars >= 1\.43\.2 .* polars 1\.30\.0 is installed"):
        _polars_version.check_polars_version()


def python_blocks(doc: str, heading: str) -> list[str]:
    """The ```python blocks of `doc`'s section `heading`."""
    import re

    section = (ROOT / doc).read_text().split(heading + "\n", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```python\n(.*?)```", section, re.S)


def run_block(code: str) -> tuple[dict[str, Any], list[Any]]:
    """Runs a documented snippet: its names, and the value of each expression statement."""
    import ast

    namespace: dict[str, Any] = {}
    values = []
    for statement in ast.parse(code).body:
        if isinstance(statement, ast.Expr):
            values.append(eval(compile(ast.Expression(statement.value), "<doc>", "eval"), namespace))
        else:
            exec(compile(ast.Module(body=[statement], type_ignores=[]), "<doc>", "exec"), namespace)
    return namespace, values


def sequences_of(value: Any) -> set[str]:
    """The `sequence` values of a DuckDB relation or a polars / pandas frame, as read."""
    if hasattr(value, "fetchall"):
        columns = [c for c in value.columns]
        return {row[columns.index("sequence")] for row in value.fetchall()}
    if isinstance(value, pl.LazyFrame):
        value = value.collect()
    return set(value["sequence"].to_list()) if isinstance(value, pl.DataFrame) else set(value["sequence"].tolist())


def test_documented_readers_keep_a_numeric_looking_sequence_id(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Before: the README's and docs/campaigns.md's snippets read `sequence=007`
    # as 7 (polars, pandas) and `2019-01-10` as a date (DuckDB, polars). Now
    # every snippet names the partition column's type.
    pytest.importorskip("duckdb")
    mmtrack.ingest("oxford", DEMO_FOLDER, tmp_path / "r.mcap", bins="auto", sequence_id="007")
    mmtrack.process("odometry", tmp_path / "r.mcap", tmp_path / "tables")
    mmtrack.analyze(tmp_path / "tables", tmp_path / "analysis", segment_lengths_m=[2, 4, 6, 8])
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "campaign").symlink_to(tmp_path)
    monkeypatch.chdir(tmp_path)
    blocks = python_blocks("README.md", "## Python and DuckDB") + python_blocks(
        "docs/campaigns.md", "## DuckDB and polars over the tables"
    )
    assert len(blocks) == 3
    checked = 0
    for code in blocks:
        namespace, values = run_block(code)
        for frame in values + [namespace[n] for n in ("odometry",) if n in namespace]:
            if frame is not None:
                assert sequences_of(frame) == {"007"}, code
                checked += 1
    # The README's DuckDB join, polars and pandas; the campaign's DuckDB and polars.
    assert checked == 5


def test_tables_reads_a_multi_run_analyze_per_run_tables(demo: dict[str, Path], tmp_path: Path) -> None:
    # Before: analyze of two runs writes run=<ID>/tables/<table>/..., and
    # mmtrack.tables(out) said "no tables". Now they come with a `run` column.
    runs = tmp_path / "runs"
    for run_id in ("a", "b"):
        mmtrack.process("odometry", demo["recording"], runs, run_id=run_id)
    out = tmp_path / "cmp"
    done = mmtrack.analyze(runs, out, segment_lengths_m=[2, 4, 6, 8])
    per_run = mmtrack.tables(out)
    assert "trajectory_metrics" in per_run
    metrics = per_run["trajectory_metrics"].collect()
    assert sorted(set(metrics["run"].to_list())) == ["a", "b"]
    assert set(metrics["sequence"].to_list()) == {"oxford-demo"}
    # One run's folder alone: its `run` folder is a string column too.
    alone = mmtrack.read_table(out / "run=a" / "tables", "trajectory_metrics").collect()
    assert set(alone["run"].to_list()) == {"a"}
    assert_frames_close(metrics.filter(pl.col("run") == "a"), alone.select(metrics.columns))
    assert list(mmtrack.tables(done["tables"])) == ["run_comparison"]
    assert mmtrack.table_info(out, "trajectory_metrics").files[0].endswith("part-0.parquet")
    # Tables directly under a directory beside its run=<ID> folders (a run
    # without --run-id next to one with it): before, tables() refused the
    # whole directory ("in more than one layout") while analyze read it. Now
    # the direct ones are a run named after the directory, as analyze names it.
    mixed = tmp_path / "mixed"
    mmtrack.process("odometry", demo["recording"], mixed)
    mmtrack.process("odometry", demo["recording"], mixed, run_id="x")
    odometry = mmtrack.tables(mixed)["odometry"].collect()
    assert sorted(set(odometry["run"].to_list())) == ["mixed", "x"]
    direct = mmtrack.read_table(mixed, "odometry").filter(pl.col("run") == "mixed").collect()
    assert_frames_close(direct.drop("run"), odometry.filter(pl.col("run") == "x").select(direct.drop("run").columns))


def test_every_error_is_an_mmtrack_error(tmp_path: Path) -> None:
    # Before: arguments numpy or pyo3 could not convert raised plain
    # ValueError / TypeError / OverflowError, though the docstring promised
    # MmtrackError. Now they are MmtrackError subclasses that are still
    # ValueError / TypeError, named after the call.
    with pytest.raises(mmtrack.MmtrackValueError, match="track_beams: could not convert string to float") as raised:
        mmtrack.track_beams(np.array([["x"] * 64] * 3))
    assert isinstance(raised.value, ValueError) and isinstance(raised.value, mmtrack.MmtrackError)
    with pytest.raises(mmtrack.MmtrackValueError, match="detect_mpc: "):
        mmtrack.detect_mpc(np.array([["a"] * 8]), tap_spacing_s=1e-9)
    with pytest.raises(mmtrack.MmtrackValueError, match=r"negative.*\(threads=-1: expected a non-negative integer\)"):
        mmtrack.process("odometry", tmp_path / "x.mcap", tmp_path / "t", threads=-1)
    with pytest.raises(mmtrack.MmtrackTypeError) as raised:
        mmtrack.process("odometry", tmp_path / "x.mcap", tmp_path / "t", no_such_option=1)
    assert isinstance(raised.value, TypeError)
    # The data's own errors stay plain MmtrackError with the CLI's line.
    with pytest.raises(mmtrack.MmtrackError) as raised:
        mmtrack.process("odometry", tmp_path / "x.mcap", tmp_path / "t")
    assert type(raised.value) is mmtrack.MmtrackError
    # Labels name each row's snapshot: repeated ones could not be told apart
    # (before, every detection read as the last row's), and a short t_ns is
    # named as such (before: "cir: 192 taps for 1 snapshots of 64 taps").
    cir3 = np.ones((3, 64), dtype=complex)
    with pytest.raises(mmtrack.MmtrackError, match=r"rows 0 and 1 are both \(5, 0, 0\)"):
        mmtrack.detect_mpc(cir3, tap_spacing_s=1e-9, t_ns=[5, 5, 5], set_index=[0, 0, 0], snapshot_index=[0, 0, 0])
    with pytest.raises(mmtrack.MmtrackError, match=r"one per snapshot of cir \(3\), got 1"):
        mmtrack.detect_mpc(cir3, tap_spacing_s=1e-9, t_ns=[1])
    # A sweep period as ingest beams checks it (NaN gave "sweep time -9223372036854775808 ns"), and a
    # short t_ns named as such (the power array was blamed).
    power = np.ones((10, 64))
    with pytest.raises(mmtrack.MmtrackError, match="sweep_period_s nan: expected a positive number"):
        mmtrack.track_beams(power, sweep_period_s=float("nan"))
    with pytest.raises(mmtrack.MmtrackError, match=r"t_ns: one time per sweep of power \(10\)"):
        mmtrack.track_beams(power, t_ns=[1, 2])
    # No recording is an error, as the CLI's (it reported success, writing nothing).
    with pytest.raises(mmtrack.MmtrackError, match="no recordings"):
        mmtrack.process("beam", [], tmp_path / "nothing")
    # `config` is a path (str or pathlib.Path), as documented.
    with pytest.raises(mmtrack.MmtrackError, match="none.toml"):
        mmtrack.detect_mpc(np.ones((1, 8), dtype=complex), tap_spacing_s=1e-9, config=tmp_path / "none.toml")
    assert "oxford" in mmtrack.INGEST_OPTIONS and "INGEST_OPTIONS" in mmtrack.ingest.__doc__
    assert "odometry" in mmtrack.PROCESS_OPTIONS and "PROCESS_OPTIONS" in mmtrack.process.__doc__


def test_a_corrupt_partition_is_named_when_the_table_is_opened(demo: dict[str, Path], tmp_path: Path) -> None:
    # Before: polars' error at collect() ("The file must end with PAR1") named no file.
    bad = tmp_path / "odometry" / "sequence=x" / "part-0.parquet"
    bad.parent.mkdir(parents=True)
    bad.write_text("not parquet\n")
    with pytest.raises(mmtrack.MmtrackError, match=r"sequence=x/part-0\.parquet: not a readable Parquet table"):
        mmtrack.tables(tmp_path)
    cut = tmp_path / "odometry" / "sequence=x" / "part-0.parquet"
    good = next((demo["tables"] / "odometry").glob("sequence=*/part-0.parquet")).read_bytes()
    cut.write_bytes(good[:-1])
    with pytest.raises(mmtrack.MmtrackError, match="no Parquet footer"):
        mmtrack.read_table(tmp_path, "odometry")
