//! The run-comparison table of `mmtrack analyze` over several runs, with
//! units (in the column `unit`: one table holds every metric).

use super::TableFrame;

crate::define_table! {
    /// `run_comparison`: the runs of one `analyze` side by side, long format.
    pub const RUN_COMPARISON = "run_comparison",
        "One value of one metric of one run, in long format: the main metrics of the result tables \
(trajectory_metrics, mpc_summary, beam_sweep_summary, spebt_summary, geometric_summary, slam_summary) of every run \
analyzed together, plus the pooled trajectory rows (sequence `all`: KITTI drift over segments, RMSEs over poses, RPE over frame pairs; \
sequence `mean`: the mean of the per-sequence values). Partitioned by sequence like every table (`sequence=<id>`, \
`sequence=all`, `sequence=mean`), so the Hive column `sequence` filters it (`WHERE sequence = '<id>'` in DuckDB, \
pyarrow or polars). Pivot on `run` for the side-by-side table.",
        frame: TableFrame::NotApplicable;
    /// One row of [`RUN_COMPARISON`].
    #[derive(Debug, Clone, PartialEq)]
    pub struct RunComparisonRow {
        run: String, "", "run id (the run=<id> folder of the inputs, or the input directory's name)";
        source_table: String, "", "result table the value comes from";
        key: String, "",
            "row within the sequence: the tracker of beam_sweep_summary, the experiment / trajectory of \
spebt_summary, the scenario row of slam_summary; empty otherwise";
        metric: String, "", "column of source_table";
        unit: String, "", "unit of that column (empty for unitless)";
        value: Option<f64>, "", "the value in that unit; null where the table has none (e.g. KITTI drift of a path \
shorter than every segment)";
    }
}
