//! Comma-separated text with a header line, as the Oxford SDK files use:
//! columns found by name (order does not matter), required ones checked up
//! front, and every field error naming the file, the line and the column. A
//! header without a single data row is an error: every such file (ground
//! truth, GNSS, INS) is a record of something, and an empty one means a
//! truncated or mis-exported file, not an empty drive. A UTF-8 byte order
//! mark before the header (Excel and other Windows tools write one) is not
//! part of the first column's name.

use std::collections::HashMap;
use std::path::Path;

use crate::IngestError;

/// `text` without a leading UTF-8 byte order mark (U+FEFF).
pub(crate) fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// One data line, with typed access by column name.
pub struct CsvRow<'a> {
    path: &'a Path,
    line: usize,
    fields: Vec<&'a str>,
    columns: &'a HashMap<&'a str, usize>,
}

impl CsvRow<'_> {
    /// An error about `field` of this line.
    pub fn bad(&self, field: &str, detail: String) -> IngestError {
        IngestError::BadRecord {
            path: self.path.to_path_buf(),
            record: format!("line {}", self.line),
            field: field.into(),
            detail,
        }
    }

    /// The raw text of a column.
    pub fn text(&self, name: &str) -> Result<&str, IngestError> {
        self.columns.get(name).and_then(|&i| self.fields.get(i).copied()).ok_or_else(|| {
            self.bad(name, format!("row has {} fields, header has {}", self.fields.len(), self.columns.len()))
        })
    }

    /// A finite number.
    pub fn finite(&self, name: &str) -> Result<f64, IngestError> {
        let raw = self.text(name)?;
        raw.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| self.bad(name, format!("'{raw}' is not a finite number")))
    }

    /// A finite number within a plausibility bound
    /// ([`mmtrack_core::plausible`]), e.g. `COORDINATE_M` for a position.
    pub fn bounded(&self, name: &str, bound: &mmtrack_core::plausible::Bound) -> Result<f64, IngestError> {
        let value = self.finite(name)?;
        bound.check(value).map_err(|e| self.bad(name, e.to_string()))
    }

    /// A positive UNIX time in microseconds, as nanoseconds.
    pub fn micros_ns(&self, name: &str) -> Result<i64, IngestError> {
        let raw = self.text(name)?;
        raw.parse::<i64>()
            .ok()
            .and_then(|us| us.checked_mul(1000))
            .filter(|t| *t > 0)
            .ok_or_else(|| self.bad(name, format!("'{raw}' is not a microsecond UNIX timestamp")))
    }
}

/// The header's columns, checked for `required`.
pub struct CsvTable<'a> {
    path: &'a Path,
    columns: HashMap<&'a str, usize>,
    body: Vec<(usize, &'a str)>,
}

impl<'a> CsvTable<'a> {
    /// Splits `text` into header and data lines; fails naming a missing
    /// column, or when there is no data line after the header.
    pub fn parse(path: &'a Path, text: &'a str, required: &[&str]) -> Result<Self, IngestError> {
        let mut lines = without_bom(text).lines().enumerate();
        let header = lines.next().map(|(_, l)| l).ok_or_else(|| IngestError::BadLayout {
            path: path.to_path_buf(),
            detail: "empty file: no header line".into(),
        })?;
        let columns: HashMap<&str, usize> = header.split(',').map(str::trim).enumerate().map(|(i, c)| (c, i)).collect();
        if let Some(missing) = required.iter().find(|name| !columns.contains_key(*name)) {
            return Err(IngestError::BadRecord {
                path: path.to_path_buf(),
                record: "line 1 (header)".into(),
                field: (*missing).into(),
                detail: format!("missing column; expected {}", required.join(", ")),
            });
        }
        let body: Vec<(usize, &str)> = lines.filter(|(_, l)| !l.trim().is_empty()).map(|(i, l)| (i + 1, l)).collect();
        if body.is_empty() {
            return Err(IngestError::BadLayout {
                path: path.to_path_buf(),
                detail: "no data rows after the header (line 1): the file holds nothing to ingest".into(),
            });
        }
        Ok(Self { path, columns, body })
    }

    /// Whether the header has a column.
    #[must_use]
    pub fn has(&self, name: &str) -> bool {
        self.columns.contains_key(name)
    }

    /// The data lines, in order.
    pub fn rows(&self) -> impl Iterator<Item = CsvRow<'_>> {
        self.body.iter().map(|&(line, text)| CsvRow {
            path: self.path,
            line,
            fields: text.split(',').map(str::trim).collect(),
            columns: &self.columns,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_header_without_rows_is_an_error() {
        let path = Path::new("gt/radar_odometry.csv");
        for text in ["a,b\n", "a,b\n\n  \n", "a,b"] {
            let err = CsvTable::parse(path, text, &["a"]).err().map(|e| e.to_string()).unwrap_or_default();
            assert!(err.contains("gt/radar_odometry.csv") && err.contains("no data rows after the header"), "{err}");
        }
        assert_eq!(CsvTable::parse(path, "a,b\n1,2\n", &["a"]).unwrap().rows().count(), 1);
    }

    #[test]
    fn a_byte_order_mark_is_not_part_of_the_first_column() {
        let path = Path::new("gps.csv");
        let table = CsvTable::parse(path, "\u{feff}timestamp,b\n1,2\n", &["timestamp"]).unwrap();
        assert!(table.has("timestamp"));
        let err = CsvTable::parse(path, "\u{feff}time,b\n1,2\n", &["timestamp"]).err().unwrap().to_string();
        assert!(err.starts_with("gps.csv: line 1 (header): timestamp: missing column"), "{err}");
    }
}
