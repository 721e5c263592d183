use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use arrow_array::RecordBatch;
use parquet::arrow::ArrowWriter;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use parquet::basic::{Compression, ZstdLevel};
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;

use super::columns::{Columns, check_no_nulls};
use super::{
    FRAME_KEY, FRAME_MEANING_KEY, FRAME_NOT_APPLICABLE, FRAME_ORIGIN_KEY, Frame, NOT_APPLICABLE_MEANING, TIME_BASE_KEY,
    TableFrame, TableRow, TableSpec, TableTimeBase,
};
use crate::atomic::{AtomicFile, Durability, Overwrite, commit_all};
use crate::error::{IoError, Result, os_err};
use crate::recording::TIME_BASE_MEANING_KEY;

/// Provenance of a run and what its numbers are measured against, stored in
/// every table it writes.
#[derive(Debug, Clone, PartialEq)]
pub struct RunInfo {
    /// The run's full configuration as JSON.
    pub config_json: String,
    /// What `t_ns` counts from: the input recording's time base (key `time_base`).
    pub time_base: TableTimeBase,
    /// The world frame of the run's positions (keys `frame`, `frame.meaning`,
    /// `frame.origin`), for its tables of [`TableFrame::Run`]; a run that
    /// writes such a table without it fails.
    pub frame: Option<Frame>,
}

impl RunInfo {
    /// A run on inputs of `time_base`, without a world frame (enough for
    /// tables without positions).
    #[must_use]
    pub fn new(config_json: impl Into<String>, time_base: impl Into<TableTimeBase>) -> Self {
        Self { config_json: config_json.into(), time_base: time_base.into(), frame: None }
    }

    /// The same run with its positions in `frame`.
    #[must_use]
    pub fn with_frame(mut self, frame: Frame) -> Self {
        self.frame = Some(frame);
        self
    }

    /// The key-value pairs stating the time base and the frame of a table of
    /// `spec` written by this run.
    ///
    /// # Errors
    /// A table of [`TableFrame::Run`] when the run states no frame.
    pub fn context_metadata(&self, spec: &TableSpec) -> std::result::Result<Vec<(String, String)>, String> {
        let mut pairs = vec![
            (TIME_BASE_KEY.to_string(), self.time_base.name.clone()),
            (TIME_BASE_MEANING_KEY.to_string(), self.time_base.meaning.clone()),
        ];
        match spec.frame {
            TableFrame::NotApplicable => {
                pairs.push((FRAME_KEY.to_string(), FRAME_NOT_APPLICABLE.to_string()));
                pairs.push((FRAME_MEANING_KEY.to_string(), NOT_APPLICABLE_MEANING.to_string()));
            }
            TableFrame::Fixed { id, meaning } => {
                pairs.push((FRAME_KEY.to_string(), id.to_string()));
                pairs.push((FRAME_MEANING_KEY.to_string(), meaning.to_string()));
            }
            TableFrame::Run => {
                let frame = self.frame.as_ref().ok_or_else(|| {
                    format!("table {} holds positions but the run states no frame for them", spec.name)
                })?;
                pairs.push((FRAME_KEY.to_string(), frame.id.clone()));
                pairs.push((FRAME_MEANING_KEY.to_string(), frame.meaning.clone()));
                if let Some(origin) = &frame.origin {
                    let json: serde_json::Map<String, serde_json::Value> =
                        origin.iter().map(|(k, v)| (k.clone(), serde_json::Value::from(v.as_str()))).collect();
                    pairs.push((FRAME_ORIGIN_KEY.to_string(), serde_json::Value::Object(json).to_string()));
                }
            }
        }
        Ok(pairs)
    }
}

/// Checks that `sequence_id` can name a table partition (the folder
/// `sequence=<id>`): not empty, not `.` or `..`, and only ASCII letters,
/// digits, `-`, `_` and `.` (no path separator, space or `=`), at most
/// [`MAX_PARTITION_NAME_BYTES`] long. The error is
/// what is wrong, for the caller to place. Ingest checks the id it writes
/// into a recording with this, so a recording that `process` would refuse
/// is refused when it is made. [`HIVE_NULL_PARTITION`] is refused too: Hive
/// readers (DuckDB, polars, pyarrow) read that value as a missing id.
pub fn check_partition_name(sequence_id: &str) -> std::result::Result<(), String> {
    if sequence_id == HIVE_NULL_PARTITION {
        return Err(format!(
            "'{HIVE_NULL_PARTITION}' is not a valid partition name (Hive readers take it for a missing value)"
        ));
    }
    if sequence_id.len() > MAX_PARTITION_NAME_BYTES {
        return Err(format!(
            "a partition name of {} bytes is too long (at most {MAX_PARTITION_NAME_BYTES}: the folder \
             sequence=<id> is one file name, at most 255 bytes)",
            sequence_id.len()
        ));
    }
    let safe = !sequence_id.is_empty()
        && sequence_id != "."
        && sequence_id != ".."
        && sequence_id.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'));
    if safe {
        Ok(())
    } else {
        Err(format!(
            "'{}' is not a valid partition name (use ASCII letters, digits, '-', '_', '.'; not '.' or '..' alone)",
            sequence_id.escape_debug()
        ))
    }
}

