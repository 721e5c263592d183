"""Types of the extension module ``mmtrack._native`` (the public names are in ``mmtrack``)."""

from typing import Any, Optional

__version__: str

class MmtrackError(Exception):
    """An mmtrack call failed; the message is the CLI's one line."""

def ingest_oxford(
    input: str,
    output: str,
    flags: dict[str, Any],
    threads: int,
    range_resolution_m: Optional[float],
    bins: str,
    decode: bool,
    sequence_id: Optional[str],
) -> dict[str, Any]: ...
def ingest_boreas(
    input: str,
    output: str,
    flags: dict[str, Any],
    threads: int,
    range_resolution_m: Optional[float],
    decode: bool,
    sequence_id: Optional[str],
) -> dict[str, Any]: ...
def ingest_mulran(
    input: str,
    output: str,
    flags: dict[str, Any],
    threads: int,
    range_resolution_m: Optional[float],
    stamp_at: str,
    scan_period_s: float,
    sequence_id: Optional[str],
) -> dict[str, Any]: ...
def ingest_cir(
    input: str, output: str, flags: dict[str, Any], format: str, sidecar: Optional[str]
) -> dict[str, Any]: ...
def ingest_nmea(input: str, output: str, flags: dict[str, Any], add_to: Optional[str]) -> dict[str, Any]: ...
def ingest_poses(
    input: str,
    output: str,
    flags: dict[str, Any],
    format: str,
    add_to: Optional[str],
    estimate: bool,
    times: Optional[str],
    t0_ns: int,
    plane: str,
) -> dict[str, Any]: ...
def ingest_ros2(
    input: str,
    output: str,
    flags: dict[str, Any],
    pose_topic: str,
    poses_are_ground_truth: bool,
    ground_truth_topic: Optional[str],
    gnss_topic: Optional[str],
    radar_topic: Optional[str],
    radar_range_resolution_m: Optional[float],
    stamp_at: str,
    scan_period_s: float,
) -> dict[str, Any]: ...
def ingest_beams(
    input: str,
    output: str,
    flags: dict[str, Any],
    scenario: Optional[int],
    positions: str,
    sweep_period_s: float,
) -> list[dict[str, Any]]: ...
def process_odometry(
    recording: str,
    output: str,
    preset: str,
    config: Optional[str],
    sequence: Optional[str],
    force: bool,
    run_id: Optional[str],
    threads: int,
) -> dict[str, Any]: ...
def process_poses(
    recording: str, output: str, sequence: Optional[str], force: bool, run_id: Optional[str]
) -> dict[str, Any]: ...
def process_raw(
    recording: str, output: str, sequence: Optional[str], force: bool, run_id: Optional[str]
) -> dict[str, Any]: ...
def effective_config(pipeline: str, preset: str, config: Optional[str], gmphd: bool) -> str: ...
def process_mpc(
    recording: str,
    output: str,
    config: Optional[str],
    pulse: Optional[str],
    link: Optional[str],
    gmphd: bool,
    sequence: Optional[str],
    force: bool,
    run_id: Optional[str],
    threads: int,
) -> dict[str, Any]: ...
def process_beam(
    recordings: list[str],
    output: str,
    tracker: list[str],
    reacquire: str,
    force: bool,
    run_id: Optional[str],
    spebt: dict[str, Any],
    geometric: dict[str, Any],
) -> dict[str, Any]: ...
def process_slam(
    recording: str,
    output: str,
    config: Optional[str],
    particles: Optional[int],
    seed: int,
    prior: Optional[list[float]],
    strict: bool,
    sequence: Optional[str],
    force: bool,
    run_id: Optional[str],
    threads: int,
) -> dict[str, Any]: ...
def analyze_tables(
    tables: list[str],
    output: str,
    force: bool,
    segment_lengths_m: Optional[list[float]],
    step_frames: Optional[int],
    step_m: Optional[float],
    first_path_range_db: Optional[float],
) -> dict[str, Any]: ...
def reproduce_experiment(experiment: str, threads: int, request: dict[str, Any]) -> dict[str, Any]: ...
def reproduce_all(output: str, smoke: bool, readme: Optional[str]) -> dict[str, Any]: ...
def table_specs() -> list[dict[str, Any]]: ...
def table_file_metadata(path: str) -> dict[str, str]: ...
def table_field_metadata(path: str) -> list[tuple[str, dict[str, str]]]: ...
def recording_metadata(path: str) -> dict[str, str]: ...
def detect_mpc(
    taps: bytes,
    taps_per_snapshot: int,
    t_ns: bytes,
    set_index: list[int],
    snapshot_index: list[int],
    tap_spacing_s: float,
    config: Optional[str],
    pulse: Optional[bytes],
) -> bytes: ...
def track_beams(
    power: bytes,
    beams: int,
    t_ns: bytes,
    tracker: list[str],
    reacquire: str,
    site: str,
    pass_index: Optional[bytes] = None,
    car: Optional[bytes] = None,
    car_frame: str = "east_north_m",
    array_lat_lon_deg: Optional[bytes] = None,
) -> list[tuple[int, bytes]]: ...
def trajectory_metrics(
    sequence: str,
    estimate_t_ns: bytes,
    estimate: bytes,
    ground_truth_t_ns: bytes,
    ground_truth: bytes,
    segment_lengths_m: Optional[list[float]],
    step_frames: Optional[int],
    step_m: Optional[float],
) -> tuple[bytes, bytes, bytes]: ...
