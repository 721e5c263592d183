//! Parquet result tables.
//!
//! A table is described by a [`TableSpec`] (name, columns, types, units,
//! meaning): the one source for the Arrow schema, the `units` metadata and the
//! documents in `schemas/tables/`. Files are laid out Hive-style,
//! `<root>/<table>/sequence=<id>/part-0.parquet`, so DuckDB, polars, pyarrow,
//! Spark and DataFusion read a whole campaign as one dataset. Each file carries
//! in its key-value metadata:
//!
//! - `units`: JSON object column -> unit (also on each Arrow field as `unit`,
//!   beside its `description`); `1` for a dimensionless number, `none` for a
//!   string, flag or bytes;
//! - `time_base`, `time_base.meaning`: what `t_ns` counts from, the input
//!   recording's ([`TableTimeBase`]);
//! - `frame`, `frame.meaning` (and `frame.origin` where the recording names an
//!   origin): the coordinate frame of the table's positions and angles,
//!   `not_applicable` for a table without any ([`TableFrame`]);
//! - `mmtrack.table`, `mmtrack.version`;
//! - `mmtrack.run_config`: the run's full configuration as JSON.
//!
//! Each table is declared once with [`define_table!`](crate::define_table):
//! its columns (name, Rust type, unit, meaning) give the spec, the writer and
//! the reader.

mod beam_result_rows;
mod beam_rows;
mod campaign_rows;
mod columns;
mod context;
mod define;
mod geometric_rows;
mod io;
mod mpc_result_rows;
mod mpc_rows;
mod odometry_rows;
mod rows;
mod slam_rows;
mod spebt_rows;
mod trajectory_result_rows;

pub use arrow_array::ArrayRef;
pub use beam_result_rows::{
    BEAM_RMS_PER_BLOCK, BEAM_SWEEP_POOLED, BEAM_SWEEP_SUMMARY, BEAM_VALID_TRACKING, BeamRmsRow, BeamSweepPooledRow,
    BeamSweepSummaryRow, BeamValidTrackingRow,
};
pub use beam_rows::{BEAM_SWEEPS_TRACKED, BeamSweepTracked};
pub use campaign_rows::{RUN_COMPARISON, RunComparisonRow};
pub use columns::{ColumnValue, Columns, ListColumn};
pub use context::{
    FRAME_KEY, FRAME_MEANING_KEY, FRAME_NOT_APPLICABLE, FRAME_ORIGIN_KEY, Frame, NOT_APPLICABLE_MEANING, TIME_BASE_KEY,
    TableFrame, TableTimeBase,
};
pub use geometric_rows::{
    GEOMETRIC_FILTER_H_INFINITY, GEOMETRIC_FILTER_RLS, GEOMETRIC_PER_EPOCH, GEOMETRIC_SUMMARY, GeometricEpochRow,
    GeometricSummaryRow, ZOECHMANN_NLOS_ERROR, ZOECHMANN_NMSE, ZOECHMANN_PATH_LABELS, ZOECHMANN_SUMMARY,
    ZoechmannNlosErrorRow, ZoechmannNmseRow, ZoechmannPathLabelRow, ZoechmannSummaryRow,
};
pub use io::{
    MAX_PARTITION_NAME_BYTES, ROW_GROUP_BYTES, RunInfo, StagedTable, TableFileSummary, TableWriteSummary, TableWriter,
    check_partition_name, inspect_table_dir, inspect_table_file, publish_tables, read_table, read_table_dir,
    stage_table, table_bytes, table_path, write_table,
};
pub use mpc_result_rows::{
    ChiClassShare, CountBin, FirstPathRow, MPC_CHI_CLASSES, MPC_COUNT_DISTRIBUTION, MPC_FIRST_PATH, MPC_SET_METRICS,
    MPC_SUMMARY, MPC_TRACK_POWER_STD, MpcSummary, SetMetrics, TrackPowerStd,
};
pub use mpc_rows::{
    GROUND_TRUTH_RX, GROUND_TRUTH_TX, GmPhdTrack, GroundTruthRxPose, GroundTruthTxPose, MPC_LONG_TERM, MPC_SETS,
    MPC_SNAPSHOTS, MPC_TRACKS_GMPHD, MPC_TRUTH, MpcSnapshotStats,
};
pub use odometry_rows::{GROUND_TRUTH, GroundTruthPose, ODOMETRY, ODOMETRY_TIMING};
pub use rows::{ALL_TABLES, CIR_SNAPSHOTS, GNSS_FIXES, MPC_DETECTIONS, MPC_TRACKS, POSES, RADAR_SCANS, RESULT_TABLES};
pub use slam_rows::{
    SLAM_ASSOCIATIONS, SLAM_MAP, SLAM_PER_EPOCH, SLAM_SUMMARY, SLAM_TRUE_SOURCES, SLAM_UE, SlamAssociationRow,
    SlamMapRow, SlamPerEpochRow, SlamSummaryRow, SlamTrueSourceRow, SlamUeRow,
};
pub use spebt_rows::{SPEBT_PER_SLOT, SPEBT_POOLED, SPEBT_SUMMARY, SpebtPooledRow, SpebtSlotRow, SpebtSummaryRow};
pub use trajectory_result_rows::{
    DRIFT_PER_LENGTH, DriftPerLength, RELATIVE_POSE_ERRORS, RelativePoseErrorRow, TRAJECTORY_METRICS, TrajectoryMetrics,
};