/// Longest partition name: `sequence=` and the name make one file name,
/// and file systems allow at most 255 bytes for one.
pub const MAX_PARTITION_NAME_BYTES: usize = 255 - "sequence=".len();

/// The partition value Hive readers read as null.
pub const HIVE_NULL_PARTITION: &str = "__HIVE_DEFAULT_PARTITION__";

/// Path of one partition: `<root>/<table>/sequence=<id>/part-0.parquet`.
pub fn table_path(root: &Path, table: &str, sequence_id: &str) -> Result<PathBuf> {
    check_partition_name(sequence_id).map_err(|detail| IoError::BadValue {
        path: root.to_path_buf(),
        record: format!("table {table}"),
        field: "sequence_id",
        detail,
    })?;
    Ok(root.join(table).join(format!("sequence={sequence_id}")).join("part-0.parquet"))
}

/// What a finished table write reports.
#[derive(Debug, Clone, PartialEq)]
pub struct TableWriteSummary {
    /// The file written.
    pub path: PathBuf,
    /// Rows written.
    pub rows: u64,
}

/// The Arrow schema (units on each field, the key-value pairs on the
/// schema) and the writer properties (zstd, the key-value pairs in the file
/// footer) of every file of `spec`: `units`, `time_base`, `time_base.meaning`,
/// `frame`, `frame.meaning` (`frame.origin`), `mmtrack.table`,
/// `mmtrack.version`, `mmtrack.run_config`.
fn schema_and_properties(
    spec: &TableSpec,
    run: &RunInfo,
) -> std::result::Result<(Arc<arrow_schema::Schema>, WriterProperties), String> {
    let mut metadata = vec![KeyValue::new("units".to_string(), spec.units_json())];
    metadata.extend(run.context_metadata(spec)?.into_iter().map(|(k, v)| KeyValue::new(k, v)));
    metadata.extend([
        KeyValue::new("mmtrack.table".to_string(), spec.name.to_string()),
        KeyValue::new("mmtrack.version".to_string(), env!("CARGO_PKG_VERSION").to_string()),
        KeyValue::new("mmtrack.run_config".to_string(), run.config_json.clone()),
    ]);
    // The same pairs on the Arrow schema, where pyarrow and pandas users
    // look (`pq.read_table(f).schema.metadata`), and in the file footer.
    let schema_metadata: std::collections::HashMap<String, String> =
        metadata.iter().map(|kv| (kv.key.clone(), kv.value.clone().unwrap_or_default())).collect();
    let level = ZstdLevel::try_new(3).map_err(|e| e.to_string())?;
    let props = WriterProperties::builder()
        .set_compression(Compression::ZSTD(level))
        .set_key_value_metadata(Some(metadata))
        .build();
    Ok((Arc::new(spec.arrow_schema().with_metadata(schema_metadata)), props))
}

/// `rows` as the bytes of a Parquet file of their table, exactly as
/// [`write_table`] writes it (schema, units, key-value metadata), but in
/// memory: for front ends that hand results over without a file (the
/// Python package's array calls, read back with `polars.read_parquet`).
///
/// # Errors
/// An encoding error of the Parquet writer.
pub fn table_bytes<T: TableRow>(rows: &[T], run: &RunInfo) -> Result<Vec<u8>> {
    let path = Path::new(T::SPEC.name);
    let (schema, props) = schema_and_properties(T::SPEC, run).map_err(|e| table_write_err(path, e))?;
    let mut writer =
        ArrowWriter::try_new(Vec::new(), schema.clone(), Some(props)).map_err(|e| table_write_err(path, e))?;
    let batch = RecordBatch::try_new(schema, T::to_columns(rows)).map_err(|e| table_write_err(path, e))?;
    writer.write(&batch).map_err(|e| table_write_err(path, e))?;
    writer.into_inner().map_err(|e| table_write_err(path, e))
}

