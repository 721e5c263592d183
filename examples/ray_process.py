"""Process a campaign on a Ray cluster: one Ray task per sequence.

The tasks are the per-sequence command lines of `mmtrack process manifest
--print-commands` (the same commands the local run executes on its thread
pool), so the tables are identical to a local `mmtrack process manifest`.

    pip install "ray[default]"
    python examples/ray_process.py campaign.toml out/tables [--mmtrack target/release/mmtrack]

Starts a local Ray cluster when none is running (`ray.init()`); on a real
cluster set RAY_ADDRESS and make the recordings and the output directory
visible to every node (a shared file system).
"""

import argparse
import shlex
import subprocess
import sys

import ray


@ray.remote
def run_sequence(command):
    """Runs one `mmtrack process ...` command; returns (command, exit code, stderr)."""
    done = subprocess.run(command, capture_output=True, text=True)
    return command, done.returncode, done.stderr


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("manifest")
    parser.add_argument("output")
    parser.add_argument("--mmtrack", default="mmtrack", help="the mmtrack binary")
    parser.add_argument("--force", action="store_true")
    args = parser.parse_args()

    printed = [args.mmtrack, "process", "manifest", args.manifest, "-o", args.output, "--print-commands"]
    if args.force:
        printed.append("--force")
    lines = subprocess.run(printed, check=True, capture_output=True, text=True).stdout.splitlines()
    commands = [[args.mmtrack] + shlex.split(line)[1:] + ["--quiet"] for line in lines]

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    results = ray.get([run_sequence.remote(c) for c in commands])
    failed = [(c, code, err) for c, code, err in results if code != 0]
    for command, code, err in failed:
        print(f"failed ({code}): {shlex.join(command)}: {err.strip()}", file=sys.stderr)
    print(f"{len(results) - len(failed)} of {len(results)} sequences done on Ray; tables under {args.output}")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
