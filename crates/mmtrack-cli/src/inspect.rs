//! `mmtrack inspect <recording.mcap | table dir>`.

use std::borrow::Cow;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use mmtrack_core::error::printable;
use mmtrack_io::recording::{RecordingSummary, inspect_recording_with_progress};
use mmtrack_io::table::{TableFileSummary, inspect_table_dir, inspect_table_file};
use serde_json::json;

#[derive(Args)]
pub struct InspectArgs {
    /// An MCAP file (ours or any other, e.g. a ROS 2 bag), a directory of Parquet tables, or one `.parquet` file.
    path: PathBuf,
    /// Print JSON instead of text (metadata values whole; the text output shortens long ones).
    #[arg(long)]
    json: bool,
}

impl InspectArgs {
    /// Text output for `path`.
    pub fn new(path: PathBuf) -> Self {
        Self { path, json: false }
    }
}

/// Metadata values longer than this (in characters) are shortened in the
/// text output: a recording's `sounder.pulse_spectrum` runs to kilobytes.
const MAX_SHOWN_VALUE_CHARS: usize = 120;

/// Characters kept of a shortened metadata value.
const SHORTENED_VALUE_CHARS: usize = 80;

/// A metadata value as the text output shows it: control characters
/// escaped, and a long value cut to its first [`SHORTENED_VALUE_CHARS`]
/// characters with its length and where to get it whole.
fn shown_value(value: &str) -> Cow<'_, str> {
    let shown = printable(value);
    if shown.chars().count() <= MAX_SHOWN_VALUE_CHARS {
        return shown;
    }
    let head: String = shown.chars().take(SHORTENED_VALUE_CHARS).collect();
    Cow::Owned(format!("{head}… ({} bytes; `--json` prints it whole)", value.len()))
}

/// Nanoseconds since 1970-01-01 UTC as `YYYY-MM-DD HH:MM:SS UTC` (what a
/// viewer that shows dates shows for this log time).
fn utc(ns: i64) -> String {
    mmtrack_core::calendar::utc_text(ns.div_euclid(1_000_000_000))
}

/// Where the recording's first time lies: a UTC date when its time base
/// dates its times (UNIX time, a scenario's stated date), else the time
/// base's name (sim time or a relative log shown as a date would read as
/// 1970).
fn start_words(summary: &RecordingSummary, start_ns: u64) -> String {
    use mmtrack_io::recording::{METADATA_NAME, TimeBase};
    let time_base =
        summary.metadata.get(METADATA_NAME).and_then(|m| m.get("time_base")).and_then(|t| TimeBase::parse(t));
    match time_base {
        Some(TimeBase::SimTime | TimeBase::Relative) => {
            format!("time_base = {}: not a date", time_base.map_or("", TimeBase::as_str))
        }
        _ => format!("from {}", utc(i64::try_from(start_ns).unwrap_or(i64::MAX))),
    }
}

fn seconds(ns: u64) -> f64 {
    ns as f64 * 1e-9
}

fn recording_json(summary: &RecordingSummary) -> serde_json::Value {
    json!({
        "path": summary.path,
        "metadata": summary.metadata,
        "channels": summary.channels.iter().map(|c| json!({
            "topic": c.topic,
            "schema": c.schema_name,
            "message_encoding": c.message_encoding,
            "messages": c.message_count,
            "start_ns": c.start_ns,
            "end_ns": c.end_ns,
        })).collect::<Vec<_>>(),
    })
}

fn print_recording(summary: &RecordingSummary) {
    println!("recording {}", summary.path.display());
    for (name, map) in &summary.metadata {
        println!("  metadata {}:", printable(name));
        for (k, v) in map {
            println!("    {} = {}", printable(k), shown_value(v));
        }
    }
    let start = summary.channels.iter().map(|c| c.start_ns).min();
    let end = summary.channels.iter().map(|c| c.end_ns).max();
    if let (Some(start), Some(end)) = (start, end) {
        println!("  time span: {:.3} s ({start} .. {end} ns; {})", seconds(end - start), start_words(summary, start));
    }
    let topic_width = summary.channels.iter().map(|c| c.topic.len()).max().unwrap_or(0).max(5);
    let schema_width = summary.channels.iter().map(|c| c.schema_name.len()).max().unwrap_or(0).max(6);
    println!("  {:<topic_width$} {:<schema_width$} {:>9} {:>12}", "topic", "schema", "messages", "span [s]");
    for c in &summary.channels {
        println!(
            "  {:<topic_width$} {:<schema_width$} {:>9} {:>12.3}",
            printable(&c.topic),
            printable(&c.schema_name),
            c.message_count,
            seconds(c.end_ns - c.start_ns)
        );
    }
}

fn tables_json(tables: &[TableFileSummary]) -> serde_json::Value {
    json!(
        tables
            .iter()
            .map(|t| json!({
                "table": t.table, "sequence": t.sequence, "path": t.path, "rows": t.rows,
                "columns": t.columns, "t_ns_span": t.t_ns_span, "time_base": t.time_base, "frame": t.frame,
            }))
            .collect::<Vec<_>>()
    )
}

fn print_tables(root: &std::path::Path, tables: &[TableFileSummary]) {
    println!("tables under {}", root.display());
    for t in tables {
        let span = t.t_ns_span.map(|(a, b)| format!(", {:.3} s", (b - a) as f64 * 1e-9)).unwrap_or_default();
        println!("  {} / sequence={}: {} rows{span}", t.table, t.sequence, t.rows);
        if t.time_base.is_some() || t.frame.is_some() {
            let shown =
                |v: &Option<String>| v.as_deref().map_or_else(|| "-".to_string(), |v| printable(v).into_owned());
            println!("    time base: {}, frame: {}", shown(&t.time_base), shown(&t.frame));
        }
        for c in &t.columns {
            println!("      {c}");
        }
    }
}

pub fn run(args: &InspectArgs, quiet: bool) -> anyhow::Result<ExitCode> {
    let is_parquet = args.path.extension().is_some_and(|e| e.eq_ignore_ascii_case("parquet"));
    if args.path.is_dir() || is_parquet {
        let tables = if is_parquet { vec![inspect_table_file(&args.path)?] } else { inspect_table_dir(&args.path)? };
        if tables.is_empty() {
            anyhow::bail!(
                "{}: no Parquet tables found (expected <table>/sequence=<id>/part-0.parquet)",
                args.path.display()
            );
        }
        if args.json {
            println!("{}", tables_json(&tables));
        } else {
            print_tables(&args.path, &tables);
        }
    } else {
        let bar = crate::progress::bytes_bar(std::fs::metadata(&args.path).map_or(0, |m| m.len()), "inspect", quiet);
        let summary = inspect_recording_with_progress(&args.path, &mut |done, total| {
            bar.set_length(total);
            bar.set_position(done);
        });
        bar.finish_and_clear();
        let summary = summary?;
        if args.json {
            println!("{}", recording_json(&summary));
        } else {
            print_recording(&summary);
        }
    }
    Ok(ExitCode::SUCCESS)
}