/// Encoded bytes a [`TableWriter`] buffers before it writes them to the
/// file as a row group.
pub const ROW_GROUP_BYTES: usize = 64 << 20;

/// Writes one partition of one table; nothing appears until [`TableWriter::finish`].
/// Rows may come in any number of calls; memory stays near [`ROW_GROUP_BYTES`].
pub struct TableWriter {
    spec: &'static TableSpec,
    schema: Arc<arrow_schema::Schema>,
    file: AtomicFile,
    overwrite: Overwrite,
    writer: ArrowWriter<BufWriter<File>>,
    rows: u64,
}

impl TableWriter {
    /// Starts `<root>/<table>/sequence=<id>/part-0.parquet`.
    pub fn create(
        root: &Path,
        spec: &'static TableSpec,
        sequence_id: &str,
        run: &RunInfo,
        overwrite: Overwrite,
    ) -> Result<Self> {
        let path = table_path(root, spec.name, sequence_id)?;
        let file = AtomicFile::create(&path, overwrite)?;
        let (schema, props) = schema_and_properties(spec, run).map_err(|e| table_write_err(&path, e))?;
        let writer =
            ArrowWriter::try_new(file.writer()?, schema.clone(), Some(props)).map_err(|e| table_write_err(&path, e))?;
        Ok(Self { spec, schema, file, overwrite, writer, rows: 0 })
    }

    /// Appends rows.
    pub fn write<T: TableRow>(&mut self, rows: &[T]) -> Result<()> {
        let path = self.file.target().to_path_buf();
        if T::SPEC.name != self.spec.name {
            return Err(table_write_err(
                &path,
                format!("rows of table {} written to table {}", T::SPEC.name, self.spec.name),
            ));
        }
        let batch =
            RecordBatch::try_new(self.schema.clone(), T::to_columns(rows)).map_err(|e| table_write_err(&path, e))?;
        self.writer.write(&batch).map_err(|e| table_write_err(&path, e))?;
        // Bounded memory for tables written in many calls (radar scans of a
        // whole drive): the buffered row group goes to the file once it
        // holds ROW_GROUP_BYTES.
        if self.writer.in_progress_size() >= ROW_GROUP_BYTES {
            self.writer.flush().map_err(|e| table_write_err(&path, e))?;
        }
        self.rows += rows.len() as u64;
        Ok(())
    }

    /// Rows written so far.
    #[must_use]
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Completes the file and moves it into place.
    pub fn finish(self) -> Result<TableWriteSummary> {
        let overwrite = self.overwrite;
        let mut published = publish_tables(vec![self.stage()?], overwrite)?;
        published.pop().ok_or_else(|| table_write_err(Path::new(""), "no table published"))
    }

    /// Completes the file without moving it into place: it stays a partial
    /// output (removed when dropped) until [`publish_tables`] publishes it
    /// with the other tables of its run.
    pub fn stage(self) -> Result<StagedTable> {
        let path = self.file.target().to_path_buf();
        let inner = self.writer.into_inner().map_err(|e| table_write_err(&path, e))?;
        inner.into_inner().map_err(|e| IoError::Os { path: path.clone(), source: e.into_error() })?;
        Ok(StagedTable { file: self.file, rows: self.rows })
    }
}

/// A complete table file not yet at its path ([`TableWriter::stage`]).
#[derive(Debug)]
pub struct StagedTable {
    file: AtomicFile,
    rows: u64,
}

impl StagedTable {
    /// Where it will be published.
    #[must_use]
    pub fn target(&self) -> &Path {
        self.file.target()
    }
}

/// Publishes `tables` together, each synced to disk first: all of them or,
/// on an error, none ([`crate::atomic::commit_all`]).
///
/// # Errors
/// A table that exists meanwhile (with [`Overwrite::Refuse`]) or an OS error
/// of a sync or rename.
pub fn publish_tables(tables: Vec<StagedTable>, overwrite: Overwrite) -> Result<Vec<TableWriteSummary>> {
    let rows: Vec<u64> = tables.iter().map(|t| t.rows).collect();
    let paths = commit_all(tables.into_iter().map(|t| t.file).collect(), overwrite, Durability::Fsync)?;
    Ok(paths.into_iter().zip(rows).map(|(path, rows)| TableWriteSummary { path, rows }).collect())
}