use std::sync::Arc;

use arrow_schema::{DataType, Field, Schema};

/// Arrow type of a column, as tables use them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnType {
    /// 64-bit signed integer.
    Int64,
    /// 64-bit unsigned integer.
    UInt64,
    /// 32-bit unsigned integer.
    UInt32,
    /// 64-bit float.
    Float64,
    /// Boolean.
    Boolean,
    /// UTF-8 string.
    Utf8,
    /// Opaque bytes.
    Binary,
    /// List of 64-bit floats.
    ListFloat64,
    /// List of 64-bit signed integers.
    ListInt64,
    /// List of booleans.
    ListBoolean,
}

impl ColumnType {
    /// The Arrow data type.
    #[must_use]
    pub fn data_type(self) -> DataType {
        let list = |t: DataType| DataType::List(Arc::new(Field::new("item", t, true)));
        match self {
            Self::Int64 => DataType::Int64,
            Self::UInt64 => DataType::UInt64,
            Self::UInt32 => DataType::UInt32,
            Self::Float64 => DataType::Float64,
            Self::Boolean => DataType::Boolean,
            Self::Utf8 => DataType::Utf8,
            Self::Binary => DataType::Binary,
            Self::ListFloat64 => list(DataType::Float64),
            Self::ListInt64 => list(DataType::Int64),
            Self::ListBoolean => list(DataType::Boolean),
        }
    }

    /// Whether `found` is acceptable for this column: lists compare by item
    /// type only (writers name the item field differently).
    #[must_use]
    pub fn accepts(self, found: &DataType) -> bool {
        match (self.data_type(), found) {
            (DataType::List(want), DataType::List(got) | DataType::LargeList(got)) => {
                want.data_type() == got.data_type()
            }
            (want, got) => &want == got,
        }
    }

    /// Name used in the schema documents.
    #[must_use]
    pub fn doc_name(self) -> &'static str {
        match self {
            Self::Int64 => "int64",
            Self::UInt64 => "uint64",
            Self::UInt32 => "uint32",
            Self::Float64 => "float64",
            Self::Boolean => "bool",
            Self::Utf8 => "string",
            Self::Binary => "binary",
            Self::ListFloat64 => "list<float64>",
            Self::ListInt64 => "list<int64>",
            Self::ListBoolean => "list<bool>",
        }
    }
}

/// One column of a table.
#[derive(Debug, Clone, Copy)]
pub struct ColumnSpec {
    /// Column name (units in the name).
    pub name: &'static str,
    /// Arrow type.
    pub ty: ColumnType,
    /// Whether nulls are allowed (meaning "not available").
    pub nullable: bool,
    /// Unit, or "" for unitless.
    pub unit: &'static str,
    /// Meaning, one sentence.
    pub meaning: &'static str,
}

impl ColumnSpec {
    /// The unit as the files state it: [`ColumnSpec::unit`], or `1` for a
    /// dimensionless number (a count, ratio or index) and `none` for a
    /// string, flag or bytes, so every field names one.
    #[must_use]
    pub fn unit_label(&self) -> &'static str {
        match (self.unit, self.ty) {
            ("", ColumnType::Utf8 | ColumnType::Boolean | ColumnType::Binary | ColumnType::ListBoolean) => "none",
            ("", _) => "1",
            (unit, _) => unit,
        }
    }
}

/// A table: its name, what one row is, and its columns.
#[derive(Debug, Clone, Copy)]
pub struct TableSpec {
    /// Table name (the directory under the output root).
    pub name: &'static str,
    /// What one row means.
    pub description: &'static str,
    /// Columns in file order.
    pub columns: &'static [ColumnSpec],
    /// The coordinate frame of its positions and angles.
    pub frame: TableFrame,
}

impl TableSpec {
    /// The Arrow schema, with each field's `unit` ([`ColumnSpec::unit_label`])
    /// and `description` in its metadata.
    #[must_use]
    pub fn arrow_schema(&self) -> Schema {
        let fields: Vec<Field> = self
            .columns
            .iter()
            .map(|c| {
                Field::new(c.name, c.ty.data_type(), c.nullable).with_metadata(std::collections::HashMap::from([
                    ("unit".to_string(), c.unit_label().to_string()),
                    ("description".to_string(), c.meaning.to_string()),
                ]))
            })
            .collect();
        Schema::new(fields)
    }

    /// JSON object column -> unit ([`ColumnSpec::unit_label`]), for the
    /// `units` key-value metadata.
    #[must_use]
    pub fn units_json(&self) -> String {
        let map: serde_json::Map<String, serde_json::Value> =
            self.columns.iter().map(|c| (c.name.to_string(), serde_json::Value::from(c.unit_label()))).collect();
        serde_json::Value::Object(map).to_string()
    }

    /// Column names, comma-separated, for error messages.
    #[must_use]
    pub fn column_list(&self) -> String {
        self.columns.iter().map(|c| c.name).collect::<Vec<_>>().join(", ")
    }
}

/// A Rust type stored as rows of a table.
pub trait TableRow: Sized {
    /// The table.
    const SPEC: &'static TableSpec;
    /// Column arrays for `rows`, in [`TableSpec::columns`] order.
    fn to_columns(rows: &[Self]) -> Vec<ArrayRef>;
    /// Rows from a batch whose columns have been checked against the spec.
    /// Errors name the row and column.
    fn from_columns(columns: &Columns<'_>) -> Result<Vec<Self>, String>;
}
