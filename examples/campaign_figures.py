"""Load a campaign's tables with polars and draw the main figures.

    pip install polars matplotlib
    python examples/campaign_figures.py out/demo/tables out/demo/analysis/tables -o out/demo/figures

Reads the Hive-partitioned tables (`<table>/sequence=<id>/part-0.parquet`) of
`mmtrack process` and `mmtrack analyze` and writes PNG figures for whatever
they hold: trajectories (estimate and ground truth), KITTI drift per segment
length, MPCs per set and SPEBT angle errors per slot. Prints a per-sequence
summary table.
"""

import argparse
import math
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import polars as pl  # noqa: E402


def scan(root, table):
    """The table as a LazyFrame with its `sequence` column, or None when absent."""
    files = sorted((root / table).glob("sequence=*/part-0.parquet"))
    if not files:
        return None
    # The sequence id as written (polars would read `007` as the number 7).
    return pl.scan_parquet(
        str(root / table / "*" / "*.parquet"), hive_partitioning=True, hive_schema={"sequence": pl.String}
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tables", type=pathlib.Path, help="tables of mmtrack process")
    parser.add_argument("results", type=pathlib.Path, help="tables of mmtrack analyze (<out>/tables)")
    parser.add_argument("-o", "--output", type=pathlib.Path, required=True)
    args = parser.parse_args()
    args.output.mkdir(parents=True, exist_ok=True)
    written = []

    metrics = scan(args.results, "trajectory_metrics")
    if metrics is not None:
        summary = (
            metrics.select("sequence", "path_length_m", "kitti_translational_pct", "ate_rmse_m", "rpe_translation_rmse_m")
            .sort("sequence")
            .collect()
        )
        print(summary)

    odometry, truth = scan(args.tables, "odometry"), scan(args.tables, "ground_truth")
    if odometry is not None and truth is not None:
        fig, ax = plt.subplots(figsize=(6, 6))
        for (sequence,), est in odometry.collect().sort("t_ns").group_by("sequence", maintain_order=True):
            ax.plot(est["x_m"], est["y_m"], label=f"{sequence} estimate")
        for (sequence,), gt in truth.collect().sort("t_ns").group_by("sequence", maintain_order=True):
            ax.plot(gt["x_m"], gt["y_m"], "k--", label=f"{sequence} ground truth")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(fontsize=7)
        written.append(save(fig, args.output / "trajectories.png"))

    drift = scan(args.results, "drift_per_length")
    if drift is not None:
        fig, ax = plt.subplots()
        for (sequence,), d in drift.collect().sort("length_m").group_by("sequence", maintain_order=True):
            ax.plot(d["length_m"], d["translational_pct"], "o-", label=sequence)
        ax.set_xlabel("segment length (m)")
        ax.set_ylabel("KITTI translational drift (%)")
        ax.legend(fontsize=7)
        written.append(save(fig, args.output / "drift_per_length.png"))

    sets = scan(args.results, "mpc_set_metrics")
    if sets is not None:
        fig, ax = plt.subplots()
        for (sequence,), s in sets.collect().sort("set_index").group_by("sequence", maintain_order=True):
            ax.step(s["set_index"], s["long_term_mpcs"], where="mid", label=sequence)
        ax.set_xlabel("set")
        ax.set_ylabel("MPCs per set")
        ax.legend(fontsize=7)
        written.append(save(fig, args.output / "mpcs_per_set.png"))

    spebt = scan(args.tables, "spebt_per_slot")
    if spebt is not None:
        fig, ax = plt.subplots()
        for (sequence,), s in spebt.collect().sort("slot").group_by("sequence", maintain_order=True):
            ax.plot(s["slot"], s["rmse_aod_rad"] * 180.0 / math.pi, label=f"{sequence} AoD")
            ax.plot(s["slot"], s["rmse_aoa_rad"] * 180.0 / math.pi, label=f"{sequence} AoA")
        ax.set_xlabel("slot")
        ax.set_ylabel("RMSE over runs (deg)")
        ax.legend(fontsize=7)
        written.append(save(fig, args.output / "spebt_errors.png"))

    for path in written:
        print(f"wrote {path}")
    if not written:
        raise SystemExit(f"nothing to draw: no known tables under {args.tables} or {args.results}")


def save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


if __name__ == "__main__":
    main()