/// Writes `rows` as one partition in one call.
pub fn write_table<T: TableRow>(
    root: &Path,
    sequence_id: &str,
    rows: &[T],
    run: &RunInfo,
    overwrite: Overwrite,
) -> Result<TableWriteSummary> {
    let mut writer = TableWriter::create(root, T::SPEC, sequence_id, run, overwrite)?;
    writer.write(rows)?;
    writer.finish()
}

/// Writes `rows` as one partition without publishing it
/// ([`TableWriter::stage`]).
pub fn stage_table<T: TableRow>(
    root: &Path,
    sequence_id: &str,
    rows: &[T],
    run: &RunInfo,
    overwrite: Overwrite,
) -> Result<StagedTable> {
    let mut writer = TableWriter::create(root, T::SPEC, sequence_id, run, overwrite)?;
    writer.write(rows)?;
    writer.stage()
}

fn table_write_err(path: &Path, e: impl std::fmt::Display) -> IoError {
    IoError::TableWrite { path: path.to_path_buf(), detail: e.to_string() }
}

fn corrupt(path: &Path, e: impl std::fmt::Display) -> IoError {
    IoError::CorruptTable { path: path.to_path_buf(), detail: e.to_string() }
}

/// Checks a file's Arrow schema against the spec: every column present with
/// the right type, no unknown columns.
fn check_schema(path: &Path, spec: &TableSpec, schema: &arrow_schema::Schema) -> Result<()> {
    for column in spec.columns {
        let field = schema.field_with_name(column.name).map_err(|_| IoError::MissingColumn {
            path: path.to_path_buf(),
            table: spec.name.to_string(),
            column: column.name.to_string(),
            expected: spec.column_list(),
        })?;
        if !column.ty.accepts(field.data_type()) {
            return Err(IoError::WrongColumnType {
                path: path.to_path_buf(),
                table: spec.name.to_string(),
                column: column.name.to_string(),
                expected: column.ty.doc_name().to_string(),
                found: field.data_type().to_string(),
            });
        }
    }
    if let Some(extra) = schema.fields().iter().find(|f| !spec.columns.iter().any(|c| c.name == f.name())) {
        return Err(IoError::UnknownColumn {
            path: path.to_path_buf(),
            table: spec.name.to_string(),
            column: extra.name().to_string(),
            expected: spec.column_list(),
        });
    }
    Ok(())
}

/// Reads all rows of one Parquet file of table `T`, validating the schema.
///
/// The file's record batches are joined before rows are built, so a record
/// that spans several rows (a track's points in `mpc_tracks`) is read whole
/// wherever the reader's batch boundaries fall, and errors give the row
/// number within the file.
pub fn read_table<T: TableRow>(path: &Path) -> Result<Vec<T>> {
    let file = File::open(path).map_err(os_err(path))?;
    let builder = ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| corrupt(path, e))?;
    check_schema(path, T::SPEC, builder.schema())?;
    let schema = builder.schema().clone();
    let reader = builder.build().map_err(|e| corrupt(path, e))?;
    let batches = reader.collect::<std::result::Result<Vec<_>, _>>().map_err(|e| corrupt(path, e))?;
    let batch = arrow_select::concat::concat_batches(&schema, &batches).map_err(|e| corrupt(path, e))?;
    let corrupt_table = |detail| IoError::CorruptTable { path: path.to_path_buf(), detail };
    for column in T::SPEC.columns.iter().filter(|c| !c.nullable) {
        check_no_nulls(&batch, column.name).map_err(corrupt_table)?;
    }
    T::from_columns(&Columns::new(&batch)).map_err(corrupt_table)
}

fn partitions(table_dir: &Path) -> Result<Vec<(String, PathBuf)>> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(table_dir).map_err(os_err(table_dir))? {
        let entry = entry.map_err(os_err(table_dir))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if let Some(sequence) = name.strip_prefix("sequence=") {
            let file = entry.path().join("part-0.parquet");
            if file.is_file() {
                found.push((sequence.to_string(), file));
            }
        }
    }
    found.sort();
    Ok(found)
}

/// Reads every `sequence=` partition of table `T` under `root`, by sequence.
pub fn read_table_dir<T: TableRow>(root: &Path) -> Result<BTreeMap<String, Vec<T>>> {
    let dir = root.join(T::SPEC.name);
    partitions(&dir)?.into_iter().map(|(sequence, file)| Ok((sequence, read_table::<T>(&file)?))).collect()
}

