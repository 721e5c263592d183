"""Run a campaign on a Ray cluster: one Ray task per manifest task.

Each Ray task runs `mmtrack process manifest <manifest> -o <tables> --task N`
(the same code a local `mmtrack process manifest` runs for that task), so the
tables are byte-identical to a local run. Tasks that need others (ingest before
process before analyze, `needs = [...]` in the manifest) get the Ray results of
those as arguments, so Ray starts them only after those finished.

    pip install "ray[default]"
    python examples/ray_process.py campaign.toml out/tables --mmtrack target/release/mmtrack
    RAY_ADDRESS=10.0.0.1:6379 python examples/ray_process.py campaign.toml out/tables   # an existing cluster
    python examples/ray_process.py campaign.toml out/tables --address 10.0.0.1:6379     # the same

- Cluster: `--address` or RAY_ADDRESS connects to a running cluster (`ray start
  --head` there); without either, a local Ray is started with `--num-cpus`
  CPUs (default: every core). On a real cluster the recordings, the output
  directory and this working directory must be the same paths on every node
  (a shared file system): each task runs in the directory this script was
  started from.
- CPUs: each Ray task asks for as many CPUs as the task uses threads: its own
  `--threads` in the manifest, else `--threads` here (default 1), which is
  also passed to it. A task asking for more CPUs than any node has is refused
  before anything runs (Ray would wait for it forever).
- Retries: a failed task is run again up to `--retries` times (default 2); a
  task whose needed task failed for good is not run.
- Resume: `--skip-existing` is passed to every task: tasks a previous run
  finished are skipped, interrupted ones redone (see docs/campaigns.md).

Prints one line per task that did not finish and a summary; exits 1 when a
task failed, 2 on a usage problem.
"""

import argparse
import json
import os
import subprocess
import sys


def run_task(command, cwd, index, *needed):
    """Runs one `mmtrack process manifest ... --task N`; returns (index, "ok" or "skipped").

    `needed` are the results of the tasks this one needs: Ray passes them only
    once those tasks finished, which is all they are here for.
    """
    done = subprocess.run(command, cwd=cwd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"task {index} exited with {done.returncode}: {done.stderr.strip()}")
    return index, "skipped" if done.stdout.startswith("skipped") else "ok"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("manifest")
    parser.add_argument("output", help="the tables directory (the manifest's -o)")
    parser.add_argument("--mmtrack", default="mmtrack", help="the mmtrack binary (same path on every node)")
    parser.add_argument("--address", help="a running Ray cluster (default: RAY_ADDRESS, else start a local one)")
    parser.add_argument("--num-cpus", type=int, default=os.cpu_count(), help="CPUs of the local Ray started without --address")
    parser.add_argument("--threads", type=int, default=1, help="threads (and Ray CPUs) of a task without its own --threads")
    parser.add_argument("--retries", type=int, default=2, help="times a failed task is run again")
    parser.add_argument("--skip-existing", action="store_true", help="skip finished tasks, redo interrupted ones")
    parser.add_argument("--force", action="store_true", help="replace earlier outputs of every task")
    args = parser.parse_args()
    if args.skip_existing and args.force:
        parser.error("--skip-existing and --force exclude each other")
    if args.threads < 1 or args.retries < 0:
        parser.error("--threads must be at least 1 and --retries at least 0")

    mmtrack = os.path.abspath(args.mmtrack) if os.sep in args.mmtrack else args.mmtrack
    listed = [mmtrack, "process", "manifest", args.manifest, "-o", args.output, "--print-tasks"]
    try:
        printed = subprocess.run(listed, capture_output=True, text=True)
    except OSError as error:
        # A usage problem, found before Ray starts: no such binary (not on PATH).
        print(
            f"{args.mmtrack}: cannot run the mmtrack binary ({error.strerror}); give its path with --mmtrack PATH",
            file=sys.stderr,
        )
        sys.exit(2)
    if printed.returncode != 0:
        print(printed.stderr.strip(), file=sys.stderr)
        sys.exit(printed.returncode)
    tasks = [json.loads(line) for line in printed.stdout.splitlines()]

    import ray  # here, so that a usage problem is told without Ray installed

    address = args.address or os.environ.get("RAY_ADDRESS")
    if address:
        ray.init(address=address, log_to_driver=False)
    else:
        # "local": a new Ray of its own, even when `ray start` runs a cluster on this machine.
        ray.init(address="local", num_cpus=args.num_cpus, include_dashboard=False, log_to_driver=False)
    largest = max(node["Resources"].get("CPU", 0) for node in ray.nodes() if node["Alive"])
    for task in tasks:
        task["threads"] = task["threads"] or args.threads
        if task["threads"] > largest:
            print(
                f"task {task['index']} uses {task['threads']} threads but the largest Ray node has {largest:g} CPUs; "
                "lower its --threads or add a larger node (nothing was run)",
                file=sys.stderr,
            )
            sys.exit(2)

    remote = ray.remote(run_task)
    cwd = os.getcwd()
    refs = {}
    for task in sorted(tasks, key=lambda t: (t["level"], t["index"])):
        command = listed[:-1] + ["--task", str(task["index"]), "--threads", str(task["threads"])]
        command += ["--skip-existing"] if args.skip_existing else []
        command += ["--force"] if args.force else []
        options = remote.options(num_cpus=task["threads"], max_retries=args.retries, retry_exceptions=True)
        refs[task["index"]] = options.remote(command, cwd, task["index"], *[refs[n] for n in task["needs"]])

    done, skipped, failed = 0, 0, 0
    for index in sorted(refs):
        try:
            _, state = ray.get(refs[index])
            done += 1
            skipped += state == "skipped"
        except ray.exceptions.RayError as e:
            failed += 1
            cause = str(e).strip().splitlines()[-1]
            print(f"failed (after up to {args.retries} retries): task {index}: {cause}", file=sys.stderr)
    print(f"{done} of {len(tasks)} tasks done on Ray ({skipped} skipped as complete); tables under {args.output}")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
