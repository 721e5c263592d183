"""Independent re-implementation of the KITTI odometry devkit's drift
(cpp/evaluate_odometry.cpp: trajectoryDistances, lastFrameFromSegmentLength,
rotationError, translationError, calcSequenceErrors, saveStats), in Python
with numpy and 4x4 matrices, reading KITTI pose files.

Usage: kitti_devkit.py GT_POSES EST_POSES LENGTHS_M [STEP_FRAMES]
Prints one JSON object: segments, mean translational error (fraction) and
rotational error (rad/m) over all segments, and per-length means.
"""

import json
import math
import sys

import numpy as np


def load_poses(path):
    rows = np.loadtxt(path, dtype=np.float64, ndmin=2)
    if rows.shape[1] != 12:
        raise SystemExit(f"{path}: expected 12 numbers per line, got {rows.shape[1]}")
    poses = []
    for r in rows:
        m = np.eye(4)
        m[:3, :4] = r.reshape(3, 4)
        poses.append(m)
    return poses


def trajectory_distances(poses):
    dist = [0.0]
    for i in range(1, len(poses)):
        p1, p2 = poses[i - 1], poses[i]
        dx = p1[0, 3] - p2[0, 3]
        dy = p1[1, 3] - p2[1, 3]
        dz = p1[2, 3] - p2[2, 3]
        dist.append(dist[i - 1] + math.sqrt(dx * dx + dy * dy + dz * dz))
    return dist


def last_frame_from_segment_length(dist, first_frame, length):
    for i in range(first_frame, len(dist)):
        if dist[i] > dist[first_frame] + length:
            return i
    return -1


def rotation_error(e):
    a, b, c = e[0, 0], e[1, 1], e[2, 2]
    d = 0.5 * (a + b + c - 1.0)
    return math.acos(max(min(d, 1.0), -1.0))


def translation_error(e):
    dx, dy, dz = e[0, 3], e[1, 3], e[2, 3]
    return math.sqrt(dx * dx + dy * dy + dz * dz)


def sequence_errors(gt, est, lengths, step_size):
    errors = []
    dist = trajectory_distances(gt)
    for first in range(0, len(gt), step_size):
        for length in lengths:
            last = last_frame_from_segment_length(dist, first, length)
            if last == -1:
                continue
            delta_gt = np.linalg.inv(gt[first]) @ gt[last]
            delta_est = np.linalg.inv(est[first]) @ est[last]
            e = np.linalg.inv(delta_est) @ delta_gt
            errors.append((first, last, length, translation_error(e) / length, rotation_error(e) / length))
    return errors


def main():
    gt = load_poses(sys.argv[1])
    est = load_poses(sys.argv[2])
    lengths = [float(v) for v in sys.argv[3].split(",")]
    step = int(sys.argv[4]) if len(sys.argv) > 4 else 10
    if len(gt) != len(est):
        raise SystemExit(f"{len(gt)} ground-truth poses but {len(est)} estimated poses")
    errors = sequence_errors(gt, est, lengths, step)
    out = {"segments": len(errors), "per_length": []}
    if errors:
        out["t_err"] = sum(e[3] for e in errors) / len(errors)
        out["r_err"] = sum(e[4] for e in errors) / len(errors)
    for length in lengths:
        of_length = [e for e in errors if e[2] == length]
        if of_length:
            out["per_length"].append({
                "length_m": length,
                "segments": len(of_length),
                "t_err": sum(e[3] for e in of_length) / len(of_length),
                "r_err": sum(e[4] for e in of_length) / len(of_length),
            })
    print(json.dumps(out))


if __name__ == "__main__":
    main()