/// What `mmtrack inspect` reports about one table file.
#[derive(Debug, Clone, PartialEq)]
pub struct TableFileSummary {
    /// Table name.
    pub table: String,
    /// Sequence partition.
    pub sequence: String,
    /// File.
    pub path: PathBuf,
    /// Row count (from the footer).
    pub rows: i64,
    /// `name: type [unit]` per column.
    pub columns: Vec<String>,
    /// Smallest and largest `t_ns`, when the table has that column.
    pub t_ns_span: Option<(i64, i64)>,
    /// The file's `time_base` key (what `t_ns` counts from), when present.
    pub time_base: Option<String>,
    /// The file's `frame` key (the frame of its coordinates), when present.
    pub frame: Option<String>,
}

/// Summarises every table partition under `root` (a results directory) or,
/// when `root` is itself a table directory, its partitions.
pub fn inspect_table_dir(root: &Path) -> Result<Vec<TableFileSummary>> {
    let mut table_dirs = Vec::new();
    if !partitions(root)?.is_empty() {
        table_dirs.push(root.to_path_buf());
    } else {
        for entry in std::fs::read_dir(root).map_err(os_err(root))? {
            let entry = entry.map_err(os_err(root))?;
            if entry.path().is_dir() {
                table_dirs.push(entry.path());
            }
        }
        table_dirs.sort();
    }
    let mut out = Vec::new();
    for dir in table_dirs {
        let table = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        for (sequence, path) in partitions(&dir)? {
            out.push(summarise_file(&table, &sequence, &path)?);
        }
    }
    Ok(out)
}

/// Summarises one Parquet file: the table is named by its folder
/// `<table>/sequence=<id>/part-0.parquet` (a known table is checked against
/// its schema), any other file by its own name.
///
/// # Errors
/// An unreadable or corrupt file, or a known table whose schema differs.
pub fn inspect_table_file(path: &Path) -> Result<TableFileSummary> {
    let name = |p: Option<&Path>| p.and_then(Path::file_name).map(|n| n.to_string_lossy().into_owned());
    let parent = path.parent();
    match name(parent).as_deref().and_then(|n| n.strip_prefix("sequence=")) {
        Some(sequence) => {
            let table = name(parent.and_then(Path::parent)).unwrap_or_default();
            summarise_file(&table, sequence, path)
        }
        None => summarise_file(&name(Some(path)).unwrap_or_default(), "-", path),
    }
}

/// Summarises one partition; a table mmtrack knows (by directory name) is
/// also checked against its schema, so a missing or renamed column is an error.
fn summarise_file(table: &str, sequence: &str, path: &Path) -> Result<TableFileSummary> {
    let file = File::open(path).map_err(os_err(path))?;
    let builder = ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| corrupt(path, e))?;
    if let Some(spec) = super::ALL_TABLES.iter().find(|s| s.name == table) {
        check_schema(path, spec, builder.schema())?;
    }
    let rows = builder.metadata().file_metadata().num_rows();
    let key = |name: &str| {
        builder
            .metadata()
            .file_metadata()
            .key_value_metadata()
            .and_then(|kv| kv.iter().find(|e| e.key == name).and_then(|e| e.value.clone()))
    };
    let (time_base, frame) = (key("time_base"), key("frame"));
    let columns = builder
        .schema()
        .fields()
        .iter()
        .map(|f| match f.metadata().get("unit") {
            Some(unit) => format!("{}: {} [{unit}]", f.name(), f.data_type()),
            None => format!("{}: {}", f.name(), f.data_type()),
        })
        .collect();
    let has_time =
        builder.schema().field_with_name("t_ns").is_ok_and(|f| f.data_type() == &arrow_schema::DataType::Int64);
    let mut span: Option<(i64, i64)> = None;
    if has_time {
        let mask = parquet::arrow::ProjectionMask::columns(builder.parquet_schema(), ["t_ns"]);
        for batch in builder.with_projection(mask).build().map_err(|e| corrupt(path, e))? {
            let batch = batch.map_err(|e| corrupt(path, e))?;
            let columns = Columns::new(&batch);
            let t = columns.array::<arrow_array::Int64Array>("t_ns").map_err(|d| corrupt(path, d))?;
            for v in t.iter().flatten() {
                span = Some(span.map_or((v, v), |(a, b)| (a.min(v), b.max(v))));
            }
        }
    }
    Ok(TableFileSummary {
        table: table.to_string(),
        sequence: sequence.to_string(),
        path: path.to_path_buf(),
        rows,
        columns,
        t_ns_span: span,
        time_base,
        frame,
    })
}
